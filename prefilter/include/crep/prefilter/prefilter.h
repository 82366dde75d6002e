// Prefiltered single scattering on a rectified shadow map, CPU reference (Klehm, Seidel, Eisemann 2014:
// Sec. 3.1 prefix filtering, Sec. 3.2 weights, Sec. 3.3 regions and normalized storage, Listings 1-4,
// Appendix A). Double precision, multi-threaded over rows, deterministic (bit-identical output for any
// thread count). The GPU passes (gpu_*.h) implement the same rules; this header is their contract.
//
// ---------------------------------------------------------------------------------------------------
// Prefilter (prefilter())
// Prefilter regions: every layout region (split) k is cut into P = regionsPerSplit equal parts, so
// there are R = K P regions of n = W / R texels; region r = k P + q covers texel columns
// [r n, (r + 1) n) and its reference-ray profile is layout.rayProfile(row, zk, k).sub(q / P, (q+1) / P),
// zk = layout.regionReferenceDepth(row, k): the row's reference ray, or for spot/point lights the row's
// ray reaching furthest (crep/rectify/rectified_map.h ProjectiveLayout) (referenceProfiles()). Per texel row
// j (row coordinate (j + 0.5) / H) and region r, left to right:
//   z_i = texelBasisDepth(depth(i, j), depthMargin)     (fourier.h)
//   F_i = F_{i-1} + m_i (B(z_i) - F_{i-1}),  F_{-1} = 0, m_i = regionMixFactors(...)   (weights.h)
// so F_i = sum_{l<=i} w_l B(z_l) / sum_{l<=i} w_l in [-1, 1] (Appendix A), the region's own normalized
// prefix ending at the right edge of texel i. Stored: e = quantize(0.5 + 0.5 F, format), the same
// encoding for every format (decode F = 2 e - 1).
//
// ---------------------------------------------------------------------------------------------------
// Evaluation (evaluate()), per camera pixel (x, y) of a w x h depth image (row 0 at the bottom):
//   ndc = (2 (x + 0.5) / w - 1, 2 (y + 0.5) / h - 1), v = camera.rayDirection(ndc) (unit),
//   s = linearDepth(depth) / dot(v, forward) (the surface distance, world units); sky: depth >= 1
//   integrates to the far plane, s = far / dot(v, forward) (the map covers the frustum up to there and
//   has no information beyond it); p = camera.position() + s v; P = layout.toRectified(p) gives the
//   ray's row, its depth z_r and the hit's region k_s / column u (-> prefilter region r_s, u_s).
//   The ray is cut at the region boundaries: t_r = rayDistance(row, z_r, r / R) along the ray itself
//   (not the reference ray). Region r < r_s contributes on [t_r, t_{r+1}], region r_s on [t_{r_s}, s],
//   except that region 0 starts at the camera (t = 0; the map starts at X = axisMin, in front of the
//   near plane): that is the paper's 1 - exp(-s sigma) for one region.
//   Optional near-plane correction (Sec. 3.1, EvaluateOptions::nearPlaneCorrection): the integral
//   starts at the near-plane point t_n = near / dot(v, forward) instead, in region r_n (u_n); the part
//   [t_n, end] of region r_n uses the prefix difference (below); regions before r_n contribute nothing.
//   Visibility of a region segment [u_a, u_b] of region r (u_a = 0 except with the correction):
//     (a = fourierCoefficients(zb) then applyRingingFilter(EvaluateOptions::ringing, a), fourier.h)
//     V = clamp(0.5 + a(zb) . (W_b F(u_b) - W_a F(u_a)) / (W_b - W_a), 0, 1), zb = rayBasisDepth(z_r, m),
//     W = regionWeightTotal(mode, extinction, profile of the nearest texel row, n, u) (W_a = 0 for
//     u_a = 0, then V = clamp(0.5 + a . F(u_b), 0, 1)); if W_b - W_a <= 1e-12 W_b, V = clamp(0.5 + a .
//     F(u_b)).
//   F(u): the filtered basis sampled at the prefix boundary u of region r: texel-space column
//     x = clamp(u n - 1, 0, n - 1) (texel i holds the prefix at u = (i + 1) / n), row y = clamp(row H - 0.5,
//     0, H - 1); Sampling::Bilinear interpolates linearly between floor and floor + 1 in x and y (never
//     across a region boundary: x stays in [0, n - 1] of its region), Sampling::Nearest takes
//     floor(x + 0.5), floor(y + 0.5). On the GPU: texture(array, vec3((r n + x + 0.5) / W, (y + 0.5) / H,
//     layer)) with GL_LINEAR / GL_NEAREST does the same (up to the sampler's 8-bit weight precision).
//   Radiance per channel c (Eq. 1, 3, 11):
//     L_c = C_c sum_segments V (exp(-sigma_c t_a) - exp(-sigma_c t_b)) / sigma_c,
//     computed as exp(-sigma_c t_a) (t_b - t_a) phi(sigma_c (t_b - t_a)) (sigma_c -> 0 limit, weights.h),
//     C = light.irradiance() * medium.scatteringTimesPhase(dot(light.direction(), -v)) (Mie HG + Rayleigh).
//   AverageVisibility: one visibility for the whole ray is not what the regions give; the same
//   per-region formula is used (the stored F are then unweighted means per region).
//   Output RGBA: RGB = L, A = exp(-weightExtinction(medium) s), the grey transmittance to the surface
//   (composite: surface * A + L; per-channel transmittance is exp(-sigma_c s)).
//
// ---------------------------------------------------------------------------------------------------
// Light textures (crep/scatter/light_texture.h; Klehm et al. 2014, Sec. 3.2 "Angular-dependency for
// Sources": a coloured light texture is a light-side factor per colour component, "stored per component").
// With a colour c_i per texel (the texture at the texel's light ray, lightColorMap()), the light reaching a
// view ray section in texel i is c_i times the untextured one, so the region average of Eq. 5 becomes per
// channel sum_i w_i c_i V_i / sum_i w_i = cbar (sum_i w_i c_i V_i / sum_i w_i c_i) with the prefix mean
// colour cbar = sum w_i c_i / sum w_i. The second factor is an ordinary normalized prefix with the weights
// w_i c_i, so per channel c and texel i of a region (m_i the untextured mix factors):
//   cbar_i = cbar_{i-1} + m_i (c_i - cbar_{i-1}),  cbar_{-1} = 0        (the same filter as F)
//   m^c_i = m_i (c_i / cbar_i)   (= w_i c_i / sum_{l<=i} w_l c_l, clamped to [0, 1]; m_i where cbar_i = 0)
//   F^c_i = F^c_{i-1} + m^c_i (B(z_i) - F^c_{i-1})
// stored as three bases (3 ceil(M / 4) layers, colour c in layers [c L, (c + 1) L): 3x the storage and the
// filter work, the tripled storage of Sec. 3.2) and cbar per texel as float (one RGBA32F texture: HDR
// textures beyond binary16's 65504 are not clipped). A constant texture c gives cbar = c and m^c = m (c / c =
// 1) exactly, so F^c = F bit for bit. Evaluation per channel: V_c = cbar_c(u_b) clamp(0.5 + a . F^c(u_b), 0,
// 1) (cbar sampled like F), 0 where cbar = 0 (no weighted light); with the near-plane correction the prefix
// difference weighs each prefix by W cbar: V_c = cseg clamp(0.5 + a . (W_b cbar_b F^c_b - W_a cbar_a F^c_a) /
// (W_b cbar_b - W_a cbar_a)), cseg = (W_b cbar_b - W_a cbar_a) / (W_b - W_a) (0 where the numerator is <= 0).
// The region visibility table then holds 3 values per cell (V_c at the region's last texel) and the
// scattering prefix table multiplies each channel's section integral by its own V_c.
//
// ---------------------------------------------------------------------------------------------------
// Froxel volumes (evaluateFroxels(); EvaluatePass::FrameAttribs::froxels). The in-scattering from the camera
// to any point of a pixel ray is the evaluation above with that point's distance as the surface distance,
// so one basis fills a frustum-aligned volume (Wronski 2014; crep/scatter/froxel_grid.h) directly, one
// evaluation per cell: cell (x, y, z) of a W x H x D grid with jitter j (cells, each in [-0.5, 0.5]) samples
//   uvw = ((x + 0.5 + j.x) / W, (y + 0.5 + j.y) / H, (z + 0.5 + j.z) / D), v = camera.rayDirection(2 u - 1,
//   2 v - 1), Z = min(froxelViewDepth(range, w), camera.far()), s = Z / dot(v, forward)
// (beyond the camera's integration far the map has no information: the sky's value, as per pixel), the
// near-plane correction's start as per pixel, and stores the pixel's output rule there (RGB = L, A =
// exp(-sbar s)). So the volume at a cell centre equals the per-pixel output of a camera image of W x H pixels
// whose depth buffer holds that slice's depth. Directional light only.
//
// ---------------------------------------------------------------------------------------------------
// References. The method's own error is evaluate() against bruteForceMarch() (crep/scatter/
// rectified_march.h) on the same map: the same rays, start and end rules and output, but the visibility
// integrated exactly per texel (no Fourier truncation, no reference-ray weights, no quantization, no
// filtering). Ground truth without any map: unshadowedScattering() (crep/scatter/ray.h) for an empty
// scene, worldSpaceMarch() (crep/scatter/world_march.h) against a standard shadow map.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/prefilter/fourier.h>
#include <crep/prefilter/weights.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/froxel_grid.h>
#include <crep/scatter/ray.h>
#include <crep/scatter/ray_scattering.h>

