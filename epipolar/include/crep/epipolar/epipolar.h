// Epipolar rectification, the fallback when the projective rectification cannot be built (Klehm, Seidel,
// Eisemann 2014, Sec. 4.1 after Baran et al. 2010; slices through the screen border after Yusov 2012,
// Sec. 6.1, 6.6). CPU, double precision.
//
// ---------------------------------------------------------------------------------------------------
// Geometry (directional light). m = -light.direction(): the direction toward the light. For a point p,
// q = p - c (c the camera position): a = q.m, b = |q - a m| (the distance from the light axis through
// c), psi = atan2(b, a) in [0, pi] (the angle between q and m; 0 = looking into the light). Every view ray
// lies in one half-plane bounded by the light axis (an epipolar slice) and keeps its psi; every light ray
// keeps its half-plane and its b. So (slice, b) index light rays and (slice, psi) index view rays, and
// along a view ray of angle psi the world distance is t = b / sin(psi): linear in b.
//
// The epipole: the image of the light axis. V = the homogeneous image point of m when m is in front of
// the camera (EpipoleKind::Epipole: the light source direction), else of -m (AntiEpipole: the point the
// shafts converge to); AtInfinity when the axis is parallel to the image plane. epipoleNdc() = V.xy / V.z.
// The half-plane of a slice projects to a half-line from the epipole; its visible part is a segment from
// an entry to an exit point, and (Yusov) the slice is named by its exit point: the end farther from the
// epipole (Epipole: the larger psi; AntiEpipole: the smaller psi).
//
// Slices through the screen border (Yusov's four-border order, counter-clockwise from the top-left corner:
// left side top to bottom, bottom side left to right, right side bottom to top, top side right to left),
// parameterized by the border length in pixels sigma in [0, P), P = 2 (w + h) for a w x h screen. The exit
// points of all visible slices form one contiguous arc of the border: the sides whose inner half-plane
// contains the epipole (all four when it is on screen). Rows cover that arc: row = (sigma - arcBegin) /
// arcLength. Slice count rule: H = ceil(arcLength * slicesPerBorderPixel): with 1 slice per border pixel,
// slices are at most one pixel apart at the border and closer inside (they converge to the epipole), so
// no pixel is more than half a pixel from its slice. Texel row j covers rows [j / H, (j + 1) / H).
//
// Map coordinates (rows = slices, columns = steps along the reference ray, depth = the angle to the
// light), with per-slice bounds (Sec. 4.1) that are constant over a texel row j:
//   column: piecewise linear in b / bMax_j over K regions: region k (columns [k / K, (k + 1) / K)) covers
//                          b / bMax_j in [f_k, f_(k+1)], linearly in u = K column - k. bMax_j = the largest
//                          b of the far-plane points of the slice row's screen sector (exact: b is convex
//                          on the far plane, so its maximum is at a vertex of the sector: the entry and
//                          exit points of the row's two limiting slices and the screen corners inside it)
//   depth  = (g(psi) - g(psiMin_j)) / (g(psiMax_j) - g(psiMin_j))   psi bounds of the sector's view rays
//                          (its limiting slices' entry and exit rays, its centre slice and the corners
//                          inside it); g the depth warp (Sec. 5, "depth warp"): g(psi) = log((psi + e) /
//                          (pi - psi + e)), e = EpipolarOptions::depthWarp (g = psi when e = 0). The shadow
//                          test compares depths of one slice, so any increasing g gives the same visibility;
//                          g only moves the Fourier basis's resolution toward the rays next to the light
//                          axis (both ends: the epipole and the anti-epipole), where view and light rays are
//                          nearly parallel and linear psi leaves them a few hundredths of the depth range.
//   region fractions f_0 = 0 < f_1 < ... < f_K = 1: Uniform f_k = k / K; Logarithmic (default, like the
//   logarithmic splits of the projective rectification, Sec. 4.2 "Non-linearity"): f_k = (near / far)^(1 - k
//   / K) for 0 < k < K, so region 0 holds the camera's neighbourhood, where the transmittance weights are
//   largest.
// Distances are linear in the column inside each region (weights: constant world step along the
// reference ray): rayDistance(row, depth, column) = b(column) / sin(psi); the reference ray of a row is the
//   bisectrix between its rays of largest and smallest sin(psi) (Sec. 3.2; ReferenceRay::Optimal takes
//   sin(psi_ref) = sqrt(k_min k_max) and falls back to the bisectrix when k_min = 0).
// The map has to be exactly sliceCount() rows high (texel row j = slice j).
//
// Local lights (a spot light or a point-light face at L, in or near the view, where the projective
// rectification falls back; Klehm et al. 2014, Sec. 3.2 "Local Lights" on the Sec. 4.1 layout): the same
// slices, rows and depth around the axis through the camera and the light, m = (L - c) / D, D = |L - c|
// (the epipole is the light's image). Light rays are half-lines from L; in a slice, the one at angle theta
// from the direction L -> c holds the points with theta = atan2(b, D - a), theta in [0, pi], and along it psi
// grows from 0 (at L) in the direction of travel, so the stored depth (psi) keeps its meaning. Columns:
//   theta in [0, thetaMax_j] (thetaMax_j = the largest theta of the far-plane points of the slice row's
//   sector, sampled along its limiting rays, clamped to pi), regions at theta_k = f_k thetaMax_j, and inside
//   region k (mid angle mu, half width h <= pi / 4: the fractions are raised so no region spans more than
//   half of [0, thetaMax_j]) theta = mu + atan((2 u - 1) tan h), the light rays through evenly spaced points
//   of the chord: the law of sines in the triangle (c, L, p) gives the distance along the view ray of
//   angle psi, t = D sin(theta) / sin(psi + theta), a projective function of u inside each region (exact
//   DistanceProfile), +infinity where psi + theta >= pi (the ray never reaches that light ray).
//
// Epipole block (Fig. 8): next to the epipole view rays and light rays are nearly parallel and a slice
// holds little information (sin(psi) -> 0): the pixels within epipoleBlockRadiusPixels() of the epipole (or
// the anti-epipole) are left to a march (epipoleBlockPixels(); crep::Scattering marches them over the map).
#pragma once

