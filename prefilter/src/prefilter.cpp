// CPU reference of prefiltered single scattering: Klehm, Seidel, Eisemann 2014, Sec. 3.1 (prefix
// filtering of the Fourier basis, Eq. 5-9), Sec. 3.2 (transmittance weights, Eq. 10-11), Sec. 3.3
// (regions, normalized storage, Listings 1-4), Appendix A (normalized filtered basis). The exact rules
// (also the GPU's contract) are documented in crep/prefilter/prefilter.h; the rays and the integration
// rule are crep/scatter/ray.h's.
#include <crep/core/error.h>
#include <crep/core/parallel.h>
#include <crep/prefilter/prefilter.h>
#include <crep/scatter/light_texture.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

namespace crep {

namespace {

/// A point of a ray in prefilter-region coordinates: region r of R = K P, u in [0, 1] within it.
struct RegionPoint {
  int region = 0;
  double u = 0.0;
};

RegionPoint regionPoint(const RectPoint& p, int layoutRegions, int perSplit) {
  const int k = std::clamp(p.split, 0, layoutRegions - 1);
  const double uk = std::clamp(p.splitColumn, 0.0, 1.0);
  const int q = std::min(static_cast<int>(std::floor(uk * perSplit)), perSplit - 1);
  return {k * perSplit + q, std::clamp(uk * perSplit - q, 0.0, 1.0)};
}

/// The mapped part of one pixel's ray: row, depth, and the regions from start to surface.
struct MappedRay {
  double row = 0.0, depth = 0.0;
  RegionPoint first, last; ///< where the integration starts (region 0, u 0 without the correction) / ends
};

/// Maps a pixel ray into the layout; false when the layout cannot map its points.
bool mapRay(const RectifiedLayout& layout, const glm::dvec3& origin, const PixelRay& ray, int perSplit,
            bool nearPlaneCorrection, MappedRay& out) {
  const int K = layout.regionCount();
  try {
    const RectPoint hit = layout.toRectified(origin + ray.surface * ray.direction);
    out.row = hit.row;
    out.depth = hit.depth;
    out.last = regionPoint(hit, K, perSplit);
    out.first = {0, 0.0};
    if (nearPlaneCorrection) {
      const RectPoint np = layout.toRectified(origin + ray.start * ray.direction);
      out.first = regionPoint(np, K, perSplit);
      if (out.first.region > out.last.region ||
          (out.first.region == out.last.region && out.first.u > out.last.u))
        out.first = out.last; // rounding: the surface is at the near plane
    }
  } catch (const InvalidArgument&) {
    return false;
  }
  return true;
}

/// Calls segment(region, ua, ub, ta, tb) for every region the ray crosses from start to surface (world
/// distances along the ray itself; region 0 starts at the camera without the correction).
template <class Segment>
void forEachSegment(const RectifiedLayout& layout, const PixelRay& ray, const MappedRay& m, int regions,
                    const Segment& segment) {
  double ta = ray.start;
  for (int r = m.first.region; r <= m.last.region; ++r) {
    const double ua = r == m.first.region ? m.first.u : 0.0;
    const double ub = r == m.last.region ? m.last.u : 1.0;
    double tb = r == m.last.region ? ray.surface
                                   : layout.rayDistance(m.row, m.depth, static_cast<double>(r + 1) / regions);
    tb = std::clamp(tb, ta, ray.surface);
    segment(r, ua, ub, ta, tb);
    ta = tb;
  }
}

void validateBasis(const FilteredBasis& b) {
  const auto bad = [](const std::string& what) {
    throw InvalidArgument("FilteredBasis", what, "must be a consistent result of prefilter()");
  };
  if (!b.layout) bad("layout null");
  validateBases(b.bases);
  if (b.layers != layerCount(b.bases)) bad("layers " + std::to_string(b.layers));
  if (b.width <= 0 || b.height <= 0)
    bad("size " + std::to_string(b.width) + " x " + std::to_string(b.height));
  if (b.regionsPerSplit < 1 || b.regions != b.layout->regionCount() * b.regionsPerSplit ||
      b.width % b.regions != 0)
    bad("regions " + std::to_string(b.regions));
  const std::size_t area = static_cast<std::size_t>(b.height) * static_cast<std::size_t>(b.width);
  const bool exact = b.reconstruction == VisibilityReconstruction::Exact;
  if (!exact && b.reconstruction != VisibilityReconstruction::Fourier)
    bad("reconstruction " + std::to_string(static_cast<int>(b.reconstruction)));
  if (b.texels.size() != (exact ? 0 : static_cast<std::size_t>(b.colorBases() * b.layers) * area * 4))
    bad("texels size " + std::to_string(b.texels.size()));
  if (b.depth.size() != (exact ? area : 0)) bad("depth size " + std::to_string(b.depth.size()));
  if (b.weight.size() != (exact ? static_cast<std::size_t>(b.colorBases()) * area : 0))
    bad("weight size " + std::to_string(b.weight.size()));
  if (b.meanColor.size() !=
      (b.textured ? static_cast<std::size_t>(b.height) * static_cast<std::size_t>(b.width) * 3 : 0))
    bad("meanColor size " + std::to_string(b.meanColor.size()));
  if (b.profiles.size() != static_cast<std::size_t>(b.height) * static_cast<std::size_t>(b.regions))
    bad("profiles size " + std::to_string(b.profiles.size()));
  if (!(b.extinction >= 0.0) || !std::isfinite(b.extinction))
    bad("extinction " + detail::formatValue(b.extinction));
  if (!(b.depthMargin >= 0.0 && b.depthMargin <= 0.25))
    bad("depthMargin " + detail::formatValue(b.depthMargin));
}

/// Samples the decoded filtered basis of region r at prefix boundary u and normalized row (see the
/// header: x = clamp(u n - 1, 0, n - 1), y = clamp(row H - 0.5, 0, H - 1)).
void sampleFiltered(const FilteredBasis& b, Sampling sampling, int r, double u, double row, double* out,
                    int color = 0) {
  const int n = b.regionWidth();
  const double x = std::clamp(u * n - 1.0, 0.0, static_cast<double>(n - 1));
  const double y = std::clamp(row * b.height - 0.5, 0.0, static_cast<double>(b.height - 1));
  const int base = r * n;
  if (sampling == Sampling::Nearest) {
    const int xi = base + static_cast<int>(std::floor(x + 0.5));
    const int yi = static_cast<int>(std::floor(y + 0.5));
    for (int j = 0; j < b.bases; ++j)
      out[j] = b.filtered(xi, yi, j, color);
    return;
  }
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const int x1 = std::min(x0 + 1, n - 1), y1 = std::min(y0 + 1, b.height - 1);
  const double fx = x - x0, fy = y - y0;
  for (int j = 0; j < b.bases; ++j) {
    const double e00 = b.stored(base + x0, y0, j, color), e10 = b.stored(base + x1, y0, j, color);
    const double e01 = b.stored(base + x0, y1, j, color), e11 = b.stored(base + x1, y1, j, color);
    const double e = (1.0 - fy) * ((1.0 - fx) * e00 + fx * e10) + fy * ((1.0 - fx) * e01 + fx * e11);
    out[j] = 2.0 * e - 1.0;
  }
}

/// The prefix mean colour cbar of a textured basis at the same sample position as sampleFiltered.
glm::dvec3 sampleMeanColor(const FilteredBasis& b, Sampling sampling, int r, double u, double row) {
  const int n = b.regionWidth();
  const double x = std::clamp(u * n - 1.0, 0.0, static_cast<double>(n - 1));
  const double y = std::clamp(row * b.height - 0.5, 0.0, static_cast<double>(b.height - 1));
  const int base = r * n;
  glm::dvec3 out;
  if (sampling == Sampling::Nearest) {
    const int xi = base + static_cast<int>(std::floor(x + 0.5)), yi = static_cast<int>(std::floor(y + 0.5));
    for (int c = 0; c < 3; ++c)
      out[c] = b.mean(xi, yi, c);
    return out;
  }
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const int x1 = std::min(x0 + 1, n - 1), y1 = std::min(y0 + 1, b.height - 1);
  const double fx = x - x0, fy = y - y0;
  for (int c = 0; c < 3; ++c)
    out[c] = (1.0 - fy) * ((1.0 - fx) * b.mean(base + x0, y0, c) + fx * b.mean(base + x1, y0, c)) +
             fy * ((1.0 - fx) * b.mean(base + x0, y1, c) + fx * b.mean(base + x1, y1, c));
  return out;
}

/// VisibilityReconstruction::Exact: the weighted average P_x = sum_{i <= x} [z_i >= z] (W_i - W_{i-1}) / W_x
/// of region r's texels in row y (region-local x, W_{-1} = 0; 0 where W_x = 0), colour `color`'s cumulative
/// weights, at x1; P at x0 <= x1 into `atX0`.
double exactRunningPrefix(const FilteredBasis& b, int r, int y, int x0, int x1, double z, int color,
                          double& atX0) {
  const int n = b.regionWidth();
  const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(b.width) +
                          static_cast<std::size_t>(r) * static_cast<std::size_t>(n);
  const std::size_t weightRow = static_cast<std::size_t>(color) * static_cast<std::size_t>(b.height) *
                                    static_cast<std::size_t>(b.width) +
                                row;
  double lit = 0.0, previous = 0.0;
  atX0 = 0.0;
  for (int k = 0; k <= x1; ++k) {
    const double W = b.weight[weightRow + static_cast<std::size_t>(k)];
    if (static_cast<double>(b.depth[row + static_cast<std::size_t>(k)]) >= z) lit += W - previous;
    previous = W;
    if (k == x0) atX0 = W > 0.0 ? lit / W : 0.0;
  }
  return previous > 0.0 ? lit / previous : 0.0;
}

/// VisibilityReconstruction::Exact: the prefix visibility of region r at boundary u for the ray depth z, in
/// the ray's own (nearest) row: a neighbouring row's receiver texels near the ray's end lie on either side of
/// z (shadow acne), so rows are not blended; Bilinear interpolates along the row at sampleFiltered's
/// positions.
double exactPrefixVisibility(const FilteredBasis& b, Sampling sampling, int r, double u, double row, double z,
                             int color) {
  const int n = b.regionWidth();
  const double x = std::clamp(u * n - 1.0, 0.0, static_cast<double>(n - 1));
  const int y = std::clamp(static_cast<int>(std::floor(row * b.height)), 0, b.height - 1);
  double p0 = 0.0;
  if (sampling == Sampling::Nearest) {
    const int xi = static_cast<int>(std::floor(x + 0.5));
    return exactRunningPrefix(b, r, y, xi, xi, z, color, p0);
  }
  const int x0 = static_cast<int>(std::floor(x)), x1 = std::min(x0 + 1, n - 1);
  const double p1 = exactRunningPrefix(b, r, y, x0, x1, z, color, p0);
  return p0 + (x - x0) * (p1 - p0);
}

} // namespace

// ---------------------------------------------------------------------------------------------------

const char* visibilityReconstructionToken(VisibilityReconstruction reconstruction) {
  return reconstruction == VisibilityReconstruction::Exact ? "exact" : "fourier";
}

const char* storageFormatToken(StorageFormat format) {
  switch (format) {
  case StorageFormat::RGBA8:
    return "rgba8";
  case StorageFormat::RGBA16F:
    return "rgba16f";
  case StorageFormat::RGBA32F:
    return "rgba32f";
  }
  return "unknown";
}

void validate(const PrefilterOptions& o, std::string_view owner) {
  const auto field = [&](const char* name) { return std::string(owner) + "." + name; };
  validateBases(o.bases, field("bases"));
  if (o.format != StorageFormat::RGBA8 && o.format != StorageFormat::RGBA16F &&
      o.format != StorageFormat::RGBA32F)
    throw InvalidArgument(field("format"), detail::formatValue(static_cast<int>(o.format)),
                          "must be RGBA8, RGBA16F or RGBA32F");
  if (o.weights != WeightMode::AverageVisibility && o.weights != WeightMode::ConstantStep &&
      o.weights != WeightMode::ConstantRatio && o.weights != WeightMode::Exact)
    throw InvalidArgument(field("weights"), detail::formatValue(static_cast<int>(o.weights)),
                          "must be a WeightMode enumerator");
  if (o.regionsPerSplit < 1 || o.regionsPerSplit > 1024)
    throw InvalidArgument(field("regionsPerSplit"), detail::formatValue(o.regionsPerSplit),
                          "must be in [1, 1024]");
  if (!(o.depthMargin >= 0.0 && o.depthMargin <= 0.25))
    throw InvalidArgument(field("depthMargin"), detail::formatValue(o.depthMargin), "must be in [0, 0.25]");
  if (o.basesPerInvocation < 4 || o.basesPerInvocation > kMaxBases || o.basesPerInvocation % 4 != 0)
    throw InvalidArgument(field("basesPerInvocation"), detail::formatValue(o.basesPerInvocation),
                          "must be a multiple of 4 in [4, " + std::to_string(kMaxBases) + "]");
  if (o.threads < 0) throw InvalidArgument(field("threads"), detail::formatValue(o.threads), "must be >= 0");
  if (o.reconstruction != VisibilityReconstruction::Fourier &&
      o.reconstruction != VisibilityReconstruction::Exact)
    throw InvalidArgument(field("reconstruction"), detail::formatValue(static_cast<int>(o.reconstruction)),
                          "must be Fourier or Exact");
}

void validate(const EvaluateOptions& o, std::string_view owner) {
  const auto field = [&](const char* name) { return std::string(owner) + "." + name; };
  if (o.sampling != Sampling::Bilinear && o.sampling != Sampling::Nearest)
    throw InvalidArgument(field("sampling"), detail::formatValue(static_cast<int>(o.sampling)),
                          "must be Bilinear or Nearest");
  if (o.ringing != RingingFilter::None && o.ringing != RingingFilter::Lanczos)
    throw InvalidArgument(field("ringing"), detail::formatValue(static_cast<int>(o.ringing)),
                          "must be None or Lanczos");
  if (o.visibilityTableSamples != 0 &&
      (o.visibilityTableSamples < 2 || o.visibilityTableSamples > kMaxVisibilityTableSamples))
    throw InvalidArgument(field("visibilityTableSamples"), detail::formatValue(o.visibilityTableSamples),
                          "must be 0 (no table) or in [2, " + std::to_string(kMaxVisibilityTableSamples) +
                              "]");
  if (o.threads < 0) throw InvalidArgument(field("threads"), detail::formatValue(o.threads), "must be >= 0");
}

float roundToHalf(double v) {
  if (!std::isfinite(v) || v == 0.0) return static_cast<float>(v);
  const double a = std::abs(v);
  if (a >= 65520.0) return static_cast<float>(std::copysign(std::numeric_limits<double>::infinity(), v));
  int e = 0;
  std::frexp(a, &e); // a = f 2^e, f in [0.5, 1): the leading bit is 2^(e-1)
  // binary16: 11 significant bits for normals (exponent >= -14), fixed quantum 2^-24 below.
  const int quantumExp = std::max(e - 11, -24);
  const double q = std::ldexp(1.0, quantumExp);
  const double rounded = std::nearbyint(a / q) * q; // default rounding mode: ties to even
  return static_cast<float>(std::copysign(rounded, v));
}

float storeFiltered(double filtered, StorageFormat format) {
  const double e = 0.5 + 0.5 * filtered;
  switch (format) {
  case StorageFormat::RGBA8:
    return static_cast<float>(std::floor(std::clamp(e, 0.0, 1.0) * 255.0 + 0.5) / 255.0);
  case StorageFormat::RGBA16F:
    return roundToHalf(e);
  case StorageFormat::RGBA32F:
    break;
  }
  return static_cast<float>(e);
}

std::vector<DistanceProfile> referenceProfiles(const RectifiedLayout& layout, int height,
                                               int regionsPerSplit) {
  if (height <= 0)
    throw InvalidArgument("referenceProfiles.height", detail::formatValue(height), "must be > 0");
  if (regionsPerSplit < 1)
    throw InvalidArgument("PrefilterOptions.regionsPerSplit", detail::formatValue(regionsPerSplit),
                          "must be >= 1");
  const int K = layout.regionCount(), P = regionsPerSplit, R = K * P;
  std::vector<DistanceProfile> out(static_cast<std::size_t>(height) * static_cast<std::size_t>(R));
  for (int j = 0; j < height; ++j) {
    const double row = (j + 0.5) / height;
    for (int k = 0; k < K; ++k) {
      const DistanceProfile p = layout.rayProfile(row, layout.regionReferenceDepth(row, k), k);
      for (int q = 0; q < P; ++q)
        out[static_cast<std::size_t>(j) * static_cast<std::size_t>(R) + static_cast<std::size_t>(k * P + q)] =
            P == 1 ? p : p.sub(static_cast<double>(q) / P, static_cast<double>(q + 1) / P);
    }
  }
  return out;
}

FilteredBasis prefilter(const RectifiedMap& map, const Medium& medium, const PrefilterOptions& options) {
  return prefilter(map, weightExtinction(medium), options);
}

namespace {

FilteredBasis prefilterImpl(const RectifiedMap& map, double extinction, const PrefilterOptions& options,
                            const LocalLight* light, const Medium* medium, const Image* colors);

} // namespace

FilteredBasis prefilter(const RectifiedMap& map, double extinction, const PrefilterOptions& options) {
  return prefilterImpl(map, extinction, options, nullptr, nullptr, nullptr);
}

FilteredBasis prefilter(const RectifiedMap& map, const Medium& medium, const LocalLight& light,
                        const PrefilterOptions& options) {
  return prefilterImpl(map, weightExtinction(medium), options, &light, &medium, nullptr);
}

FilteredBasis prefilter(const RectifiedMap& map, const Medium& medium, const Image& lightColors,
                        const PrefilterOptions& options) {
  return prefilterImpl(map, weightExtinction(medium), options, nullptr, &medium, &lightColors);
}

FilteredBasis prefilter(const RectifiedMap& map, const Medium& medium, const LocalLight& light,
                        const Image& lightColors, const PrefilterOptions& options) {
  return prefilterImpl(map, weightExtinction(medium), options, &light, &medium, &lightColors);
}

namespace {

FilteredBasis prefilterImpl(const RectifiedMap& map, double extinction, const PrefilterOptions& options,
                            const LocalLight* light, const Medium* medium, const Image* colors) {
  validate(map);
  validate(options);
  if (colors) validateLightColors(*colors, map.width(), map.height(), "lightColors");
  requireNonNegative("extinction", extinction);
  const int W = map.width(), H = map.height(), M = options.bases;
  const int R = map.layout->regionCount() * options.regionsPerSplit;
  if (W % R != 0)
    throw InvalidArgument("RectifiedMap.depth", "width " + std::to_string(W),
                          "must be a multiple of regionCount() * PrefilterOptions.regionsPerSplit = " +
                              std::to_string(R));
  FilteredBasis b;
  b.width = W;
  b.height = H;
  b.bases = M;
  b.layers = layerCount(M);
  b.regions = R;
  b.regionsPerSplit = options.regionsPerSplit;
  b.format = options.format;
  b.weights = options.weights;
  b.extinction = extinction;
  b.depthMargin = options.depthMargin;
  if (light && options.weights != WeightMode::Exact)
    throw InvalidArgument("PrefilterOptions.weights", weightModeToken(options.weights),
                          "must be exact with a local light (its factor is sampled at exact distances)");
  b.layout = map.layout;
  b.localLight = light != nullptr;
  b.textured = colors != nullptr;
  b.profiles = referenceProfiles(*map.layout, H, options.regionsPerSplit);
  const int C = b.colorBases();
  const std::size_t area = static_cast<std::size_t>(H) * static_cast<std::size_t>(W);
  b.reconstruction = options.reconstruction;
  const bool exact = options.reconstruction == VisibilityReconstruction::Exact;
  if (exact) {
    b.depth.assign(map.depth.data().begin(), map.depth.data().end());
    b.weight.assign(static_cast<std::size_t>(C) * area, 0.0f);
  } else {
    b.texels.assign(static_cast<std::size_t>(C * b.layers) * area * 4, storeFiltered(0.0, options.format));
  }
  if (colors) b.meanColor.assign(area * 3, 0.0f);

  const int n = W / R;
  const std::size_t layerStride = static_cast<std::size_t>(H) * static_cast<std::size_t>(W) * 4;
  parallelRows(H, options.threads, [&](int j) {
    std::vector<double> mix(static_cast<std::size_t>(n));
    std::vector<double> lightSamples(light ? 2 * static_cast<std::size_t>(n) + 1 : 0);
    std::array<std::array<double, kMaxBases>, 3> Fc{};
    std::array<double, kMaxBases> B{};
    const std::span<double> basisSpan(B.data(), static_cast<std::size_t>(M));
    std::array<std::vector<double>, 3> exactMix; // VisibilityReconstruction::Exact: a region's mix factors
    if (exact)
      for (std::vector<double>& m : exactMix)
        m.assign(static_cast<std::size_t>(n), 0.0);
    const double row = (j + 0.5) / H;
    const glm::dvec3 origin = map.layout->origin();
    for (int r = 0; r < R; ++r) {
      const DistanceProfile& profile =
          b.profiles[static_cast<std::size_t>(j) * static_cast<std::size_t>(R) + static_cast<std::size_t>(r)];
      const glm::dvec3 reference =
          light ? map.layout->viewRayDirection(
                      row, map.layout->regionReferenceDepth(row, r / options.regionsPerSplit))
                : glm::dvec3(0.0);
      // Sec. 3.2: the light-side factor along the region's reference ray (texel boundaries and centres).
      for (std::size_t k = 0; k < lightSamples.size(); ++k) {
        const double t = profile(static_cast<double>(k) / (2.0 * n));
        lightSamples[k] = std::isfinite(t) ? light->weightFactor(*medium, extinction, origin + t * reference,
                                                                 reference, options.localLightWeights)
                                           : 0.0;
      }
      regionMixFactors(options.weights, extinction, profile, n, lightSamples, mix);
      for (auto& F : Fc)
        std::fill(F.begin(), F.end(), 0.0);
      glm::dvec3 cbar(0.0); // light textures: the prefix mean colour (prefilter.h, "Light textures")
      for (int i = 0; i < n; ++i) {
        const int x = r * n + i;
        if (!exact) fourierBasis(texelBasisDepth(map.depth.at(x, j), options.depthMargin), basisSpan);
        const double m = mix[static_cast<std::size_t>(i)];
        const std::size_t texel =
            (static_cast<std::size_t>(j) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x)) * 4;
        for (int c = 0; c < C; ++c) {
          // Light textures: the weights w_i c_i of channel c as mix factors, m_i c_i / cbar_i.
          double mc = m;
          if (colors) {
            const double ci = colors->at(x, j, c);
            cbar[c] += m * (ci - cbar[c]);
            if (cbar[c] > 0.0) mc = std::clamp(m * (ci / cbar[c]), 0.0, 1.0);
            b.meanColor[texel / 4 * 3 + static_cast<std::size_t>(c)] = static_cast<float>(cbar[c]);
          }
          if (exact) { // VisibilityReconstruction::Exact: the factors alone, made cumulative below
            exactMix[static_cast<std::size_t>(c)][static_cast<std::size_t>(i)] = mc;
            continue;
          }
          std::array<double, kMaxBases>& F = Fc[static_cast<std::size_t>(c)];
          // Listing 2: the normalized weighted prefix, F_i = F_{i-1} + m_i (B_i - F_{i-1}).
          for (int k = 0; k < M; ++k)
            F[static_cast<std::size_t>(k)] +=
                mc * (B[static_cast<std::size_t>(k)] - F[static_cast<std::size_t>(k)]);
          for (int k = 0; k < M; ++k)
            b.texels[static_cast<std::size_t>(c * b.layers + k / 4) * layerStride + texel +
                     static_cast<std::size_t>(k % 4)] =
                storeFiltered(F[static_cast<std::size_t>(k)], options.format);
        }
      }
      if (exact) // W_i = prod_{k > i} (1 - m_k): the weights' cumulative sum over the region's total
        for (int c = 0; c < C; ++c) {
          double carry = 1.0;
          for (int i = n - 1; i >= 0; --i) {
            b.weight[static_cast<std::size_t>(c) * area +
                     static_cast<std::size_t>(j) * static_cast<std::size_t>(W) +
                     static_cast<std::size_t>(r * n + i)] = static_cast<float>(carry);
            carry *= 1.0 - exactMix[static_cast<std::size_t>(c)][static_cast<std::size_t>(i)];
          }
        }
    }
  });
  return b;
}

} // namespace

