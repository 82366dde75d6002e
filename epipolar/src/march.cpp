// CPU references of the ray marches (crep/epipolar/march.h): 1D min/max trees per rectified row and the
// tree march (Chen et al. 2011; Yusov 2012, seed 000 Sec. 4 Algorithm 2 and Sec. 6.3), the brute-force
// march of the same row, and the world-space march against a standard shadow map (seed 003 Eq. 1 and 3,
// seed 000 Eq. 15-16). The rules are in the header.
#include <crep/core/error.h>
#include <crep/core/parallel.h>
#include <crep/epipolar/march.h>

#include "march_common.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace crep {

using epipolar_detail::PixelRay;
using epipolar_detail::pixelRay;
// scatteringConstant: crep::scatteringConstant (prefilter.h).
using epipolar_detail::sectionIntegral;

// ---------------------------------------------------------------------------------------------------
// MarchResult

double MarchResult::meanSteps() const {
  if (steps.empty()) return 0.0;
  double sum = 0.0;
  for (float v : steps.data())
    sum += v;
  return sum / static_cast<double>(steps.sampleCount());
}

double MarchResult::maxSteps() const {
  double m = 0.0;
  for (float v : steps.data())
    m = std::max(m, static_cast<double>(v));
  return m;
}

// ---------------------------------------------------------------------------------------------------
// MinMaxTrees (seed 000 Sec. 4 Fig. 6, Sec. 6.3: level l from two nodes of level l - 1)

int MinMaxTrees::levelCount(int width) {
  int L = 0;
  while ((1LL << L) < static_cast<long long>(width))
    ++L;
  return L;
}

int MinMaxTrees::levelSize(int width, int level) {
  return static_cast<int>((static_cast<long long>(width) + (1LL << level) - 1) >> level);
}

int MinMaxTrees::levelOffset(int width, int level) {
  int offset = 0;
  for (int l = 1; l < level; ++l)
    offset += levelSize(width, l);
  return offset;
}

int MinMaxTrees::rowStrideFor(int width) {
  return levelOffset(width, levelCount(width) + 1);
}

// Yusov Sec. 6.3 / Chen et al. 2011: level 1 from texel pairs, level l from node pairs of level l - 1.
MinMaxTrees::MinMaxTrees(const Image& depth, int threads) {
  if (depth.empty()) throw InvalidArgument("MinMaxTrees.depth", "empty", "must be a W x H 1-channel image");
  if (depth.channels() != 1)
    throw InvalidArgument("MinMaxTrees.depth", std::to_string(depth.channels()) + " channels",
                          "must have 1 channel");
  if (threads < 0) throw InvalidArgument("MinMaxTrees.threads", detail::formatValue(threads), "must be >= 0");
  width_ = depth.width();
  height_ = depth.height();
  const int W = width_, L = levels(), stride = rowStride();
  data_.assign(static_cast<std::size_t>(stride) * static_cast<std::size_t>(height_) * 2, 0.0f);
  parallelRows(height_, threads, [&](int j) {
    float* row = data_.data() + static_cast<std::size_t>(j) * static_cast<std::size_t>(stride) * 2;
    int below = W; // node count of the level below
    for (int l = 1; l <= L; ++l) {
      const int size = levelSize(W, l), off = levelOffset(W, l), offBelow = levelOffset(W, l - 1);
      for (int m = 0; m < size; ++m) {
        const int a = 2 * m, b = std::min(2 * m + 1, below - 1);
        float mn, mx;
        if (l == 1) {
          mn = std::min(depth.at(a, j), depth.at(b, j));
          mx = std::max(depth.at(a, j), depth.at(b, j));
        } else {
          const float* na = row + 2 * (offBelow + a);
          const float* nb = row + 2 * (offBelow + b);
          mn = std::min(na[0], nb[0]);
          mx = std::max(na[1], nb[1]);
        }
        row[2 * (off + m)] = mn;
        row[2 * (off + m) + 1] = mx;
      }
      below = size;
    }
  });
}

glm::vec2 MinMaxTrees::node(int level, int row, int index) const {
  const std::size_t i = (static_cast<std::size_t>(row) * static_cast<std::size_t>(rowStride()) +
                         static_cast<std::size_t>(levelOffset(width_, level) + index)) *
                        2;
  return {data_[i], data_[i + 1]};
}

// ---------------------------------------------------------------------------------------------------
// Rectified marches

