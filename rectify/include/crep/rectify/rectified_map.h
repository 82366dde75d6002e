// The RectifiedMap contract: what both rectifications (projective, Klehm et al. 2014 Sec. 4.2; epipolar
// fallback, Sec. 4.1) hand to every consumer: a W x H depth image plus a layout. Rows, columns, regions and
// stored values: rectify/README.md, "rectified_map.h".
#pragma once

#include <functional>
#include <memory>
#include <optional>

#include <glm/glm.hpp>

#include <crep/core/image.h>
#include <crep/rectify/gpu_layout.h>
#include <crep/rectify/rectify.h>

namespace crep {

/// World distance from the camera along one view ray inside one region, t(u) = (a + b u) / (c + d u), u in
/// [0, 1] the column within the region (world units; the coefficients of each layout: README).
struct DistanceProfile {
  double a = 0.0, b = 0.0, c = 1.0, d = 0.0;

  /// t(u); +infinity where c + d u <= 0 (spot/point light: beyond the ray's horizon).
  double operator()(double u) const;
  /// t(u) - t(0) = u (b c - a d) / (c (c + d u)) without cancellation; +infinity where c + d u <= 0.
  double fromStart(double u) const;
  /// The sub-range [u0, u1] re-parameterized to [0, 1]: sub(u0, u1)(v) = t(u0 + (u1 - u0) v).
  DistanceProfile sub(double u0, double u1) const;
  /// True when t is finite and > 0 on [0, 1] (c > 0 and c + d > 0, a + b u > 0 at both ends).
  bool valid() const;
};

/// The geometric side of a rectified map (ProjectiveLayout, EpipolarLayout): normalized coordinates, double
/// precision, CPU only, thread-safe (const methods only, no mutable state).
class RectifiedLayout {
public:
  virtual ~RectifiedLayout() = default;

  /// K >= 1: number of layout regions (equal column ranges [k / K, (k + 1) / K)).
  virtual int regionCount() const = 0;
  /// The camera position (every view ray starts there).
  virtual glm::dvec3 origin() const = 0;
  /// World point -> (region in RectPoint::split, u in splitColumn, column, row, depth); InvalidArgument for
  /// points the layout cannot map (projective: X <= 0).
  virtual RectPoint toRectified(const glm::dvec3& world) const = 0;
  /// The light ray of (column, row): all its points map there, the depth growing along the travel.
  virtual LightRay lightRay(double column, double row) const = 0;
  /// Unit world direction of the view ray of (row, depth).
  virtual glm::dvec3 viewRayDirection(double row, double depth) const = 0;
  /// World distance along the view ray of (row, depth) to `column` (+infinity if it never reaches it).
  virtual double rayDistance(double row, double depth, double column) const = 0;
  /// The same for the row's reference ray (Sec. 3.2), whose distances define the prefilter's weights.
  virtual double referenceDistance(double row, double column) const = 0;
  /// Normalized depth of the row's reference ray.
  virtual double referenceDepth(double row) const = 0;
  /// rayDistance(row, depth, (region + u) / K) as a DistanceProfile of u (exact).
  virtual DistanceProfile rayProfile(double row, double depth, int region) const = 0;
  /// referenceDistance(row, (region + u) / K) as a DistanceProfile of u (exact).
  virtual DistanceProfile referenceProfile(double row, int region) const = 0;
  /// Depth of the reference ray the prefilter weights `region` of the row with (default referenceDepth).
  virtual double regionReferenceDepth(double row, int region) const {
    static_cast<void>(region);
    return referenceDepth(row);
  }
  /// The layout for the GPU, or nullopt without a GLSL mapping; InvalidArgument beyond the blocks' limits.
  virtual std::optional<GpuLayoutData> gpuLayoutData() const { return std::nullopt; }
  /// The local light's position (spot or point-light face), nullopt for a directional light.
  virtual std::optional<glm::dvec3> localLightPosition() const { return std::nullopt; }
};

/// The projective rectification (Sec. 4.2) as a RectifiedLayout: regions = splits.
class ProjectiveLayout final : public RectifiedLayout {
public:
  /// InvalidArgument ("Rectification.status", ".layout") unless projective with SplitLayout::Regions.
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
  /// Local lights: the row's extreme ray (RowReference::depthLo or depthHi) reaching furthest (README).
  double regionReferenceDepth(double row, int region) const override;
  std::optional<GpuLayoutData> gpuLayoutData() const override;
  std::optional<glm::dvec3> localLightPosition() const override;

private:
  Rectification rect_;
};

/// A rectified map on the CPU: layout + depth image (on the GPU: a texture and the layout's numbers).
struct RectifiedMap {
  std::shared_ptr<const RectifiedLayout> layout;
  /// 1 channel, W x H (W a multiple of regionCount()), depth-buffer values in [0, 1], row 0 at the bottom.
  Image depth;

  int width() const noexcept { return depth.width(); }
  int height() const noexcept { return depth.height(); }
};

/// Throws InvalidArgument naming "RectifiedMap.layout" (null) or "RectifiedMap.depth" (shape, or a value NaN,
/// Inf or outside [0, 1], with its texel).
void validate(const RectifiedMap& map);

/// A validated map from a CPU depth image (e.g. gl::readTexture(..., gl::TexelData::Depth) of the map).
RectifiedMap makeRectifiedMap(std::shared_ptr<const RectifiedLayout> layout, Image depth);

/// A W x H map without GL from `firstHit` (the first occluder on a texel's light ray, or nothing), rows on
/// `threads` threads (0 = all cores): the callback must be thread-safe. InvalidArgument for bad sizes.
RectifiedMap castRectifiedMap(std::shared_ptr<const RectifiedLayout> layout, int width, int height,
                              const std::function<std::optional<glm::dvec3>(const LightRay&)>& firstHit,
                              int threads = 0);

} // namespace crep