namespace crep {

/// How the filtered basis is stored (as the GPU texture array stores it).
enum class StorageFormat {
  RGBA8,   ///< GL_RGBA8 (UNORM): quantize(e) = round(clamp(e, 0, 1) 255) / 255, round half up
  RGBA16F, ///< GL_RGBA16F: e rounded to the nearest binary16 (ties to even)
  RGBA32F, ///< GL_RGBA32F: e rounded to the nearest float
};
/// "rgba8", "rgba16f", "rgba32f".
const char* storageFormatToken(StorageFormat format);

/// How evaluate() samples the filtered basis.
enum class Sampling {
  Nearest,  ///< GL_NEAREST
  Bilinear, ///< GL_LINEAR: hardware bilinear filtering of the array layer (paper Sec. 5) (default)
};

struct PrefilterOptions {
  /// M, even, in [kMinBases, kMaxBases] (fourier.h). Layers = ceil(M / 4).
  int bases = kDefaultBases;
  WeightMode weights = WeightMode::Exact;
  StorageFormat format = StorageFormat::RGBA8;
  /// P >= 1: prefilter regions per layout region (Sec. 3.3, Table 1); map width must be a multiple of
  /// regionCount() * P.
  int regionsPerSplit = 1;
  /// m in [0, 0.25] of texelBasisDepth / rayBasisDepth (fourier.h). Default 1/16: see prefilter/README.md.
  double depthMargin = 0.0625;
  /// GPU pass only (Table 1: bases per invocation, a multiple of 4 in [4, 128]; the last group of a row
  /// may be partial when it does not divide M); ignored by the CPU. Default 16, a choice for GPUs: every
  /// invocation repeats the per-texel set-up (depth, two exact sin/cos, the weight) for its group, and
  /// with the library's 16 prefilter regions a 1024^2 map at M = 32 still gives 32k invocations, enough
  /// to fill low-end and integrated GPUs, which are the ALU-bound ones (the paper's 8 was measured with
  /// 1-3 regions per row). On llvmpipe 16 is 1.5x faster than 8 (`crep bench`, "limits").
  int basesPerInvocation = 16;
  /// Local lights only: the light-side factors in the weights (LocalLightWeights; README "Local lights"
  /// gives the figures of each).
  LocalLightWeights localLightWeights = LocalLightWeights::Full;
  /// CPU worker threads: 0 = std::thread::hardware_concurrency(). Never changes the result.
  int threads = 0;
};

/// The one validation of the prefilter's parameters, for the CPU reference and the GPU pass: throws
/// InvalidArgument naming the field as `<owner>.bases`, `<owner>.format`, `<owner>.weights`,
/// `<owner>.regionsPerSplit`, `<owner>.depthMargin`, `<owner>.basesPerInvocation`, `<owner>.threads`
/// (owner e.g. "PrefilterOptions" or "PrefilterPass::CreateInfo.options").
void validate(const PrefilterOptions& options, std::string_view owner = "PrefilterOptions");

/// Number of RGBA layers for M bases: (M + 3) / 4 (channels beyond M are stored as encoded 0.5, i.e. F = 0).
inline int layerCount(int bases) {
  return (bases + 3) / 4;
}

/// Bytes of one RGBA texel in `format` (4, 8 or 16).
inline std::size_t texelBytes(StorageFormat format) {
  return format == StorageFormat::RGBA8 ? 4 : format == StorageFormat::RGBA16F ? 8 : 16;
}
/// GPU bytes of a W x H filtered basis of M bases (ceil(M / 4) RGBA layers in `format`).
inline std::size_t filteredBasisBytes(int width, int height, int bases, StorageFormat format) {
  return static_cast<std::size_t>(width) * static_cast<std::size_t>(height) *
         static_cast<std::size_t>(layerCount(bases)) * texelBytes(format);
}
/// GPU bytes of the region visibility table (EvaluateOptions::visibilityTableSamples Z): R Z x H, R32F.
inline std::size_t visibilityTableBytes(int height, int regions, int samples) {
  return static_cast<std::size_t>(height) * static_cast<std::size_t>(regions) *
         static_cast<std::size_t>(samples) * 4;
}
/// GPU bytes of the scattering prefix table (EvaluateOptions::scatteringPrefix): R Z x H, RGBA32F.
inline std::size_t scatteringPrefixBytes(int height, int regions, int samples) {
  return 4 * visibilityTableBytes(height, regions, samples);
}

/// The storage rule of the filtered basis: encode F in [-1, 1] as e = 0.5 + 0.5 F and round it to
/// `format` (RGBA8: round(clamp(e, 0, 1) * 255) / 255; RGBA16F: nearest binary16, ties to even; RGBA32F:
/// nearest float). Returns the stored value e as the GPU reads it back.
float storeFiltered(double filtered, StorageFormat format);
/// Nearest binary16 value of v (ties to even, subnormals included, +-inf beyond 65504), as a float.
float roundToHalf(double v);

/// The per-row, per-region reference-ray profiles the prefilter uses (see top): H * R values, index
/// j * R + r. What the GPU uploads (4 numbers per row and region).
std::vector<DistanceProfile> referenceProfiles(const RectifiedLayout& layout, int height,
                                               int regionsPerSplit);

/// The prefiltered ("filtered-basis") texture array and what evaluation needs with it.
struct FilteredBasis {
  int width = 0, height = 0; ///< texels, the map's size
  int bases = 0;             ///< M
  int layers = 0;            ///< ceil(M / 4)
  int regions = 0;           ///< R = layout regions * regionsPerSplit
  int regionsPerSplit = 1;   ///< P
  StorageFormat format = StorageFormat::RGBA8;
  WeightMode weights = WeightMode::Exact;
  double extinction = 0.0;  ///< the scalar weight extinction s (1/world unit)
  double depthMargin = 0.0; ///< m of fourier.h
  /// Stored values e (encoded, already rounded to `format`), layers * height * width * 4, index
  /// ((layer * height + y) * width + x) * 4 + channel; basis j = 4 layer + channel; y = 0 bottom.
  /// Exactly what glTexSubImage3D of a GL_RGBA / GL_FLOAT array upload would contain.
  std::vector<float> texels;
  /// referenceProfiles(): height * regions, index y * regions + r.
  std::vector<DistanceProfile> profiles;
  /// The map's layout (shared with the RectifiedMap).
  std::shared_ptr<const RectifiedLayout> layout;
  /// Prefiltered for a local light (its light-side factor in the weights): evaluate with that light.
  bool localLight = false;
  /// Prefiltered with a light texture's colour map (see "Light textures" at the top): `texels` holds three
  /// bases, colour channel c in layers [c layers, (c + 1) layers), and `meanColor` the prefix mean colours.
  bool textured = false;
  /// Textured only: cbar_c of every texel, height * width * 3, index (y * width + x) * 3 + c, as float (the
  /// GPU's GL_RGBA32F texture). Empty otherwise.
  std::vector<float> meanColor;

