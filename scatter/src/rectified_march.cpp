// The brute-force march along rectified rows (Klehm et al. 2014, Sec. 2.2; the exact transmittance of
// Eq. 1 per texel section, Yusov 2012, Eq. 16). Rules at the top of crep/scatter/rectified_march.h.
#include <crep/core/error.h>
#include <crep/scatter/rectified_march.h>

namespace crep {

bool mapRowRay(const RectifiedLayout& layout, const glm::dvec3& origin, const PixelRay& ray, int W, int H,
               RowRay& out) {
  const int K = layout.regionCount(), n = W / K;
  RectPoint hit;
  try {
    hit = layout.toRectified(origin + ray.surface * ray.direction);
  } catch (const InvalidArgument&) {
    return false;
  }
  if (!std::isfinite(hit.row) || !std::isfinite(hit.depth)) return false;
  out.row = hit.row;
  out.depth = std::clamp(hit.depth, 0.0, 1.0);
  out.texelRow = std::clamp(static_cast<int>(std::floor(hit.row * H)), 0, H - 1);
  const int k = std::clamp(hit.split, 0, K - 1);
  const double u = std::isfinite(hit.splitColumn) ? std::clamp(hit.splitColumn, 0.0, 1.0) : 1.0;
  out.last = k * n + std::clamp(static_cast<int>(std::ceil(u * n)) - 1, 0, n - 1);
  return true;
}

RowDistances::RowDistances(const RectifiedLayout& layout, const RowRay& r, int W, double surface)
    : n_(W / layout.regionCount()), last_(r.last), surface_(surface) {
  const int K = layout.regionCount();
  const int used = r.last / n_ + 1; // regions crossed
  bounds_.assign(static_cast<std::size_t>(used) + 1, 0.0);
  profiles_.resize(static_cast<std::size_t>(used));
  for (int k = 0; k < used; ++k) {
    profiles_[static_cast<std::size_t>(k)] = layout.rayProfile(r.row, r.depth, k);
    double t = layout.rayDistance(r.row, r.depth, static_cast<double>(k + 1) / K);
    if (!(t == t)) t = surface; // NaN: treat as beyond the surface
    bounds_[static_cast<std::size_t>(k) + 1] = std::clamp(t, bounds_[static_cast<std::size_t>(k)], surface);
  }
}

double RowDistances::at(int i) const {
  if (i <= 0) return 0.0;
  if (i > last_) return surface_;
  const int r = i / n_, q = i - r * n_;
  const double lo = bounds_[static_cast<std::size_t>(r)];
  if (q == 0) return lo;
  const double hi = bounds_[static_cast<std::size_t>(r) + 1];
  const double t = profiles_[static_cast<std::size_t>(r)](static_cast<double>(q) / n_);
  return std::clamp(t == t ? t : hi, lo, hi);
}

// Yusov 2012, Eq. 16 texel by texel on a rectified row; Klehm et al. 2014, Eq. 5 with the exact
// transmittance of Eq. 1.
namespace {
/// The texel-by-texel walk of a row (every texel tested).
auto bruteForceWalk(const RectifiedMap& map) {
  return [&map](const RowRay& r, const RowDistances& T, const auto& litSection, int& steps) {
    for (int i = 0; i <= r.last; ++i) {
      ++steps;
      if (map.depth.at(i, r.texelRow) >= r.depth) litSection(T.at(i), T.at(i + 1));
    }
  };
}

template <class Light>
MarchResult bruteForce(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                       const Light& light, const Medium& medium, const MarchOptions& options,
                       const Image* lightColors = nullptr) {
  return marchRectifiedRows(map, cameraDepth, camera, light, medium, options, lightColors,
                            bruteForceWalk(map));
}
} // namespace

MarchResult bruteForceMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                            const DirectionalLight& light, const Medium& medium,
                            const MarchOptions& options) {
  return bruteForce(map, cameraDepth, camera, light, medium, options);
}

MarchResult bruteForceMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                            const LocalLight& light, const Medium& medium, const MarchOptions& options) {
  return bruteForce(map, cameraDepth, camera, light, medium, options);
}

// Yusov 2012, Sec. 6.4: the same march on the rays of screen samples (epipolar sampling's marched samples).
MarchResult bruteForceMarch(const RectifiedMap& map, std::span<const ScreenSample> samples, int width,
                            int height, const Camera& camera, const DirectionalLight& light,
                            const Medium& medium, const MarchOptions& options) {
  return marchRectifiedSamples(map, samples, width, height, camera, light, medium, options, nullptr,
                               bruteForceWalk(map));
}

// Light textures: each lit texel's section times the texel's colour (Klehm et al. 2014, Sec. 3.2).
MarchResult bruteForceMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                            const DirectionalLight& light, const Medium& medium, const Image& lightColors,
                            const MarchOptions& options) {
  return bruteForce(map, cameraDepth, camera, light, medium, options, &lightColors);
}

MarchResult bruteForceMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                            const LocalLight& light, const Medium& medium, const Image& lightColors,
                            const MarchOptions& options) {
  return bruteForce(map, cameraDepth, camera, light, medium, options, &lightColors);
}

} // namespace crep
