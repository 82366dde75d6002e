// The world-space reference march against a standard shadow map: single scattering that depends on no
// rectification (Klehm et al. 2014, Eq. 1 and 3; Yusov 2012, Eq. 15-16: the integral as a sum over lit
// sections), on the rays and with the output of crep/scatter/ray.h. CPU reference in double; the GL pass
// of the same rule is WorldMarchPass (crep/scatter/gpu_world_march.h).
//
// The shadow map is a depth image rendered with `lightClipFromWorld` (GL conventions, glDepthRange(0, 1),
// GL_LESS, cleared to 1), texel (i, j) covering uv in [i / W, (i + 1) / W) x [j / H, (j + 1) / H).
// Visibility of a world point p: q = lightClipFromWorld p, (u, v, d) = q.xyz / q.w * 0.5 + 0.5; outside
// the map (u or v outside [0, 1]) -> lit; else lit iff clamp(d, 0, 1) <= depth(floor(u W), floor(v H)) +
// bias (nearest texel, clamped to the map); a point with clip w <= 0 (behind a perspective light's eye
// plane) -> lit. The ray [0, s] is cut into N = steps equal sections; the
// visibility is sampled at their N + 1 ends; a section whose ends agree takes that visibility, a section
// whose ends differ is bisected `refinements` times to locate the change, and the parts on either side
// take the visibility of their end. Each lit part is integrated exactly (transmittanceIntegral), so the
// result is exact for visibility with at most one change per section, up to s / (N 2^refinements) at
// each change. Steps (MarchResult::steps) = visibility lookups.
// Light textures (crep/scatter/light_texture.h): each lit part [ta, tb] is multiplied by the texture's
// colour at its midpoint, lightTextureColor(texture, camera + (ta + tb) / 2 v) (the colour of the light ray
// through it), so a colour edge inside a part is located to that part's length (at most s / N).
#pragma once

#include <span>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/scatter/light_texture.h>
#include <crep/scatter/ray.h>
#include <crep/scatter/ray_scattering.h>

namespace crep {

struct WorldMarchOptions {
  int steps = 256;      ///< N >= 1 equal sections from the camera to the surface
  int refinements = 16; ///< bisections at each visibility change, in [0, 60]
  double bias = 0.0;    ///< added to the stored depth (depth-buffer units), finite
  int threads = 0;      ///< CPU worker threads, 0 = hardware concurrency
};

/// Throws InvalidArgument naming the field ("WorldMarchOptions.steps", ...).
void validate(const WorldMarchOptions& options);

/// Visibility of a world point against a standard shadow map (rule above; no validation: hot path).
bool standardShadowLit(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld, const glm::dvec3& p,
                       double bias = 0.0);

/// The world-space reference march (rule above). Throws InvalidArgument for an empty shadow map, more
/// than 1 channel, a NaN texel ("shadowDepth", with the texel), a non-finite matrix
/// ("lightClipFromWorld"), a bad camera depth ("cameraDepth") or options.
MarchResult worldSpaceMarch(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                            const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                            const Medium& medium, const WorldMarchOptions& options = {});

/// The same for a local light (a spot, or one face of a point light: add the six faces' results) against
/// its perspective shadow map (SpotLight::lightClipFromWorld, PointLight::faceClipFromWorld): each lit part
/// integrated by RayScattering (the falloffs, 1 / d^2 and the light path's extinction included). Points
/// behind the light's eye plane count as lit (nothing is emitted there). RGB is the radiance itself.
MarchResult worldSpaceMarch(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                            const Image& cameraDepth, const Camera& camera, const LocalLight& light,
                            const Medium& medium, const WorldMarchOptions& options = {});
/// The world march with a light texture (rule at the top) for the directional light and a local light.
/// Throws InvalidArgument naming "lightTexture.rgb" / "lightTexture.textureClipFromWorld"
/// (validateLightTexture: also a projection that is not along the light's rays).
MarchResult worldSpaceMarch(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                            const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                            const Medium& medium, const LightTexture& lightTexture,
                            const WorldMarchOptions& options = {});
MarchResult worldSpaceMarch(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                            const Image& cameraDepth, const Camera& camera, const LocalLight& light,
                            const Medium& medium, const LightTexture& lightTexture,
                            const WorldMarchOptions& options = {});
/// The same for the pixels of `pixels` only (indices y * w + x), written into `scattering` (RGBA,
/// cameraDepth's size, e.g. the output of another method) and, if given, `steps` (1 channel, same size);
/// other pixels are left untouched. What the epipole block uses (Klehm et al. 2014, Fig. 8: brute-force
/// march a small block of pixels around the epipole). Throws InvalidArgument as worldSpaceMarch, and
/// ("scattering" / "steps" / "pixels") for wrong sizes or indices.
void worldSpaceMarchPixels(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                           const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                           const Medium& medium, std::span<const int> pixels, Image& scattering,
                           Image* steps = nullptr, const WorldMarchOptions& options = {});

} // namespace crep
