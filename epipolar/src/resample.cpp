// Point resampling of a standard shadow map into a rectified map with blocker clamping (Klehm et al. 2014,
// Sec. 4.1); rules in crep/epipolar/resample.h. Shader: passes/epipolar_resample.comp.
#include <crep/core/error.h>
#include <crep/core/parallel.h>
#include <crep/core/shader_library.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_layout.h>
#include <crep/epipolar/resample.h>

#include <crep/scatter/gpu_layout_buffers.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace crep {

void validateLightMatrix(const glm::dmat4& M, const glm::dvec3& lightDirection) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(M[c][r]))
        throw InvalidArgument("lightClipFromWorld", detail::formatValue(M[c][r]), "must be finite");
  if (M[0][3] != 0.0 || M[1][3] != 0.0 || M[2][3] != 0.0 || M[3][3] == 0.0)
    throw InvalidArgument("lightClipFromWorld", "a perspective matrix",
                          "must be affine (an orthographic shadow matrix: last row 0 0 0 w)");
  if (std::abs(glm::determinant(M)) < 1e-300)
    throw InvalidArgument("lightClipFromWorld", "a singular matrix", "must be invertible");
  // The light direction must map to a pure depth increase: every light ray is one texel, and the depth
  // buffer keeps the occluder nearest to the light. The tolerance admits matrices stored in float (an
  // engine's): 1e-3 of the matrix scale moves a point 1e-3 texel-space units per unit of depth at most.
  const glm::dvec4 d = M * glm::dvec4(lightDirection, 0.0);
  const double scale =
      std::max({glm::length(glm::dvec3(M[0])), glm::length(glm::dvec3(M[1])), glm::length(glm::dvec3(M[2]))});
  if (!(std::hypot(d.x, d.y) <= 1e-3 * scale) || !(d.z > 0.0))
    throw InvalidArgument("lightClipFromWorld",
                          "light direction maps to clip (" + detail::formatValue(d.x) + ", " +
                              detail::formatValue(d.y) + ", " + detail::formatValue(d.z) + ")",
                          "must look along the light direction: (0, 0, > 0) expected");
}

// Sec. 4.1: point resampling over the texels of the rectified map, blockers clamped to the slice's range.
RectifiedMap resampleShadowMap(std::shared_ptr<const RectifiedLayout> layout, int width, int height,
                               const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                               const ResampleOptions& options) {
  if (!layout) throw InvalidArgument("resampleShadowMap.layout", "null", "must be set");
  if (width <= 0 || height <= 0 || width > Image::kMaxDimension || height > Image::kMaxDimension ||
      width % layout->regionCount() != 0)
    throw InvalidArgument("resampleShadowMap.size", std::to_string(width) + " x " + std::to_string(height),
                          "must be positive, <= " + std::to_string(Image::kMaxDimension) +
                              ", the width a multiple of the region count " +
                              std::to_string(layout->regionCount()));
  if (const auto* e = dynamic_cast<const EpipolarLayout*>(layout.get()); e && e->sliceCount() != height)
    throw InvalidArgument("resampleShadowMap.size", "height " + std::to_string(height),
                          "must be the EpipolarLayout's slice count " + std::to_string(e->sliceCount()));
  if (options.threads < 0)
    throw InvalidArgument("ResampleOptions.threads", detail::formatValue(options.threads), "must be >= 0");
  if (shadowDepth.empty() || shadowDepth.channels() != 1)
    throw InvalidArgument(
        "shadowDepth", shadowDepth.empty() ? "empty" : std::to_string(shadowDepth.channels()) + " channels",
        "must be a 1-channel depth image");
  const int Ws = shadowDepth.width(), Hs = shadowDepth.height();
  for (int j = 0; j < Hs; ++j)
    for (int i = 0; i < Ws; ++i)
      if (std::isnan(shadowDepth.at(i, j)))
        throw InvalidArgument("shadowDepth",
                              "texel (" + std::to_string(i) + ", " + std::to_string(j) + ") = NaN",
                              "depth-buffer values must not be NaN");
  const RectifiedLayout& L = *layout;
  validateLightMatrix(lightClipFromWorld, L.lightRay(0.5, 0.5).direction);
  const glm::dmat4 worldFromClip = glm::inverse(lightClipFromWorld);

  Image depth(width, height, 1, 1.0f);
  parallelRows(height, options.threads, [&](int j) {
    const double row = (j + 0.5) / height;
    for (int i = 0; i < width; ++i) {
      const LightRay ray = L.lightRay((i + 0.5) / width, row);
      const glm::dvec4 q = lightClipFromWorld * glm::dvec4(ray.origin, 1.0);
      const double x = q.x / q.w, y = q.y / q.w;
      if (!(x >= -1.0 && x <= 1.0 && y >= -1.0 && y <= 1.0)) continue;
      const int si = std::min(static_cast<int>((x + 1.0) * 0.5 * Ws), Ws - 1);
      const int sj = std::min(static_cast<int>((y + 1.0) * 0.5 * Hs), Hs - 1);
      const double d = shadowDepth.at(si, sj);
      if (d >= 1.0) continue;
      const glm::dvec4 h = worldFromClip * glm::dvec4(x, y, 2.0 * d - 1.0, 1.0);
      try {
        depth.at(i, j) = static_cast<float>(std::clamp(L.toRectified(glm::dvec3(h) / h.w).depth, 0.0, 1.0));
      } catch (const InvalidArgument&) {
        // An occluder the layout cannot map (on the light axis through the camera): nothing stored.
      }
    }
  });
  return makeRectifiedMap(std::move(layout), std::move(depth));
}