std::vector<double> visibilityTableCoefficients(int samples, int bases, double depthMargin,
                                                RingingFilter ringing) {
  std::vector<double> a(static_cast<std::size_t>(samples) * static_cast<std::size_t>(bases));
  for (int s = 0; s < samples; ++s) {
    const std::span<double> as(a.data() + static_cast<std::size_t>(s) * static_cast<std::size_t>(bases),
                               static_cast<std::size_t>(bases));
    fourierCoefficients(rayBasisDepth(static_cast<double>(s) / (samples - 1), depthMargin), as);
    applyRingingFilter(ringing, as);
  }
  return a;
}

std::vector<double> visibilityTable(const FilteredBasis& basis, int samples, RingingFilter ringing) {
  validateBasis(basis);
  if (samples < 2 || samples > kMaxVisibilityTableSamples)
    throw InvalidArgument("visibilityTable.samples", detail::formatValue(samples),
                          "must be in [2, " + std::to_string(kMaxVisibilityTableSamples) + "]");
  const int H = basis.height, R = basis.regions, M = basis.bases, n = basis.regionWidth();
  const int C = basis.colorBases();
  std::vector<double> table(static_cast<std::size_t>(H) * static_cast<std::size_t>(R) *
                            static_cast<std::size_t>(samples) * static_cast<std::size_t>(C));
  const bool exact = basis.reconstruction == VisibilityReconstruction::Exact;
  const std::vector<double> a =
      exact ? std::vector<double>() : visibilityTableCoefficients(samples, M, basis.depthMargin, ringing);
  parallelRows(H, 0, [&](int j) { // rows are independent: the same result for any thread count
    for (int r = 0; r < R; ++r) {
      const int x = r * n + n - 1; // the region's last texel: its whole weighted average
      for (int s = 0; s < samples; ++s)
        for (int c = 0; c < C; ++c) {
          double V = 0.0, unused = 0.0;
          if (exact) {
            // The exact region average at the sample's ray depth s / (Z - 1); sample 0 takes the limit from
            // above (z > 0), so that casters clamped to depth 0 shadow every ray between samples 0 and 1.
            const double z = s == 0 ? std::nextafter(0.0, 1.0) : static_cast<double>(s) / (samples - 1);
            V = exactRunningPrefix(basis, r, j, n - 1, n - 1, z, c, unused);
          } else {
            double dot = 0.0;
            for (int k = 0; k < M; ++k)
              dot +=
                  a[static_cast<std::size_t>(s) * static_cast<std::size_t>(M) + static_cast<std::size_t>(k)] *
                  basis.filtered(x, j, k, c);
            V = std::clamp(0.5 + dot, 0.0, 1.0);
          }
          if (basis.textured) V *= basis.mean(x, j, c); // light textures: V_c = cbar_c clamp(...)
          table[((static_cast<std::size_t>(j) * static_cast<std::size_t>(R) + static_cast<std::size_t>(r)) *
                     static_cast<std::size_t>(samples) +
                 static_cast<std::size_t>(s)) *
                    static_cast<std::size_t>(C) +
                static_cast<std::size_t>(c)] = V;
        }
    }
  });
  return table;
}

