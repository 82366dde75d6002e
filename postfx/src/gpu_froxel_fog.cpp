// The froxel fog's GL passes and front door (crep/postfx/gpu_froxel_fog.h; Wronski 2014, "Volumetric
// Fog"). Shaders: passes/postfx/esm_downsample.comp, passes/postfx/esm_blur.comp,
// passes/postfx/froxel_light.comp, passes/postfx/froxel_accumulate.comp, passes/postfx/froxel_temporal.comp,
// passes/postfx/froxel_apply.comp, crep/froxel.glsl.
#include <crep/gpu/checks.h>
#include <crep/postfx/gpu_froxel_fog.h>

#include <crep/core/error.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/shader_library.h>
#include <crep/scatter/gpu_world_march.h>
#include <crep/scatter/ray.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <cmath>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace crep {

namespace gpu {

FroxelCamera froxelCamera(const Camera& camera) {
  const GpuCamera c = gpuCamera(camera);
  return {c.position, c.forward, c.right, c.up, c.center};
}

} // namespace gpu

namespace {

std::string name(const char* owner, const char* field) {
  return std::string(owner) + "." + field;
}

const char* formatQualifier(std::uint32_t format) {
  return format == GL_RGBA32F ? "rgba32f" : "rgba16f";
}

gpu::Format froxelFormat(std::uint32_t format) {
  return format == GL_RGBA32F ? gpu::Format::RGBA32F : gpu::Format::RGBA16F;
}

/// A froxel program in the volume's format.
std::vector<ShaderDefine> formatDefines(std::uint32_t format) {
  return {{"CREP_FROXEL_FORMAT", formatQualifier(format)}};
}

void requireJitter(const glm::dvec3& j, const std::string& parameter) {
  for (int c = 0; c < 3; ++c)
    if (!(j[c] >= -0.5 && j[c] <= 0.5))
      throw InvalidArgument(parameter, detail::formatValue(j[c]), "cells, each component in [-0.5, 0.5]");
}

/// A caller's volume: an existing 3D texture of the grid's size (and `format` when not 0) of `backend`.
void requireVolume(const gpu::Backend& backend, const std::string& parameter, std::uint32_t texture,
                   const FroxelGrid& grid, std::uint32_t format) {
  const gpu::TextureLevel l = gpu::textureLevelOf(backend, parameter.c_str(), texture);
  if (l.type != gpu::TextureType::Texture3D)
    throw InvalidArgument(parameter, std::to_string(texture), "must be a 3D texture");
  if (l.width != grid.width || l.height != grid.height || l.depth != grid.depth)
    throw InvalidArgument(
        parameter, std::to_string(l.width) + "x" + std::to_string(l.height) + "x" + std::to_string(l.depth),
        "must be the grid's size " + std::to_string(grid.width) + "x" + std::to_string(grid.height) + "x" +
            std::to_string(grid.depth));
  const std::string given = l.format ? gpu::formatName(*l.format) : "another format";
  if (format != 0 && l.format != froxelFormat(format))
    throw InvalidArgument(parameter, given, std::string("must be ") + gpu::formatName(froxelFormat(format)));
  if (format == 0 && l.format != gpu::Format::RGBA16F && l.format != gpu::Format::RGBA32F)
    throw InvalidArgument(parameter, given, "must be RGBA16F or RGBA32F");
}

/// Checks the grid (validate) and, on GL, the driver's 3D texture limit (other backends: at creation).
void requireGrid(const FroxelGrid& grid, const char* owner, const gpu::Backend* backend = nullptr) {
  validate(grid, owner);
  if (backend != nullptr && backend->kind() != gpu::BackendKind::OpenGL) return;
  GLint limit = 0;
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &limit);
  const int sizes[3] = {grid.width, grid.height, grid.depth};
  const char* fields[3] = {"width", "height", "depth"};
  for (int i = 0; i < 3; ++i)
    if (sizes[i] > limit)
      throw InvalidArgument(std::string(owner) + ".grid." + fields[i], detail::formatValue(sizes[i]),
                            "cells, must be <= GL_MAX_3D_TEXTURE_SIZE (" + std::to_string(limit) + ")");
}