// ---------------------------------------------------------------------------------------------------
// ShadowResamplePass

ShadowResamplePass::ShadowResamplePass(const CreateInfo& info) : info_(info) {
  gl::checkTextureSize("ShadowResamplePass::CreateInfo.mapWidth/mapHeight", info.mapWidth, info.mapHeight);
  params_ = gl::createDynamicBuffer(sizeof(gpu::MarchParams));
  sampler_ = gl::createClampSampler(GL_NEAREST);
  gl::checkError("ShadowResamplePass");
}

void ShadowResamplePass::run(const FrameAttribs& f) {
  if (!f.layout) throw InvalidArgument("ShadowResamplePass::FrameAttribs.layout", "null", "must be set");
  const int W = info_.mapWidth, H = info_.mapHeight;
  if (W % f.layout->regionCount() != 0)
    throw InvalidArgument("ShadowResamplePass::CreateInfo.mapWidth/mapHeight", std::to_string(W),
                          "must be a multiple of the layout's region count " +
                              std::to_string(f.layout->regionCount()));
  if (const auto* e = dynamic_cast<const EpipolarLayout*>(f.layout); e && e->sliceCount() != H)
    throw InvalidArgument("ShadowResamplePass::CreateInfo.mapWidth/mapHeight", "height " + std::to_string(H),
                          "must be the EpipolarLayout's slice count " + std::to_string(e->sliceCount()));
  const gl::TextureLevel shadow =
      gl::requireTexture2D("ShadowResamplePass::FrameAttribs.shadowMap", f.shadowMap);
  gl::requireTexture2D("ShadowResamplePass::FrameAttribs.output", f.output, W, H, GL_R32F);
  validateLightMatrix(f.lightClipFromWorld, f.layout->lightRay(0.5, 0.5).direction);

  const gpu::LayoutKind kind = layoutBuffers_.upload(*f.layout, H);
  gl::Handle& program = programs_[static_cast<int>(kind)];
  if (!program)
    program = buildProgram({{ShaderStage::Compute,
                             "passes/epipolar_resample.comp",
                             {{"CREP_LAYOUT", std::to_string(static_cast<int>(kind))}}}});
  gpu::MarchParams params;
  params.sizes = glm::ivec4(shadow.width, shadow.height, W, H);
  params.lightClipFromWorld = glm::mat4(f.lightClipFromWorld);
  glNamedBufferSubData(params_.get(), 0, sizeof(params), &params);
  const glm::mat4 worldFromClip(glm::inverse(f.lightClipFromWorld));

  const GLuint p = program.get();
  glUseProgram(p);
  glProgramUniformMatrix4fv(p, 0, 1, GL_FALSE, &worldFromClip[0][0]);
  glBindBufferBase(GL_UNIFORM_BUFFER, 0, params_.get());
  layoutBuffers_.bind(1, 1);
  glBindTextureUnit(0, f.shadowMap);
  glBindSampler(0, sampler_.get());
  glBindImageTexture(0, f.output, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
  glDispatchCompute(static_cast<GLuint>((W + 7) / 8), static_cast<GLuint>((H + 7) / 8), 1);
  gl::passOutputBarrier();
  gl::unbindPassState(2);
  gl::checkError("ShadowResamplePass::run");
}

} // namespace crep
