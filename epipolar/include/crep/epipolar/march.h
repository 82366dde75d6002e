// The min/max tree march (Chen et al. 2011; Yusov 2012, Sec. 4, 6.3 and Algorithm 2 on a rectified row:
// Klehm et al. 2014, Sec. 2.2), CPU reference in double, on the brute-force march's scaffolding
// (crep/scatter/rectified_march.h). Trees, traversal, steps: epipolar/README.md, "crep/epipolar/march.h".
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/ray.h>
#include <crep/scatter/rectified_march.h>
#include <crep/scatter/world_march.h>

namespace crep {

/// The 1D min/max binary trees of every row of a W x H depth image: node (l, j, m) is the float pair
/// data()[2 (j rowStride() + levelOffset(l) + m)] = (min, max) (storage shared with the GPU: README).
class MinMaxTrees {
public:
  MinMaxTrees() = default;
  /// Builds the trees of `depth` (1 channel, not checked for NaN) on `threads` workers (0 = all cores).
  /// Throws InvalidArgument ("MinMaxTrees.depth") for an empty or multi-channel image. O(W H).
  explicit MinMaxTrees(const Image& depth, int threads = 0);

  int width() const noexcept { return width_; }
  int height() const noexcept { return height_; }
  int levels() const noexcept { return levelCount(width_); }
  int rowStride() const noexcept { return rowStrideFor(width_); }
  /// (min, max) of node m of level l (1 <= l <= levels(), 0 <= m < levelSize(width(), l)) in row j.
  glm::vec2 node(int level, int row, int index) const;
  std::span<const float> data() const noexcept { return data_; }

  static int levelCount(int width);             ///< L = ceil(log2 W), 0 for W = 1
  static int levelSize(int width, int level);   ///< ceil(W / 2^l)
  static int levelOffset(int width, int level); ///< sum of levelSize(W, l') for 1 <= l' < l
  static int rowStrideFor(int width);           ///< sum of levelSize(W, l) for 1 <= l <= L

private:
  int width_ = 0, height_ = 0;
  std::vector<float> data_;
};

/// The tree march with prebuilt trees of `map.depth` (InvalidArgument "MinMaxTrees" when their size
/// differs). Validates the map, "cameraDepth" and the options. O(pixels x node tests).
MarchResult minMaxMarch(const RectifiedMap& map, const MinMaxTrees& trees, const Image& cameraDepth,
                        const Camera& camera, const DirectionalLight& light, const Medium& medium,
                        const MarchOptions& options = {});
/// The same, building the trees first.
MarchResult minMaxMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                        const DirectionalLight& light, const Medium& medium,
                        const MarchOptions& options = {});
/// At screen samples of a width x height image (Yusov 2012, Sec. 6.4): results samples.size() x 1. Throws
/// InvalidArgument for the map, "MinMaxTrees", "samples[i]", "width" / "height" or the options.
MarchResult minMaxMarch(const RectifiedMap& map, const MinMaxTrees& trees,
                        std::span<const ScreenSample> samples, int width, int height, const Camera& camera,
                        const DirectionalLight& light, const Medium& medium,
                        const MarchOptions& options = {});
/// For a local light (a spot or one point-light face, on a map of its rectification).
MarchResult minMaxMarch(const RectifiedMap& map, const MinMaxTrees& trees, const Image& cameraDepth,
                        const Camera& camera, const LocalLight& light, const Medium& medium,
                        const MarchOptions& options = {});
MarchResult minMaxMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                        const LocalLight& light, const Medium& medium, const MarchOptions& options = {});
/// With a light texture's colour map (lightColorMap() of the map's layout and size; InvalidArgument
/// "lightColors"): the parts and order of bruteForceMarch with the same colours.
MarchResult minMaxMarch(const RectifiedMap& map, const MinMaxTrees& trees, const Image& cameraDepth,
                        const Camera& camera, const DirectionalLight& light, const Medium& medium,
                        const Image& lightColors, const MarchOptions& options = {});
MarchResult minMaxMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                        const DirectionalLight& light, const Medium& medium, const Image& lightColors,
                        const MarchOptions& options = {});
MarchResult minMaxMarch(const RectifiedMap& map, const MinMaxTrees& trees, const Image& cameraDepth,
                        const Camera& camera, const LocalLight& light, const Medium& medium,
                        const Image& lightColors, const MarchOptions& options = {});
MarchResult minMaxMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                        const LocalLight& light, const Medium& medium, const Image& lightColors,
                        const MarchOptions& options = {});

/// The lit sections [ta, tb] (world distances) minMaxMarch integrates for every pixel ray, row-major,
/// disjoint and merged (README). Throws InvalidArgument as minMaxMarch does.
std::vector<std::vector<glm::dvec2>> minMaxLitSections(const RectifiedMap& map, const MinMaxTrees& trees,
                                                       const Image& cameraDepth, const Camera& camera,
                                                       const MarchOptions& options = {});

} // namespace crep