namespace {

/// The tables' sample rays (scatteringPrefixTable, localSectionTable): for texel row j and depth sample s,
/// `rayFor(row, depth)` makes the sample ray's state, then `region(state, cell, ta, tb)` runs for r = 0 .. R
/// - 1 in order with the region's boundary distances (tb = +infinity where the ray never gets there) and its
/// cell (j R + r) Z + s.
template <class RayFor, class Region>
void forEachTableRegion(const FilteredBasis& basis, int samples, const RayFor& rayFor, const Region& region) {
  const int H = basis.height, R = basis.regions, Z = samples;
  const RectifiedLayout& layout = *basis.layout;
  parallelRows(H, 0, [&](int j) {
    const double row = (j + 0.5) / H;
    for (int s = 0; s < Z; ++s) {
      const double depth = static_cast<double>(s) / (Z - 1);
      auto ray = rayFor(row, depth);
      double ta = 0.0;
      for (int r = 0; r < R; ++r) {
        const std::size_t cell =
            (static_cast<std::size_t>(j) * static_cast<std::size_t>(R) + static_cast<std::size_t>(r)) *
                static_cast<std::size_t>(Z) +
            static_cast<std::size_t>(s);
        const double tb = std::max(ta, layout.rayDistance(row, depth, static_cast<double>(r + 1) / R));
        region(ray, cell, ta, tb);
        ta = tb;
      }
    }
  });
}

/// The scattering prefix table (prefilter.h) with `sectionsFor(row, depth)` giving the sample ray's
/// section rule section(ta, tb) (per channel; region boundaries at +infinity contribute nothing).
template <class SectionsFor>
std::vector<double> prefixTable(const FilteredBasis& basis, const std::vector<double>& visibility,
                                int samples, const SectionsFor& sectionsFor) {
  validateBasis(basis);
  const int H = basis.height, R = basis.regions, Z = samples, C = kScatteringPrefixChannels;
  const std::size_t cells =
      static_cast<std::size_t>(H) * static_cast<std::size_t>(R) * static_cast<std::size_t>(Z);
  const std::size_t perCell = static_cast<std::size_t>(basis.colorBases());
  if (samples < 2 || samples > kMaxVisibilityTableSamples || visibility.size() != cells * perCell)
    throw InvalidArgument("scatteringPrefixTable.visibility", "size " + std::to_string(visibility.size()),
                          "must be visibilityTable(basis, samples) with samples in [2, " +
                              std::to_string(kMaxVisibilityTableSamples) + "]");
  std::vector<double> table(cells * static_cast<std::size_t>(C));
  forEachTableRegion(
      basis, samples,
      [&](double row, double depth) { return std::make_pair(sectionsFor(row, depth), glm::dvec3(0.0)); },
      [&](auto& ray, std::size_t cell, double ta, double tb) {
        auto& [section, sum] = ray;
        for (int c = 0; c < C; ++c)
          table[cell * C + static_cast<std::size_t>(c)] = sum[c];
        const glm::dvec3 V = perCell == 1 ? glm::dvec3(visibility[cell])
                                          : glm::dvec3(visibility[cell * 3], visibility[cell * 3 + 1],
                                                       visibility[cell * 3 + 2]);
        if (std::isfinite(tb)) sum += V * section(ta, tb);
      });
  return table;
}

} // namespace

