// The RectifiedMap contract: what both rectifications (the projective one of Klehm et al. 2014,
// Sec. 4.2, and the epipolar resampling fallback of Sec. 4.1) hand to every consumer (prefilter, min/max
// trees, ray marches, evaluation), so those are written once.
//
// A rectified map is a W x H depth image plus a layout:
//   - rows are epipolar slices: texel row j has normalized row (j + 0.5) / H, row 0 at the bottom (GL);
//   - columns are steps along the view rays, left = near the camera: texel column i has normalized
//     column (i + 0.5) / W;
//   - the stored value is the depth-buffer value in [0, 1] of the first occluder along the texel's
//     light ray (0 = a caster clamped in front of the region, 1 = nothing: cleared or clamped behind);
//     a view ray keeps one row and one depth from the camera to infinity (Sec. 2.2);
//   - the columns are cut into K layout regions of W / K columns each, side by side (for the
//     projective layout these are the splits rendered with SplitLayout::Regions): region k holds the
//     normalized columns [k / K, (k + 1) / K) and u = K column - k in [0, 1] is the column within it.
// World distances along a view ray are a 1D projective function of u inside one region (exact for a
// projective rectification; linear for a constant-step epipolar layout), so a consumer (the CPU and GPU
// prefilter) describes a row's reference ray per region with four numbers (DistanceProfile).
#pragma once

#include <functional>
#include <memory>
#include <optional>

#include <glm/glm.hpp>

#include <crep/core/image.h>
#include <crep/rectify/gpu_layout.h>
#include <crep/rectify/rectify.h>

namespace crep {

/// World distance from the camera along one view ray inside one region, as a function of the column
/// within the region u in [0, 1]:  t(u) = (a + b u) / (c + d u).
/// Projective layout (rectify.h "The math"): a = sqrt(1 + y^2 + z^2), b = 0, c = zeta_begin - rho z,
/// d = zeta_end - zeta_begin (y, z = the ray's row and depth slopes). A constant-step layout: b = step
/// per unit u, a = start distance, c = 1, d = 0. Units: world units. Precondition for a finite profile:
/// c + d u > 0 on [0, 1] (always true for a directional light).
struct DistanceProfile {
  double a = 0.0, b = 0.0, c = 1.0, d = 0.0;

  /// t(u); +infinity where c + d u <= 0 (spot/point light: beyond the ray's horizon).
  double operator()(double u) const;
  /// t(u) - t(0) = u (b c - a d) / (c (c + d u)), evaluated without the cancellation of the difference
  /// (what the transmittance weights need); +infinity where c + d u <= 0.
  double fromStart(double u) const;
  /// The profile of the sub-range [u0, u1] re-parameterized to [0, 1]: sub(u0, u1)(v) = t(u0 + (u1 - u0) v).
  DistanceProfile sub(double u0, double u1) const;
  /// True when t is finite and > 0 on [0, 1] (c > 0 and c + d > 0, a + b u > 0 at both ends).
  bool valid() const;
};

/// The geometric side of a rectified map: how world points and view rays map into it. Implemented by
/// ProjectiveLayout (Sec. 4.2) and, later, by the epipolar resampling layout (Sec. 4.1). All
/// coordinates are normalized as described at the top of this file. Double precision, CPU only,
/// thread-safe (const methods only, no mutable state).
class RectifiedLayout {
public:
  virtual ~RectifiedLayout() = default;

  /// K >= 1: number of layout regions (equal column ranges [k / K, (k + 1) / K)).
  virtual int regionCount() const = 0;
  /// The camera position (every view ray starts there).
  virtual glm::dvec3 origin() const = 0;
  /// World point -> (region in RectPoint::split, splitColumn = u within it, column, row, depth).
  /// Throws InvalidArgument for points the layout cannot map (projective: X <= 0).
  virtual RectPoint toRectified(const glm::dvec3& world) const = 0;
  /// The light ray of map position (column, row): every point of it maps to this (column, row) and
  /// its depth grows in the direction of travel.
  virtual LightRay lightRay(double column, double row) const = 0;
  /// Unit world direction of the view ray of (row, depth).
  virtual glm::dvec3 viewRayDirection(double row, double depth) const = 0;
  /// World distance from the camera along the view ray of (row, depth) to where it reaches `column`
  /// (+infinity if it never does).
  virtual double rayDistance(double row, double depth, double column) const = 0;
  /// The same for the row's reference ray (Sec. 3.2), whose distances define the prefilter's weights.
  virtual double referenceDistance(double row, double column) const = 0;
  /// Normalized depth of the row's reference ray.
  virtual double referenceDepth(double row) const = 0;
  /// rayDistance(row, depth, (region + u) / K) as a DistanceProfile of u (exact).
  virtual DistanceProfile rayProfile(double row, double depth, int region) const = 0;
  /// referenceDistance(row, (region + u) / K) as a DistanceProfile of u (exact).
  virtual DistanceProfile referenceProfile(double row, int region) const = 0;
  /// Normalized depth of the reference ray the prefilter weights layout region `region` of the row with
  /// (crep/prefilter/prefilter.h referenceProfiles()): referenceDepth(row) unless the layout says otherwise
  /// (ProjectiveLayout for spot/point lights).
  virtual double regionReferenceDepth(double row, int region) const {
    static_cast<void>(region);
    return referenceDepth(row);
  }
  /// The layout serialized for the GPU (crep/rectify/gpu_layout.h), or nullopt when the GLSL has no
  /// mapping for it. Throws InvalidArgument when the layout exceeds what the GPU blocks hold.
  virtual std::optional<GpuLayoutData> gpuLayoutData() const { return std::nullopt; }
  /// The position of the layout's light when it is local (a spot light or point-light face: light rays
  /// leave it), nullopt for a directional light.
  virtual std::optional<glm::dvec3> localLightPosition() const { return std::nullopt; }
};

/// The projective rectification (Sec. 4.2) as a RectifiedLayout: regions = splits.
class ProjectiveLayout final : public RectifiedLayout {
public:
  /// Throws InvalidArgument ("Rectification.status") unless the rectification is projective, and
  /// ("Rectification.layout") unless its layout is SplitLayout::Regions (split k = region k).
  explicit ProjectiveLayout(Rectification rectification);