/// The medium, light and camera members of the block.
void assignFrame(gpu::FroxelParams& p, const Camera& camera, const FroxelGrid& grid) {
  p.camera = gpu::froxelCamera(camera);
  p.previous = p.camera;
  p.cameraDepth = gpu::gpuCamera(camera).depth;
  const FroxelDepthRange r = froxelDepthRange(grid, camera, "FroxelGrid");
  p.range = glm::vec4(static_cast<float>(r.near), static_cast<float>(r.far), static_cast<float>(r.near),
                      static_cast<float>(r.far));
  p.grid = glm::ivec4(grid.width, grid.height, grid.depth, 0);
}

void assignMedium(gpu::FroxelParams& p, const Medium& medium) {
  p.mieScattering = glm::vec4(glm::vec3(medium.mieScattering()), static_cast<float>(medium.hgG()));
  p.rayleighScattering = glm::vec4(glm::vec3(medium.rayleighScattering()), 0.0f);
  p.extinction = glm::vec4(glm::vec3(medium.extinction()), static_cast<float>(weightExtinction(medium)));
}

/// 4 x 4 x 4 cells per workgroup: 64 invocations, a multiple of every GPU's SIMD width (32 / 64).
glm::uvec3 groups3D(const FroxelGrid& g) {
  return {static_cast<unsigned>((g.width + 3) / 4), static_cast<unsigned>((g.height + 3) / 4),
          static_cast<unsigned>((g.depth + 3) / 4)};
}

glm::uvec3 groups2D(int width, int height) {
  return {static_cast<unsigned>((width + 7) / 8), static_cast<unsigned>((height + 7) / 8), 1u};
}

/// A dispatch of `program` (in `defines`' variant) on the block `params` and `resources`.
gpu::Dispatch froxelDispatch(const char* label, const char* program, std::vector<ShaderDefine> defines,
                             std::uint32_t paramsBinding, const gpu::Buffer& params,
                             std::vector<gpu::Resource> resources, glm::uvec3 groups) {
  gpu::Dispatch d;
  d.label = label;
  d.program = program;
  d.defines = std::move(defines);
  d.resources = std::move(resources);
  d.resources.push_back(gpu::Resource::uniform(paramsBinding, params.id()));
  d.groups = groups;
  return d;
}

} // namespace

void validateFroxelFormat(std::uint32_t format, const char* owner) {
  if (format != GL_RGBA16F && format != GL_RGBA32F)
    throw InvalidArgument(name(owner, "format"), std::to_string(format),
                          "must be GL_RGBA16F (0x881A) or GL_RGBA32F (0x8814)");
}

