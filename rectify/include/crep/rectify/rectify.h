// Projective shadow-map rectification (Klehm, Seidel, Eisemann 2014, JCGT 3(3): Sec. 2.2, 3.2, 4.2, Eq. 12),
// CPU only, double precision, no GL. rectify() every frame: projective -> draw the casters once per split
// with Split::rectClipFromWorld; else the epipolar fallback, with the reason. The math, the fallback decision
// and what a split pass must set: rectify/README.md, "rectify.h".
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/light.h>

namespace crep {

/// Where the split boundaries x_0 = axisMin < ... < x_K = axisMax go (Sec. 4.2 "Non-linearity").
enum class SplitScheme {
  Uniform,     ///< x_j = xmin + (xmax - xmin) j / K
  Logarithmic, ///< x_j = xmin (xmax / xmin)^(j / K)
  Blend,       ///< x_j = lambda * logarithmic_j + (1 - lambda) * uniform_j (parallel-split shadow maps)
};

/// How the splits are laid out in the rectified map.
enum class SplitLayout {
  Regions, ///< split k renders into the k-th of K equal column ranges of one 2D map (a row is contiguous)
  Layers,  ///< split k into layer k of a texture array: for engines only, no pass here reads it
};

/// The reference ray of a slice (Sec. 3.2): its world step per texel stands for the row in the weights.
enum class ReferenceRay {
  Bisectrix, ///< the bisectrix of the row's rays with the smallest and largest step (paper default)
  Optimal,   ///< k_ref = sqrt(k_min k_max): minimizes the worst step ratio max(1/c_min, c_max)
};

struct RectifyOptions {
  int splits = 4;                                ///< K along the projection axis, in [1, kMaxSplits]
  SplitScheme scheme = SplitScheme::Logarithmic; ///< split placement
  double blend = 0.5; ///< lambda in [0, 1] of SplitScheme::Blend: weight of the logarithmic positions
  SplitLayout layout = SplitLayout::Regions;
  /// Fallback threshold on the lit region's angular span seen from the camera along the light (degrees,
  /// (0, 180]; 180: only the impossible case). At 150 the edge slices are 14.9x denser than the middle.
  double maxSpanDegrees = 150.0;
  /// Fallback threshold on the region's view rays' angle to the light line (degrees, [0, 90); 0 = none).
  /// At 5 a row's world steps per texel differ by at most 1 / sin(5 deg) = 11.5x.
  double minEpipoleAngleDegrees = 5.0;
  ReferenceRay referenceRay = ReferenceRay::Bisectrix; ///< of referenceDistance() and rowReference()

  static constexpr int kMaxSplits = 64;

  bool operator==(const RectifyOptions&) const = default;
};

enum class RectifyStatus {
  Projective, ///< usable: render the splits
  Fallback,   ///< use the epipolar resampling fallback; see reason
  Empty,      ///< spot / point light face only: its frustum does not meet the camera frustum (nothing lit)
};

enum class FallbackReason {
  None,                   ///< projective
  ViewRayParallelToLight, ///< a view ray through the region is a light ray (epipole on screen): impossible
  NonLinearity,           ///< span >= maxSpanDegrees: possible but the rows are too non-linear
  EpipoleTooClose,        ///< a view ray of the region is within minEpipoleAngleDegrees of the light line
  EmptyRegion,            ///< status Empty
};

/// Stable token for logs and JSON, e.g. "view-ray-parallel-to-light", "epipole-too-close".
const char* reasonToken(FallbackReason reason);
/// "projective", "fallback", "empty".
const char* statusToken(RectifyStatus status);

/// The rectified light view and the bounds of the lit region in it (README "rectify.h": the math).
struct RectifiedFrame {
  glm::dvec3 origin{0.0};                          ///< camera position, the centre of projection
  glm::dvec3 axisX{1, 0, 0};                       ///< projection axis (bisectrix), orthogonal to axisZ
  glm::dvec3 axisY{0, 1, 0};                       ///< axisZ x axisX
  glm::dvec3 axisZ{0, 0, 1};                       ///< direction light travels at the camera
  double inverseLightDistance = 0.0;               ///< rho = 1 / |camera - light|, 0 for a directional light
  glm::dvec3 lightPosition{0.0};                   ///< L (spot / point light only) = origin - axisZ / rho
  double rowSlopeMin = 0.0, rowSlopeMax = 0.0;     ///< bounds of y = Y / X
  double depthSlopeMin = 0.0, depthSlopeMax = 0.0; ///< bounds of z = Z / X
  double axisMin = 0.0, axisMax = 0.0;             ///< bounds of xh (world units along axisX if directional)

