// The world-space reference march against a standard shadow map (Klehm et al. 2014, Eq. 1 and 3; Yusov
// 2012, Eq. 15-16): single scattering without rectification, CPU reference in double (WorldMarchPass on
// the GPU). Visibility, sections, local lights, light textures: scatter/README.md,
// "crep/scatter/world_march.h".
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

/// Visibility of a world point against a standard shadow map (no validation: hot path).
bool standardShadowLit(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld, const glm::dvec3& p,
                       double bias = 0.0);

/// The world-space reference march. Throws InvalidArgument for a bad shadow map ("shadowDepth"), matrix
/// ("lightClipFromWorld"), "cameraDepth" or options. O(pixels x steps), + refinements per change.
MarchResult worldSpaceMarch(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                            const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                            const Medium& medium, const WorldMarchOptions& options = {});

/// For a local light (a spot, or one point-light face: add the faces' results) against its perspective
/// shadow map; RGB is the radiance itself.
MarchResult worldSpaceMarch(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                            const Image& cameraDepth, const Camera& camera, const LocalLight& light,
                            const Medium& medium, const WorldMarchOptions& options = {});
/// With a light texture, directional or local light. Throws InvalidArgument naming "lightTexture.rgb" /
/// "lightTexture.textureClipFromWorld" (validateLightTexture).
MarchResult worldSpaceMarch(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                            const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                            const Medium& medium, const LightTexture& lightTexture,
                            const WorldMarchOptions& options = {});
MarchResult worldSpaceMarch(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                            const Image& cameraDepth, const Camera& camera, const LocalLight& light,
                            const Medium& medium, const LightTexture& lightTexture,
                            const WorldMarchOptions& options = {});
/// The same for `pixels` only (indices y * w + x) into `scattering` / `steps`, others untouched: the
/// epipole block (Klehm et al. 2014, Fig. 8). InvalidArgument also for "scattering", "steps", "pixels".
void worldSpaceMarchPixels(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                           const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                           const Medium& medium, std::span<const int> pixels, Image& scattering,
                           Image* steps = nullptr, const WorldMarchOptions& options = {});

} // namespace crep
