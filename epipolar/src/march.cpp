// CPU reference of the min/max tree march (crep/epipolar/march.h): 1D min/max trees per rectified row and
// the tree march (Chen et al. 2011; Yusov 2012, Sec. 4, Algorithm 2 and Sec. 6.3) on the scaffolding of
// the brute-force march (crep/scatter/rectified_march.h). The rules are in the header.
#include <crep/core/error.h>
#include <crep/core/parallel.h>
#include <crep/epipolar/march.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace crep {

// ---------------------------------------------------------------------------------------------------
// MinMaxTrees (Yusov 2012, Sec. 4 Fig. 6, Sec. 6.3: level l from two nodes of level l - 1)

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

void requireSameSize(const RectifiedMap& map, const MinMaxTrees& trees) {
  if (trees.width() != map.width() || trees.height() != map.height())
    throw InvalidArgument("MinMaxTrees",
                          std::to_string(trees.width()) + " x " + std::to_string(trees.height()),
                          "must be built from the map's depth (" + std::to_string(map.width()) + " x " +
                              std::to_string(map.height()) + ")");
}

} // namespace

// Yusov 2012, Algorithm 2 on a rectified row (Klehm et al. 2014, Sec. 2.2: the ray's depth is constant),
// Eq. 16 sums.
namespace {
/// The tree walk of a row (marchRectifiedRays' `walk`) on prebuilt trees of the map.
struct MinMaxWalk {
  const RectifiedMap* map = nullptr;
  const float* nodes = nullptr;
  int L = 0, stride = 0;
  std::vector<int> offsets;

  MinMaxWalk(const RectifiedMap& m, const MinMaxTrees& trees)
      : map(&m), nodes(trees.data().data()), L(trees.levels()), stride(trees.rowStride()),
        offsets(static_cast<std::size_t>(trees.levels()) + 1, 0) {
    for (int l = 1; l <= L; ++l)
      offsets[static_cast<std::size_t>(l)] = MinMaxTrees::levelOffset(m.width(), l);
  }

  template <class Section>
  void operator()(const RowRay& r, const RowDistances& T, const Section& litSection, int& steps) const {
    const double z = r.depth;
    const int j = r.texelRow, end = r.last + 1;
    const float* row = nodes + static_cast<std::size_t>(j) * static_cast<std::size_t>(stride) * 2;
    int i = 0, level = 0;
    while (i < end) {
      // Algorithm 2 step 5.1: one level up where the position is aligned to it.
      if (level < L && (i & ((2 << level) - 1)) == 0) ++level;
      bool lit = false;
      for (;;) {
        ++steps;
        double mn, mx;
        if (level == 0) {
          mn = mx = map->depth.at(i, j);
        } else {
          const float* node = row + 2 * (offsets[static_cast<std::size_t>(level)] + (i >> level));
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
  }
};

template <class Light>
MarchResult minMaxMarchImpl(const RectifiedMap& map, const MinMaxTrees& trees, const Image& cameraDepth,
                            const Camera& camera, const Light& light, const Medium& medium,
                            const MarchOptions& options, const Image* lightColors = nullptr) {
  requireSameSize(map, trees);
  return marchRectifiedRows(map, cameraDepth, camera, light, medium, options, lightColors,
                            MinMaxWalk(map, trees));
}

} // namespace

// Yusov 2012, Sec. 6.4: the tree march of the marched samples' rays (screen samples).
MarchResult minMaxMarch(const RectifiedMap& map, const MinMaxTrees& trees,
                        std::span<const ScreenSample> samples, int width, int height, const Camera& camera,
                        const DirectionalLight& light, const Medium& medium, const MarchOptions& options) {
  requireSameSize(map, trees);
  return marchRectifiedSamples(map, samples, width, height, camera, light, medium, options, nullptr,
                               MinMaxWalk(map, trees));
}

MarchResult minMaxMarch(const RectifiedMap& map, const MinMaxTrees& trees, const Image& cameraDepth,
                        const Camera& camera, const DirectionalLight& light, const Medium& medium,
                        const MarchOptions& options) {
  return minMaxMarchImpl(map, trees, cameraDepth, camera, light, medium, options);
}

MarchResult minMaxMarch(const RectifiedMap& map, const MinMaxTrees& trees, const Image& cameraDepth,
                        const Camera& camera, const LocalLight& light, const Medium& medium,
                        const MarchOptions& options) {
  return minMaxMarchImpl(map, trees, cameraDepth, camera, light, medium, options);
}

namespace {
/// minMaxMarch after building the trees of the map.
template <class Light>
MarchResult minMaxMarchBuildingTrees(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                                     const Light& light, const Medium& medium, const MarchOptions& options,
                                     const Image* lightColors = nullptr) {
  validate(map);
  validate(options);
  const MinMaxTrees trees(map.depth, options.threads);
  return minMaxMarchImpl(map, trees, cameraDepth, camera, light, medium, options, lightColors);
}
} // namespace

MarchResult minMaxMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                        const DirectionalLight& light, const Medium& medium, const MarchOptions& options) {
  return minMaxMarchBuildingTrees(map, cameraDepth, camera, light, medium, options);
}

MarchResult minMaxMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                        const LocalLight& light, const Medium& medium, const MarchOptions& options) {
  return minMaxMarchBuildingTrees(map, cameraDepth, camera, light, medium, options);
}

// Light textures (Klehm et al. 2014, Sec. 3.2): marchRectifiedRows splits each lit node's section per texel.
MarchResult minMaxMarch(const RectifiedMap& map, const MinMaxTrees& trees, const Image& cameraDepth,
                        const Camera& camera, const DirectionalLight& light, const Medium& medium,
                        const Image& lightColors, const MarchOptions& options) {
  return minMaxMarchImpl(map, trees, cameraDepth, camera, light, medium, options, &lightColors);
}

MarchResult minMaxMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                        const DirectionalLight& light, const Medium& medium, const Image& lightColors,
                        const MarchOptions& options) {
  return minMaxMarchBuildingTrees(map, cameraDepth, camera, light, medium, options, &lightColors);
}