  int regionWidth() const noexcept { return regions > 0 ? width / regions : 0; } ///< n
  int colorBases() const noexcept { return textured ? 3 : 1; } ///< bases stored: 3 with a texture, else 1
  /// Stored value e of basis j at texel (x, y), of colour channel `color`'s basis (0 untextured).
  float stored(int x, int y, int basis, int color = 0) const {
    return texels[((static_cast<std::size_t>(color * layers + basis / 4) * static_cast<std::size_t>(height) +
                    static_cast<std::size_t>(y)) *
                       static_cast<std::size_t>(width) +
                   static_cast<std::size_t>(x)) *
                      4 +
                  static_cast<std::size_t>(basis % 4)];
  }
  /// Decoded F = 2 e - 1 of basis j at texel (x, y) (of colour channel `color`'s basis when textured).
  double filtered(int x, int y, int basis, int color = 0) const {
    return 2.0 * static_cast<double>(stored(x, y, basis, color)) - 1.0;
  }
  /// cbar_c at texel (x, y) (textured only).
  float mean(int x, int y, int color) const {
    return meanColor[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                      static_cast<std::size_t>(x)) *
                         3 +
                     static_cast<std::size_t>(color)];
  }
};

/// The CPU reference prefilter (see top) with the medium's weight extinction (weightExtinction()).
/// Validates the map and options (InvalidArgument naming them).
FilteredBasis prefilter(const RectifiedMap& map, const Medium& medium, const PrefilterOptions& options = {});
/// The same with an explicit scalar weight extinction s >= 0 (1/world unit).
FilteredBasis prefilter(const RectifiedMap& map, double extinction, const PrefilterOptions& options = {});
/// For a local light (a spot, or one point-light face; the map rendered with its rectification): the
/// weights also carry the light-side factor along each region's reference ray (regionMixFactors with
/// light samples; LocalLight::weightFactor), Klehm et al. 2014, Sec. 3.2 "Local Lights" / "Angular-
/// dependency for Sources". The evaluation then restores each view ray's exact unoccluded in-scattering
/// per region (RayScattering), so the weights only shape the visibility average within a region.
FilteredBasis prefilter(const RectifiedMap& map, const Medium& medium, const LocalLight& light,
                        const PrefilterOptions& options = {});