gl::Handle createFroxelVolume(const FroxelGrid& grid, std::uint32_t format, const char* owner) {
  requireGrid(grid, owner);
  validateFroxelFormat(format, owner);
  gl::Handle t = gl::createTexture(GL_TEXTURE_3D);
  glTextureStorage3D(t.get(), 1, format, grid.width, grid.height, grid.depth);
  glTextureParameteri(t.get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(t.get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(t.get(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(t.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTextureParameteri(t.get(), GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
  gl::checkError("createFroxelVolume");
  return t;
}

gpu::Texture createFroxelVolume(gpu::Backend& backend, const FroxelGrid& grid, std::uint32_t format,
                                const char* owner) {
  requireGrid(grid, owner, &backend);
  validateFroxelFormat(format, owner);
  return gpu::Texture(backend, {gpu::TextureType::Texture3D, froxelFormat(format), grid.width, grid.height,
                                grid.depth, std::string(owner) + ": froxel volume"});
}

// ---- EsmPass: Annen et al. 2008 downsampled and box-blurred as Wronski 2014 (rule 1) ----

EsmPass::EsmPass(const CreateInfo& info) : info_(info) {
  crep::validate(info.options, "EsmPass::CreateInfo.options");
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  backend_->prepareProgram("passes/postfx/esm_downsample.comp", {});
  backend_->prepareProgram("passes/postfx/esm_blur.comp", {});
  params_ = gpu::Buffer(*backend_, sizeof(gpu::FroxelParams), "EsmPass: parameters");
}

std::size_t EsmPass::memoryBytes() const noexcept {
  return 2 * sizeof(float) * static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
}

void EsmPass::validate(const FrameAttribs& f, std::string_view owner) const {
  const std::string o(owner);
  const std::string map = name(o.c_str(), "shadowMap");
  gpu::requireTexture2DOf(*backend_, map.c_str(), f.shadowMap);
  gpu::requireDepthFormatOf(*backend_, map.c_str(), f.shadowMap);
  requireFinite(name(o.c_str(), "lightClipFromWorld"), f.lightClipFromWorld);
}

void EsmPass::run(const FrameAttribs& f) {
  validate(f);
  gpu::Backend& b = *backend_;
  const gpu::TextureLevel map = gpu::textureLevelOf(b, "EsmPass::FrameAttribs.shadowMap", f.shadowMap);
  const double c = esmDepthExponent(info_.options, f.lightClipFromWorld);
  const int factor = info_.options.downsample;
  const int w = (map.width + factor - 1) / factor, h = (map.height + factor - 1) / factor;
  if (w != width_ || h != height_) {
    esm_ = gpu::Texture(b, {gpu::TextureType::Texture2D, gpu::Format::R32F, w, h, 1, "EsmPass: ESM"});
    scratch_ = gpu::Texture(b, {gpu::TextureType::Texture2D, gpu::Format::R32F, w, h, 1, "EsmPass: blur"});
    width_ = w;
    height_ = h;
  }
  gpu::FroxelParams p;
  p.esm = glm::vec4(static_cast<float>(c), static_cast<float>(info_.options.bias), 1.0f, 0.0f);
  p.sizes = glm::ivec4(map.width, map.height, w, h);
  p.info = glm::ivec4(factor, info_.options.blurRadius, 0, 0);
  b.writeBuffer(params_.id(), 0, std::as_bytes(std::span(&p, 1)));
  // Downsample into the ESM, blur x into the scratch texture, blur y back into the ESM.
  b.dispatch(froxelDispatch("EsmPass::run (downsample)", "passes/postfx/esm_downsample.comp", {},
                            CREP_ESM_FROXEL_BINDING, params_,
                            {gpu::Resource::sampled(CREP_ESM_SHADOW_MAP_UNIT, f.shadowMap),
                             gpu::Resource::image(CREP_ESM_OUT_IMAGE, esm_.id(), gpu::Access::WriteOnly)},
                            groups2D(w, h)));
  if (info_.options.blurRadius > 0)
    for (int direction = 0; direction < 2; ++direction) {
      gpu::Dispatch d = froxelDispatch(
          "EsmPass::run (blur)", "passes/postfx/esm_blur.comp", {}, CREP_ESM_FROXEL_BINDING, params_,
          {gpu::Resource::sampled(CREP_ESM_IN_UNIT, direction == 0 ? esm_.id() : scratch_.id()),
           gpu::Resource::image(CREP_ESM_OUT_IMAGE, direction == 0 ? scratch_.id() : esm_.id(),
                                gpu::Access::WriteOnly)},
          groups2D(w, h));
      d.push = {gpu::PushValue::of(0, direction)};
      b.dispatch(d);
    }
}

// ---- FroxelLightingPass: Wronski 2014, "Density estimation and volume lighting" (rule 2) ----

FroxelLightingPass::FroxelLightingPass(const CreateInfo& info) : info_(info) {
  const char* owner = "FroxelLightingPass::CreateInfo";
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  requireGrid(info.grid, owner, backend_);
  crep::validate(info.density, "FroxelLightingPass::CreateInfo.density");
  crep::validate(info.esm, "FroxelLightingPass::CreateInfo.esm");
  validateFroxelFormat(info.format, owner);
  for (int c = 0; c < 3; ++c)
    if (!(info.ambient[c] >= 0.0) || !std::isfinite(info.ambient[c]))
      throw InvalidArgument(name(owner, "ambient"), detail::formatValue(info.ambient[c]),
                            "must be finite and >= 0");
  backend_->prepareProgram("passes/postfx/froxel_light.comp", formatDefines(info.format));
  params_ = gpu::Buffer(*backend_, sizeof(gpu::FroxelParams), "FroxelLightingPass: parameters");
}

void FroxelLightingPass::validate(const FrameAttribs& f, std::string_view ownerName) const {
  const std::string o(ownerName);
  const char* owner = o.c_str();
  if (!f.camera || !f.light || !f.medium) invalid(name(owner, "camera/light/medium"), "null", "must be set");
  requireVolume(*backend_, name(owner, "output"), f.output, info_.grid, info_.format);
  requireJitter(f.jitter, name(owner, "jitter"));
  requireFinite(name(owner, "noiseOffset"), f.noiseOffset);
  if (f.esm != 0) {
    const std::string esmName = name(owner, "esm");
    const gpu::TextureLevel esm = gpu::requireTexture2DOf(*backend_, esmName.c_str(), f.esm);
    if (esm.format != gpu::Format::R32F)
      invalid(esmName, esm.format ? gpu::formatName(*esm.format) : "another format",
              "must be R32F (EsmPass::esm())");
    requireFinite(name(owner, "lightClipFromWorld"), f.lightClipFromWorld);
  }
}

void FroxelLightingPass::run(const FrameAttribs& f) {
  validate(f);
  gpu::Backend& b = *backend_;
  const gpu::TextureLevel esm = f.esm != 0
                                    ? gpu::textureLevelOf(b, "FroxelLightingPass::FrameAttribs.esm", f.esm)
                                    : gpu::TextureLevel{};
  gpu::FroxelParams p;
  assignFrame(p, *f.camera, info_.grid);
  assignMedium(p, *f.medium);
  p.jitter = glm::vec4(glm::vec3(f.jitter), 0.0f);
  p.lightDirection = glm::vec4(glm::vec3(f.light->direction()), 0.0f);
  p.lightIrradiance = glm::vec4(glm::vec3(f.light->irradiance()), 0.0f);
  p.ambient = glm::vec4(glm::vec3(info_.ambient), 0.0f);
  const FroxelDensity& d = info_.density;
  p.density = glm::vec4(static_cast<float>(d.heightBase), static_cast<float>(d.heightFalloff),
                        static_cast<float>(d.noiseAmplitude), static_cast<float>(d.noiseFrequency));
  p.noiseOffset = glm::vec4(glm::vec3(f.noiseOffset), 0.0f);
  p.esm = glm::vec4(f.esm != 0 ? static_cast<float>(esmDepthExponent(info_.esm, f.lightClipFromWorld)) : 1.0f,
                    static_cast<float>(info_.esm.bias), f.esm != 0 ? 1.0f : 0.0f, 0.0f);
  p.sizes = glm::ivec4(0, 0, esm.width, esm.height);
  p.lightClipFromWorld = glm::mat4(f.lightClipFromWorld);
  b.writeBuffer(params_.id(), 0, std::as_bytes(std::span(&p, 1)));
  // Without an ESM (every point lit, p.esm.z = 0) the shader reads none; a 1-texel stand-in keeps the
  // descriptor valid on every API.
  if (f.esm == 0 && !unlit_) {
    unlit_ = gpu::Texture(
        b, {gpu::TextureType::Texture2D, gpu::Format::R32F, 1, 1, 1, "FroxelLightingPass: no ESM"});
    b.writeTexture(unlit_.id(), std::vector<float>{1.0f});
  }
  b.dispatch(
      froxelDispatch("FroxelLightingPass::run", "passes/postfx/froxel_light.comp",
                     formatDefines(info_.format), CREP_FROXEL_PARAMS_BINDING, params_,
                     {gpu::Resource::sampled(CREP_FROXEL_ESM_UNIT, f.esm != 0 ? f.esm : unlit_.id()),
                      gpu::Resource::image(CREP_FROXEL_LIGHTING_OUT_IMAGE, f.output, gpu::Access::WriteOnly)},
                     groups3D(info_.grid)));
}

// ---- FroxelAccumulatePass: Wronski 2014, "Solving scattering equation" (rule 3) ----

FroxelAccumulatePass::FroxelAccumulatePass(const CreateInfo& info) : info_(info) {
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  requireGrid(info.grid, "FroxelAccumulatePass::CreateInfo", backend_);
  validateFroxelFormat(info.format, "FroxelAccumulatePass::CreateInfo");
  backend_->prepareProgram("passes/postfx/froxel_accumulate.comp", formatDefines(info.format));
  params_ = gpu::Buffer(*backend_, sizeof(gpu::FroxelParams), "FroxelAccumulatePass: parameters");
}

void FroxelAccumulatePass::validate(const FrameAttribs& f, std::string_view ownerName) const {
  const std::string o(ownerName);
  const char* owner = o.c_str();
  if (!f.camera || !f.medium) invalid(name(owner, "camera/medium"), "null", "must be set");
  requireVolume(*backend_, name(owner, "volume"), f.volume, info_.grid, info_.format);
  requireJitter(f.jitter, name(owner, "jitter"));
}

void FroxelAccumulatePass::run(const FrameAttribs& f) {
  validate(f);
  gpu::FroxelParams p;
  assignFrame(p, *f.camera, info_.grid);
  assignMedium(p, *f.medium);
  p.jitter = glm::vec4(glm::vec3(f.jitter), 0.0f);
  backend_->writeBuffer(params_.id(), 0, std::as_bytes(std::span(&p, 1)));
  backend_->dispatch(froxelDispatch("FroxelAccumulatePass::run", "passes/postfx/froxel_accumulate.comp",
                                    formatDefines(info_.format), CREP_FROXEL_PARAMS_BINDING, params_,
                                    {gpu::Resource::image(CREP_FROXEL_VOLUME_IMAGE, f.volume)},
                                    groups2D(info_.grid.width, info_.grid.height)));
}

// ---- FroxelTemporalPass: Wronski 2014, "Temporal reprojection" (rule 5) ----

FroxelTemporalPass::FroxelTemporalPass(const CreateInfo& info) : info_(info) {
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  requireGrid(info.grid, "FroxelTemporalPass::CreateInfo", backend_);
  validateFroxelFormat(info.format, "FroxelTemporalPass::CreateInfo");
  backend_->prepareProgram("passes/postfx/froxel_temporal.comp", formatDefines(info.format));
  params_ = gpu::Buffer(*backend_, sizeof(gpu::FroxelParams), "FroxelTemporalPass: parameters");
}

void FroxelTemporalPass::validate(const FrameAttribs& f, std::string_view ownerName) const {
  const std::string o(ownerName);
  const char* owner = o.c_str();
  if (!f.camera) invalid(name(owner, "camera"), "null", "must be set");
  if (!(f.historyWeight >= 0.0 && f.historyWeight < 1.0))
    invalid(name(owner, "historyWeight"), detail::formatValue(f.historyWeight), "must be in [0, 1)");
  requireVolume(*backend_, name(owner, "current"), f.current, info_.grid, 0);
  requireVolume(*backend_, name(owner, "output"), f.output, info_.grid, info_.format);
  const bool useHistory = f.previousCamera != nullptr && f.historyWeight > 0.0;
  if (useHistory) requireVolume(*backend_, name(owner, "history"), f.history, info_.grid, 0);
  if (f.output == f.current || (useHistory && f.output == f.history))
    invalid(name(owner, "output"), std::to_string(f.output), "must differ from current and history");
}

void FroxelTemporalPass::run(const FrameAttribs& f) {
  validate(f);
  const bool useHistory = f.previousCamera != nullptr && f.historyWeight > 0.0;
  gpu::FroxelParams p;
  assignFrame(p, *f.camera, info_.grid);
  if (useHistory) {
    p.previous = gpu::froxelCamera(*f.previousCamera);
    const FroxelDepthRange r =
        froxelDepthRange(info_.grid, *f.previousCamera, "FroxelTemporalPass::CreateInfo");
    p.range.z = static_cast<float>(r.near);
    p.range.w = static_cast<float>(r.far);
    p.grid.w = 1;
  }
  p.jitter = glm::vec4(0.0f, 0.0f, 0.0f, static_cast<float>(useHistory ? f.historyWeight : 0.0));
  backend_->writeBuffer(params_.id(), 0, std::as_bytes(std::span(&p, 1)));
  backend_->dispatch(
      froxelDispatch("FroxelTemporalPass::run", "passes/postfx/froxel_temporal.comp",
                     formatDefines(info_.format), CREP_FROXEL_PARAMS_BINDING, params_,
                     {gpu::Resource::sampled(CREP_FROXEL_CURRENT_UNIT, f.current),
                      // unused without history (weight 0)
                      gpu::Resource::sampled(CREP_FROXEL_HISTORY_UNIT, useHistory ? f.history : f.current,
                                             gpu::Filter::Linear),
                      gpu::Resource::image(CREP_FROXEL_BLENDED_OUT_IMAGE, f.output, gpu::Access::WriteOnly)},
                     groups3D(info_.grid)));
}

// ---- FroxelApplyPass: Wronski 2014, "Applying effect" (rule 4) ----

FroxelApplyPass::FroxelApplyPass(const CreateInfo& info) : info_(info) {
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  requireGrid(info.grid, "FroxelApplyPass::CreateInfo", backend_);
  backend_->prepareProgram("passes/postfx/froxel_apply.comp", {});
  params_ = gpu::Buffer(*backend_, sizeof(gpu::FroxelParams), "FroxelApplyPass: parameters");
}

void FroxelApplyPass::validate(const FrameAttribs& f, std::string_view ownerName) const {
  const std::string o(ownerName);
  const char* owner = o.c_str();
  if (!f.camera) invalid(name(owner, "camera"), "null", "must be set");
  const std::string depthName = name(owner, "cameraDepth");
  const gpu::TextureLevel depth = gpu::requireTexture2DOf(*backend_, depthName.c_str(), f.cameraDepth);
  gpu::requireTexture2DOf(*backend_, name(owner, "output").c_str(), f.output, depth.width, depth.height,
                          gpu::Format::RGBA32F);
  requireVolume(*backend_, name(owner, "volume"), f.volume, info_.grid, 0);
  requireJitter(f.offset, name(owner, "offset"));
}

void FroxelApplyPass::run(const FrameAttribs& f) {
  validate(f);
  const gpu::TextureLevel depth =
      gpu::textureLevelOf(*backend_, "FroxelApplyPass::FrameAttribs.cameraDepth", f.cameraDepth);
  gpu::FroxelParams p;
  assignFrame(p, *f.camera, info_.grid);
  p.jitter = glm::vec4(glm::vec3(f.offset), 0.0f);
  p.sizes = glm::ivec4(depth.width, depth.height, 0, 0);
  backend_->writeBuffer(params_.id(), 0, std::as_bytes(std::span(&p, 1)));
  backend_->dispatch(froxelDispatch(
      "FroxelApplyPass::run", "passes/postfx/froxel_apply.comp", {}, CREP_FROXEL_PARAMS_BINDING, params_,
      {gpu::Resource::sampled(CREP_FROXEL_CAMERA_DEPTH_UNIT, f.cameraDepth),
       gpu::Resource::sampled(CREP_FROXEL_INTEGRATED_UNIT, f.volume, gpu::Filter::Linear),
       gpu::Resource::image(CREP_FROXEL_SCATTERING_OUT_IMAGE, f.output, gpu::Access::WriteOnly)},
      groups2D(depth.width, depth.height)));
}

// ---- FroxelFog ----

namespace {

const FroxelFog::CreateInfo& validated(const FroxelFog::CreateInfo& info) {
  const char* owner = "FroxelFog::CreateInfo";
  requireGrid(info.grid, owner, info.backend);
  validate(info.esm, "FroxelFog::CreateInfo.esm");
  validate(info.density, "FroxelFog::CreateInfo.density");
  validateFroxelFormat(info.format, owner);
  for (int c = 0; c < 3; ++c)
    if (!(info.ambient[c] >= 0.0) || !std::isfinite(info.ambient[c]))
      throw InvalidArgument(name(owner, "ambient"), detail::formatValue(info.ambient[c]),
                            "must be finite and >= 0");
  if (!(info.temporal.historyWeight >= 0.0 && info.temporal.historyWeight < 1.0))
    throw InvalidArgument(name(owner, "temporal.historyWeight"),
                          detail::formatValue(info.temporal.historyWeight), "must be in [0, 1) (0 = off)");
  return info;
}

} // namespace

FroxelFog::FroxelFog(const CreateInfo& info)
    : info_(validated(info)), backend_(&gpu::givenOrGl(info.backend, ownBackend_)),
      esm_({info.esm, backend_}),
      lighting_({info.grid, info.density, info.ambient, info.esm, info.format, backend_}),
      accumulate_({info.grid, info.format, backend_}), temporal_({info.grid, info.format, backend_}),
      apply_({info.grid, backend_}) {
  current_ = createFroxelVolume(*backend_, info.grid, info.format, "FroxelFog::CreateInfo");
  if (info.temporal.historyWeight > 0.0)
    for (gpu::Texture& h : history_)
      h = createFroxelVolume(*backend_, info.grid, info.format, "FroxelFog::CreateInfo");
  volume_ = current_.id();
}

glm::dvec3 FroxelFog::lightingJitter(int frameIndex) const {
  return info_.temporal.historyWeight > 0.0 && info_.temporal.jitter ? froxelJitter(frameIndex)
                                                                     : glm::dvec3(0.0);
}

glm::dvec3 FroxelFog::jitter(int frameIndex) const {
  // The integral's end points stay on the slice centres: moving the end of an integral along the ray only
  // adds noise (the integrated value grows across a slice); what the jitter anti-aliases is where the
  // lighting is sampled (lightingJitter) and which rays are integrated (x, y).
  const glm::dvec3 j = lightingJitter(frameIndex);
  return {j.x, j.y, 0.0};
}

std::size_t FroxelFog::memoryBytes() const noexcept {
  const std::size_t cells = static_cast<std::size_t>(info_.grid.width) *
                            static_cast<std::size_t>(info_.grid.height) *
                            static_cast<std::size_t>(info_.grid.depth);
  const std::size_t perCell = info_.format == GL_RGBA32F ? 16 : 8;
  const std::size_t volumes = info_.temporal.historyWeight > 0.0 ? 3 : 1;
  return volumes * cells * perCell + esm_.memoryBytes();
}

void FroxelFog::validate(const FrameAttribs& f, std::string_view ownerName) const {
  const std::string o(ownerName);
  const char* owner = o.c_str();
  const gpu::Backend& b = *backend_;
  if (!f.camera) invalid(name(owner, "camera"), "null", "must be set");
  if (f.mode == Mode::Esm && (!f.light || !f.medium))
    invalid(name(owner, "light/medium"), "null", "must be set in Mode::Esm");
  if (f.output != 0) {
    const std::string depthName = name(owner, "cameraDepth");
    const gpu::TextureLevel depth = gpu::requireTexture2DOf(b, depthName.c_str(), f.cameraDepth);
    gpu::requireTexture2DOf(b, name(owner, "output").c_str(), f.output, depth.width, depth.height,
                            gpu::Format::RGBA32F);
  }
  if (f.mode == Mode::Esm && f.shadowMap != 0) {
    const std::string mapName = name(owner, "shadowMap");
    gpu::requireTexture2DOf(b, mapName.c_str(), f.shadowMap);
    requireFinite(name(owner, "lightClipFromWorld"), f.lightClipFromWorld);
  }
  if (f.mode == Mode::Prefiltered)
    requireVolume(b, name(owner, "mode"), current_.id(), info_.grid, info_.format);
  requireFinite(name(owner, "noiseOffset"), f.noiseOffset);
  froxelDepthRange(info_.grid, *f.camera, "FroxelFog::CreateInfo");
  if (f.previousCamera) froxelDepthRange(info_.grid, *f.previousCamera, "FroxelFog::CreateInfo");
}

namespace {

/// Timings' fields in the order of FroxelFog's stages.
constexpr std::array<double FroxelFog::Timings::*, 5> kStageTimes = {
    &FroxelFog::Timings::esm, &FroxelFog::Timings::lighting, &FroxelFog::Timings::accumulate,
    &FroxelFog::Timings::temporal, &FroxelFog::Timings::apply};
enum FogStage : std::size_t { kEsm, kLighting, kAccumulate, kTemporal, kApply };

} // namespace

void FroxelFog::reportTimes(std::uint64_t run, const std::array<gpu::TimerId, 5>& spans) {
  const std::optional<gpu::FrameTimers::Times> arrived = timers_.poll(*backend_); // earlier runs only
  for (const gpu::TimerId id : spans)
    timers_.add(id);
  timers_.endFrame(run);
  if (!arrived) return;
  Timings t;
  t.run = arrived->frame;
  for (std::size_t k = 0; k < kStageTimes.size() && k < arrived->milliseconds.size(); ++k)
    t.*kStageTimes[k] = arrived->milliseconds[k];
  timings_ = t;
}

void FroxelFog::run(const FrameAttribs& f) {
  const std::uint64_t run = runs_++;
  validate(f);
  if (info_.timings && info_.blockingTimings) {
    timings_ = Timings{};
    timings_->run = run;
  }
  std::array<gpu::TimerId, 5> spans{}; // deferred timings: 0 for stages not run
  // The backend's GPU timer per stage (GL_TIME_ELAPSED, Vulkan timestamps), waited for with blockingTimings.
  const auto stage = [&](FogStage k, const auto& body) {
    if (!info_.timings) return body();
    backend_->beginTimer();
    try {
      body();
    } catch (...) {
      backend_->cancelTimer(); // GL: no GL_TIME_ELAPSED query left active in the caller's context
      throw;
    }
    if (info_.blockingTimings)
      (*timings_).*kStageTimes[k] = backend_->endTimer();
    else
      spans[k] = backend_->endTimerDeferred();
  };
  const glm::dvec3 j = jitter(f.frameIndex);
  if (f.mode == Mode::Esm) {
    if (f.shadowMap != 0) stage(kEsm, [&] { esm_.run({f.shadowMap, f.lightClipFromWorld}); });
    stage(kLighting, [&] {
      FroxelLightingPass::FrameAttribs a;
      a.camera = f.camera;
      a.light = f.light;
      a.medium = f.medium;
      a.esm = f.shadowMap != 0 ? esm_.esm() : 0;
      a.lightClipFromWorld = f.lightClipFromWorld;
      a.jitter = lightingJitter(f.frameIndex);
      a.noiseOffset = f.noiseOffset;
      a.output = current_.id();
      lighting_.run(a);
    });
    stage(kAccumulate, [&] { accumulate_.run({f.camera, f.medium, j, current_.id()}); });
  }
  glm::dvec3 offset = j;
  volume_ = current_.id();
  if (info_.temporal.historyWeight > 0.0) {
    const int out = latest_ == 0 ? 1 : 0;
    stage(kTemporal, [&] {
      FroxelTemporalPass::FrameAttribs a;
      a.camera = f.camera;
      a.previousCamera = latest_ >= 0 ? f.previousCamera : nullptr;
      a.historyWeight = info_.temporal.historyWeight;
      a.current = current_.id();
      a.history = latest_ >= 0 ? history_[static_cast<std::size_t>(latest_)].id() : 0;
      a.output = history_[static_cast<std::size_t>(out)].id();
      temporal_.run(a);
    });
    latest_ = out;
    volume_ = history_[static_cast<std::size_t>(out)].id();
    offset = glm::dvec3(0.0); // the blended volume holds its values at the cell centres
  }
  if (f.output != 0) stage(kApply, [&] { apply_.run({f.camera, f.cameraDepth, volume_, offset, f.output}); });
  if (info_.timings && !info_.blockingTimings) reportTimes(run, spans);
}

} // namespace crep