std::vector<double> scatteringPrefixTable(const FilteredBasis& basis, const std::vector<double>& visibility,
                                          int samples, const glm::dvec3& extinction) {
  return prefixTable(basis, visibility, samples, [&](double, double) {
    return [&](double ta, double tb) { return transmittanceIntegral(extinction, ta, tb); };
  });
}

std::vector<double> scatteringPrefixTable(const FilteredBasis& basis, const std::vector<double>& visibility,
                                          int samples, const LocalLight& light, const Medium& medium) {
  return prefixTable(basis, visibility, samples, [&](double row, double depth) {
    const RectifiedLayout& layout = *basis.layout; // validated by prefixTable
    return [ray = RayScattering(light, medium, layout.origin(), layout.viewRayDirection(row, depth))](
               double ta, double tb) { return ray.segment(ta, tb); };
  });
}

std::vector<double> localSectionTable(const FilteredBasis& basis, int samples, const LocalLight& light,
                                      const Medium& medium) {
  validateBasis(basis);
  if (samples < 2 || samples > kMaxVisibilityTableSamples)
    throw InvalidArgument("localSectionTable.samples", std::to_string(samples),
                          "must be in [2, " + std::to_string(kMaxVisibilityTableSamples) + "]");
  const int C = kScatteringPrefixChannels;
  const RectifiedLayout& layout = *basis.layout;
  std::vector<double> table(static_cast<std::size_t>(basis.height) * static_cast<std::size_t>(basis.regions) *
                            static_cast<std::size_t>(samples) * static_cast<std::size_t>(C));
  forEachTableRegion(
      basis, samples,
      [&](double row, double depth) {
        return RayScattering(light, medium, layout.origin(), layout.viewRayDirection(row, depth));
      },
      [&](const RayScattering& ray, std::size_t cell, double ta, double tb) {
        const glm::dvec3 S = ray.segment(std::min(ta, kLocalSectionEnd), std::min(tb, kLocalSectionEnd));
        for (int c = 0; c < C; ++c)
          table[cell * C + static_cast<std::size_t>(c)] = S[c];
      });
  return table;
}