  /// Rows are ex, ey, ez, translation -R^T c: frame coordinates (X, Y, Z, 1) of a world point.
  glm::dmat4 frameFromWorld() const;
};

/// One split: a range of the projection axis rendered with its own projection (Sec. 4.2).
struct Split {
  /// GL clip of the split's part: NDC x = column in the split (-1 near the camera), y = row, z = depth.
  glm::dmat4 rectClipFromWorld{1.0};
  double rangeBegin = 0.0, rangeEnd = 0.0;   ///< [x_k, x_k+1] along the projection axis (xh)
  double zetaBegin = 0.0, zetaEnd = 0.0;     ///< column parameter zeta at its left (near) and right edge
  int layer = 0;                             ///< texture layer (SplitLayout::Layers), else 0
  double columnBegin = 0.0, columnEnd = 1.0; ///< normalized horizontal region of the map it renders into
};

/// An integer viewport for one split: glViewport(x, y, width, height) on layer `layer`.
struct SplitViewport {
  int layer, x, y, width, height;
};

/// A point in normalized rectified coordinates (README "rectify.h").
struct RectPoint {
  int split = 0;            ///< k, the split whose range contains the point (the lower one on a boundary)
  double splitColumn = 0.0; ///< column within the split, [0, 1]
  double column = 0.0;      ///< (split + splitColumn) / K, [0, 1] over the whole row
  double row = 0.0;         ///< [0, 1]
  double depth = 0.0;       ///< [0, 1], the depth-buffer value of the split matrices
};

/// A light ray in world space: origin + t * direction, t >= 0 in the direction light travels.
struct LightRay {
  glm::dvec3 origin;    ///< the light position (spot/point), or the point of the ray with Z = 0 (directional)
  glm::dvec3 direction; ///< unit
};

/// The reference ray of one row and the error of using it for the whole row (Sec. 3.2); a ray's world step
/// per texel is proportional to 1 / k, k = cos(angle to the slice's direction orthogonal to the light).
struct RowReference {
  double row = 0.0;                    ///< normalized row
  double depthLo = 0.0, depthHi = 0.0; ///< normalized depths of the row's extreme rays
  double kMin = 0.0, kMax = 0.0;       ///< k of the rays with the largest and the smallest step
  double kRef = 0.0;                   ///< k of the chosen reference ray
  double depth = 0.0;                  ///< normalized depth of the reference ray (for rayDistance)
  glm::dvec3 direction{0.0};           ///< unit world direction of the reference ray
  /// c_min = kRef / kMax <= 1, c_max = kRef / kMin >= 1; for spot / point lights their values at the camera.
  double ratioMin = 1.0, ratioMax = 1.0;
  /// max(1 / ratioMin, ratioMax): the worst step error factor of the compromise (Sec. 3.2 E(k_ref)).
  double error() const { return ratioMax > 1.0 / ratioMin ? ratioMax : 1.0 / ratioMin; }
};

/// The result of rectify(): plain data plus mapping helpers, which need status Projective (else
/// InvalidArgument: check status first).
struct Rectification {
  RectifyStatus status = RectifyStatus::Fallback;
  FallbackReason reason = FallbackReason::None;
  std::string message;    ///< human-readable explanation with the numbers, for logs
  double measure = 0.0;   ///< degrees: epipoleAngle for reason EpipoleTooClose, else span
  double threshold = 0.0; ///< degrees: the option that measure was compared with
  /// Span of the lit region's directions seen from the camera along the light (degrees, [0, 180]).
  double span = 0.0;
  double epipoleAngle = 0.0; ///< smallest angle of a region view ray to the light line (degrees, [0, 90])