/// Light textures (see "Light textures" at the top): the prefilter per colour channel with the texel
/// colours of `lightColors` (lightColorMap() of crep/scatter/light_texture.h: the map's size, RGB, finite,
/// >= 0; InvalidArgument "lightColors" naming the texel otherwise) in the weights, for the directional light
/// with the medium's weight extinction ...
FilteredBasis prefilter(const RectifiedMap& map, const Medium& medium, const Image& lightColors,
                        const PrefilterOptions& options = {});
/// ... and for a local light (its light-side factor and the colours in the weights).
FilteredBasis prefilter(const RectifiedMap& map, const Medium& medium, const LocalLight& light,
                        const Image& lightColors, const PrefilterOptions& options = {});

struct EvaluateOptions {
  Sampling sampling = Sampling::Bilinear;
  /// Sec. 3.1: integrate from the near plane instead of the camera (see top).
  bool nearPlaneCorrection = false;
  /// Damping of the ray coefficients a (fourier.h). Default None = the paper's Eq. 8: on the built-in
  /// scenes Lanczos damping is worse (its wider step darkens the texels just before each receiver, which
  /// lies in the map itself); it is much better for open, unoccluded views (prefilter/README.md).
  RingingFilter ringing = RingingFilter::None;
  /// Z samples of the region visibility table (0 = none): a region the ray crosses whole contributes
  /// V = clamp(0.5 + a(z) . F_r(end), 0, 1), which depends only on the texel row and the ray's depth z, so
  /// it is tabulated once per frame (H rows x R regions x Z depths, built from the stored basis) and read
  /// with one bilinear fetch (row, depth) instead of M / 4; only the region where the ray ends fetches the
  /// basis. Used with Sampling::Bilinear and without the near-plane correction (else the direct path).
  /// Not in the paper: the evaluation is bound by its basis fetches (bench/README.md, "Profile").
  /// Default 128: ~8 samples across the step of M = 32 (README "Measured figures").
  int visibilityTableSamples = 128;
  /// With the visibility table: also tabulate the prefix sums of the regions' in-scattering along the
  /// table's sample rays, S_r(row, z) = sum_{r' < r} V_r'(row, z) TI_r'(row, z) per colour channel, with TI
  /// the transmittance integral of Eq. 3 over region r' of the ray of that row and depth (the ray is fixed
  /// by its row and depth z_r: all its points share them). A pixel then reads every region it crosses
  /// whole in one bilinear RGB fetch and evaluates only its last region: constant cost, whatever the
  /// number of regions it crosses (Klehm et al. 2014 Sec. 5's "constant performance"; the prefix of
  /// Sec. 3.1 run across regions, not in the paper). Default true; false = the per-region loop over the
  /// visibility table (the figures of bench/README.md, "Profile", compare them).
  bool scatteringPrefix = true;
  /// Local lights with the scattering prefix table: also tabulate each region's unshadowed in-scattering
  /// along the sample rays (the local section table, built with the prefix table); a pixel's last region
  /// [t_last, surface] then takes the section of its (row, depth) from it, times the share of it its own
  /// ray holds up to the surface (RayScattering::partialShare: the trapezoid rule in the substitution's
  /// angle, three integrand values), instead of a quadrature per pixel. Not in the paper. Default true.
  bool localSectionTable = true;
  /// CPU worker threads: 0 = hardware concurrency. Never changes the result.
  int threads = 0;
};

