// Light textures: an RGB texture projected from the light that multiplies its colour per light ray (Klehm
// et al. 2014, Sec. 3.2 "Angular-dependency for Sources"; Yusov 2012's coloured light shafts). CPU rule
// and colour maps; the sampling rule and projections: scatter/README.md, "crep/scatter/light_texture.h".
#pragma once

#include <string_view>

#include <glm/glm.hpp>

#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/ray_scattering.h>

namespace crep {

/// An RGB texture projected from the light. Non-owning.
struct LightTexture {
  /// Linear RGB (channels 0-2 of 3 or 4), finite, >= 0 (may exceed 1), row 0 at the bottom.
  const Image* rgb = nullptr;
  /// World -> the texture's clip space: NDC x, y in [-1, 1] cover the texture.
  glm::dmat4 textureClipFromWorld{1.0};
};

/// Throws InvalidArgument naming `<owner>.rgb` (null, empty, channels, a bad texel) or
/// `<owner>.textureClipFromWorld` (not finite). O(texels).
void validate(const LightTexture& texture, std::string_view owner = "LightTexture");
/// validate() and that the projection maps every ray of `light` to one texture point (README); else
/// InvalidArgument naming `<owner>.textureClipFromWorld`.
void validateLightTexture(const LightTexture& texture, const DirectionalLight& light,
                          std::string_view owner = "LightTexture");
void validateLightTexture(const LightTexture& texture, const LocalLight& light,
                          std::string_view owner = "LightTexture");
/// The projection half of validateLightTexture (for the GPU passes): InvalidArgument naming `field`.
void validateLightProjection(const glm::dmat4& textureClipFromWorld, const DirectionalLight& light,
                             std::string_view field);
void validateLightProjection(const glm::dmat4& textureClipFromWorld, const LocalLight& light,
                             std::string_view field);

/// The texture's colour at world point p (no validation: hot path).
glm::dvec3 lightTextureColor(const LightTexture& texture, const glm::dvec3& p);
/// The colour of a light ray: lightTextureColor at ray.origin + ray.direction.
glm::dvec3 lightTextureColor(const LightTexture& texture, const LightRay& ray);

/// The colour map of a W x H rectified map of `layout`: 3 channels, one per texel's light ray. Throws
/// InvalidArgument (the texture, "lightColorMap.width" / ".height"). `threads` 0 = all cores; O(W H).
Image lightColorMap(const LightTexture& texture, const RectifiedLayout& layout, int width, int height,
                    int threads = 0);

/// InvalidArgument naming `field` unless `colors` is width x height, 3 or 4 channels, RGB finite and >= 0.
void validateLightColors(const Image& colors, int width, int height, std::string_view field);

} // namespace crep
