// The GL pass of Mitchell 2007's radial blur (crep/postfx/gpu_radial_blur.h; rules in
// crep/postfx/radial_blur.h). Shaders: passes/postfx/radial_source.comp, passes/postfx/radial_blur.comp,
// crep/radial_blur.glsl, crep/march.glsl.
#include <crep/core/error.h>
#include <crep/core/shader_library.h>
#include <crep/postfx/gpu_radial_blur.h>
#include <crep/scatter/gpu_world_march.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <string>
#include <vector>

namespace crep {

namespace gpu {

// The per-frame constants of Mitchell 2007, Eq. 4 (averaged over its n + 1 terms) and the fade.
RadialBlurParams makeRadialBlurParams(const RadialBlurOptions& o, const RadialLight& sun, int width,
                                      int height) {
  const glm::ivec2 source = radialSourceSize(width, height, o.sourceScale);
  RadialBlurParams p;
  p.light =
      glm::vec4(static_cast<float>(sun.uv.x), static_cast<float>(sun.uv.y), static_cast<float>(sun.fade),
                static_cast<float>(o.exposure * o.weight / (o.samples + 1)));
  if (sun.fade <= 0.0) p.light = glm::vec4(0.0f); // nothing is added (and no uv far away reaches the GPU)
  p.shape = glm::vec4(static_cast<float>(o.decay), static_cast<float>(o.density / o.samples), 0.0f, 0.0f);
  p.info = glm::ivec4(o.samples, o.sourceScale, source.x, source.y);
  return p;
}

} // namespace gpu

RadialBlurPass::RadialBlurPass(const CreateInfo& info) : info_(info) {
  crep::validate(info.options, "RadialBlurPass::CreateInfo.options");
  // 32 x 32 = 1024 invocations: the smallest GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS GL 4.5 guarantees.
  if (info.workgroupSize < 1 || info.workgroupSize > 32)
    throw InvalidArgument("RadialBlurPass::CreateInfo.workgroupSize", detail::formatValue(info.workgroupSize),
                          "must be in [1, 32]");
  const std::vector<ShaderDefine> defines = {{"CREP_RADIAL_GROUP", std::to_string(info.workgroupSize)}};
  std::vector<ShaderDefine> blurDefines = defines;
  if (info.options.mode == RadialBlurMode::OcclusionFraction)
    blurDefines.push_back({"CREP_RADIAL_FRACTION", "1"});
  sourceProgram_ = buildProgram({{ShaderStage::Compute, "passes/postfx/radial_source.comp", defines}});
  blurProgram_ = buildProgram({{ShaderStage::Compute, "passes/postfx/radial_blur.comp", blurDefines}});
  marchParams_ = gl::createDynamicBuffer(sizeof(gpu::MarchParams));
  radialParams_ = gl::createDynamicBuffer(sizeof(gpu::RadialBlurParams));
  nearest_ = gl::createClampSampler(GL_NEAREST);
  linear_ = gl::createClampSampler(GL_LINEAR);
  gl::checkError("RadialBlurPass");
}

void RadialBlurPass::validate(const FrameAttribs& f, std::string_view owner) const {
  const std::string p = std::string(owner) + ".";
  if (!f.camera) invalid(p + "camera", "null", "must be set");
  if (!f.light) invalid(p + "light", "null", "must be set");
  if (!f.medium) invalid(p + "medium", "null", "must be set");
  const gl::TextureLevel depth = gl::requireTexture2D((p + "cameraDepth").c_str(), f.cameraDepth);
  gl::requireDepthFormat((p + "cameraDepth").c_str(), f.cameraDepth);
  gl::requireTexture2D((p + "output").c_str(), f.output, depth.width, depth.height, GL_RGBA32F);
}

void RadialBlurPass::run(const FrameAttribs& f) {
  validate(f);
  const gl::TextureLevel depth = gl::textureLevel("RadialBlurPass::FrameAttribs.cameraDepth", f.cameraDepth);
  const int width = depth.width, height = depth.height;
  const RadialBlurOptions& o = info_.options;
  const glm::ivec2 size = radialSourceSize(width, height, o.sourceScale);
  if (!source_ || size.x != sourceWidth_ || size.y != sourceHeight_) {
    // Exactly the source's size: the bilinear reads clamp at its true edge (crep::radialBilinear).
    // RGBA32F keeps the GPU within float rounding of the CPU reference; RGBA16F would halve the blur's
    // bandwidth on a GPU at ~1e-3 relative error.
    source_ =
        gl::createTexture2D(GL_RGBA32F, size.x, size.y, "RadialBlurPass source (cameraDepth / sourceScale)");
    sourceWidth_ = size.x;
    sourceHeight_ = size.y;
  }
  lastLight_ = radialLight(*f.camera, *f.light, o.fadeMargin);

  const gpu::MarchParams march = gpu::makeMarchParams(*f.camera, *f.light, *f.medium, width, height, 0, 0);
  const gpu::RadialBlurParams radial = gpu::makeRadialBlurParams(o, lastLight_, width, height);
  glNamedBufferSubData(marchParams_.get(), 0, sizeof march, &march);
  glNamedBufferSubData(radialParams_.get(), 0, sizeof radial, &radial);
  const auto groups = [&](int n) {
    return static_cast<GLuint>((n + info_.workgroupSize - 1) / info_.workgroupSize);
  };

  // The occlusion pre-pass (Mitchell 2007, Sec. 13.5.1) into the source.
  glUseProgram(sourceProgram_.get());
  glBindBufferBase(GL_UNIFORM_BUFFER, CREP_RADIAL_MARCH_BINDING, marchParams_.get());
  glBindBufferBase(GL_UNIFORM_BUFFER, CREP_RADIAL_BLUR_BINDING, radialParams_.get());
  glBindTextureUnit(CREP_RADIAL_CAMERA_DEPTH_UNIT, f.cameraDepth);
  glBindSampler(CREP_RADIAL_CAMERA_DEPTH_UNIT, nearest_.get());
  glBindImageTexture(CREP_RADIAL_SOURCE_OUT_IMAGE, source_.get(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glDispatchCompute(groups(size.x), groups(size.y), 1);
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);

  // The blur (Mitchell 2007, Eq. 4, Sec. 13.4) into the output.
  glUseProgram(blurProgram_.get());
  glBindTextureUnit(CREP_RADIAL_SOURCE_UNIT, source_.get());
  glBindSampler(CREP_RADIAL_SOURCE_UNIT, linear_.get());
  glBindImageTexture(CREP_RADIAL_SCATTERING_OUT_IMAGE, f.output, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glDispatchCompute(groups(width), groups(height), 1);
  gl::passOutputBarrier();
  gl::unbindPassState(2);
  gl::checkError("RadialBlurPass::run");
}

} // namespace crep