#include <array>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>

namespace crep {

struct EpipolarOptions {
  /// Number of slices (map rows); 0 = the automatic rule ceil(arcLength * slicesPerBorderPixel).
  int slices = 0;
  /// Slice density of the automatic rule (> 0); 1 = no pixel farther than half a pixel from its slice.
  double slicesPerBorderPixel = 1.0;
  /// K >= 1 layout regions (equal column ranges; the prefilter's regions), <= RectifyOptions::kMaxSplits.
  int regions = 4;
  /// Where the regions' boundaries f_k go in b / bMax (see top).
  SplitScheme regionScheme = SplitScheme::Logarithmic;
  /// Reference ray of a row (Sec. 3.2), for the prefilter's weights.
  ReferenceRay referenceRay = ReferenceRay::Bisectrix;
  /// Radius of the epipole block as a fraction of the screen diagonal (>= 0; 0 = no block); the value
  /// crep::Scattering uses (its CreateInfo says why).
  double epipoleBlockRadius = 0.06;
  /// Most pixels the block may hold on screen (>= 0; 0 = no bound): when the disc of epipoleBlockRadius
  /// holds more pixel centres on screen, the radius shrinks to the largest one that holds at most this
  /// many, so the block costs at most this many pixels at any screen size. A disc mostly off screen (the
  /// light just outside the view) keeps its full radius.
  int maxBlockPixels = 0;
  /// Depth warp e (radians, >= 0; 0 = linear depth in psi): depth is linear in
  /// g(psi) = log((psi + e) / (pi - psi + e)), which stretches the rays near the light axis (see top).
  double depthWarp = 0.1;
};

/// Throws InvalidArgument naming the field ("EpipolarOptions.slices", ...).
void validate(const EpipolarOptions& options);

enum class EpipoleKind {
  Epipole,     ///< the direction toward the light is in front of the camera
  AntiEpipole, ///< the direction the light travels is in front of the camera
  AtInfinity,  ///< the light axis is parallel to the image plane
};

/// The largest number of slices accepted (the automatic rule gives at most 2 (w + h)).
inline constexpr int kMaxEpipolarSlices = 65536;

/// The epipolar fallback layout (see top) for one camera, light and screen size.
class EpipolarLayout final : public RectifiedLayout {
public:
  /// One slice (texel row): its bounds.
  struct Slice {
    double bMax = 0.0;   ///< world units: column 1 is at this distance from the light axis
    double psiMin = 0.0; ///< radians: depth 0
    double psiMax = 0.0; ///< radians: depth 1
    glm::dvec3 direction{
        0.0}; ///< unit direction of the slice's half-plane orthogonal to the light (at the row centre)
    double thetaMax = 0.0; ///< local light: radians in (0, pi], the angle at the light of column 1 (see top)
  };

