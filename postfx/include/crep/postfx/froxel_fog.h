// The froxel fog volume (Wronski 2014, "Volumetric Fog"): CPU references in double of every stage the GL
// passes of gpu_froxel_fog.h run (rules 1-5: ESM after Annen et al. 2008, lighting, accumulation, apply,
// temporal reprojection) and their options. The rules: postfx/README.md, "crep/postfx/froxel_fog.h".
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/scatter/froxel_grid.h>

namespace crep {

/// The exponential shadow map's knobs (rule 1).
struct EsmOptions {
  /// c_w, per world unit along the light, in (0, 1e4]: a receiver 1 / c_w behind an occluder is exp(-1) lit.
  double exponent = 4.0;
  /// Map texels per ESM texel along each axis, in [1, 64] (Wronski 2014: 4).
  int downsample = 4;
  /// Box blur radius r in ESM texels, in [0, 32]: 2r + 1 taps per axis (0 = no blur).
  int blurRadius = 2;
  /// Added to the occluder depth of the test (depth-buffer units), finite, in [-1, 1].
  double bias = 0.0;
};
/// Throws InvalidArgument naming `owner`.field (e.g. "FroxelFog::CreateInfo.esm.exponent").
void validate(const EsmOptions& options, const char* owner);

/// The exponent c in depth-buffer units of the map of `lightClipFromWorld` (rule 1). Throws InvalidArgument
/// ("lightClipFromWorld") unless it is finite and in (0, 1e7].
double esmDepthExponent(const EsmOptions& options, const glm::dmat4& lightClipFromWorld);
/// The ESM of a standard shadow map (rule 1): 1 channel, ceil(W / f) x ceil(H / f), log-space depths.
/// Throws InvalidArgument ("shadowDepth": empty, channels, a value outside [0, 1]). O(W H).
Image buildEsm(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld, const EsmOptions& options);
/// ESM visibility of world point p (rule 1), in [0, 1].
double esmVisibility(const Image& esm, const glm::dmat4& lightClipFromWorld, const glm::dvec3& p,
                     const EsmOptions& options);

/// The medium's density variation (rule 2).
struct FroxelDensity {
  /// Height fog exp(-(y - heightBase) / heightFalloff), world units: heightFalloff 0 = off, else > 0.
  double heightBase = 0.0;
  double heightFalloff = 0.0;
  /// Value noise factor 1 + amplitude (2 n - 1): amplitude in [0, 1] (0 = off), frequency > 0 per world unit.
  double noiseAmplitude = 0.0;
  double noiseFrequency = 0.25;
};
/// Throws InvalidArgument naming `owner`.field.
void validate(const FroxelDensity& density, const char* owner);

/// Value noise in [0, 1] at p (lattice units): hashed corners, smoothstep weights; the same integers as
/// crep_froxelValueNoise (README, rule 2).
double froxelValueNoise(const glm::dvec3& p);
/// rho(p) of rule 2; `noiseOffset` (world units) animates the noise (wind).
double froxelDensity(const FroxelDensity& density, const glm::dvec3& p, const glm::dvec3& noiseOffset);

/// A froxel volume on the CPU: width x height x depth RGBA cells, index (z * height + y) * width + x.
struct FroxelVolume {
  int width = 0, height = 0, depth = 0;
  std::vector<glm::dvec4> cells;
  FroxelVolume() = default;
  FroxelVolume(int w, int h, int d, const glm::dvec4& fill = glm::dvec4(0.0));
  glm::dvec4& at(int x, int y, int z) { return cells[index(x, y, z)]; }
  const glm::dvec4& at(int x, int y, int z) const { return cells[index(x, y, z)]; }
  std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * static_cast<std::size_t>(height) + static_cast<std::size_t>(y)) *
               static_cast<std::size_t>(width) +
           static_cast<std::size_t>(x);
  }
  /// GL's trilinear fetch with clamp-to-edge at texture coordinate uvw (texel centres at (k + 0.5) / size).
  glm::dvec4 sample(const glm::dvec3& uvw) const;
};

/// What the lighting stage needs besides the camera, light and medium (rule 2).
struct FroxelLightingInputs {
  FroxelDensity density;
  glm::dvec3 ambient{0.0};     ///< isotropic ambient radiance L_amb per channel, >= 0
  glm::dvec3 jitter{0.0};      ///< sample offset in cells, each component in [-0.5, 0.5]
  glm::dvec3 noiseOffset{0.0}; ///< world units
  /// The ESM (buildEsm) and its light matrix; nullptr = every point lit.
  const Image* esm = nullptr;
  glm::dmat4 lightClipFromWorld{1.0};
  EsmOptions esmOptions;
};

/// The lighting volume of rule 2 (RGB in-scattering per world unit, A grey extinction).
FroxelVolume froxelLighting(const FroxelGrid& grid, const Camera& camera, const DirectionalLight& light,
                            const Medium& medium, const FroxelLightingInputs& inputs);
/// The integrated volume of rule 3 from a lighting volume lit with `jitter`.
FroxelVolume froxelAccumulate(const FroxelVolume& lighting, const FroxelGrid& grid, const Camera& camera,
                              const Medium& medium, const glm::dvec3& jitter);
/// Rule 4: the RGBA scattering image of the camera depth image (validated by validateCameraDepth).
Image froxelApply(const FroxelVolume& integrated, const FroxelGrid& grid, const Camera& camera,
                  const Image& cameraDepth, const glm::dvec3& offset);
/// Rule 5: the blended volume; `history` nullptr (first frame) or weight 0: the current one, non-finite
/// values replaced. The history must have the same grid.
FroxelVolume froxelTemporal(const FroxelVolume& current, const FroxelVolume* history, const FroxelGrid& grid,
                            const Camera& camera, const Camera& previousCamera, double historyWeight);

} // namespace crep