namespace {

void validateOptions(const MarchOptions& o) {
  if (o.threads < 0)
    throw InvalidArgument("MarchOptions.threads", detail::formatValue(o.threads), "must be >= 0");
}

/// The mapped part of one pixel's ray (march.h "Rectified marches").
struct RowRay {
  double row = 0.0;   ///< normalized row of the ray
  double depth = 0.0; ///< z_r, clamped to [0, 1]
  int texelRow = 0;   ///< j
  int last = 0;       ///< e: the last texel crossed
};

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

/// T(i) of march.h: the ray's own world distance at texel boundary i.
class RayDistances {
public:
  RayDistances(const RectifiedLayout& layout, const RowRay& r, int W, double surface)
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

  double at(int i) const {
    if (i <= 0) return 0.0;
    if (i > last_) return surface_;
    const int r = i / n_, q = i - r * n_;
    const double lo = bounds_[static_cast<std::size_t>(r)];
    if (q == 0) return lo;
    const double hi = bounds_[static_cast<std::size_t>(r) + 1];
    const double t = profiles_[static_cast<std::size_t>(r)](static_cast<double>(q) / n_);
    return std::clamp(t == t ? t : hi, lo, hi);
  }

private:
  int n_, last_;
  double surface_;
  std::vector<double> bounds_;
  std::vector<DistanceProfile> profiles_;
};

void requireSameSize(const RectifiedMap& map, const MinMaxTrees& trees) {
  if (trees.width() != map.width() || trees.height() != map.height())
    throw InvalidArgument("MinMaxTrees",
                          std::to_string(trees.width()) + " x " + std::to_string(trees.height()),
                          "must be built from the map's depth (" + std::to_string(map.width()) + " x " +
                              std::to_string(map.height()) + ")");
}

/// Runs walk(rowRay, distances, litSection, steps&) for every mapped pixel; litSection(ta, tb) adds a
/// lit section. Unmapped pixels are unshadowed.
template <class Walk>
MarchResult marchRows(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                      const DirectionalLight& light, const Medium& medium, const MarchOptions& options,
                      const Walk& walk) {
  validate(map);
  validateCameraDepth(cameraDepth);
  validateOptions(options);
  const RectifiedLayout& layout = *map.layout;
  const int w = cameraDepth.width(), h = cameraDepth.height(), W = map.width(), H = map.height();
  const glm::dvec3 sigma = medium.extinction();
  const double grey = epipolar_detail::greyExtinction(medium);
  const glm::dvec3 origin = camera.position();
  MarchResult out{Image(w, h, 4), Image(w, h, 1)};
  parallelRows(h, options.threads, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const PixelRay ray = pixelRay(camera, cameraDepth, x, y);
      const glm::dvec3 C = scatteringConstant(light, medium, ray.direction);
      glm::dvec3 L(0.0);
      int steps = 0;
      RowRay r;
      if (!mapRowRay(layout, origin, ray, W, H, r)) {
        L = sectionIntegral(sigma, 0.0, ray.surface);
      } else {
        const RayDistances T(layout, r, W, ray.surface);
        walk(
            r, T, [&](double ta, double tb) { L += sectionIntegral(sigma, ta, tb); }, steps);
      }
      epipolar_detail::storePixel(out.scattering, x, y, C * L, std::exp(-grey * ray.surface));
      out.steps.at(x, y) = static_cast<float>(steps);
    }
  });
  return out;
}

} // namespace

// Yusov Algorithm 2 on a rectified row (seed 003 Sec. 2.2: the ray's depth is constant), Eq. 16 sums.
MarchResult minMaxMarch(const RectifiedMap& map, const MinMaxTrees& trees, const Image& cameraDepth,
                        const Camera& camera, const DirectionalLight& light, const Medium& medium,
                        const MarchOptions& options) {
  requireSameSize(map, trees);
  const int W = map.width(), L = trees.levels(), stride = trees.rowStride();
  std::vector<int> offsets(static_cast<std::size_t>(L) + 1, 0);
  for (int l = 1; l <= L; ++l)
    offsets[static_cast<std::size_t>(l)] = MinMaxTrees::levelOffset(W, l);
  const float* nodes = trees.data().data();
  return marchRows(map, cameraDepth, camera, light, medium, options,
                   [&](const RowRay& r, const RayDistances& T, const auto& litSection, int& steps) {
                     const double z = r.depth;
                     const int j = r.texelRow, end = r.last + 1;
                     const float* row =
                         nodes + static_cast<std::size_t>(j) * static_cast<std::size_t>(stride) * 2;
                     int i = 0, level = 0;
                     while (i < end) {
                       // Algorithm 2 step 5.1: one level up where the position is aligned to it.
                       if (level < L && (i & ((2 << level) - 1)) == 0) ++level;
                       bool lit = false;
                       for (;;) {
                         ++steps;
                         double mn, mx;
                         if (level == 0) {
                           mn = mx = map.depth.at(i, j);
                         } else {
                           const float* node =
                               row + 2 * (offsets[static_cast<std::size_t>(level)] + (i >> level));
                           mn = node[0];
                           mx = node[1];
                         }
                         if (mn >= z) { // 5.2.4: every texel of the node is lit
                           lit = true;
                           break;
                         }
                         if (mx < z) break; // 5.2.3: every texel is shadowed
                         --level;           // 5.2.5 (never below 0: a texel always decides)
                       }
                       const int next = std::min(i + (1 << level), end);
                       if (lit) litSection(T.at(i), T.at(next));
                       i = next;
                     }
                   });
}