/// Whether evaluation with `options` uses the region visibility table (see visibilityTableSamples).
inline bool usesVisibilityTable(const EvaluateOptions& options) {
  return options.visibilityTableSamples > 0 && options.sampling == Sampling::Bilinear &&
         !options.nearPlaneCorrection;
}
/// Whether evaluation with `options` uses the scattering prefix table (see scatteringPrefix).
inline bool usesScatteringPrefix(const EvaluateOptions& options) {
  return usesVisibilityTable(options) && options.scatteringPrefix;
}
/// Whether a local light's evaluation with `options` uses the local section table (see localSectionTable).
inline bool usesLocalSectionTable(const EvaluateOptions& options) {
  return usesScatteringPrefix(options) && options.localSectionTable;
}
inline constexpr int kMaxVisibilityTableSamples = 4096;

/// The ray coefficients of the region visibility table's samples: a(z_s) of Eq. 8 (with `ringing`) at the
/// ray basis depth of the normalized depth s / (samples - 1), M values per sample, index s * M + k. The one
/// definition of the samples, for visibilityTable() and EvaluatePass's table pass.
std::vector<double> visibilityTableCoefficients(int samples, int bases, double depthMargin,
                                                RingingFilter ringing);

/// The region visibility table of `basis` (see visibilityTableSamples), in double from the stored values:
/// index (row * R + region) * Z + s, sample s at normalized ray depth s / (Z - 1), ray coefficients with
/// `ringing`; a textured basis holds 3 values per cell (index ((row * R + region) * Z + s) * 3 + c, V_c of
/// "Light textures" above). What EvaluatePass builds on the GPU in float
/// (glsl/passes/prefilter/visibility_table.comp).
std::vector<double> visibilityTable(const FilteredBasis& basis, int samples, RingingFilter ringing);

