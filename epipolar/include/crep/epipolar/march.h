// The min/max tree march, the accelerated peer of the prefiltered method (CPU reference in double): the
// 1D min/max binary tree of every row of a rectified map (Chen et al. 2011, as used by Yusov 2012, Sec. 4
// and Sec. 6.3) and the tree-accelerated march of each pixel's view ray along its row (Yusov 2012,
// Algorithm 2, on a rectified row: Klehm et al. 2014, Sec. 2.2). It runs on the rays, sections and output
// of the brute-force march (crep/scatter/rectified_march.h), so both agree up to the rounding of the sums.
// The world-space reference march is crep/scatter/world_march.h. The GPU passes (gpu_march.h) implement
// the same rules.
//
// Min/max tree (MinMaxTrees): level 0 is the row itself; node m of level l >= 1 covers texels
// [m 2^l, (m + 1) 2^l) (clipped to the row) and stores their (min, max). On a rectified row the ray's depth
// is constant, so one comparison decides a node: min >= z_r -> the whole node is lit; max < z_r -> the
// whole node is shadowed; otherwise descend (Algorithm 2, steps 5.2.3-5.2.5; a level-0 node always
// decides). The traversal is Algorithm 2's: start at texel 0, level 0; before each step go up one level
// when the position is a multiple of 2^(level + 1) (step 5.1); a decided node of level l advances by 2^l
// texels (clipped to e + 1) and adds its section [T(a), T(b)] when lit. The lit set is exactly the
// brute-force march's, so the results agree up to the rounding of the sums (double precision).
//
// Steps per pixel (MarchResult::steps): min/max march: node tests (every comparison of a node, including
// the ones that descend); brute force: texels visited (e + 1); world-space march: shadow-map lookups.
// Unmapped pixels: 0.
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

/// The 1D min/max binary trees of every row of a W x H depth image (see top). Storage (also the GPU's,
/// gpu_march.h): per row, levels 1..L one after the other, level l at offset levelOffset(l) with
/// levelSize(l) = ceil(W / 2^l) nodes, L = levelCount(W) = ceil(log2 W) (0 for W = 1); node (l, j, m) is
/// the float pair data()[2 (j rowStride() + levelOffset(l) + m)] = min, [+ 1] = max.
class MinMaxTrees {
public:
  MinMaxTrees() = default;
  /// Builds the trees of `depth` (1 channel; values are copied as they are, NaN is the caller's error:
  /// validate the map first). Rows in parallel on `threads` workers (0 = hardware concurrency). Throws
  /// InvalidArgument ("MinMaxTrees.depth") for an empty image or more than 1 channel.
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

/// The tree-accelerated march (see top) with prebuilt trees of `map.depth` (InvalidArgument
/// "MinMaxTrees" when their size differs). Validates the map (validate(RectifiedMap)), the camera depth
/// ("cameraDepth": empty, NaN or outside [0, 1], with the pixel) and the options.
MarchResult minMaxMarch(const RectifiedMap& map, const MinMaxTrees& trees, const Image& cameraDepth,
                        const Camera& camera, const DirectionalLight& light, const Medium& medium,
                        const MarchOptions& options = {});
/// The same, building the trees first.
MarchResult minMaxMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                        const DirectionalLight& light, const Medium& medium,
                        const MarchOptions& options = {});
/// The tree march of the rays through screen samples of a width x height camera image (Yusov 2012,
/// Sec. 6.4: epipolar sampling's marched samples; crep/scatter/rectified_march.h marchRectifiedSamples: ray
/// i = screenRay at samples[i], result images samples.size() x 1, empty for no samples, at most
/// Image::kMaxDimension samples). At pixel centres with the pixels' depth-buffer values it equals the
/// per-pixel minMaxMarch bit for bit. Throws InvalidArgument for the map, "MinMaxTrees", "samples[i]",
/// "width" / "height" or the options.
MarchResult minMaxMarch(const RectifiedMap& map, const MinMaxTrees& trees,
                        std::span<const ScreenSample> samples, int width, int height, const Camera& camera,
                        const DirectionalLight& light, const Medium& medium,
                        const MarchOptions& options = {});
/// The tree march for a local light (a spot, or one point-light face, on a map of its rectification):
/// each lit section integrated by RayScattering, as bruteForceMarch does.
MarchResult minMaxMarch(const RectifiedMap& map, const MinMaxTrees& trees, const Image& cameraDepth,
                        const Camera& camera, const LocalLight& light, const Medium& medium,
                        const MarchOptions& options = {});
MarchResult minMaxMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                        const LocalLight& light, const Medium& medium, const MarchOptions& options = {});
/// The tree march with a light texture's colour map (lightColorMap() of the map's layout and size; the
/// rule of crep/scatter/rectified_march.h, validated: InvalidArgument "lightColors"): each lit node's
/// section is split at its texels' boundaries and each part times its texel's colour, exactly the parts
/// and order of bruteForceMarch with the same colours. Directional light and local light, with prebuilt
/// trees or building them.
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

/// The lit sections [ta, tb] (world distances, ascending, clipped to [ray.start, ray.surface]) of every
/// pixel ray of `cameraDepth` from the min/max tree walk: exactly the sections minMaxMarch integrates;
/// an unmapped ray is one section [start, surface]. Row-major, width * height entries. Sections of zero
/// length are left out and adjacent sections (one's tb equal to the next one's ta) are merged into one,
/// so the sections of a ray are disjoint with gaps between them (the shadowed parts). Throws
/// InvalidArgument as minMaxMarch does (the map, "MinMaxTrees", "cameraDepth", the options).
std::vector<std::vector<glm::dvec2>> minMaxLitSections(const RectifiedMap& map, const MinMaxTrees& trees,
                                                       const Image& cameraDepth, const Camera& camera,
                                                       const MarchOptions& options = {});

} // namespace crep
