// The epipolar layout, the fallback when the projective rectification cannot be built (Klehm et al. 2014,
// Sec. 4.1; slices after Yusov 2012, Sec. 6.1, 6.6). CPU, double precision. Geometry, epipole, slices,
// map coordinates, local lights, epipole block: epipolar/README.md, "crep/epipolar/epipolar.h".
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
  /// Where the regions' boundaries f_k go in b / bMax (README).
  SplitScheme regionScheme = SplitScheme::Logarithmic;
  /// Reference ray of a row (Sec. 3.2), for the prefilter's weights.
  ReferenceRay referenceRay = ReferenceRay::Bisectrix;
  /// Epipole block radius, fraction of the screen diagonal, >= 0 (0 = no block); crep::Scattering's value.
  double epipoleBlockRadius = 0.06;
  /// Most pixels the block may hold on screen, >= 0 (0 = no bound); the radius shrinks to fit (README).
  int maxBlockPixels = 0;
  /// Depth warp e, radians, >= 0 (0 = linear in psi): depth linear in g = log((psi + e) / (pi - psi + e)).
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

/// The epipolar fallback layout for one camera, light and screen size (README).
class EpipolarLayout final : public RectifiedLayout {
public:
  /// One slice (texel row): its bounds.
  struct Slice {
    double bMax = 0.0;   ///< world units: column 1 is at this distance from the light axis
    double psiMin = 0.0; ///< radians: depth 0
    double psiMax = 0.0; ///< radians: depth 1
    glm::dvec3 direction{
        0.0}; ///< unit direction of the slice's half-plane orthogonal to the light (at the row centre)
    double thetaMax = 0.0; ///< local light: radians in (0, pi], the angle at the light of column 1
  };

  /// Throws InvalidArgument for screen sizes <= 0 or > Image::kMaxDimension ("EpipolarLayout.screenSize"),
  /// bad options, or more than kMaxEpipolarSlices slices.
  EpipolarLayout(const Camera& camera, const DirectionalLight& light, int screenWidth, int screenHeight,
                 const EpipolarOptions& options = {});

  /// The layout of a local light at `lightPosition`. Throws InvalidArgument as above, and naming
  /// "EpipolarLayout.lightPosition" (non-finite, at the camera) or "EpipolarOptions.regions" (< 2).
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
  /// Pixel coordinates of the epipole (origin bottom-left, centres at + 0.5); nullopt when AtInfinity.
  std::optional<glm::dvec2> epipolePixel() const;
  /// Indices y * w + x of the epipole block's pixels (empty at infinity or off screen). Per frame, O(block).
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
  /// The depth warp g(psi) (psi itself when options().depthWarp == 0) and its inverse.
  double warp(double psi) const;
  double unwarp(double g) const;
  /// The region boundaries f_0 = 0, ..., f_K = 1 in b / bMax.
  const std::vector<double>& regionFractions() const noexcept { return fractions_; }
  /// b / bMax of a normalized column, and its inverse.
  double columnFraction(double column) const;
  double fractionColumn(double fraction) const;

  // RectifiedLayout (see rectified_map.h).
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
  /// Directional: referenceDepth(row); local light: a ray that reaches the region's far end (README).
  double regionReferenceDepth(double row, int region) const override;
  std::optional<GpuLayoutData> gpuLayoutData() const override;
  std::optional<glm::dvec3> localLightPosition() const override {
    return localLight() ? std::optional<glm::dvec3>(lightPosition()) : std::nullopt;
  }

  /// Visible psi interval and exit sigma of the half-plane of unit direction n; nullopt when off screen.
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
  /// Local light: theta of a point q - c, and the column <-> theta mapping of slice j.
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
