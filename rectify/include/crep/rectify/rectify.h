// Projective shadow-map rectification (Klehm, Seidel, Eisemann, "Filter-based real-time single
// scattering using rectified shadow maps", JCGT 3(3) 2014: Sec. 2.2 rectified maps, Sec. 3.2 reference
// rays, Sec. 4.2 construction, non-linearity, splits, Eq. 12). CPU only, double precision, no GL.
//
// The engine calls rectify() every frame. When the result is projective it rasterizes its shadow
// casters once per split with Split::rectClipFromWorld and gets a rectified shadow map: columns are
// steps along the view rays (left = near the camera), rows are epipolar slices, and the stored depth
// is the first occluder's "height" along the light ray; every view ray keeps one row and one depth.
// When it is not (a view ray (nearly) parallel to the light, or too strong a non-linearity), the
// caller uses the epipolar resampling fallback; the result says why, with the measure and threshold.
//
// ---------------------------------------------------------------------------------------------------
// The math (names used throughout this header)
//
// Rectified light view ("frame", RectifiedFrame): origin at the camera position c; axisZ = the
// direction light travels at the camera (a directional light's direction; for a spot or point light
// at L, (c - L) / |c - L|); axisX orthogonal to axisZ along the 2D bisectrix of the lit region's
// vertices projected along axisZ as seen from c (Sec. 4.2); axisY = axisZ x axisX. A world point p has
// frame coordinates X, Y, Z = dot(axis, p - c). The construction needs X > 0 on the whole region.
//   row slope     y = Y / X                  (constant on a view ray and on an epipolar plane)
//   depth slope   z = Z / X                  (constant on a view ray)
//   column param  zeta = (1 + rho Z) / X     (rho = 1 / |c - L|, 0 for a directional light: zeta = 1/X;
//                 for a point light 1 + rho Z = rho dot(axisZ, p - L), constant ratio on a light ray)
//   axis coord    xh = 1 / (zeta - rho zmin) (= X, world distance along axisX, for a directional light;
//                 splits are placed in xh; it is > 0 on the region)
// Normalized map coordinates (all in [0, 1] on the region, bounds are tight):
//   row   = (y - rowSlopeMin) / (rowSlopeMax - rowSlopeMin)
//   depth = (z - depthSlopeMin) / (depthSlopeMax - depthSlopeMin)     (= the depth-buffer value)
//   split k covers zeta in [zetaEnd_k, zetaBegin_k]; splitColumn = (zetaBegin_k - zeta) / (zetaBegin_k -
//   zetaEnd_k); column = (k + splitColumn) / K  (one continuous, piecewise-projective axis per row)
// Why: on a view ray c + s w, y and z are constant (the camera is the centre of projection) and
// zeta = 1 / (s w_X) + rho z decreases with s, so columns run left to right. On a light ray X and Y
// are constant (directional), or X, Y and 1 + rho Z all scale with the distance from L (point light),
// so (column, row) is constant and the depth grows in the direction of travel: GL_LESS keeps the first
// occluder. World distance along a view ray of slopes (y, z) at zeta (closed form, Sec. 3.2 weights):
//   s = sqrt(1 + y^2 + z^2) / (zeta - rho z).
// The split matrix: clip = (a_k X + b_k (1 + rho Z), alpha Y + beta X, gamma Z + delta X, X), i.e.
// Split::rectClipFromWorld = S_k * frameFromWorld (GL clip conventions, NDC in [-1, 1]^3).
// A spot or point light is taken into a perspective space centred at the light (where its rays are
// parallel) before the directional construction; we orient that transform from the light toward the
// camera rather than along the spot's axis, because the spot's own projection sends the camera to
// infinity when the camera lies in the spot's plane (the columns then collapse onto the rows).
// Distances stay world distances (formula above).
//
// Fallback decision (Rectification::measure, README "Fallback"): (1) the lit region's vertices,
// seen from c and projected along axisZ, do not fit in an open half-plane (span >= 180 degrees): a view
// ray through the region is a light ray (epipole on screen), impossible; (2) span >= maxSpanDegrees:
// rows are uniform in tan(angle), too non-linear; (3) some view ray of the region is within
// minEpipoleAngleDegrees of the light line through c (the paper's "distance of the epipole to the
// screen border", as an angle): depth slopes and the row step ratios of Sec. 3.2 blow up as
// 1 / sin(angle). A spot lit near its apex can trigger (3) without (2). All measures are continuous.
//
// ---------------------------------------------------------------------------------------------------
// What the engine must set when rendering a split (also in rectify/README.md)
//   - glEnable(GL_DEPTH_CLAMP): casters between the light and the frustum lie in front of depth 0 and
//     must be kept (clamped to 0), not clipped (Sec. 4.2). Casters behind the frustum clamp to 1.
//   - Default depth conventions: glDepthRange(0, 1), glClipControl(GL_LOWER_LEFT,
//     GL_NEGATIVE_ONE_TO_ONE); depth test GL_LESS; the whole map cleared to 1 once before the first split
//     (glClear ignores the viewport: a clear per split wipes the splits before it). The stored value is
//     `depth` above. crep::RectifiedShadowPass (crep/pipeline/rectified_shadow_pass.h) sets all of this.
//   - Face culling off (the rectification may mirror the winding).
//   - Viewport per split (splitViewport()): SplitLayout::Regions renders split k into columns
//     [k W/K, (k+1) W/K) of one W x H map (W a multiple of K); SplitLayout::Layers renders split k into
//     layer k of a W x H texture array. Texel (i, j) of the map has column (i + 0.5) / W (Regions) and
//     row (j + 0.5) / H, row 0 at the bottom (GL).
//   - Depth format: GL_DEPTH_COMPONENT32F recommended; the depth is linear in the depth slope z, so
//     24-bit unorm also works (resolution 2^-24 of the depth-slope range).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/light.h>

