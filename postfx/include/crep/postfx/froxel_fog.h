// The froxel fog volume (Wronski 2014, "Volumetric Fog"): CPU references in double precision of every
// stage the GL passes of crep/postfx/gpu_froxel_fog.h run, and the options they share. The volume's
// coordinates are crep::FroxelGrid's (crep/scatter/froxel_grid.h: uvw, exponential view-depth slices,
// Halton jitter); the rays, the phase functions and the output convention are the library's
// (crep/scatter/ray.h, crep/core/medium.h), so the fog is compared with the other methods on the same rays.
//
// ---------------------------------------------------------------------------------------------------
// 1. Exponential shadow map (Annen et al. 2008, with their log-space filtering, as used by Wronski 2014,
//    "Exponential shadow maps"): the exponent is given per world unit along the light (c_w) and turned into
//    depth-buffer units with the light matrix: c = c_w 2 / |grad_world NDC z| (exact for the orthographic sun
//    map, whose depth is linear; esmDepthExponent). The test of a receiver at depth d_r against occluders
//    z_i is exp(c (z - d_r)), and filtering averages exp(c z_i); the ESM stores z = log(mean exp(c z_i)) / c
//    (a depth) evaluated around the largest z_i (log-space filtering), so no value overflows a float for
//    any c (storing exp(c d) itself would overflow beyond c = 88 in depth units, and c must be large where
//    the light's depth range is large: the shadow of an occluder fades over 1 / c_w world units behind it,
//    default c_w = 4: visibility exp(-1) a quarter unit behind the occluder, exp(-8) two units behind).
//    From a standard shadow map of depth-buffer values d in [0, 1] (rendered with lightClipFromWorld, the
//    rule of crep/scatter/world_march.h): ESM texel (i, j) = the log-space mean over the `downsample` x
//    `downsample` block of map texels it covers (blocks clipped at the map's edge: ceil(W / f) x ceil(H / f)
//    texels), then a separable box blur of radius r (2r + 1 taps per axis, clamped at the edges), also a
//    log-space mean. Visibility of a world point p: q = lightClipFromWorld p; lit (1) when q.w <= 0 or
//    (u, v) = q.xy / q.w * 0.5 + 0.5 falls outside [0, 1]^2; else V = clamp(exp(c (z(u, v) + bias - d_r)),
//    0, 1) with d_r = clamp(q.z / q.w * 0.5 + 0.5, 0, 1) and z(u, v) the bilinear interpolation of exp(c z)
//    at the texel centres ((i + 0.5) / w, ...), clamped at the edges, in log space (Wronski 2014's bilinear
//    ESM lookup).
// 2. Lighting (Wronski 2014, "Density estimation and volume lighting"), per cell (x, y, z) at its sample
//    point uvw = ((x + 0.5 + j.x) / W, (y + 0.5 + j.y) / H, (z + 0.5 + j.z) / D) (j = the frame's jitter in
//    cells, 0 without temporal jitter), p = froxelWorldPoint(camera, range, uvw), v = the unit ray
//    through (u, v):
//      rho(p) = density (below), S = rho (E sigma_s phase(dot(light.direction, -v)) V(p) + L_amb sigma_s)
//      per channel (E = light.irradiance(), sigma_s phase = medium.scatteringTimesPhase, L_amb = the
//      isotropic ambient radiance: the in-scattered radiance of a uniform sky is L_amb sigma_s for any
//      normalized phase function), stored RGB = S (in-scattered radiance per world unit), A = rho sbar
//      (grey extinction, sbar = weightExtinction(medium)). Non-finite values are stored as 0.
//    Density rho(p) = (height factor) x (noise factor):
//      height factor = exp(-(p.y - heightBase) / heightFalloff) with the exponent clamped to [-60, 20]
//      (world +Y is up), 1 when heightFalloff = 0;
//      noise factor = 1 + amplitude (2 n(frequency (p + noiseOffset)) - 1) with the value noise n in [0, 1]
//      (froxelValueNoise), 1 when amplitude = 0.
// 3. Accumulation (Wronski 2014, "Solving scattering equation": a front-to-back scan of each (x, y) column).
//    The column's samples lie on one ray (the jitter is the same for every cell of a frame) at distances
//    t_z = froxelRayDistance(camera, uvw_z, Z(w_z)). The integrand is piecewise constant: cell 0's value
//    on [0, t_0], and on [t_{z-1}, t_z] cell z-1's value up to the midpoint and cell z's after it. Every
//    piece [ta, tb] is integrated exactly with per-channel extinction: the density ratio is shared by all
//    channels, so cell k's extinction per channel is A_k (sigma_c / sbar), and the piece adds
//    T_c(ta) S_c (1 - exp(-s_c (tb - ta))) / s_c (crep::transmittanceIntegral); the stored A is the grey
//    transmittance exp(-optical depth in sbar) to the sample point. A homogeneous unshadowed medium is thus
//    exactly crep::unshadowedScattering at every sample point (up to rounding).
// 4. Apply (Wronski 2014, "Applying effect": one 3D lookup per pixel): pixel (x, y) of a w x h camera depth
//    image, view depth Z = camera.surfaceViewDepth(d) (the sky at far()), uvw = ((x + 0.5) / w,
//    (y + 0.5) / h, froxelSliceCoord(Z)) (a pixel outside the outermost sample columns, whose fetch is
//    clamped to the border column, takes the view depth on that column's ray at its own distance Z / cos:
//    Z cos_column / cos_pixel; otherwise the border band would read the wrong distance, 2% at 32 columns);
//    the volume holds its values at the sample points of `offset`
//    (the jitter it was lit with, 0 for the temporally blended volume), so the texture coordinate is uvw -
//    offset / size, fetched trilinearly with clamp-to-edge (GL's rule: texel centres at (k + 0.5) / size).
//    In front of slice 0's sample (view depth Z_0): the value at Z_0 blended linearly in Z with the camera's
//    (RGB 0, A 1): f = Z / Z_0. Beyond the last sample: clamped (the last sample's value). Output RGBA in the
//    library's convention: RGB in-scattered radiance, A = the volume's interpolated grey transmittance
//    (not the pixel's exact exp(-sbar s): with height fog or noise there is no closed form, and the
//    volume's A is the transmittance that goes with its RGB, for opaque and transparent surfaces alike).
// 5. Temporal reprojection (Wronski 2014, "Temporal reprojection", "Sample jittering"), per texel: the
//    unjittered centre p = froxelWorldPoint(camera, range, centre) is found in the previous frame's volume,
//    uvw' = froxelCoord(previousCamera, previousRange, p); history = the trilinear fetch of the previous
//    blended volume at uvw' (clamp-to-edge), rejected when uvw' is outside [0, 1]^3 or not finite, or when
//    the history is not finite. The current value c (the jittered, integrated volume) is replaced by the
//    mean of the finite values of its 3 x 3 x 3 neighbourhood (0 when none) when it is not finite. A kept
//    history is clamped per channel to [min, max] of the finite current values of that neighbourhood
//    (rejects ghosting from disocclusion and moving shadows: a history value the current frame cannot
//    produce nearby is pulled to the nearest one it can), then result = c + weight (history - c). The
//    blend of integrated values is exact for a static or rotating camera (the integral from the camera to a
//    world point does not change) and approximate under translation (the integral then starts elsewhere;
//    the clamp bounds the error by the current neighbourhood's spread).
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/scatter/froxel_grid.h>