  /// Throws InvalidArgument for screen sizes <= 0 or > Image::kMaxDimension ("EpipolarLayout.screenSize"),
  /// bad options, or more than kMaxEpipolarSlices slices.
  EpipolarLayout(const Camera& camera, const DirectionalLight& light, int screenWidth, int screenHeight,
                 const EpipolarOptions& options = {});

  /// The layout of a local light at `lightPosition` (see top, "Local lights"). Throws InvalidArgument as
  /// above, for a non-finite light position or one within 1e-9 far of the camera
  /// ("EpipolarLayout.lightPosition"), and for options.regions < 2 ("EpipolarOptions.regions").
  EpipolarLayout(const Camera& camera, const glm::dvec3& lightPosition, int screenWidth, int screenHeight,
                 const EpipolarOptions& options = {});

  /// True for the layout of a local light (light rays from lightPosition()).
  bool localLight() const noexcept { return lightDistance_ > 0.0; }
  /// Local light: its position (the camera position plus D m); directional: the camera position.
  glm::dvec3 lightPosition() const noexcept { return camera_.position() + lightDistance_ * m_; }
  /// D = |L - c| (world units) for a local light, 0 for a directional one.
  double lightDistance() const noexcept { return lightDistance_; }

  int sliceCount() const noexcept { return static_cast<int>(slices_.size()); } ///< the map height H
  int screenWidth() const noexcept { return width_; }
  int screenHeight() const noexcept { return height_; }
  const EpipolarOptions& options() const noexcept { return options_; }
  const Camera& camera() const noexcept { return camera_; }
  /// The direction light travels at the camera (a local light's: (c - L) / D).
  const glm::dvec3& lightDirection() const noexcept { return l_; }
  const std::vector<Slice>& slices() const noexcept { return slices_; }

  EpipoleKind epipoleKind() const noexcept { return kind_; }
  /// NDC of the epipole (or anti-epipole); meaningless when AtInfinity.
  glm::dvec2 epipoleNdc() const noexcept { return epipoleNdc_; }
  /// The epipole (or anti-epipole) lies on the screen (|x|, |y| <= 1 in NDC).
  bool epipoleOnScreen() const noexcept;
  /// Pixel coordinates of the epipole (origin at the bottom-left corner, pixel centres at + 0.5), when not
  /// AtInfinity.
  std::optional<glm::dvec2> epipolePixel() const;
  /// Indices y * w + x of the pixels whose centre is within epipoleBlockRadius * diagonal of the epipole or
  /// anti-epipole (empty when it is at infinity or the block misses the screen).
  std::vector<int> epipoleBlockPixels() const;
  /// The block radius in pixels: epipoleBlockRadius * diagonal, shrunk by maxBlockPixels (see there).
  double epipoleBlockRadiusPixels() const;
  /// Pixel centres on screen within `radius` pixels of the epipole (0 when it is at infinity).
  long long blockPixelCount(double radius) const;