MarchResult minMaxMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                        const DirectionalLight& light, const Medium& medium, const MarchOptions& options) {
  validate(map);
  validateOptions(options);
  const MinMaxTrees trees(map.depth, options.threads);
  return minMaxMarch(map, trees, cameraDepth, camera, light, medium, options);
}

// Yusov Algorithm 1 / Eq. 16 texel by texel; seed 003 Eq. 5 with the exact transmittance of Eq. 1.
MarchResult bruteForceMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                            const DirectionalLight& light, const Medium& medium,
                            const MarchOptions& options) {
  return marchRows(map, cameraDepth, camera, light, medium, options,
                   [&](const RowRay& r, const RayDistances& T, const auto& litSection, int& steps) {
                     for (int i = 0; i <= r.last; ++i) {
                       ++steps;
                       if (map.depth.at(i, r.texelRow) >= r.depth) litSection(T.at(i), T.at(i + 1));
                     }
                   });
}

// ---------------------------------------------------------------------------------------------------
// World-space reference march

void validate(const WorldMarchOptions& o) {
  if (o.steps < 1 || o.steps > (1 << 24))
    throw InvalidArgument("WorldMarchOptions.steps", detail::formatValue(o.steps), "must be in [1, 2^24]");
  if (o.refinements < 0 || o.refinements > 60)
    throw InvalidArgument("WorldMarchOptions.refinements", detail::formatValue(o.refinements),
                          "must be in [0, 60]");
  if (!std::isfinite(o.bias))
    throw InvalidArgument("WorldMarchOptions.bias", detail::formatValue(o.bias), "must be finite");
  if (o.threads < 0)
    throw InvalidArgument("WorldMarchOptions.threads", detail::formatValue(o.threads), "must be >= 0");
}

bool standardShadowLit(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld, const glm::dvec3& p,
                       double bias) {
  const glm::dvec4 q = lightClipFromWorld * glm::dvec4(p, 1.0);
  const glm::dvec3 uvd = glm::dvec3(q) / q.w * 0.5 + 0.5;
  if (!(uvd.x >= 0.0 && uvd.x <= 1.0 && uvd.y >= 0.0 && uvd.y <= 1.0)) return true;
  const int W = shadowDepth.width(), H = shadowDepth.height();
  const int i = std::min(static_cast<int>(uvd.x * W), W - 1),
            j = std::min(static_cast<int>(uvd.y * H), H - 1);
  return std::clamp(uvd.z, 0.0, 1.0) <= static_cast<double>(shadowDepth.at(i, j)) + bias;
}

namespace {

void validateShadowMap(const Image& shadowDepth, const glm::dmat4& m) {
  if (shadowDepth.empty())
    throw InvalidArgument("shadowDepth", "empty", "must be a W x H 1-channel depth image");
  if (shadowDepth.channels() != 1)
    throw InvalidArgument("shadowDepth", std::to_string(shadowDepth.channels()) + " channels",
                          "must have 1 channel");
  for (int j = 0; j < shadowDepth.height(); ++j)
    for (int i = 0; i < shadowDepth.width(); ++i)
      if (std::isnan(shadowDepth.at(i, j)))
        throw InvalidArgument("shadowDepth",
                              "texel (" + std::to_string(i) + ", " + std::to_string(j) + ") = NaN",
                              "depth-buffer values must not be NaN");
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r]))
        throw InvalidArgument("lightClipFromWorld", detail::formatValue(m[c][r]), "must be finite");
}