MarchResult minMaxMarch(const RectifiedMap& map, const MinMaxTrees& trees, const Image& cameraDepth,
                        const Camera& camera, const LocalLight& light, const Medium& medium,
                        const Image& lightColors, const MarchOptions& options) {
  return minMaxMarchImpl(map, trees, cameraDepth, camera, light, medium, options, &lightColors);
}

MarchResult minMaxMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                        const LocalLight& light, const Medium& medium, const Image& lightColors,
                        const MarchOptions& options) {
  return minMaxMarchBuildingTrees(map, cameraDepth, camera, light, medium, options, &lightColors);
}

// The lit sections of the tree walk (Yusov 2012, Algorithm 2), the ones marchRectifiedRays integrates:
// clipped to [start, surface], empty ones left out, touching ones merged.
std::vector<std::vector<glm::dvec2>> minMaxLitSections(const RectifiedMap& map, const MinMaxTrees& trees,
                                                       const Image& cameraDepth, const Camera& camera,
                                                       const MarchOptions& options) {
  validate(map);
  validateCameraDepth(cameraDepth);
  validate(options);
  requireSameSize(map, trees);
  const int w = cameraDepth.width(), h = cameraDepth.height(), W = map.width(), H = map.height();
  const RectifiedLayout& layout = *map.layout;
  const glm::dvec3 origin = camera.position();
  const MinMaxWalk walk(map, trees);
  std::vector<std::vector<glm::dvec2>> out(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  parallelRows(h, options.threads, [&](int y) {
    for (int x = 0; x < w; ++x) {
      std::vector<glm::dvec2>& sections =
          out[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)];
      const PixelRay ray = pixelRay(camera, cameraDepth, x, y, options.nearPlaneCorrection);
      RowRay r;
      if (!mapRowRay(layout, origin, ray, W, H, r)) {
        sections.emplace_back(ray.start, ray.surface);
        continue;
      }
      const RowDistances T(layout, r, W, ray.surface);
      int steps = 0;
      walk(
          r, T,
          [&](double ta, double tb) {
            ta = std::max(ta, ray.start);
            tb = std::min(tb, ray.surface);
            if (!(tb > ta)) return;
            if (!sections.empty() && sections.back().y == ta)
              sections.back().y = tb;
            else
              sections.emplace_back(ta, tb);
          },
          steps);
    }
  });
  return out;
}

} // namespace crep