namespace {

/// The in-scattering of a region segment of one view ray for a directional light: C V TI (Eq. 1, 3, 11).
struct DirectionalSegments {
  glm::dvec3 C, sigma;
  glm::dvec3 weighted(const glm::dvec3& V, double ta, double tb) const {
    return C * V * transmittanceIntegral(sigma, ta, tb);
  }
  glm::dvec3 prefix(const glm::dvec3& S) const { return C * S; }
};

/// The same for a local light: V times the ray's own unoccluded in-scattering of the segment.
struct LocalSegments {
  RayScattering ray;
  glm::dvec3 weighted(const glm::dvec3& V, double ta, double tb) const { return V * ray.segment(ta, tb); }
  glm::dvec3 prefix(const glm::dvec3& S) const { return S; }
};

/// GL_LINEAR of a table texture (width R Z, height H, `channels` values per texel) at depth d and normalized
/// row: x = d (Z - 1) inside the region's samples, y = clamp(row H - 0.5, 0, H - 1) as for the basis.
struct TableLerp {
  int Z = 2, R = 1, H = 1;
  double operator()(const std::vector<double>& values, int channels, int channel, int r, double depth,
                    double row) const {
    const double xs = std::clamp(depth, 0.0, 1.0) * (Z - 1);
    const double ys = std::clamp(row * H - 0.5, 0.0, static_cast<double>(H - 1));
    const int x0 = static_cast<int>(std::floor(xs)), y0 = static_cast<int>(std::floor(ys));
    const int x1 = std::min(x0 + 1, Z - 1), y1 = std::min(y0 + 1, H - 1);
    const double fx = xs - x0, fy = ys - y0;
    const auto at = [&](int xi, int yi) {
      return values[((static_cast<std::size_t>(yi) * static_cast<std::size_t>(R) +
                      static_cast<std::size_t>(r)) *
                         static_cast<std::size_t>(Z) +
                     static_cast<std::size_t>(xi)) *
                        static_cast<std::size_t>(channels) +
                    static_cast<std::size_t>(channel)];
    };
    return (1.0 - fy) * ((1.0 - fx) * at(x0, y0) + fx * at(x1, y0)) +
           fy * ((1.0 - fx) * at(x0, y1) + fx * at(x1, y1));
  }
};

/// The visibility of region r's segment [ua, ub] of a mapped ray from the filtered basis, one value per
/// colour basis: the prefix at ub, or with the near-plane correction (ua > 0, Sec. 3.1) the corrected
/// difference. `a` holds the ray's M coefficients; Fa and Fb are scratch.
glm::dvec3 regionVisibility(const FilteredBasis& basis, const EvaluateOptions& options, const MappedRay& m,
                            int nearestRow, int r, double ua, double ub,
                            const std::array<double, kMaxBases>& a, std::array<double, kMaxBases>& Fa,
                            std::array<double, kMaxBases>& Fb) {
  const int M = basis.bases, R = basis.regions, C = basis.colorBases();
  glm::dvec3 V(0.0);
  bool plain = ua <= 0.0;
  double wa = 0.0, wb = 0.0;
  if (!plain) {
    // Near-plane correction: the prefix difference of one region, each prefix restored by its own
    // weight total (Appendix A), then renormalized by the segment's total.
    const DistanceProfile& p =
        basis.profiles[static_cast<std::size_t>(nearestRow) * static_cast<std::size_t>(R) +
                       static_cast<std::size_t>(r)];
    wa = regionWeightTotal(basis.weights, basis.extinction, p, basis.regionWidth(), ua);
    wb = regionWeightTotal(basis.weights, basis.extinction, p, basis.regionWidth(), ub);
    plain = !(wb - wa > 1e-12 * wb);
  }
  // Light textures (prefilter.h): each channel's basis, its prefix weighted by W cbar.
  const glm::dvec3 cb =
      basis.textured ? sampleMeanColor(basis, options.sampling, r, ub, m.row) : glm::dvec3(1.0);
  const glm::dvec3 ca =
      basis.textured && !plain ? sampleMeanColor(basis, options.sampling, r, ua, m.row) : glm::dvec3(1.0);
  // The prefix visibility P(u) of colour c: 0.5 + a . F(u) (Eq. 9), or the exact prefix (Exact).
  const auto prefixAt = [&](double u, int c, std::array<double, kMaxBases>& F) {
    if (basis.reconstruction == VisibilityReconstruction::Exact)
      return exactPrefixVisibility(basis, options.sampling, r, u, m.row, std::clamp(m.depth, 0.0, 1.0), c);
    sampleFiltered(basis, options.sampling, r, u, m.row, F.data(), c);
    double dot = 0.0;
    for (int k = 0; k < M; ++k)
      dot += a[static_cast<std::size_t>(k)] * F[static_cast<std::size_t>(k)];
    return 0.5 + dot;
  };
  for (int c = 0; c < C; ++c) {
    if (plain) {
      V[c] = std::clamp(prefixAt(ub, c, Fb), 0.0, 1.0) * cb[c];
      continue;
    }
    const double wbc = wb * cb[c], wac = wa * ca[c];
    if (!(wbc - wac > 0.0)) continue; // no weighted light in the segment: V = 0
    // (wb Pb - wa Pa) / (wb - wa) = 0.5 + a . (wb Fb - wa Fa) / (wb - wa) for the series.
    const double P = (wbc * prefixAt(ub, c, Fb) - wac * prefixAt(ua, c, Fa)) / (wbc - wac);
    V[c] = (wbc - wac) / (wb - wa) * std::clamp(P, 0.0, 1.0);
  }
  return V;
}

/// The evaluation (see prefilter.h) with `segmentsFor(direction)` giving the light's segment rule and
/// `prefixTable(visibility)` the scattering prefix table.
/// `rayAt(x, y)` gives the PixelRay of output pixel (x, y) of a w x h image (the camera image's pixel rays,
/// or the froxel volume's sample rays).
/// `sectionTable()` gives a local light's section table (EvaluateOptions::localSectionTable) or nothing.
template <class RayAt, class SegmentsFor, class PrefixTable, class SectionTable>
Image evaluateImpl(const FilteredBasis& basis, int w, int h, const RayAt& rayAt, const Camera& camera,
                   const Medium& medium, const EvaluateOptions& options, const SegmentsFor& segmentsFor,
                   const PrefixTable& prefixTable, const SectionTable& sectionTable) {
  validateBasis(basis);
  validate(options);
  const RectifiedLayout& layout = *basis.layout;
  const int M = basis.bases, R = basis.regions;
  const double greySigma = weightExtinction(medium);
  const glm::dvec3 origin = camera.position();
  const bool table = usesVisibilityTable(options);
  const int Z = options.visibilityTableSamples;
  const bool prefix = usesScatteringPrefix(options);
  const std::vector<double> tableValues =
      table ? visibilityTable(basis, Z, options.ringing) : std::vector<double>();
  const std::vector<double> prefixValues = prefix ? prefixTable(tableValues) : std::vector<double>();
  const std::vector<double> sectionValues = prefix ? sectionTable() : std::vector<double>();
  const TableLerp lerpTable{Z, R, basis.height};
  const int C = basis.colorBases(); // light textures: one basis per colour channel
  Image out(w, h, 4);
  parallelRows(h, options.threads, [&](int y) {
    std::array<double, kMaxBases> a{}, Fa{}, Fb{};
    const std::span<double> aSpan(a.data(), static_cast<std::size_t>(M));
    for (int x = 0; x < w; ++x) {
      const PixelRay ray = rayAt(x, y);
      const auto segment = segmentsFor(ray.direction);
      glm::dvec3 L(0.0);
      MappedRay m;
      if (!mapRay(layout, origin, ray, basis.regionsPerSplit, options.nearPlaneCorrection, m)) {
        L = segment.weighted(glm::dvec3(1.0), ray.start, ray.surface);
      } else {
        if (basis.reconstruction ==
            VisibilityReconstruction::Fourier) { // the exact prefix needs no coefficients
          fourierCoefficients(rayBasisDepth(m.depth, basis.depthMargin), aSpan);
          applyRingingFilter(options.ringing, aSpan);
        }
        const int nearestRow =
            std::clamp(static_cast<int>(std::floor(m.row * basis.height)), 0, basis.height - 1);
        PixelRay segments = ray; // what the region loop below integrates
        if (prefix && m.last.region > 0) {
          // The regions crossed whole from the scattering prefix table (EvaluateOptions::scatteringPrefix);
          // the loop then integrates the last region alone, from t_last = rayDistance(row, z_r, last / R)
          // of the ray itself.
          glm::dvec3 S;
          for (int c = 0; c < kScatteringPrefixChannels; ++c)
            S[c] = lerpTable(prefixValues, kScatteringPrefixChannels, c, m.last.region, m.depth, m.row);
          L += segment.prefix(S);
          segments.start =
              std::clamp(layout.rayDistance(m.row, m.depth, static_cast<double>(m.last.region) / R),
                         ray.start, ray.surface);
          m.first = {m.last.region, 0.0};
        }
        forEachSegment(layout, segments, m, R, [&](int r, double ua, double ub, double ta, double tb) {
          glm::dvec3 V(0.0);
          if (table && r < m.last.region) { // a region crossed whole: the table (see EvaluateOptions)
            for (int c = 0; c < C; ++c)
              V[c] = lerpTable(tableValues, C, c, r, m.depth, m.row);
            L += segment.weighted(C == 1 ? glm::dvec3(V[0]) : V, ta, tb);
            return;
          }
          V = regionVisibility(basis, options, m, nearestRow, r, ua, ub, a, Fa, Fb);
          if constexpr (requires { segment.ray.partialShare(ta, tb, tb); }) {
            if (!sectionValues.empty() && r == m.last.region) {
              // The last region of a local light from the section table (EvaluateOptions::localSectionTable):
              // its sample rays' section times this ray's share of it up to the surface.
              const double tEnd =
                  std::min(std::max(layout.rayDistance(m.row, m.depth, static_cast<double>(r + 1) / R), tb),
                           kLocalSectionEnd);
              glm::dvec3 S;
              for (int c = 0; c < kScatteringPrefixChannels; ++c)
                S[c] = lerpTable(sectionValues, kScatteringPrefixChannels, c, r, m.depth, m.row);
              L += (C == 1 ? glm::dvec3(V[0]) : V) * S * segment.ray.partialShare(ta, tb, tEnd);
              return;
            }
          }
          L += segment.weighted(C == 1 ? glm::dvec3(V[0]) : V, ta, tb);
        });
      }
      storeScattering(out, x, y, L, std::exp(-greySigma * ray.surface));
    }
  });
  return out;
}

} // namespace