namespace crep {

/// Where the split boundaries x_0 = axisMin < x_1 < ... < x_K = axisMax go (Sec. 4.2 "Non-linearity",
/// split shadow maps). Measured along every row's reference ray (tests/rectify/RectifySplitStudyTest.cpp,
/// 60 degree camera, near 0.1, far 80, light from the side, K = 4, 1024 columns): spread max/min of the
/// world length per texel, of that length relative to the distance from the camera, and the worst
/// relative length x W:
///   uniform      2.9e4 / 710 / 709     blend 0.5   1.0e4 / 255 / 435
///   blend 0.75   3.3e3 / 117 / 251     logarithmic 3.3e3 / 5.7 / 18.8
/// (median over 200 random light directions: uniform 1.1e4 / 337 / 383, logarithmic 2.7e3 / 6.0 / 20).
/// Logarithmic is the default: every texel covers about the same fraction of its distance.
enum class SplitScheme {
  Uniform,     ///< x_j = xmin + (xmax - xmin) j / K
  Logarithmic, ///< x_j = xmin (xmax / xmin)^(j / K)
  Blend,       ///< x_j = lambda * logarithmic_j + (1 - lambda) * uniform_j (parallel-split shadow maps)
};

/// How the splits are laid out in the rectified map.
enum class SplitLayout {
  Regions, ///< split k renders into the k-th of K equal column ranges of one 2D map (a row is contiguous)
  /// Split k renders into layer k of a 2D texture array, full width: only for engines that sample the
  /// splits themselves (splitViewport() gives the layer). Nothing downstream in this library reads such a
  /// map: ProjectiveLayout, RectifiedShadowPass, the prefilter and the marches need Regions and say so
  /// (InvalidArgument naming the layout).
  Layers,
};

/// The reference ray of an epipolar slice (Sec. 3.2): the one ray whose world step per texel stands for
/// the whole row in the prefilter's transmittance weights.
enum class ReferenceRay {
  Bisectrix, ///< the bisectrix of the row's rays with the smallest and largest step (paper default)
  Optimal,   ///< k_ref = sqrt(k_min k_max): minimizes the worst step ratio max(1/c_min, c_max)
};

struct RectifyOptions {
  /// Number of splits K along the projection axis, in [1, kMaxSplits].
  int splits = 4;
  /// Split placement. Default logarithmic: in the study above (SplitScheme) it gives the smallest
  /// spread and worst case of the relative texel length (world length per texel / distance from the
  /// camera) for every K, and an absolute spread no larger than the blends' for K <= 4.
  SplitScheme scheme = SplitScheme::Logarithmic;
  /// lambda in [0, 1] for SplitScheme::Blend: weight of the logarithmic positions.
  double blend = 0.5;
  SplitLayout layout = SplitLayout::Regions;
  /// Fallback threshold on the angular span (degrees) of the lit region seen from the camera and
  /// projected along the light, in (0, 180]. 180 = no span criterion (only the impossible case).
  /// Default 150: rows are uniform in tan(angle), so slices near the edges are 1 / cos^2(span / 2) =
  /// 14.9x denser in angle than in the middle at 150 degrees. For a 60 degree 16:9 camera and uniformly
  /// random light directions, 23.5% are impossible and 8.9% more exceed 150 degrees (README "Fallback").
  double maxSpanDegrees = 150.0;
  /// Fallback threshold on the angle (degrees, [0, 90)) between the region's view rays and the light
  /// line through the camera. 0 = no such criterion. Default 5: the slowest ray of a row then has a
  /// world step per texel at most 1 / sin(5 deg) = 11.5x that of the fastest (Sec. 3.2); it costs 1.3%
  /// of random light directions for a 60 degree camera (README "Fallback").
  double minEpipoleAngleDegrees = 5.0;
  /// Reference ray used by Rectification::referenceDistance() and rowReference().
  ReferenceRay referenceRay = ReferenceRay::Bisectrix;

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

/// Stable token for logs and JSON: "none", "view-ray-parallel-to-light", "non-linearity",
/// "epipole-too-close", "empty-region".
const char* reasonToken(FallbackReason reason);
/// "projective", "fallback", "empty".
const char* statusToken(RectifyStatus status);

/// The rectified light view and the bounds of the lit region in it (see the math at the top).
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
  /// GL clip coordinates of the split's part of the map: NDC x = column within the split (-1 = near
  /// the camera), NDC y = row, NDC z = depth. Column-major (glm), ready for glUniformMatrix4fv.
  glm::dmat4 rectClipFromWorld{1.0};
  double rangeBegin = 0.0, rangeEnd = 0.0;   ///< [x_k, x_k+1] along the projection axis (xh)
  double zetaBegin = 0.0, zetaEnd = 0.0;     ///< column parameter zeta at its left (near) and right edge
  int layer = 0;                             ///< texture layer (SplitLayout::Layers), else 0
  double columnBegin = 0.0, columnEnd = 1.0; ///< normalized horizontal region of the map it renders into
};

/// An integer viewport for one split in a map of the given size (glViewport(x, y, width, height) on
/// layer `layer`).
struct SplitViewport {
  int layer, x, y, width, height;
};

/// A point in normalized rectified coordinates (see the math at the top).
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

/// The reference ray of one row and the error of using it for the whole row (Sec. 3.2).
/// k(w) = cosine of the angle between a ray w of the slice and the slice's direction orthogonal to
/// the light; a ray's world step per texel is proportional to 1 / k.
struct RowReference {
  /// Normalized row.
  double row = 0.0;
  /// Normalized depths of the row's extreme rays (the row's part of the region lies between them).
  double depthLo = 0.0, depthHi = 0.0;
  /// k of the rays with the largest step (w_max, kMin) and the smallest step (w_min, kMax).
  double kMin = 0.0, kMax = 0.0;
  /// k of the chosen reference ray.
  double kRef = 0.0;
  /// Normalized depth of the reference ray (use with Rectification::rayDistance).
  double depth = 0.0;
  /// Unit world direction of the reference ray.
  glm::dvec3 direction{0.0};
  /// c_min = kRef / kMax <= 1 and c_max = kRef / kMin >= 1: ratios of the reference ray's world step to
  /// the extreme rays' steps. Exact at every column for a directional light; for spot/point lights the
  /// step ratio also drifts along the row and these are its values at the camera.
  double ratioMin = 1.0, ratioMax = 1.0;
  /// max(1 / ratioMin, ratioMax): the worst step error factor of the compromise (Sec. 3.2 E(k_ref)).
  double error() const { return ratioMax > 1.0 / ratioMin ? ratioMax : 1.0 / ratioMin; }
};

/// The result of rectify(). Plain data plus mapping helpers; the helpers require status Projective and
/// throw InvalidArgument otherwise ("degenerate is a result": check status first).
struct Rectification {
  RectifyStatus status = RectifyStatus::Fallback;
  FallbackReason reason = FallbackReason::None;
  std::string message; ///< human-readable explanation with the numbers, for logs
  /// The measure that decided, and its threshold (degrees): epipoleAngle and minEpipoleAngleDegrees for
  /// reason EpipoleTooClose, else span and maxSpanDegrees.
  double measure = 0.0;
  double threshold = 0.0;
  /// Angular span (degrees, [0, 180]) of the lit region's vertices seen from the camera and projected
  /// along the light: the angle between the two extreme projected directions. 180 when they do not fit
  /// in an open half-plane, i.e. some view ray through the region is a light ray.
  double span = 0.0;
  /// Smallest angle (degrees, [0, 90]) between a view ray of the region and the light line through the
  /// camera (either direction); 0 when the epipole or anti-epipole lies in the region's view.
  double epipoleAngle = 0.0;

