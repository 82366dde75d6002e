// The GL pass of Mitchell 2007's radial blur (crep/postfx/gpu_radial_blur.h; rules in
// crep/postfx/radial_blur.h). Shaders: passes/postfx/radial_source.comp, passes/postfx/radial_blur.comp,
// crep/radial_blur.glsl, crep/march.glsl.
#include <crep/core/error.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/shader_library.h>
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

namespace {
/// The blur's two programs (Mitchell 2007, Sec. 13.5.1 pre-pass and Eq. 4), in the CreateInfo's variant.
ShaderStageSource radialStage(const RadialBlurPass::CreateInfo& info, bool blur) {
  std::vector<ShaderDefine> defines = {{"CREP_RADIAL_GROUP", std::to_string(info.workgroupSize)}};
  if (blur && info.options.mode == RadialBlurMode::OcclusionFraction)
    defines.push_back({"CREP_RADIAL_FRACTION", "1"});
  return {ShaderStage::Compute, blur ? "passes/postfx/radial_blur.comp" : "passes/postfx/radial_source.comp",
          defines};
}
} // namespace

RadialBlurPass::RadialBlurPass(const CreateInfo& info) : info_(info) {
  crep::validate(info.options, "RadialBlurPass::CreateInfo.options");
  // 32 x 32 = 1024 invocations: the smallest GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS GL 4.5 guarantees.
  if (info.workgroupSize < 1 || info.workgroupSize > 32)
    throw InvalidArgument("RadialBlurPass::CreateInfo.workgroupSize", detail::formatValue(info.workgroupSize),
                          "must be in [1, 32]");
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  for (const bool blur : {false, true}) {
    const ShaderStageSource stage = radialStage(info, blur);
    backend_->prepareProgram(stage.path, stage.defines);
  }
  marchParams_ = gpu::Buffer(*backend_, sizeof(gpu::MarchParams), "RadialBlurPass: march block");
  radialParams_ = gpu::Buffer(*backend_, sizeof(gpu::RadialBlurParams), "RadialBlurPass: blur block");
}

void RadialBlurPass::validate(const FrameAttribs& f, std::string_view owner) const {
  const std::string p = std::string(owner) + ".";
  if (!f.camera) invalid(p + "camera", "null", "must be set");
  if (!f.light) invalid(p + "light", "null", "must be set");
  if (!f.medium) invalid(p + "medium", "null", "must be set");
  const gpu::Backend& b = *backend_;
  const gpu::TextureLevel depth = gpu::requireTexture2DOf(b, (p + "cameraDepth").c_str(), f.cameraDepth);
  gpu::requireDepthFormatOf(b, (p + "cameraDepth").c_str(), f.cameraDepth);
  gpu::requireTexture2DOf(b, (p + "output").c_str(), f.output, depth.width, depth.height,
                          gpu::Format::RGBA32F);
}

void RadialBlurPass::run(const FrameAttribs& f) {
  validate(f);
  gpu::Backend& b = *backend_;
  const gpu::TextureLevel depth =
      gpu::textureLevelOf(b, "RadialBlurPass::FrameAttribs.cameraDepth", f.cameraDepth);
  const int width = depth.width, height = depth.height;
  const RadialBlurOptions& o = info_.options;
  const glm::ivec2 size = radialSourceSize(width, height, o.sourceScale);
  if (!source_ || size.x != sourceWidth_ || size.y != sourceHeight_) {
    // Exactly the source's size: the bilinear reads clamp at its true edge (crep::radialBilinear).
    // RGBA32F keeps the GPU within float rounding of the CPU reference; RGBA16F would halve the blur's
    // bandwidth on a GPU at ~1e-3 relative error.
    source_ = gpu::Texture(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, size.x, size.y, 1,
                               "RadialBlurPass source (cameraDepth / sourceScale)"});
    sourceWidth_ = size.x;
    sourceHeight_ = size.y;
  }
  lastLight_ = radialLight(*f.camera, *f.light, o.fadeMargin);

  const gpu::MarchParams march = gpu::makeMarchParams(*f.camera, *f.light, *f.medium, width, height, 0, 0);
  const gpu::RadialBlurParams radial = gpu::makeRadialBlurParams(o, lastLight_, width, height);
  b.writeBuffer(marchParams_.id(), 0, std::as_bytes(std::span(&march, 1)));
  b.writeBuffer(radialParams_.id(), 0, std::as_bytes(std::span(&radial, 1)));
  const auto groups = [&](int n) {
    return static_cast<unsigned>((n + info_.workgroupSize - 1) / info_.workgroupSize);
  };
  const auto dispatch = [&](bool blur, std::vector<gpu::Resource> resources, int w, int h) {
    const ShaderStageSource stage = radialStage(info_, blur);
    gpu::Dispatch d;
    d.label = blur ? "RadialBlurPass::run (blur)" : "RadialBlurPass::run (source)";
    d.program = stage.path;
    d.defines = stage.defines;
    d.resources = {gpu::Resource::uniform(CREP_RADIAL_MARCH_BINDING, marchParams_.id()),
                   gpu::Resource::uniform(CREP_RADIAL_BLUR_BINDING, radialParams_.id()),
                   gpu::Resource::sampled(CREP_RADIAL_CAMERA_DEPTH_UNIT, f.cameraDepth)};
    d.resources.insert(d.resources.end(), resources.begin(), resources.end());
    d.groups = glm::uvec3(groups(w), groups(h), 1u);
    b.dispatch(d);
  };
  // The occlusion pre-pass (Mitchell 2007, Sec. 13.5.1) into the source, then the blur (Eq. 4, Sec. 13.4)
  // into the output, reading the source bilinearly.
  dispatch(false, {gpu::Resource::image(CREP_RADIAL_SOURCE_OUT_IMAGE, source_.id(), gpu::Access::WriteOnly)},
           size.x, size.y);
  dispatch(true,
           {gpu::Resource::sampled(CREP_RADIAL_SOURCE_UNIT, source_.id(), gpu::Filter::Linear),
            gpu::Resource::image(CREP_RADIAL_SCATTERING_OUT_IMAGE, f.output, gpu::Access::WriteOnly)},
           width, height);
}

} // namespace crep
