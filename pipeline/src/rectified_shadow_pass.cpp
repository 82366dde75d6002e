#include <crep/core/error.h>
#include <crep/gpu/gl_state.h>
#include <crep/pipeline/rectified_shadow_pass.h>

#include <epoxy/gl.h>

#include <string>

namespace crep {

RectifiedShadowPass::RectifiedShadowPass(const CreateInfo& info) : info_(info) {
  gl::checkTextureSize("RectifiedShadowPass::CreateInfo.mapWidth/mapHeight", info.mapWidth, info.mapHeight);
  framebuffer_ = gl::createFramebuffer();
  glNamedFramebufferDrawBuffer(framebuffer_.get(), GL_NONE);
  glNamedFramebufferReadBuffer(framebuffer_.get(), GL_NONE);
  gl::checkError("RectifiedShadowPass: texture and framebuffer");
}

RectifiedShadowPass::~RectifiedShadowPass() = default;
RectifiedShadowPass::RectifiedShadowPass(RectifiedShadowPass&&) noexcept = default;
RectifiedShadowPass& RectifiedShadowPass::operator=(RectifiedShadowPass&&) noexcept = default;

std::size_t RectifiedShadowPass::memoryBytes() const noexcept {
  return texture_ ? static_cast<std::size_t>(info_.mapWidth) * static_cast<std::size_t>(info_.mapHeight) * 4
                  : 0;
}

void RectifiedShadowPass::validate(const FrameAttribs& frame, std::string_view owner) const {
  const std::string p = std::string(owner) + ".";
  const Rectification* r = frame.rectification;
  if (r == nullptr) invalid(p + "rectification", "null", "must be set");
  if (!r->projective())
    invalid(p + "rectification", r->message, "must be projective (else use the epipolar fallback)");
  if (r->layout != SplitLayout::Regions)
    invalid(p + "rectification", "SplitLayout::Layers",
            "must use SplitLayout::Regions (the splits side by side in one map)");
  if (!frame.drawCasters) invalid(p + "drawCasters", "empty", "must be set");
  const int W = info_.mapWidth, H = info_.mapHeight;
  if (W % r->splitCount() != 0)
    invalid("RectifiedShadowPass::CreateInfo.mapWidth", std::to_string(W),
            "must be a multiple of the split count " + std::to_string(r->splitCount()));
  if (frame.depthTexture != 0) gl::requireTexture2D((p + "depthTexture").c_str(), frame.depthTexture, W, H);
}

void RectifiedShadowPass::run(const FrameAttribs& frame) {
  gl::requireNotMovedFrom(framebuffer_, "RectifiedShadowPass");
  validate(frame);
  const Rectification* r = frame.rectification;
  const int W = info_.mapWidth, H = info_.mapHeight;
  if (frame.depthTexture == 0 && !texture_)
    texture_ = gl::createTexture2D(GL_DEPTH_COMPONENT32F, W, H,
                                   "RectifiedShadowPass::CreateInfo.mapWidth/mapHeight");
  const std::uint32_t target = frame.depthTexture != 0 ? frame.depthTexture : texture_.get();
  const GLuint fb = framebuffer_.get();
  glNamedFramebufferTexture(fb, GL_DEPTH_ATTACHMENT, target, 0);
  struct Detach { // the caller's texture is not kept attached, whatever leaves run()
    GLuint fb;
    ~Detach() { glNamedFramebufferTexture(fb, GL_DEPTH_ATTACHMENT, 0, 0); }
  } detach{fb};
  if (glCheckNamedFramebufferStatus(fb, GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    invalid("RectifiedShadowPass::FrameAttribs.depthTexture", std::to_string(target),
            "must have a depth format (GL_DEPTH_COMPONENT32F, 24 or 16)");
  }
  {
    // Every raster state the map depends on, whatever the caller left (docs/GL_STATE.md); restored after.
    gl::DepthPassScope scope(fb, W, H);
    const float one = 1.0f;
    glClearNamedFramebufferfv(fb, GL_DEPTH, 0, &one); // once, the whole map (the scissor box is the map)
    for (int k = 0; k < r->splitCount(); ++k) {
      const SplitViewport v = r->splitViewport(k, W, H);
      scope.setViewport(v.x, v.y, v.width, v.height); // and the scissor box: a clear stays inside split k
      frame.drawCasters(k, r->splits[static_cast<std::size_t>(k)].rectClipFromWorld);
    }
    scope.requireUnchanged("RectifiedShadowPass::FrameAttribs.drawCasters");
    gl::checkError("the rectified map drawn by RectifiedShadowPass::FrameAttribs.drawCasters");
  }
  gl::checkError("RectifiedShadowPass::run");
}

} // namespace crep