/// The scattering prefix table (see EvaluateOptions::scatteringPrefix) of `basis` and its region
/// visibility table `visibility` (visibilityTable(), Z = samples): index ((row * R + region) * Z + s) * 3 +
/// c, the in-scattering (without the constant C of Eq. 1) of regions 0 .. region - 1 along the ray of texel
/// row (row + 0.5) / H and normalized depth s / (Z - 1), region r' cut at t_r' = layout.rayDistance(row,
/// depth, r' / R) (t_0 = 0, each t at least the one before), per channel of `extinction`. What
/// EvaluatePass builds on the GPU in float (glsl/passes/prefilter/scattering_prefix.comp).
std::vector<double> scatteringPrefixTable(const FilteredBasis& basis, const std::vector<double>& visibility,
                                          int samples, const glm::dvec3& extinction);
inline constexpr int kScatteringPrefixChannels = 3;

/// Throws InvalidArgument naming the field as `<owner>.sampling`, `<owner>.ringing`,
/// `<owner>.visibilityTableSamples` (0 or in [2, kMaxVisibilityTableSamples]), `<owner>.threads`.
void validate(const EvaluateOptions& options, std::string_view owner = "EvaluateOptions");

/// Evaluation (see top): a 4-channel image of cameraDepth's size, RGB = in-scattered radiance, A =
/// grey transmittance. `cameraDepth`: 1 channel (channel 0 used if more), depth-buffer values of
/// `camera` in [0, 1] (1 = sky). Throws InvalidArgument ("cameraDepth") for an empty image or a value
/// NaN / outside [0, 1] (with its pixel), ("FilteredBasis") for an inconsistent basis or no layout.
/// Pixels whose surface point the layout cannot map (toRectified throws: only when `camera` is not the
/// rectification's camera) get the unshadowed value (V = 1 on the whole ray), never NaN.
Image evaluate(const FilteredBasis& basis, const Image& cameraDepth, const Camera& camera,
               const DirectionalLight& light, const Medium& medium, const EvaluateOptions& options = {});
