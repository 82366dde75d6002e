// Ray-marching peers of the prefiltered method, CPU references in double precision:
//   - the 1D min/max binary tree of every row of a rectified map (Chen et al. 2011 as used by Yusov 2012,
//     seed 000 Sec. 4 and Sec. 6.3) and the tree-accelerated march of each pixel's view ray along its row
//     (seed 000 Algorithm 2, on a rectified row: seed 003 Sec. 2.2);
//   - the brute-force march of the same row, texel by texel (identical result, more steps);
//   - a world-space march against a standard shadow map, the reference that does not depend on any
//     rectification (seed 003 Eq. 1 and 3; seed 000 Eq. 15-16: the integral as a sum over lit sections).
// The GPU passes (gpu_march.h) implement the same rules.
//
// ---------------------------------------------------------------------------------------------------
// Rays and output (the rules of prefilter.h "Evaluation", so every method is compared on identical rays)
// Per camera pixel (x, y) of a w x h depth image (row 0 at the bottom):
//   ndc = (2 (x + 0.5) / w - 1, 2 (y + 0.5) / h - 1), v = camera.rayDirection(ndc) (unit);
//   s = linearDepth(depth) / dot(v, forward) (surface distance); sky (depth >= 1): s = far / dot(v, forward).
//   C = light.irradiance() * medium.scatteringTimesPhase(dot(light.direction(), -v)) per channel;
//   L = C sum_{lit sections [ta, tb]} (exp(-sigma ta) - exp(-sigma tb)) / sigma   (sigma = extinction,
//       per channel; evaluated as exp(-sigma ta) (tb - ta) phi(sigma (tb - ta)), finite as sigma -> 0).
//   Output RGBA: RGB = L, A = exp(-sbar s), sbar = mean of the three extinction channels.
//
// Rectified marches (minMaxMarch, bruteForceMarch). P = layout.toRectified(camera.position() + s v) gives
// the ray's row, its depth z_r (clamped to [0, 1]: 1 is "behind every stored occluder") and the region k
// and column u of its end. Texel row j = clamp(floor(row H), 0, H - 1); the ray crosses texels 0..e of
// that row, e = k n + clamp(ceil(u n) - 1, 0, n - 1) (K regions of n = W / K texels). Texel i is lit iff
// depth(i, j) >= z_r (the GL_LESS shadow test). Its section of the ray is [T(i), T(i + 1)] with the ray's
// own world distances (DistanceProfile of the layout, exact):
//   T(0) = 0 (region 0 starts at the camera), T(e + 1) = s,
//   T(r n) = clamp(layout.rayDistance(row, z_r, r / K), T((r - 1) n), s) at region boundaries,
//   T(r n + q) = clamp(layout.rayProfile(row, z_r, r)(q / n), T(r n), T((r + 1) n)) inside region r.
// These are the rules of prefilter's marchReference(), so both brute-force marches agree.
// Pixels whose end point the layout cannot map (toRectified throws) are unshadowed (V = 1).
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

namespace crep {

struct MarchOptions {
  /// CPU worker threads: 0 = std::thread::hardware_concurrency(). Never changes the result.
  int threads = 0;
};

struct MarchResult {
  Image scattering;         ///< RGBA, cameraDepth's size: RGB = in-scattered radiance, A = grey transmittance
  Image steps;              ///< 1 channel, cameraDepth's size: steps of the pixel's march (see top)
  double meanSteps() const; ///< mean of `steps` over all pixels (0 for an empty result)
  double maxSteps() const;  ///< max of `steps`
};

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

/// The brute-force march of the same rows (see top), texel by texel. Same validation.
MarchResult bruteForceMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                            const DirectionalLight& light, const Medium& medium,
                            const MarchOptions& options = {});

// ---------------------------------------------------------------------------------------------------
// World-space reference march against a standard shadow map.
//
// The shadow map is a depth image rendered with `lightClipFromWorld` (GL conventions, glDepthRange(0, 1),
// GL_LESS, cleared to 1), texel (i, j) covering uv in [i / W, (i + 1) / W) x [j / H, (j + 1) / H).
// Visibility of a world point p: q = lightClipFromWorld p, (u, v, d) = q.xyz / q.w * 0.5 + 0.5; outside
// the map (u or v outside [0, 1]) -> lit; else lit iff clamp(d, 0, 1) <= depth(floor(u W), floor(v H)) +
// bias (nearest texel, clamped to the map). The ray [0, s] is cut into N = steps equal sections; the
// visibility is sampled at their N + 1 ends; a section whose ends agree takes that visibility, a section
// whose ends differ is bisected `refinements` times to locate the change, and the parts on either side
// take the visibility of their end. Each lit part is integrated exactly (formula at the top), so the
// result is exact for visibility with at most one change per section, up to s / (N 2^refinements) at
// each change. Steps = visibility lookups.
struct WorldMarchOptions {
  int steps = 256;      ///< N >= 1 equal sections from the camera to the surface
  int refinements = 16; ///< bisections at each visibility change, in [0, 60]
  double bias = 0.0;    ///< added to the stored depth (depth-buffer units), finite
  int threads = 0;      ///< CPU worker threads, 0 = hardware concurrency
};

/// Throws InvalidArgument naming the field ("WorldMarchOptions.steps", ...).
void validate(const WorldMarchOptions& options);

/// Visibility of a world point against a standard shadow map (rule above; no validation: hot path).
bool standardShadowLit(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld, const glm::dvec3& p,
                       double bias = 0.0);

/// The world-space reference march (see above and the top). Throws InvalidArgument for an empty
/// shadow map, more than 1 channel, a NaN texel ("shadowDepth", with the texel), a non-finite matrix
/// ("lightClipFromWorld"), a bad camera depth ("cameraDepth") or options.
MarchResult worldSpaceMarch(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                            const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                            const Medium& medium, const WorldMarchOptions& options = {});

/// The same for the pixels of `pixels` only (indices y * w + x), written into `scattering` (RGBA,
/// cameraDepth's size, e.g. the output of another method) and, if given, `steps` (1 channel, same size);
/// other pixels are left untouched. What the epipole block uses (seed 003 Fig. 8: brute-force march a small
/// block of pixels around the epipole; EpipolarLayout::epipoleBlockPixels()). Throws InvalidArgument as
/// worldSpaceMarch, and ("scattering" / "steps" / "pixels") for wrong sizes or indices.
void worldSpaceMarchPixels(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                           const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                           const Medium& medium, std::span<const int> pixels, Image& scattering,
                           Image* steps = nullptr, const WorldMarchOptions& options = {});

} // namespace crep
