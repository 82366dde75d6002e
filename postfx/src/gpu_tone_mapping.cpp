// The GL tone-mapping pass (crep/postfx/gpu_tone_mapping.h): log-average luminance (Reinhard et al. 2002,
// Eq. 1) by a two-pass reduction, light adaptation (Pattanaik et al. 2000 as in Yusov's demo) and the
// operators of glsl/crep/tone_mapping.glsl. Shaders: passes/postfx/luminance_reduce.comp,
// passes/postfx/luminance_adapt.comp, passes/tone_map.comp.
#include <crep/core/error.h>
#include <crep/core/shader_library.h>
#include <crep/postfx/gpu_tone_mapping.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <cmath>
#include <string>

namespace crep {

namespace {

constexpr const char* kOwner = "ToneMapPass::CreateInfo.options";

} // namespace

ToneMapPass::ToneMapPass(const CreateInfo& info) : info_(info) {
  crep::validate(info.options, kOwner);
  reduceProgram_ = buildProgram({{ShaderStage::Compute, "passes/postfx/luminance_reduce.comp", {}}});
  adaptProgram_ = buildProgram({{ShaderStage::Compute, "passes/postfx/luminance_adapt.comp", {}}});
  params_ = gl::createDynamicBuffer(sizeof(gpu::ToneMapParams));
  // The state starts zeroed: valid = 0, so the first reduced frame sets the adapted luminance.
  state_ = gl::createBuffer();
  const gpu::ToneMapState zero{};
  glNamedBufferStorage(state_.get(), sizeof zero, &zero, GL_DYNAMIC_STORAGE_BIT);
  // texelFetch through a nearest sampler: a caller's texture with a mipmapping filter and one level would
  // be incomplete (and read as zero) without it.
  sampler_ = gl::createClampSampler(GL_NEAREST);
  toneMapProgram(GL_RGBA32F); // compile errors surface at construction
  gl::checkError("ToneMapPass");
}

void ToneMapPass::setOptions(const ToneMapOptions& options) {
  crep::validate(options, "ToneMapPass::options");
  info_.options = options;
}

std::uint32_t ToneMapPass::toneMapProgram(std::uint32_t outputFormat) {
  const bool rgba8 = outputFormat == GL_RGBA8;
  const int key = static_cast<int>(info_.options.op) * 2 + (rgba8 ? 1 : 0);
  gl::Handle& program = toneMapPrograms_[key];
  if (!program)
    program = buildProgram({{ShaderStage::Compute,
                             "passes/postfx/tone_map.comp",
                             {{"CREP_TONE_MAP_OPERATOR", std::to_string(static_cast<int>(info_.options.op))},
                              {"CREP_TONE_MAP_FORMAT", rgba8 ? "rgba8" : "rgba32f"},
                              {"CREP_TONE_MAP_SRGB", info_.encodeSrgb ? "1" : "0"}}}});
  return program.get();
}

void ToneMapPass::validate(const FrameAttribs& f, std::string_view owner) const {
  const std::string p = std::string(owner) + ".";
  const gl::TextureLevel in = gl::requireTexture2D((p + "input").c_str(), f.input);
  if (in.internalFormat != GL_RGBA32F && in.internalFormat != GL_RGBA16F)
    invalid(p + "input", "internal format " + std::to_string(in.internalFormat),
            "must be GL_RGBA32F or GL_RGBA16F");
  if (f.output == f.input) invalid(p + "output", std::to_string(f.output), "must not be the input texture");
  const gl::TextureLevel out = gl::requireTexture2D((p + "output").c_str(), f.output);
  if (out.internalFormat != GL_RGBA8 && out.internalFormat != GL_RGBA32F)
    invalid(p + "output", "internal format " + std::to_string(out.internalFormat),
            "must be GL_RGBA8 or GL_RGBA32F");
  if (out.width != in.width || out.height != in.height)
    invalid(p + "output", std::to_string(out.width) + "x" + std::to_string(out.height),
            "must be the input's size " + std::to_string(in.width) + "x" + std::to_string(in.height));
  requireNonNegative(p + "dt", f.dt);
}

void ToneMapPass::run(const FrameAttribs& f) {
  validate(f);
  const gl::TextureLevel in = gl::textureLevel("ToneMapPass::FrameAttribs.input", f.input);
  const gl::TextureLevel out = gl::textureLevel("ToneMapPass::FrameAttribs.output", f.output);

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
  glNamedBufferSubData(params_.get(), 0, sizeof params, &params);

  const GLuint program = toneMapProgram(out.internalFormat);
  glBindBufferBase(GL_UNIFORM_BUFFER, CREP_TONE_MAP_PARAMS_BINDING, params_.get());
  glBindTextureUnit(CREP_TONE_MAP_HDR_UNIT, f.input);
  glBindSampler(CREP_TONE_MAP_HDR_UNIT, sampler_.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, CREP_TONE_MAP_STATE_BINDING, state_.get());
  if (o.autoExposure) {
    const std::size_t bytes = sizeof(gpu::LuminancePartial) * static_cast<std::size_t>(groupsX * groupsY);
    if (!partials_ || partialsCapacity_ < bytes) {
      partials_ = gl::createDynamicBuffer(bytes);
      partialsCapacity_ = bytes;
    }
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, CREP_TONE_MAP_LUMINANCE_PARTIALS_BINDING, partials_.get());
    glUseProgram(reduceProgram_.get());
    glDispatchCompute(static_cast<GLuint>(groupsX), static_cast<GLuint>(groupsY), 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    glUseProgram(adaptProgram_.get());
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  }
  glUseProgram(program);
  glBindImageTexture(CREP_TONE_MAP_DISPLAY_IMAGE, f.output, 0, GL_FALSE, 0, GL_WRITE_ONLY,
                     out.internalFormat);
  glDispatchCompute(static_cast<GLuint>((in.width + 7) / 8), static_cast<GLuint>((in.height + 7) / 8), 1);
  gl::passOutputBarrier();
  gl::unbindPassState(2);
  gl::checkError("ToneMapPass::run");
}

gpu::ToneMapState ToneMapPass::readState() const {
  gpu::ToneMapState s;
  glGetNamedBufferSubData(state_.get(), 0, sizeof s, &s);
  gl::checkError("ToneMapPass::readState");
  return s;
}

} // namespace crep