  RectifiedFrame frame;      ///< valid when Projective
  std::vector<Split> splits; ///< K splits when Projective, else empty
  SplitLayout layout = SplitLayout::Regions;
  ReferenceRay referenceRay = ReferenceRay::Bisectrix;
  /// Vertices of the lit region the bounds come from: the 8 camera frustum corners (directional), or the
  /// vertices of the camera frustum intersected with the light's frustum (spot / point face).
  std::vector<glm::dvec3> regionVertices;
  /// Convex hull of the region's (row slope, depth slope) pairs: the region's view rays (Sec. 3.2 rows).
  std::vector<glm::dvec2> slopeHull;

  bool projective() const noexcept { return status == RectifyStatus::Projective; }
  int splitCount() const noexcept { return static_cast<int>(splits.size()); }

  /// World point -> normalized rectified coordinates (math at the top). Requires X > 0 (in front of the
  /// plane through the camera orthogonal to axisX; every region point is); throws InvalidArgument else.
  RectPoint toRectified(const glm::dvec3& world) const;
  /// Inverse of toRectified: column and row in [0, 1] (values outside extrapolate the nearest split),
  /// depth any. Throws InvalidArgument if no world point has these coordinates (spot light: beyond the
  /// horizon of that depth slope).
  glm::dvec3 toWorld(double column, double row, double depth) const;
  glm::dvec3 toWorld(const RectPoint& p) const { return toWorld(p.column, p.row, p.depth); }
  /// The light ray of map position (column, row): every point of it maps to this (column, row).
  LightRay lightRay(double column, double row) const;
  /// The view ray of (row, depth): unit world direction from the camera position.
  glm::dvec3 viewRayDirection(double row, double depth) const;
  /// World distance from the camera along the view ray of (row, depth) to where it reaches `column`
  /// (closed form, math at the top). +infinity when that ray never reaches the column (spot/point
  /// lights only, beyond its horizon; never for a directional light).
  double rayDistance(double row, double depth, double column) const;
  /// The reference ray of a row (Sec. 3.2) chosen by `referenceRay`.
  RowReference rowReference(double row) const;
  RowReference rowReference(double row, ReferenceRay choice) const;
  /// rayDistance along the row's reference ray: the world distance the prefilter's exact
  /// transmittance weights need at each texel boundary.
  double referenceDistance(double row, double column) const;
  /// Eq. 12: the paper's constant step factor d of a row in split k rendered with `texelsPerSplit`
  /// columns: world distances t0, t1, t2 of the first three texel centres along the reference ray,
  /// d = (t2 - t1) / (t1 - t0). An approximation to compare the exact weights against.
  double texelStepRatio(double row, int split, int texelsPerSplit) const;
  /// Integer viewport and layer for split k in a width x height map (throws InvalidArgument if width is
  /// not a multiple of K in the Regions layout, or sizes are not positive).
  SplitViewport splitViewport(int split, int width, int height) const;
};

/// Sec. 4.2: the projective rectification for a directional light. Throws InvalidArgument for invalid
/// options (the parameter is named, e.g. "RectifyOptions.splits").
Rectification rectify(const Camera& camera, const DirectionalLight& light,
                      const RectifyOptions& options = {});

/// A spot light: the same construction in a perspective space centred at the light, over the part of
/// the camera frustum inside the spot's shadow frustum (SpotLight::lightClipFromWorld; that is the
/// "region"; outside it nothing is lit). Status Empty when they do not intersect.
Rectification rectify(const Camera& camera, const SpotLight& light, const RectifyOptions& options = {});

/// An omnidirectional point light as six spot faces (Sec. 3.2 "Local Lights"), in GL cube-map face
/// order +X, -X, +Y, -Y, +Z, -Z: face i covers the directions within 45 degrees (per axis) of its axis,
/// from `nearPlane` to `range` along that axis (nearPlane <= 0 means range * 1e-3). Faces that miss the
/// camera frustum are Empty; a face whose region contains the camera-light line falls back, and with
/// the light on screen (or within minEpipoleAngleDegrees of it) every face lit next to the light
/// falls back too (EpipoleTooClose). Add the faces' contributions.
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