/// One pixel of the world-space march; returns the lookups.
int worldMarchPixel(const Image& shadowDepth, const glm::dmat4& M, const glm::dvec3& origin,
                    const PixelRay& ray, const glm::dvec3& sigma, const WorldMarchOptions& o, glm::dvec3& L) {
  const double s = ray.surface;
  int lookups = 0;
  const auto lit = [&](double t) {
    ++lookups;
    return standardShadowLit(shadowDepth, M, origin + t * ray.direction, o.bias);
  };
  L = glm::dvec3(0.0);
  double ta = 0.0;
  bool va = lit(0.0);
  for (int k = 1; k <= o.steps; ++k) {
    const double tb = k == o.steps ? s : s * k / o.steps;
    const bool vb = lit(tb);
    if (va == vb) {
      if (va) L += sectionIntegral(sigma, ta, tb);
    } else {
      // Bisect for the change: [lo, hi] keeps va at lo and vb at hi.
      double lo = ta, hi = tb;
      for (int r = 0; r < o.refinements; ++r) {
        const double mid = 0.5 * (lo + hi);
        (lit(mid) == va ? lo : hi) = mid;
      }
      const double change = 0.5 * (lo + hi);
      if (va) L += sectionIntegral(sigma, ta, change);
      if (vb) L += sectionIntegral(sigma, change, tb);
    }
    ta = tb;
    va = vb;
  }
  return lookups;
}

} // namespace

// Seed 003 Eq. 1 and 3 (Yusov Eq. 15-16) against a standard shadow map: the rectification-free reference.
MarchResult worldSpaceMarch(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                            const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                            const Medium& medium, const WorldMarchOptions& options) {
  validateShadowMap(shadowDepth, lightClipFromWorld);
  validateCameraDepth(cameraDepth);
  validate(options);
  const int w = cameraDepth.width(), h = cameraDepth.height();
  MarchResult out{Image(w, h, 4), Image(w, h, 1)};
  const glm::dvec3 sigma = medium.extinction();
  const double grey = epipolar_detail::greyExtinction(medium);
  parallelRows(h, options.threads, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const PixelRay ray = pixelRay(camera, cameraDepth, x, y);
      glm::dvec3 L;
      const int lookups =
          worldMarchPixel(shadowDepth, lightClipFromWorld, camera.position(), ray, sigma, options, L);
      epipolar_detail::storePixel(out.scattering, x, y, scatteringConstant(light, medium, ray.direction) * L,
                                  std::exp(-grey * ray.surface));
      out.steps.at(x, y) = static_cast<float>(lookups);
    }
  });
  return out;
}

void worldSpaceMarchPixels(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                           const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                           const Medium& medium, std::span<const int> pixels, Image& scattering, Image* steps,
                           const WorldMarchOptions& options) {
  validateShadowMap(shadowDepth, lightClipFromWorld);
  validateCameraDepth(cameraDepth);
  validate(options);
  const int w = cameraDepth.width(), h = cameraDepth.height();
  if (scattering.width() != w || scattering.height() != h || scattering.channels() != 4)
    throw InvalidArgument("scattering",
                          std::to_string(scattering.width()) + " x " + std::to_string(scattering.height()),
                          "must be an RGBA image of cameraDepth's size");
  if (steps && (steps->width() != w || steps->height() != h || steps->channels() != 1))
    throw InvalidArgument("steps", std::to_string(steps->width()) + " x " + std::to_string(steps->height()),
                          "must be a 1-channel image of cameraDepth's size");
  for (int p : pixels)
    if (p < 0 || p >= w * h)
      throw InvalidArgument("pixels", detail::formatValue(p),
                            "must be in [0, " + std::to_string(w * h) + ")");
  const glm::dvec3 sigma = medium.extinction();
  const double grey = epipolar_detail::greyExtinction(medium);
  const int count = static_cast<int>(pixels.size());
  parallelRows(count, options.threads, [&](int k) {
    const int p = pixels[static_cast<std::size_t>(k)], x = p % w, y = p / w;
    const PixelRay ray = pixelRay(camera, cameraDepth, x, y);
    glm::dvec3 L;
    const int lookups =
        worldMarchPixel(shadowDepth, lightClipFromWorld, camera.position(), ray, sigma, options, L);
    epipolar_detail::storePixel(scattering, x, y, scatteringConstant(light, medium, ray.direction) * L,
                                std::exp(-grey * ray.surface));
    if (steps) steps->at(x, y) = static_cast<float>(lookups);
  });
}

} // namespace crep
