// Light textures on the GPU (Klehm et al. 2014, Sec. 3.2 coloured light textures; the rule is
// light_texture.h's): GpuLightTexture and LightColorMapPass, the colour map of a rectified map.
// Requires a current OpenGL 4.5 context. GL state: scatter/README.md, "crep/scatter/gpu_light_texture.h".
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>

#include <glm/glm.hpp>

#include <crep/core/light.h>
#include <crep/gpu/backend.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/gl.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/gpu_layout_buffers.h>
#include <crep/scatter/ray_scattering.h>

namespace crep {

namespace gpu {

/// std140 twin of CrepLightTextureParams (glsl/crep/light_texture.glsl).
struct LightTextureParams {
  glm::mat4 textureClipFromWorld{1.0f}; ///< LightTexture::textureClipFromWorld
  glm::ivec4 size{0};                   ///< xy: texture size (texels); zw: colour map size (colour map pass)
  glm::vec4 lightPosition{0.0f};        ///< xyz: local light position; w: 1 = local light, 0 = directional
};
static_assert(sizeof(LightTextureParams) == 96, "std140 CrepLightTextureParams");

} // namespace gpu

/// A light texture on the GPU (crep::LightTexture's rule): non-owning.
struct GpuLightTexture {
  /// The caller's GL_TEXTURE_2D: linear RGB >= 0, any colour format read as float; level 0 (README).
  std::uint32_t texture = 0;
  glm::dmat4 textureClipFromWorld{1.0}; ///< LightTexture::textureClipFromWorld (along the light's rays)
};

namespace gpu {
/// Throws InvalidArgument naming `<field>.texture` (not a 2D texture) or `<field>.textureClipFromWorld`
/// (validateLightProjection). Returns the texture's level 0.
gpu::TextureLevel validateGpuLightTexture(const GpuLightTexture& texture, const DirectionalLight* light,
                                          const LocalLight* localLight, std::string_view field);
/// The same for a texture of `backend` (any colour format, not depth).
gpu::TextureLevel validateGpuLightTexture(const Backend& backend, const GpuLightTexture& texture,
                                          const DirectionalLight* light, const LocalLight* localLight,
                                          std::string_view field);
/// The block of `texture` (level 0 `level`) for a mapWidth x mapHeight colour map; w = 0 without localLight.
LightTextureParams makeLightTextureParams(const GpuLightTexture& texture, const gpu::TextureLevel& level,
                                          int mapWidth, int mapHeight, const LocalLight* localLight);
} // namespace gpu

/// crep::lightColorMap on the GPU into a mapWidth x mapHeight GL_RGBA32F texture it owns (A = 1).
class LightColorMapPass {
public:
  struct CreateInfo {
    int mapWidth = 1024;  ///< W of the rectified maps it colours
    int mapHeight = 1024; ///< H
    /// Runs the pass (must outlive it); null: a gpu::GlBackend of its own on the current GL context.
    gpu::Backend* backend = nullptr;
  };
  struct FrameAttribs {
    /// The map's layout: any layout with a GPU mapping. Not owned.
    const RectifiedLayout* layout = nullptr;
    GpuLightTexture lightTexture; ///< the texture and its projection
    /// Exactly one of `light` and `localLight` (a spot or point-light face, on a ProjectiveLayout).
    const DirectionalLight* light = nullptr;
    const LocalLight* localLight = nullptr;
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "LightColorMapPass::FrameAttribs") const;

  /// Throws InvalidArgument ("LightColorMapPass::CreateInfo.mapWidth" / ".mapHeight") for sizes <= 0,
  /// GlError beyond GL_MAX_TEXTURE_SIZE. One-time: 16 bytes per texel.
  explicit LightColorMapPass(const CreateInfo& info);
  /// Writes colorMapTexture(). Throws InvalidArgument naming the FrameAttribs field. Per frame, O(W H).
  void run(const FrameAttribs& frame);

  /// 2D texture, RGBA32F, mapWidth x mapHeight (a GL name on OpenGL): read texel by texel by the passes.
  std::uint32_t colorMapTexture() const noexcept { return colors_.id(); }
  const CreateInfo& createInfo() const noexcept { return info_; }
  /// GPU memory it owns, bytes: the colour map (16 per texel) and its block.
  std::size_t memoryBytes() const noexcept;

private:
  struct Plan;
  Plan plan(const FrameAttribs& frame, std::string_view owner) const;

  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr;
  gpu::Texture colors_;
  gpu::Buffer params_;
  gpu::LayoutBuffers layout_;
};

} // namespace crep