Image evaluate(const FilteredBasis& basis, const Image& cameraDepth, const Camera& camera,
               const DirectionalLight& light, const Medium& medium, const EvaluateOptions& options) {
  if (basis.localLight)
    throw InvalidArgument("FilteredBasis.localLight", "true",
                          "the basis was prefiltered for a local light: evaluate it with that LocalLight");
  validateCameraDepth(cameraDepth);
  const glm::dvec3 sigma = medium.extinction();
  const int Z = options.visibilityTableSamples;
  return evaluateImpl(
      basis, cameraDepth.width(), cameraDepth.height(),
      [&](int x, int y) { return pixelRay(camera, cameraDepth, x, y, options.nearPlaneCorrection); }, camera,
      medium, options,
      [&](const glm::dvec3& v) {
        return DirectionalSegments{scatteringConstant(light, medium, v), sigma};
      },
      [&](const std::vector<double>& visibility) {
        return scatteringPrefixTable(basis, visibility, Z, sigma);
      },
      [] { return std::vector<double>(); });
}

// The froxel fill (prefilter.h, "Froxel volumes"): Klehm et al. 2014's per-ray evaluation (Sec. 3.3,
// Listing 4) at the sample points of Wronski 2014's frustum-aligned volume.
PixelRay froxelSampleRay(const Camera& camera, const FroxelDepthRange& range, const FroxelGrid& grid,
                         const glm::dvec3& jitter, int x, int y, int z, bool nearPlaneCorrection) {
  const glm::dvec3 uvw((x + 0.5 + jitter.x) / grid.width, (y + 0.5 + jitter.y) / grid.height,
                       (z + 0.5 + jitter.z) / grid.depth);
  PixelRay r;
  r.direction = camera.rayDirection(2.0 * uvw.x - 1.0, 2.0 * uvw.y - 1.0);
  const double cosForward = glm::dot(r.direction, camera.forward());
  // Beyond the camera's integration far the map has no information: the far plane's value (the sky's).
  r.surface = std::min(froxelViewDepth(range, uvw.z), camera.far()) / cosForward;
  r.start = nearPlaneCorrection ? std::min(camera.near() / cosForward, r.surface) : 0.0;
  return r;
}