  double perimeter() const noexcept { return 2.0 * (width_ + height_); } ///< P, border pixels
  double arcBegin() const noexcept { return arcBegin_; }                 ///< sigma of row 0
  double arcLength() const noexcept { return arcLength_; } ///< border pixels covered by the rows
  /// Exit sides (bit s for side s: 0 left, 1 bottom, 2 right, 3 top).
  int exitSides() const noexcept { return exitSides_; }
  /// NDC point of the border at sigma (any real; taken modulo P).
  glm::dvec2 borderPoint(double sigma) const;
  /// sigma of a border point given in NDC (the nearest side).
  double borderSigma(const glm::dvec2& ndc) const;
  /// The border sigma of a normalized row.
  double rowSigma(double row) const;
  /// The unit direction orthogonal to the light of the slice at a normalized row.
  glm::dvec3 sliceDirection(double row) const;
  /// Texel row j of a normalized row: clamp(floor(row H), 0, H - 1).
  int sliceIndex(double row) const;
  /// The psi of a normalized depth in slice row j, and the normalized depth of psi in it.
  double psi(int slice, double depth) const;
  double depthOfPsi(int slice, double psi) const;
  /// The depth warp g(psi) (see top; psi itself when options().depthWarp == 0) and its inverse.
  double warp(double psi) const;
  double unwarp(double g) const;
  /// The region boundaries f_0 = 0, ..., f_K = 1 in b / bMax (see top).
  const std::vector<double>& regionFractions() const noexcept { return fractions_; }
  /// b / bMax of a normalized column, and its inverse.
  double columnFraction(double column) const;
  double fractionColumn(double fraction) const;

  // RectifiedLayout (see rectified_map.h; conventions at the top of this file).
  int regionCount() const override { return options_.regions; }
  glm::dvec3 origin() const override { return camera_.position(); }
  /// Throws InvalidArgument for points on the light axis (b = 0) or whose half-plane has no visible part.
  RectPoint toRectified(const glm::dvec3& world) const override;
  LightRay lightRay(double column, double row) const override;
  glm::dvec3 viewRayDirection(double row, double depth) const override;
  double rayDistance(double row, double depth, double column) const override;
  double referenceDistance(double row, double column) const override;
  double referenceDepth(double row) const override;
  DistanceProfile rayProfile(double row, double depth, int region) const override;
  DistanceProfile referenceProfile(double row, int region) const override;
  /// Local light: the row's reference ray when it reaches the region's far end with a margin (psi <= 3/4
  /// (pi - theta_(k+1))), else the ray of angle 1/2 (pi - theta_(k+1)) (clamped to the row's rays and >=
  /// 1e-3): the row's rays closest to the light reach furthest, and the exact weights of a ray that meets
  /// the region's far light rays near its horizon vanish there. Directional: referenceDepth(row).
  double regionReferenceDepth(double row, int region) const override;
  std::optional<GpuLayoutData> gpuLayoutData() const override;
  std::optional<glm::dvec3> localLightPosition() const override {
    return localLight() ? std::optional<glm::dvec3>(lightPosition()) : std::nullopt;
  }

  /// The visible psi interval of the half-plane with unit in-plane direction n (orthogonal to the light)
  /// and the border sigma of its exit point; nullopt when no part of it is on screen.
  struct HalfPlaneView {
    double psiLo = 0.0, psiHi = 0.0, exitSigma = 0.0;
  };
  std::optional<HalfPlaneView> viewOfHalfPlane(const glm::dvec3& n) const;

private:
  glm::dvec3
  image(const glm::dvec3& w) const; ///< homogeneous image point (x tX, y tY, forward) of a direction
  glm::dvec3 borderDirection(double sigma) const;
  double rowOfSigma(double sigma) const;
  void init();
  void buildSlices();
  /// Local light: theta of a point q - c (see top), and the column <-> theta mapping of slice j.
  double thetaOf(const glm::dvec3& q) const;
  double columnTheta(int slice, double column) const;
  double thetaColumn(int slice, double theta, int& region, double& u) const;
  /// Local light: mid angle and tan of the half width of region k in slice j.
  glm::dvec2 regionAngles(int slice, int region) const;

  Camera camera_;
  glm::dvec3 l_, m_;
  double lightDistance_ = 0.0; ///< D, 0 for a directional light
  int width_, height_;
  EpipolarOptions options_;
  double tanX_ = 0.0, tanY_ = 0.0;
  EpipoleKind kind_ = EpipoleKind::Epipole;
  glm::dvec3 vanishing_{0.0}; ///< homogeneous epipole V (V.z >= 0)
  glm::dvec2 epipoleNdc_{0.0};
  bool exitAtHigh_ = true; ///< exit = psiHi (Epipole, AtInfinity) or psiLo (AntiEpipole)
  int exitSides_ = 0;
  double arcBegin_ = 0.0, arcLength_ = 0.0;
  std::vector<Slice> slices_;
  std::vector<double> fractions_;
};

} // namespace crep