namespace crep {

/// The exponential shadow map's knobs (rule 1 above).
struct EsmOptions {
  /// c_w, per world unit along the light, in (0, 1e4] (rule 1): a receiver 1 / c_w behind an occluder is
  /// exp(-1) lit.
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
/// Throws InvalidArgument ("shadowDepth") for an empty map, more than one channel or a value outside [0, 1]
/// (NaN included).
Image buildEsm(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld, const EsmOptions& options);
/// ESM visibility of world point p (rule 1), in [0, 1].
double esmVisibility(const Image& esm, const glm::dmat4& lightClipFromWorld, const glm::dvec3& p,
                     const EsmOptions& options);

/// The medium's density variation (rule 2).
struct FroxelDensity {
  /// Height fog: density exp(-(y - heightBase) / heightFalloff); heightFalloff 0 = off, else > 0 (world
  /// units); heightBase finite.
  double heightBase = 0.0;
  double heightFalloff = 0.0;
  /// 3D value noise multiplying scattering and extinction: 1 + amplitude (2 n - 1), amplitude in [0, 1]
  /// (0 = off), frequency > 0 (lattice cells per world unit).
  double noiseAmplitude = 0.0;
  double noiseFrequency = 0.25;
};
/// Throws InvalidArgument naming `owner`.field.
void validate(const FroxelDensity& density, const char* owner);

/// Value noise in [0, 1] at p (lattice units): a hash of the 8 integer corners of p's lattice cell,
/// interpolated with the smoothstep weights 3t^2 - 2t^3. The corner (i, j, k) hashes to lowbias32 (C.
/// Wellons' 32-bit integer finalizer: x ^= x >> 16; x *= 0x7feb352d; x ^= x >> 15; x *= 0x846ca68b; x ^= x >>
/// 16) of (i * 73856093) ^ (j * 19349663) ^ (k * 83492791) in 32-bit unsigned arithmetic, divided by 2^32.
/// The GLSL twin (glsl/crep/froxel.glsl, crep_froxelValueNoise) computes the same integers.
double froxelValueNoise(const glm::dvec3& p);
/// rho(p) of rule 2; `noiseOffset` (world units) animates the noise (wind).
double froxelDensity(const FroxelDensity& density, const glm::dvec3& p, const glm::dvec3& noiseOffset);

/// A froxel volume on the CPU: width x height x depth cells of RGBA, index (z * height + y) * width + x.
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
/// Rule 5: the blended volume. `history` nullptr (first frame) or weight 0: the current volume with its
/// non-finite values replaced. The history was made with the same grid (its depth range for
/// `previousCamera`).
FroxelVolume froxelTemporal(const FroxelVolume& current, const FroxelVolume* history, const FroxelGrid& grid,
                            const Camera& camera, const Camera& previousCamera, double historyWeight);

} // namespace crep