void validateFroxelJitter(const glm::dvec3& jitter, const std::string& field) {
  for (int c = 0; c < 3; ++c)
    if (!(std::abs(jitter[c]) <= 0.5))
      throw InvalidArgument(field,
                            "(" + detail::formatValue(jitter.x) + ", " + detail::formatValue(jitter.y) +
                                ", " + detail::formatValue(jitter.z) + ")",
                            "cells, each component finite and in [-0.5, 0.5]");
}

Image evaluateFroxels(const FilteredBasis& basis, const FroxelGrid& grid, const glm::dvec3& jitter,
                      const Camera& camera, const DirectionalLight& light, const Medium& medium,
                      const EvaluateOptions& options) {
  if (basis.localLight)
    throw InvalidArgument("FilteredBasis.localLight", "true",
                          "froxel volumes are filled for the directional light only");
  validate(grid, "evaluateFroxels");
  validateFroxelJitter(jitter, "evaluateFroxels.jitter");
  const FroxelDepthRange range = froxelDepthRange(grid, camera, "evaluateFroxels");
  const glm::dvec3 sigma = medium.extinction();
  const int Z = options.visibilityTableSamples;
  return evaluateImpl(
      basis, grid.width, grid.height * grid.depth,
      [&](int x, int y) {
        return froxelSampleRay(camera, range, grid, jitter, x, y % grid.height, y / grid.height,
                               options.nearPlaneCorrection);
      },
      camera, medium, options,
      [&](const glm::dvec3& v) {
        return DirectionalSegments{scatteringConstant(light, medium, v), sigma};
      },
      [&](const std::vector<double>& visibility) {
        return scatteringPrefixTable(basis, visibility, Z, sigma);
      },
      [] { return std::vector<double>(); });
}

Image evaluate(const FilteredBasis& basis, const Image& cameraDepth, const Camera& camera,
               const LocalLight& light, const Medium& medium, const EvaluateOptions& options) {
  if (!basis.localLight)
    throw InvalidArgument("FilteredBasis.localLight", "false",
                          "the basis was prefiltered for a directional light: prefilter(map, medium, light)");
  if (options.nearPlaneCorrection)
    throw InvalidArgument("EvaluateOptions.nearPlaneCorrection", "true", "not supported for local lights");
  validateCameraDepth(cameraDepth);
  const int Z = options.visibilityTableSamples;
  return evaluateImpl(
      basis, cameraDepth.width(), cameraDepth.height(),
      [&](int x, int y) { return pixelRay(camera, cameraDepth, x, y, options.nearPlaneCorrection); }, camera,
      medium, options,
      [&](const glm::dvec3& v) { return LocalSegments{RayScattering(light, medium, camera.position(), v)}; },
      [&](const std::vector<double>& visibility) {
        return scatteringPrefixTable(basis, visibility, Z, light, medium);
      },
      [&] {
        return usesLocalSectionTable(options) ? localSectionTable(basis, Z, light, medium)
                                              : std::vector<double>();
      });
}

} // namespace crep
