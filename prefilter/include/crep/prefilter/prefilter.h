// Prefiltered single scattering on a rectified shadow map, CPU reference (Klehm, Seidel, Eisemann 2014,
// Sec. 3.1-3.3, Listings 1-4, Appendix A): double precision, rows in parallel, bit-identical for any thread
// count. The contract the GPU passes (gpu_pass.h) implement in float; the rules: prefilter/README.md.
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

/// How evaluation reconstructs the weighted visibility of a row prefix for a view ray's depth z_r.
enum class VisibilityReconstruction {
  /// Klehm et al. 2014, Eq. 9: 0.5 + a(z_r) . F, the truncated Fourier series of the prefiltered basis
  /// (default).
  Fourier,
  /// Not in the paper: the exact weighted prefix of the depth test, sum_i w_i [z_i >= z_r] / sum_i w_i,
  /// walked
  /// over the region a ray ends in (at most n = width / R texels per pixel; the GPU passes uniform blocks of
  /// 8
  /// in one step), and sampled exactly at the table's Z ray depths for the regions it crosses whole. No
  /// truncation error: the error budget in docs/MEASUREMENTS.md. crep::Scattering's default.
  Exact,
};
/// "fourier", "exact".
const char* visibilityReconstructionToken(VisibilityReconstruction reconstruction);

struct PrefilterOptions {
  int bases = kDefaultBases; ///< M: even, in [kMinBases, kMaxBases] (fourier.h); ceil(M / 4) RGBA layers
  WeightMode weights = WeightMode::Exact;      ///< weights.h (Sec. 3.2, Eq. 11-12)
  StorageFormat format = StorageFormat::RGBA8; ///< of the filtered basis (Sec. 3.3)
  /// P >= 1 prefilter regions per layout region (Sec. 3.3, Table 1); map width a multiple of regionCount() P.
  int regionsPerSplit = 1;
  double depthMargin = 0.0625; ///< m in [0, 0.25] of texelBasisDepth / rayBasisDepth (fourier.h)
  /// GPU only (Table 1): bases per invocation, a multiple of 4 in [4, 128]; ignored by the CPU.
  int basesPerInvocation = 16;
  LocalLightWeights localLightWeights = LocalLightWeights::Full; ///< local lights: light-side factors
  int threads = 0; ///< CPU workers, 0 = hardware concurrency; never changes the result
  /// What the basis holds for evaluation: the Fourier basis (default), or the map's depths and cumulative
  /// weights.
  VisibilityReconstruction reconstruction = VisibilityReconstruction::Fourier;
};

/// The one validation of the options (CPU and GPU): InvalidArgument naming `<owner>.bases`, `.format`,
/// `.weights`, `.regionsPerSplit`, `.depthMargin`, `.basesPerInvocation`, `.threads` or `.reconstruction`.
void validate(const PrefilterOptions& options, std::string_view owner = "PrefilterOptions");

/// RGBA layers of M bases: (M + 3) / 4 (channels beyond M store the encoded 0.5, F = 0).
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
/// GPU bytes of a W x H exact basis (VisibilityReconstruction::Exact): two RG32F layers, (depth, cumulative
/// weight) per texel and the blocks' depth ranges.
inline std::size_t exactBasisBytes(int width, int height) {
  return static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 16;
}
/// GPU bytes of the region visibility table (Z = EvaluateOptions::visibilityTableSamples): R Z x H, R32F.
inline std::size_t visibilityTableBytes(int height, int regions, int samples) {
  return static_cast<std::size_t>(height) * static_cast<std::size_t>(regions) *
         static_cast<std::size_t>(samples) * 4;
}
/// GPU bytes of the scattering prefix table (EvaluateOptions::scatteringPrefix): R Z x H, RGBA32F.
inline std::size_t scatteringPrefixBytes(int height, int regions, int samples) {
  return 4 * visibilityTableBytes(height, regions, samples);
}

/// The storage rule: e = 0.5 + 0.5 F rounded to `format` (StorageFormat); returns e as the GPU reads it.
float storeFiltered(double filtered, StorageFormat format);
/// Nearest binary16 value of v (ties to even, subnormals included, +-inf beyond 65504), as a float.
float roundToHalf(double v);