/// The same for a local light, on a basis prefiltered for it (prefilter(map, medium, light)): every region
/// segment [ta, tb] of a view ray contributes V RayScattering::segment(ta, tb) (the falloffs, 1 / d^2 and
/// the light path's extinction of the ray itself), the scattering prefix table holds the same along its
/// sample rays, and RGB is the radiance itself. Throws InvalidArgument ("FilteredBasis.localLight") when
/// the basis was prefiltered for the other kind of light; the near-plane correction is not supported for
/// local lights ("EvaluateOptions.nearPlaneCorrection").
Image evaluate(const FilteredBasis& basis, const Image& cameraDepth, const Camera& camera,
               const LocalLight& light, const Medium& medium, const EvaluateOptions& options = {});
/// The sample ray of froxel cell (x, y, z) of `grid` (depth range `range`) with `jitter` (see "Froxel
/// volumes" at the top): direction, distance to the sample point, start (near-plane correction).
PixelRay froxelSampleRay(const Camera& camera, const FroxelDepthRange& range, const FroxelGrid& grid,
                         const glm::dvec3& jitter, int x, int y, int z, bool nearPlaneCorrection);
/// Throws InvalidArgument naming `field` unless each component of `jitter` is finite and in [-0.5, 0.5].
void validateFroxelJitter(const glm::dvec3& jitter, const std::string& field);
/// The froxel fill (see "Froxel volumes" at the top) of `basis` for the directional light: an RGBA image of
/// grid.width x (grid.height grid.depth), slice z in rows [z height, (z + 1) height) (the memory order of the
/// 3D texture: x, then y, then z), RGB in-scattered radiance, A grey transmittance. Throws InvalidArgument
/// naming "evaluateFroxels.grid.*" / "evaluateFroxels.jitter", ("FilteredBasis.localLight") for a local
/// light's basis, and as evaluate().
Image evaluateFroxels(const FilteredBasis& basis, const FroxelGrid& grid, const glm::dvec3& jitter,
                      const Camera& camera, const DirectionalLight& light, const Medium& medium,
                      const EvaluateOptions& options = {});

/// scatteringPrefixTable for a local light: the in-scattering itself (RayScattering along each sample ray
/// from layout.origin() in the direction layout.viewRayDirection(row, depth)).
std::vector<double> scatteringPrefixTable(const FilteredBasis& basis, const std::vector<double>& visibility,
                                          int samples, const LocalLight& light, const Medium& medium);
/// A local section's far end when its end boundary is beyond reach (glsl CREP_LOCAL_SECTION_END).
inline constexpr double kLocalSectionEnd = 1e29;
/// The local section table (EvaluateOptions::localSectionTable): for texel row j, depth sample s and region
/// r, the unshadowed in-scattering RayScattering::segment(t_r, min(t_r+1, kLocalSectionEnd)) along the sample
/// ray of scatteringPrefixTable; the same layout (3 channels). What EvaluatePass's prefix pass writes beside
/// the prefix table on the GPU.
std::vector<double> localSectionTable(const FilteredBasis& basis, int samples, const LocalLight& light,
                                      const Medium& medium);

} // namespace crep