  RectifiedFrame frame;      ///< valid when Projective
  std::vector<Split> splits; ///< K splits when Projective, else empty
  SplitLayout layout = SplitLayout::Regions;
  ReferenceRay referenceRay = ReferenceRay::Bisectrix;
  /// The lit region's vertices: the frustum's 8 corners (directional), or the frustum cut by the light's.
  std::vector<glm::dvec3> regionVertices;
  std::vector<glm::dvec2> slopeHull; ///< convex hull of the region's (row slope, depth slope) pairs

  bool projective() const noexcept { return status == RectifyStatus::Projective; }
  int splitCount() const noexcept { return static_cast<int>(splits.size()); }

  /// World point -> normalized rectified coordinates. Requires X > 0 (every region point), else
  /// InvalidArgument.
  RectPoint toRectified(const glm::dvec3& world) const;
  /// Inverse of toRectified (column, row outside [0, 1] extrapolate); InvalidArgument where no world point
  /// has these coordinates (spot light: beyond the horizon).
  glm::dvec3 toWorld(double column, double row, double depth) const;
  glm::dvec3 toWorld(const RectPoint& p) const { return toWorld(p.column, p.row, p.depth); }
  /// The light ray of map position (column, row): every point of it maps to this (column, row).
  LightRay lightRay(double column, double row) const;
  /// The view ray of (row, depth): unit world direction from the camera position.
  glm::dvec3 viewRayDirection(double row, double depth) const;
  /// World distance from the camera along the view ray of (row, depth) to `column` (closed form); +infinity
  /// when it never reaches it (spot / point lights only).
  double rayDistance(double row, double depth, double column) const;
  /// The reference ray of a row (Sec. 3.2) chosen by `referenceRay`.
  RowReference rowReference(double row) const;
  RowReference rowReference(double row, ReferenceRay choice) const;
  /// rayDistance along the row's reference ray (what the exact weights need at each texel boundary).
  double referenceDistance(double row, double column) const;
  /// Eq. 12's constant step factor d = (t2 - t1) / (t1 - t0) of the first three texel centres of split k
  /// along the reference ray, with `texelsPerSplit` columns.
  double texelStepRatio(double row, int split, int texelsPerSplit) const;
  /// Viewport and layer of split k in a width x height map (InvalidArgument: bad sizes, or W % K with
  /// Regions).
  SplitViewport splitViewport(int split, int width, int height) const;
};

/// Sec. 4.2 for a directional light; InvalidArgument naming a bad option (e.g. "RectifyOptions.splits").
Rectification rectify(const Camera& camera, const DirectionalLight& light,
                      const RectifyOptions& options = {});

/// A spot light: the same in a perspective space centred at the light, over the camera frustum's part
/// inside the spot's shadow frustum (SpotLight::lightClipFromWorld); Empty when they do not meet.
Rectification rectify(const Camera& camera, const SpotLight& light, const RectifyOptions& options = {});

/// A point light as six spot faces in cube-map order (Sec. 3.2 "Local Lights"), from `nearPlane` (<= 0:
/// range * 1e-3) to `range`; add the faces' contributions.
std::array<Rectification, 6> rectifyPointLight(const Camera& camera, const glm::dvec3& position, double range,
                                               const RectifyOptions& options = {}, double nearPlane = -1.0);
/// The same for a PointLight: its faces are PointLight::faceClipFromWorld(i)'s frusta.
std::array<Rectification, 6> rectifyPointLight(const Camera& camera, const PointLight& light,
                                               const RectifyOptions& options = {});

/// Split boundaries x_0..x_K of a scheme on [xmin, xmax] (0 < xmin < xmax), exact at both ends.
std::vector<double> splitPositions(double xmin, double xmax, int splits, SplitScheme scheme, double blend);

/// Validates options; throws InvalidArgument naming the field ("RectifyOptions.splits", ...).
void validate(const RectifyOptions& options);

} // namespace crep