/// The reference-ray profiles of the prefilter: H * R values, index j * R + r (what the GPU uploads).
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
  /// Stored e, index ((layer * height + y) * width + x) * 4 + channel (basis 4 layer + channel, y = 0
  /// bottom): what a GL_RGBA / GL_FLOAT glTexSubImage3D upload of the array would contain.
  std::vector<float> texels;
  std::vector<DistanceProfile> profiles;         ///< referenceProfiles(): index y * regions + r
  std::shared_ptr<const RectifiedLayout> layout; ///< the map's layout (shared with the RectifiedMap)
  bool localLight = false;                       ///< prefiltered for a local light: evaluate with that light
  /// Prefiltered with a light texture's colours: `texels` holds three bases, colour c in layers [c layers,
  /// (c + 1) layers), `meanColor` the prefix mean colours.
  bool textured = false;
  /// Textured only: cbar_c per texel as float, index (y * width + x) * 3 + c; empty otherwise.
  std::vector<float> meanColor;
  /// Fourier: `texels` holds the basis. Exact: `texels` is empty and evaluation walks `depth` with `weight`.
  VisibilityReconstruction reconstruction = VisibilityReconstruction::Fourier;
  /// Exact only: the rectified map's depths, index y * width + x; empty otherwise.
  std::vector<float> depth;
  /// Exact only: the cumulative weight W_i = sum_{k <= i} w_k / sum_region w_k of each texel within its
  /// region (= prod_{k > i} (1 - m_k) of Listing 2's mix factors; with a texture, of colour c's weights
  /// w_i c_i), index (c * height + y) * width + x. Texel i's share of a prefix is W_i - W_{i-1}.
  std::vector<float> weight;

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

/// The CPU reference prefilter with weightExtinction(medium); InvalidArgument naming a bad map or option.
FilteredBasis prefilter(const RectifiedMap& map, const Medium& medium, const PrefilterOptions& options = {});
/// The same with an explicit scalar weight extinction s >= 0 (1/world unit).
FilteredBasis prefilter(const RectifiedMap& map, double extinction, const PrefilterOptions& options = {});
/// For a local light (Klehm et al. 2014, Sec. 3.2 "Local Lights"): its light-side factor along each region's
/// reference ray (LocalLight::weightFactor) in the weights.
FilteredBasis prefilter(const RectifiedMap& map, const Medium& medium, const LocalLight& light,
                        const PrefilterOptions& options = {});
/// Light textures: per colour channel with `lightColors` (lightColorMap(): the map's size, RGB, finite, >= 0,
/// else InvalidArgument "lightColors") in the weights, for the directional light ...
FilteredBasis prefilter(const RectifiedMap& map, const Medium& medium, const Image& lightColors,
                        const PrefilterOptions& options = {});
/// ... and for a local light (its light-side factor and the colours in the weights).
FilteredBasis prefilter(const RectifiedMap& map, const Medium& medium, const LocalLight& light,
                        const Image& lightColors, const PrefilterOptions& options = {});

