// Light textures on the GPU (Klehm et al. 2014, Sec. 3.2 coloured light textures): validation of the
// caller's texture and projection, and the colour map pass (glsl/passes/scatter/light_colors.comp). Rules in
// crep/scatter/light_texture.h.
#include <crep/core/error.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/shader_library.h>
#include <crep/scatter/gpu_light_texture.h>
#include <crep/scatter/light_texture.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <string>

namespace crep {

namespace gpu {

gpu::TextureLevel validateGpuLightTexture(const GpuLightTexture& texture, const DirectionalLight* light,
                                          const LocalLight* localLight, std::string_view field) {
  const std::string f(field);
  const std::string textureField = f + ".texture";
  const gpu::TextureLevel level =
      textureLevelFromGl(gl::requireTexture2D(textureField.c_str(), texture.texture));
  gl::requireColorFormat(textureField.c_str(), texture.texture);
  if (level.width <= 0 || level.height <= 0)
    throw InvalidArgument(textureField, std::to_string(level.width) + " x " + std::to_string(level.height),
                          "must have a level 0");
  if (localLight)
    validateLightProjection(texture.textureClipFromWorld, *localLight, f + ".textureClipFromWorld");
  else if (light)
    validateLightProjection(texture.textureClipFromWorld, *light, f + ".textureClipFromWorld");
  return level;
}

gpu::TextureLevel validateGpuLightTexture(const Backend& backend, const GpuLightTexture& texture,
                                          const DirectionalLight* light, const LocalLight* localLight,
                                          std::string_view field) {
  if (backend.kind() == BackendKind::OpenGL)
    return validateGpuLightTexture(texture, light, localLight, field);
  const std::string f(field);
  const std::string textureField = f + ".texture";
  const gpu::TextureLevel level = requireTexture2DOf(backend, textureField.c_str(), texture.texture);
  if (level.isDepth)
    throw InvalidArgument(textureField, std::to_string(texture.texture),
                          "must have a colour format (not depth)");
  if (localLight)
    validateLightProjection(texture.textureClipFromWorld, *localLight, f + ".textureClipFromWorld");
  else if (light)
    validateLightProjection(texture.textureClipFromWorld, *light, f + ".textureClipFromWorld");
  return level;
}

LightTextureParams makeLightTextureParams(const GpuLightTexture& texture, const gpu::TextureLevel& level,
                                          int mapWidth, int mapHeight, const LocalLight* localLight) {
  LightTextureParams p;
  p.textureClipFromWorld = glm::mat4(texture.textureClipFromWorld);
  p.size = glm::ivec4(level.width, level.height, mapWidth, mapHeight);
  if (localLight) p.lightPosition = glm::vec4(glm::vec3(localLight->position), 1.0f);
  return p;
}

} // namespace gpu

LightColorMapPass::LightColorMapPass(const CreateInfo& info) : info_(info) {
  if (info.mapWidth <= 0)
    throw InvalidArgument("LightColorMapPass::CreateInfo.mapWidth", detail::formatValue(info.mapWidth),
                          "must be > 0");
  if (info.mapHeight <= 0)
    throw InvalidArgument("LightColorMapPass::CreateInfo.mapHeight", detail::formatValue(info.mapHeight),
                          "must be > 0");
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  gpu::checkTextureSize(*backend_, "LightColorMapPass::CreateInfo", info.mapWidth, info.mapHeight);
  layout_ = gpu::LayoutBuffers(backend_);
  colors_ = gpu::Texture(*backend_, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, info.mapWidth,
                                     info.mapHeight, 1, "LightColorMapPass: colour map"});
  params_ = gpu::Buffer(*backend_, sizeof(gpu::LightTextureParams), "LightColorMapPass: light texture");
}

std::size_t LightColorMapPass::memoryBytes() const noexcept {
  return static_cast<std::size_t>(info_.mapWidth) * static_cast<std::size_t>(info_.mapHeight) * 16 +
         sizeof(gpu::LightTextureParams);
}

// The colour of each map texel's light ray (Klehm et al. 2014, Sec. 3.2: the light-side factor per colour
// component), crep::lightColorMap in float.
/// A validated frame of the pass (LightColorMapPass::validate) and what run() derives from it.
struct LightColorMapPass::Plan {
  gpu::TextureLevel level;  ///< the light texture's level 0
  GpuLayoutData layoutData; ///< the map's layout block
};

void LightColorMapPass::validate(const FrameAttribs& frame, std::string_view owner) const {
  plan(frame, owner);
}

LightColorMapPass::Plan LightColorMapPass::plan(const FrameAttribs& f, std::string_view owner) const {
  const std::string p = std::string(owner) + ".";
  if (f.layout == nullptr) invalid(p + "layout", "null", "must be set");
  if ((f.light != nullptr) == (f.localLight != nullptr))
    invalid(p + "light/localLight", f.light ? "both set" : "both null", "exactly one must be set");
  if (f.localLight && !f.layout->localLightPosition())
    invalid(p + "layout", "a directional light's",
            "a local light's map has its layout (ProjectiveLayout or EpipolarLayout of the light)");
  Plan plan;
  plan.level =
      gpu::validateGpuLightTexture(*backend_, f.lightTexture, f.light, f.localLight, p + "lightTexture");
  plan.layoutData = gpu::requireGpuLayout(*f.layout, (p + "layout").c_str());
  gpu::LayoutBuffers::requireUploadable(plan.layoutData, info_.mapHeight, (p + "layout").c_str());
  return plan;
}

void LightColorMapPass::run(const FrameAttribs& f) {
  const Plan p = plan(f, "LightColorMapPass::FrameAttribs");
  const gpu::LayoutKind kind =
      layout_.upload(p.layoutData, info_.mapHeight, "LightColorMapPass::FrameAttribs.layout");
  const gpu::LightTextureParams params =
      gpu::makeLightTextureParams(f.lightTexture, p.level, info_.mapWidth, info_.mapHeight, f.localLight);
  backend_->writeBuffer(params_.id(), 0, std::as_bytes(std::span(&params, 1)));
  gpu::Dispatch d;
  d.label = "LightColorMapPass::run";
  d.program = "passes/scatter/light_colors.comp";
  d.defines = {{"CREP_LAYOUT", std::to_string(static_cast<int>(kind))}};
  d.resources = {
      gpu::Resource::uniform(CREP_LIGHT_COLORS_LIGHT_TEXTURE_BINDING, params_.id()),
      gpu::Resource::sampled(CREP_LIGHT_COLORS_LIGHT_TEXTURE_UNIT, f.lightTexture.texture),
      gpu::Resource::image(CREP_LIGHT_COLORS_COLORS_OUT_IMAGE, colors_.id(), gpu::Access::WriteOnly)};
  layout_.appendResources(d.resources, CREP_LAYOUT_DEFAULT_BINDING, CREP_SLICES_DEFAULT_BINDING);
  d.groups = glm::uvec3(static_cast<unsigned>((info_.mapWidth + 7) / 8),
                        static_cast<unsigned>((info_.mapHeight + 7) / 8), 1u);
  backend_->dispatch(d);
}

} // namespace crep
