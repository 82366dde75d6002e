// Light textures: an RGB texture projected from the light that multiplies the light's colour per light ray
// (a projector's slide or a gobo on a spot light, a stained-glass window over the sun). Klehm et al. 2014,
// Sec. 3.2 "Angular-dependency for Sources": a coloured light texture is a light-side factor per channel,
// "stored per component" (the prefilter then keeps one basis per colour channel); Yusov 2012's coloured
// light shafts (a stained-glass texture seen from the light modulating the sun's colour).
//
// ---------------------------------------------------------------------------------------------------
// Rule (the CPU reference; the GLSL twin is crep_lightTextureColor of glsl/crep/light_texture.glsl).
// The colour of a world point p: q = textureClipFromWorld (p, 1); behind the projector (q.w <= 0) the colour
// is 0 (a projector emits nothing backwards); else (u, v) = 0.5 q.xy / q.w + 0.5 and the texture is
// sampled bilinearly with clamp to edge, exactly as GL_LINEAR + GL_CLAMP_TO_EDGE define it: x = u Wt - 0.5,
// y = v Ht - 0.5 (texel centres at integers + 0.5, row 0 at the bottom, the Image convention), the four
// texels floor(x) + {0, 1}, floor(y) + {0, 1} clamped to the image, weights from the fractions, computed
// as c0 + f (c1 - c0) in x, then in y (so a constant texture gives its value exactly). Outside
// [-1, 1] NDC the edge texels continue (clamp to edge).
// The projection must map every light ray to one texture point (validateLightTexture checks it), so a
// light ray has one colour: for a spot light or a point-light face a perspective projection whose centre
// is the light's position (e.g. SpotLight::lightClipFromWorld(): the texture over the cone); for the
// directional light an orthographic (affine) projection along the light's direction (the window's plane).
// The colour of a light ray (origin o, unit direction d) is the colour of its point o + d (for a local
// light o is the light itself, where the projection is singular).
//
// Colour map of a rectified map (lightColorMap): texel (i, j) of a W x H map gets the colour of its light
// ray, layout.lightRay((i + 0.5) / W, (j + 0.5) / H): what every rectified method (prefilter, marches)
// multiplies that texel's visibility with.
#pragma once

#include <string_view>

#include <glm/glm.hpp>

#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/ray_scattering.h>

namespace crep {

/// An RGB texture projected from the light (rule at the top). Non-owning.
struct LightTexture {
  /// Linear RGB (channels 0-2 used; 3 or 4 channels), finite and >= 0, row 0 at the bottom. Values may
  /// exceed 1 (an HDR slide); the light's colour is multiplied by them.
  const Image* rgb = nullptr;
  /// World -> the texture's clip space: NDC x, y in [-1, 1] cover the texture.
  glm::dmat4 textureClipFromWorld{1.0};
};

/// Throws InvalidArgument naming `<owner>.rgb` (null, empty, fewer than 3 or more than 4 channels, a
/// texel NaN, infinite or negative, with its coordinates) or `<owner>.textureClipFromWorld` (not finite).
void validate(const LightTexture& texture, std::string_view owner = "LightTexture");
/// validate() and that the projection maps every ray of `light` to one texture point (rule at the top):
/// textureClipFromWorld (d, 0) has x = y = w = 0 (relative 1e-6 of the matrix rows) for the directional
/// light's direction d; textureClipFromWorld (L, 1) has x = y = w = 0 for a local light at L. Throws
/// InvalidArgument naming `<owner>.textureClipFromWorld` otherwise.
void validateLightTexture(const LightTexture& texture, const DirectionalLight& light,
                          std::string_view owner = "LightTexture");
void validateLightTexture(const LightTexture& texture, const LocalLight& light,
                          std::string_view owner = "LightTexture");
/// The projection half of validateLightTexture: InvalidArgument naming `field` for a non-finite matrix or
/// one that does not project along the light's rays (for the GPU passes, whose texture is a GL name).
void validateLightProjection(const glm::dmat4& textureClipFromWorld, const DirectionalLight& light,
                             std::string_view field);
void validateLightProjection(const glm::dmat4& textureClipFromWorld, const LocalLight& light,
                             std::string_view field);

/// The texture's colour at world point p (rule at the top; no validation: hot path).
glm::dvec3 lightTextureColor(const LightTexture& texture, const glm::dvec3& p);
/// The colour of a light ray: lightTextureColor at ray.origin + ray.direction (rule at the top).
glm::dvec3 lightTextureColor(const LightTexture& texture, const LightRay& ray);

/// The colour map of a W x H rectified map of `layout` (rule at the top): an RGB Image (3 channels, row 0
/// at the bottom). Validates the texture (validate(texture)); throws InvalidArgument ("lightColorMap.width"
/// / ".height") for sizes <= 0. Rows in parallel on `threads` threads (0 = hardware concurrency).
Image lightColorMap(const LightTexture& texture, const RectifiedLayout& layout, int width, int height,
                    int threads = 0);

/// Throws InvalidArgument naming `field` unless `colors` is a width x height image of 3 or 4 channels
/// whose RGB values are finite and >= 0 (the bad texel named).
void validateLightColors(const Image& colors, int width, int height, std::string_view field);

} // namespace crep