struct EvaluateOptions {
  Sampling sampling = Sampling::Bilinear;
  bool nearPlaneCorrection = false; ///< Sec. 3.1: integrate from the near plane instead of the camera
  RingingFilter ringing = RingingFilter::None; ///< damping of the ray coefficients (fourier.h); None: Eq. 8
  /// Z samples of the region visibility table (0 = none, else [2, kMaxVisibilityTableSamples]; not in the
  /// paper). Cost: per frame O(H R Z M); then one fetch per region crossed whole, not M / 4.
  int visibilityTableSamples = 128;
  /// Also tabulate the regions' in-scattering prefix along the table's rays (not in the paper): one fetch for
  /// every region a pixel crosses whole, a constant cost per pixel (Sec. 5).
  bool scatteringPrefix = true;
  /// Local lights: a table of each region's unshadowed in-scattering for a pixel's last region, instead of a
  /// quadrature per pixel (not in the paper).
  bool localSectionTable = true;
  int threads = 0; ///< CPU workers, 0 = hardware concurrency; never changes the result
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
/// The most table samples Z of the GPU passes with VisibilityReconstruction::Exact: the prefix table bins a
/// region's Z + 1 depths per colour in shared memory, within GL's minimum of 32 KB.
inline constexpr int kMaxExactTableSamples = 2047;

/// a(z_s) of Eq. 8 (with `ringing`) at the ray basis depth of s / (samples - 1), index s * M + k: the one
/// definition of the table's samples (visibilityTable() and EvaluatePass).
std::vector<double> visibilityTableCoefficients(int samples, int bases, double depthMargin,
                                                RingingFilter ringing);

/// The region visibility table of `basis` from its stored values, index (row * R + region) * Z + s (times 3,
/// + c, when textured); what EvaluatePass builds in float (glsl/passes/prefilter/visibility_table.comp).
/// Exact bases: the weighted average of [z_i >= s / (Z - 1)] over the region's texels, [z_i > 0] for s = 0
/// (the limit from above: casters clamped to depth 0 shadow every ray of positive depth).
std::vector<double> visibilityTable(const FilteredBasis& basis, int samples, RingingFilter ringing);

/// The scattering prefix table of `basis` and visibilityTable() `visibility`, index ((row * R + region) * Z +
/// s) * 3 + c; what EvaluatePass builds in float (glsl/passes/prefilter/scattering_prefix.comp).
std::vector<double> scatteringPrefixTable(const FilteredBasis& basis, const std::vector<double>& visibility,
                                          int samples, const glm::dvec3& extinction);
inline constexpr int kScatteringPrefixChannels = 3;

/// Throws InvalidArgument naming `<owner>.sampling`, `.ringing`, `.visibilityTableSamples` or `.threads`.
void validate(const EvaluateOptions& options, std::string_view owner = "EvaluateOptions");

/// Evaluation: RGBA of cameraDepth's size (depth values, 1 = sky): RGB in-scattered radiance, A grey
/// transmittance. InvalidArgument ("cameraDepth": empty, NaN or outside [0, 1]; "FilteredBasis").
Image evaluate(const FilteredBasis& basis, const Image& cameraDepth, const Camera& camera,
               const DirectionalLight& light, const Medium& medium, const EvaluateOptions& options = {});
/// The same for a local light on a basis prefiltered for it; InvalidArgument ("FilteredBasis.localLight") for
/// the other kind of basis, ("EvaluateOptions.nearPlaneCorrection") with the near-plane correction.
Image evaluate(const FilteredBasis& basis, const Image& cameraDepth, const Camera& camera,
               const LocalLight& light, const Medium& medium, const EvaluateOptions& options = {});
/// The sample ray of froxel cell (x, y, z) of `grid` (depth range `range`) with `jitter` (cells).
PixelRay froxelSampleRay(const Camera& camera, const FroxelDepthRange& range, const FroxelGrid& grid,
                         const glm::dvec3& jitter, int x, int y, int z, bool nearPlaneCorrection);
/// Throws InvalidArgument naming `field` unless each component of `jitter` is finite and in [-0.5, 0.5].
void validateFroxelJitter(const glm::dvec3& jitter, const std::string& field);
/// The froxel fill (directional light): RGBA grid.width x (grid.height grid.depth), slice z in rows [z
/// height, (z + 1) height). Throws InvalidArgument ("evaluateFroxels.grid.*", ".jitter", as evaluate()).
Image evaluateFroxels(const FilteredBasis& basis, const FroxelGrid& grid, const glm::dvec3& jitter,
                      const Camera& camera, const DirectionalLight& light, const Medium& medium,
                      const EvaluateOptions& options = {});

/// scatteringPrefixTable for a local light: the in-scattering itself (RayScattering) along each sample ray.
std::vector<double> scatteringPrefixTable(const FilteredBasis& basis, const std::vector<double>& visibility,
                                          int samples, const LocalLight& light, const Medium& medium);
/// A local section's far end when its end boundary is beyond reach (CREP_LOCAL_SECTION_END).
inline constexpr double kLocalSectionEnd = 1e29;
/// The local section table (EvaluateOptions::localSectionTable), laid out as scatteringPrefixTable; what
/// EvaluatePass's prefix pass writes beside the prefix table.
std::vector<double> localSectionTable(const FilteredBasis& basis, int samples, const LocalLight& light,
                                      const Medium& medium);

} // namespace crep
