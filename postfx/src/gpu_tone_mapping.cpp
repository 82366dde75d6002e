// The GL tone-mapping pass (crep/postfx/gpu_tone_mapping.h): log-average luminance (Reinhard et al. 2002,
// Eq. 1) by a two-pass reduction, light adaptation (Pattanaik et al. 2000 as in Yusov's demo) and the
// operators of glsl/crep/tone_mapping.glsl. Shaders: passes/postfx/luminance_reduce.comp,
// passes/postfx/luminance_adapt.comp, passes/tone_map.comp.
#include <crep/core/error.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/shader_library.h>
#include <crep/postfx/gpu_tone_mapping.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace crep {

namespace {

constexpr const char* kOwner = "ToneMapPass::CreateInfo.options";

} // namespace

ToneMapPass::ToneMapPass(const CreateInfo& info) : info_(info) {
  crep::validate(info.options, kOwner);
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  gpu::Backend& b = *backend_;
  b.prepareProgram("passes/postfx/luminance_reduce.comp", {});
  b.prepareProgram("passes/postfx/luminance_adapt.comp", {});
  params_ = gpu::Buffer(b, sizeof(gpu::ToneMapParams), "ToneMapPass: parameters");
  // The state starts zeroed: valid = 0, so the first reduced frame sets the adapted luminance.
  state_ = gpu::Buffer(b, sizeof(gpu::ToneMapState), "ToneMapPass: adaptation state");
  const gpu::ToneMapState zero{};
  b.writeBuffer(state_.id(), 0, std::as_bytes(std::span(&zero, 1)));
  const ShaderStageSource stage = toneMapStage(false); // compile errors surface at construction
  b.prepareProgram(stage.path, stage.defines);
}

void ToneMapPass::setOptions(const ToneMapOptions& options) {
  crep::validate(options, "ToneMapPass::options");
  info_.options = options;
}

ShaderStageSource ToneMapPass::toneMapStage(bool rgba8) const {
  return {ShaderStage::Compute,
          "passes/postfx/tone_map.comp",
          {{"CREP_TONE_MAP_OPERATOR", std::to_string(static_cast<int>(info_.options.op))},
           {"CREP_TONE_MAP_FORMAT", rgba8 ? "rgba8" : "rgba32f"},
           {"CREP_TONE_MAP_SRGB", info_.encodeSrgb ? "1" : "0"}}};
}

void ToneMapPass::validate(const FrameAttribs& f, std::string_view owner) const {
  const std::string p = std::string(owner) + ".";
  const gpu::Backend& b = *backend_;
  const gpu::TextureLevel in = gpu::requireTexture2DOf(b, (p + "input").c_str(), f.input);
  if (in.format != gpu::Format::RGBA32F && in.format != gpu::Format::RGBA16F)
    invalid(p + "input", in.format ? gpu::formatName(*in.format) : "another format",
            "must be RGBA32F or RGBA16F");
  if (f.output == f.input) invalid(p + "output", std::to_string(f.output), "must not be the input texture");
  const gpu::TextureLevel out = gpu::requireTexture2DOf(b, (p + "output").c_str(), f.output);
  if (out.format != gpu::Format::RGBA8 && out.format != gpu::Format::RGBA32F)
    invalid(p + "output", out.format ? gpu::formatName(*out.format) : "another format",
            "must be RGBA8 or RGBA32F");
  if (out.width != in.width || out.height != in.height)
    invalid(p + "output", std::to_string(out.width) + "x" + std::to_string(out.height),
            "must be the input's size " + std::to_string(in.width) + "x" + std::to_string(in.height));
  requireNonNegative(p + "dt", f.dt);
}

void ToneMapPass::run(const FrameAttribs& f) {
  validate(f);
  gpu::Backend& b = *backend_;
  const gpu::TextureLevel in = gpu::textureLevelOf(b, "ToneMapPass::FrameAttribs.input", f.input);
  const gpu::TextureLevel out = gpu::textureLevelOf(b, "ToneMapPass::FrameAttribs.output", f.output);

  const ToneMapOptions& o = info_.options;
  const int groupsX = (in.width + kReductionTile - 1) / kReductionTile;
  const int groupsY = (in.height + kReductionTile - 1) / kReductionTile;
  gpu::ToneMapParams params;
  params.curve = glm::vec4(static_cast<float>(o.middleGrey), static_cast<float>(o.whitePoint),
                           static_cast<float>(o.saturation), static_cast<float>(o.exposure));
  // The exact step of the exponential lag for this dt, in double (adaptLuminance's factor).
  const double factor = o.adaptationTau == 0.0 ? 1.0 : -std::expm1(-f.dt / o.adaptationTau);
  params.adaptation = glm::vec4(static_cast<float>(factor), 0.0f, 0.0f, 0.0f);
  params.flags = glm::ivec4(o.autoExposure ? 1 : 0, f.resetAdaptation ? 1 : 0, groupsX * groupsY, 0);
  params.sizes = glm::ivec4(in.width, in.height, groupsX, groupsY);
  b.writeBuffer(params_.id(), 0, std::as_bytes(std::span(&params, 1)));

  const gpu::Resource block = gpu::Resource::uniform(CREP_TONE_MAP_PARAMS_BINDING, params_.id()),
                      state = gpu::Resource::storage(CREP_TONE_MAP_STATE_BINDING, state_.id()),
                      hdr = gpu::Resource::sampled(CREP_TONE_MAP_HDR_UNIT, f.input); // texelFetch, nearest
  if (o.autoExposure) {
    // The log-average luminance by tiles, then the adaptation of the state (one invocation).
    const std::size_t bytes = sizeof(gpu::LuminancePartial) * static_cast<std::size_t>(groupsX * groupsY);
    if (partials_.bytes() < bytes) partials_ = gpu::Buffer(b, bytes, "ToneMapPass: luminance partials");
    const gpu::Resource partials =
        gpu::Resource::storage(CREP_TONE_MAP_LUMINANCE_PARTIALS_BINDING, partials_.id(), 0, bytes);
    b.dispatch({"ToneMapPass::run (reduce)",
                "passes/postfx/luminance_reduce.comp",
                {},
                {hdr, block, partials},
                {},
                glm::uvec3(static_cast<unsigned>(groupsX), static_cast<unsigned>(groupsY), 1u)});
    b.dispatch({"ToneMapPass::run (adapt)",
                "passes/postfx/luminance_adapt.comp",
                {},
                {block, partials, state},
                {},
                glm::uvec3(1u)});
  }
  const ShaderStageSource stage = toneMapStage(out.format == gpu::Format::RGBA8);
  b.dispatch({"ToneMapPass::run",
              stage.path,
              stage.defines,
              {hdr, block, state,
               gpu::Resource::image(CREP_TONE_MAP_DISPLAY_IMAGE, f.output, gpu::Access::WriteOnly)},
              {},
              glm::uvec3(static_cast<unsigned>((in.width + 7) / 8),
                         static_cast<unsigned>((in.height + 7) / 8), 1u)});
}

gpu::ToneMapState ToneMapPass::readState() const {
  gpu::ToneMapState s;
  const std::vector<std::byte> bytes = backend_->readBuffer(state_.id(), 0, sizeof s);
  std::memcpy(&s, bytes.data(), sizeof s);
  return s;
}

} // namespace crep
