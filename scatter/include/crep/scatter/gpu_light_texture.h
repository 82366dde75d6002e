// Light textures on the GPU (crep/scatter/light_texture.h has the rule; Klehm et al. 2014, Sec. 3.2
// coloured light textures): the texture as the passes take it (GpuLightTexture, the caller's GL texture and
// its projection) and LightColorMapPass, which makes the colour map of a rectified map (one RGB colour per
// texel, the texture at the texel's light ray: crep::lightColorMap's rule in float) for the prefilter
// (PrefilterPass::FrameAttribs::lightColors) and the rectified marches.
//
// GL state: LightColorMapPass::run binds texture unit 0 (+ sampler), image unit 0, uniform buffer 0 and,
// for the layout, uniform buffer 1 and storage buffer 1 (gpu::LayoutBuffers), and unbinds them (0).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include <glm/glm.hpp>

#include <crep/core/gl.h>
#include <crep/core/light.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/gpu_layout_buffers.h>
#include <crep/scatter/ray_scattering.h>

namespace crep {

namespace gpu {

/// std140 block CrepLightTextureBlock { CrepLightTextureParams ...; } of glsl/crep/light_texture.glsl (the
/// colour map pass and the textured world march).
struct LightTextureParams {
  glm::mat4 textureClipFromWorld{1.0f}; ///< LightTexture::textureClipFromWorld
  glm::ivec4 size{0};                   ///< xy: texture size (texels); zw: colour map size (colour map pass)
  glm::vec4 lightPosition{0.0f};        ///< xyz: local light position; w: 1 = local light, 0 = directional
};
static_assert(sizeof(LightTextureParams) == 96, "std140 CrepLightTextureParams");

} // namespace gpu

/// A light texture on the GPU (crep::LightTexture's rule): non-owning.
struct GpuLightTexture {
  /// The caller's GL_TEXTURE_2D: linear RGB in channels r, g, b, any colour format read as float (e.g.
  /// GL_RGBA8, GL_RGBA16F, GL_RGBA32F), values >= 0; level 0 is read with texelFetch (its own filtering
  /// and wrap modes do not matter: the shader interpolates bilinearly with clamp to edge).
  std::uint32_t texture = 0;
  glm::dmat4 textureClipFromWorld{1.0}; ///< LightTexture::textureClipFromWorld (along the light's rays)
};

namespace gpu {
/// Checks a GpuLightTexture for `light`: the texture is a GL_TEXTURE_2D (InvalidArgument naming
/// `<field>.texture`), the projection finite and along the light's rays (`<field>.textureClipFromWorld`,
/// validateLightProjection). Returns the texture's level 0.
gl::TextureLevel validateGpuLightTexture(const GpuLightTexture& texture, const DirectionalLight* light,
                                         const LocalLight* localLight, std::string_view field);
/// The block of `texture` (of level 0 `level`) for a colour map of mapWidth x mapHeight; lightPosition
/// from `localLight` (or w = 0).
LightTextureParams makeLightTextureParams(const GpuLightTexture& texture, const gl::TextureLevel& level,
                                          int mapWidth, int mapHeight, const LocalLight* localLight);
} // namespace gpu

/// The colour map pass (crep::lightColorMap on the GPU, glsl/passes/light_colors.comp): a mapWidth x
/// mapHeight GL_RGBA32F texture it owns (RGB the colour of each texel's light ray, A = 1).
class LightColorMapPass {
public:
  struct CreateInfo {
    int mapWidth = 1024;  ///< W of the rectified maps it colours
    int mapHeight = 1024; ///< H
  };
  struct FrameAttribs {
    /// The map's layout: a ProjectiveLayout (directional or local light) or any layout with a GPU mapping
    /// (the epipolar one, for the sun). Not owned.
    const RectifiedLayout* layout = nullptr;
    GpuLightTexture lightTexture; ///< the texture and its projection
    /// The light: exactly one of `light` (directional) and `localLight` (a spot, or one point-light face;
    /// its rectification's ProjectiveLayout).
    const DirectionalLight* light = nullptr;
    const LocalLight* localLight = nullptr;
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "LightColorMapPass::FrameAttribs") const;

  /// Throws InvalidArgument ("LightColorMapPass::CreateInfo.mapWidth" / ".mapHeight") for sizes <= 0,
  /// GlError beyond GL_MAX_TEXTURE_SIZE; allocates the colour map.
  explicit LightColorMapPass(const CreateInfo& info);
  /// Writes colorMapTexture(). Throws InvalidArgument naming the FrameAttribs field (null layout, both or
  /// neither light, a local light without a ProjectiveLayout, the texture, the projection).
  void run(const FrameAttribs& frame);

  /// GL_TEXTURE_2D, GL_RGBA32F, mapWidth x mapHeight (nearest filtering, clamp to edge).
  std::uint32_t colorMapTexture() const noexcept { return colors_.get(); }
  const CreateInfo& createInfo() const noexcept { return info_; }
  /// GPU memory it owns, bytes: the colour map (16 per texel) and its block.
  std::size_t memoryBytes() const noexcept;

private:
  struct Plan;
  Plan plan(const FrameAttribs& frame, std::string_view owner) const;

  CreateInfo info_;
  gl::Handle colors_, params_, sampler_;
  gl::Handle programs_[2]; ///< per gpu::LayoutKind, built on first use
  gpu::LayoutBuffers layout_;
};

} // namespace crep