  const Rectification& rectification() const noexcept { return rect_; }

  int regionCount() const override;
  glm::dvec3 origin() const override;
  RectPoint toRectified(const glm::dvec3& world) const override;
  LightRay lightRay(double column, double row) const override;
  glm::dvec3 viewRayDirection(double row, double depth) const override;
  double rayDistance(double row, double depth, double column) const override;
  double referenceDistance(double row, double column) const override;
  double referenceDepth(double row) const override;
  DistanceProfile rayProfile(double row, double depth, int region) const override;
  DistanceProfile referenceProfile(double row, int region) const override;
  /// Spot/point lights: a view ray's distances reach +infinity at its horizon column (c + d u = 0, the
  /// column of its vanishing point) and the row's rays have different horizons (rays of smaller depth
  /// reach further). The row's reference ray (chosen for the step at the camera) can reach its horizon
  /// inside a region other rays of the row cross whole, or come close to it: its exact weights then
  /// vanish over the region's far texels (colonnade, point light 3 units behind the camera: a lit wedge,
  /// 24% from the brute-force march over the same map). Every region of a local light therefore takes the
  /// row's extreme ray (RowReference::depthLo or depthHi) reaching furthest, the larger c + d: finite
  /// wherever any ray of the row crosses the region. Directional lights (rho = 0): referenceDepth(row).
  double regionReferenceDepth(double row, int region) const override;
  std::optional<GpuLayoutData> gpuLayoutData() const override;
  std::optional<glm::dvec3> localLightPosition() const override;

private:
  Rectification rect_;
};

/// A rectified map on the CPU: layout + depth image (GPU code passes the same data as a GL texture
/// plus the layout's per-row numbers).
struct RectifiedMap {
  std::shared_ptr<const RectifiedLayout> layout;
  /// 1 channel, W x H, W a multiple of layout->regionCount(), depth-buffer values in [0, 1], row 0 at
  /// the bottom (Image convention, as glReadPixels and gl::readTexture(..., gl::TexelData::Depth) return it).
  Image depth;

  int width() const noexcept { return depth.width(); }
  int height() const noexcept { return depth.height(); }
};

/// Throws InvalidArgument naming the problem: "RectifiedMap.layout" (null), "RectifiedMap.depth"
/// (empty, not 1 channel, width not a multiple of regionCount(), a value NaN/Inf or outside [0, 1],
/// with its texel coordinates).
void validate(const RectifiedMap& map);

/// Builds a map from a CPU depth image (e.g. gl::readTexture(texture, W, H, gl::TexelData::Depth) of a map
/// rendered with the split matrices) and validates it.
RectifiedMap makeRectifiedMap(std::shared_ptr<const RectifiedLayout> layout, Image depth);

/// Builds a W x H map on the CPU without GL: for each texel, `firstHit(lightRay(column, row))`
/// returns the first occluder along the texel's light ray (a world point; the callback decides how far
/// behind the ray's origin it searches), or nothing; the stored depth is toRectified(hit).depth clamped
/// to [0, 1] (as GL_DEPTH_CLAMP does), or 1 without a hit (the cleared value). Rows in parallel on up
/// to `threads` threads (0 = hardware concurrency); the callback must be thread-safe. Throws
/// InvalidArgument for non-positive sizes or a width that is not a multiple of regionCount().
RectifiedMap castRectifiedMap(std::shared_ptr<const RectifiedLayout> layout, int width, int height,
                              const std::function<std::optional<glm::dvec3>(const LightRay&)>& firstHit,
                              int threads = 0);

} // namespace crep
