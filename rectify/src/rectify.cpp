// Projective rectification: construction and fallback decision.
// Klehm, Seidel, Eisemann 2014, "Filter-based real-time single scattering using rectified shadow maps",
// JCGT 3(3), Sec. 4.2 (light view along the bisectrix, projection along X with the camera as centre,
// depth clamping, splits), Sec. 3.2 (spot lights via their perspective space, point lights as faces).
// The formulas are summarized at the top of crep/rectify/rectify.h.
#include <crep/core/error.h>
#include <crep/rectify/rectify.h>

#include "region.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

namespace crep {

using rectify_detail::Pyramid;

const char* reasonToken(FallbackReason reason) {
  switch (reason) {
  case FallbackReason::None:
    return "none";
  case FallbackReason::ViewRayParallelToLight:
    return "view-ray-parallel-to-light";
  case FallbackReason::NonLinearity:
    return "non-linearity";
  case FallbackReason::EpipoleTooClose:
    return "epipole-too-close";
  case FallbackReason::EmptyRegion:
    return "empty-region";
  }
  return "unknown";
}

const char* statusToken(RectifyStatus status) {
  switch (status) {
  case RectifyStatus::Projective:
    return "projective";
  case RectifyStatus::Fallback:
    return "fallback";
  case RectifyStatus::Empty:
    return "empty";
  }
  return "unknown";
}

glm::dmat4 RectifiedFrame::frameFromWorld() const {
  glm::dmat4 m(1.0);
  for (int i = 0; i < 3; ++i) {
    m[i][0] = axisX[i];
    m[i][1] = axisY[i];
    m[i][2] = axisZ[i];
  }
  m[3][0] = -glm::dot(axisX, origin);
  m[3][1] = -glm::dot(axisY, origin);
  m[3][2] = -glm::dot(axisZ, origin);
  return m;
}

void validate(const RectifyOptions& o) {
  if (o.splits < 1 || o.splits > RectifyOptions::kMaxSplits)
    throw InvalidArgument("RectifyOptions.splits", detail::formatValue(o.splits),
                          "must be in [1, " + std::to_string(RectifyOptions::kMaxSplits) + "]");
  if (!std::isfinite(o.blend) || o.blend < 0.0 || o.blend > 1.0)
    throw InvalidArgument("RectifyOptions.blend", detail::formatValue(o.blend), "must be in [0, 1]");
  if (!std::isfinite(o.maxSpanDegrees) || !(o.maxSpanDegrees > 0.0) || o.maxSpanDegrees > 180.0)
    throw InvalidArgument("RectifyOptions.maxSpanDegrees", detail::formatValue(o.maxSpanDegrees),
                          "degrees, must be in (0, 180]");
  switch (o.scheme) {
  case SplitScheme::Uniform:
  case SplitScheme::Logarithmic:
  case SplitScheme::Blend:
    break;
  default:
    throw InvalidArgument("RectifyOptions.scheme", detail::formatValue(static_cast<int>(o.scheme)),
                          "must be Uniform, Logarithmic or Blend");
  }
  if (!std::isfinite(o.minEpipoleAngleDegrees) || o.minEpipoleAngleDegrees < 0.0 ||
      o.minEpipoleAngleDegrees >= 90.0)
    throw InvalidArgument("RectifyOptions.minEpipoleAngleDegrees",
                          detail::formatValue(o.minEpipoleAngleDegrees), "degrees, must be in [0, 90)");
  if (o.layout != SplitLayout::Regions && o.layout != SplitLayout::Layers)
    throw InvalidArgument("RectifyOptions.layout", detail::formatValue(static_cast<int>(o.layout)),
                          "must be Regions or Layers");
  if (o.referenceRay != ReferenceRay::Bisectrix && o.referenceRay != ReferenceRay::Optimal)
    throw InvalidArgument("RectifyOptions.referenceRay",
                          detail::formatValue(static_cast<int>(o.referenceRay)),
                          "must be Bisectrix or Optimal");
}

std::vector<double> splitPositions(double xmin, double xmax, int splits, SplitScheme scheme, double blend) {
  requirePositive("splitPositions.xmin", xmin);
  if (!std::isfinite(xmax) || !(xmax > xmin))
    throw InvalidArgument("splitPositions.xmax", detail::formatValue(xmax), "must be finite and > xmin");
  RectifyOptions o;
  o.splits = splits;
  o.scheme = scheme;
  o.blend = blend;
  validate(o);
  // x_j = xmin (1 + g_j) with relative offsets g_j, exact at both ends.
  const double q = (xmax - xmin) / xmin, logRatio = std::log1p(q);
  const double lambda = scheme == SplitScheme::Uniform       ? 0.0
                        : scheme == SplitScheme::Logarithmic ? 1.0
                                                             : blend;
  std::vector<double> x(static_cast<std::size_t>(splits) + 1);
  for (int j = 1; j < splits; ++j) {
    const double t = static_cast<double>(j) / splits;
    x[static_cast<std::size_t>(j)] =
        xmin * (1.0 + lambda * std::expm1(logRatio * t) + (1.0 - lambda) * q * t);
  }
  x.front() = xmin;
  x.back() = xmax;
  return x;
}

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = 180.0 / std::numbers::pi;

Pyramid cameraPyramid(const Camera& camera) {
  Pyramid p;
  p.apex = camera.position();
  p.axis = camera.forward();
  const glm::dvec4& t = camera.tangents(); // left, right, bottom, top at unit distance (off-centre too)
  const glm::dvec3 r = camera.right(), u = camera.up();
  // Same corner order as Camera::frustumCorners: (-x,-y), (+x,-y), (+x,+y), (-x,+y).
  const double sx[4] = {t.x, t.y, t.y, t.x}, sy[4] = {t.z, t.z, t.w, t.w};
  for (unsigned i = 0; i < 4; ++i)
    p.edges[i] = p.axis + sx[i] * r + sy[i] * u;
  p.near = camera.near();
  p.far = camera.far();
  return p;
}

Pyramid lightPyramid(const glm::dvec3& apex, const glm::dvec3& axis, const glm::dvec3& right,
                     const glm::dvec3& up, double tanHalf, double near, double far) {
  Pyramid p;
  p.apex = apex;
  p.axis = axis;
  const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
  for (unsigned i = 0; i < 4; ++i)
    p.edges[i] = axis + sx[i] * tanHalf * right + sy[i] * tanHalf * up;
  p.near = near;
  p.far = far;
  return p;
}

std::string fmt(const char* format, double a, double b = 0.0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, format, a, b);
  return buf;
}

/// Smallest angle between the light line (the frame's Z axis, either direction) and a view ray of the
/// region: the minimum of tan^2(angle) = (1 + y^2) / z^2 over the slope hull. Its sublevel sets are
/// convex on each side of z = 0, so along a hull edge (split at z = 0) it is quasi-convex.
double epipoleAngle(const std::vector<glm::dvec2>& hull) {
  const auto tan2 = [](const glm::dvec2& p) {
    return p.y == 0.0 ? std::numeric_limits<double>::infinity() : (1.0 + p.x * p.x) / (p.y * p.y);
  };
  double best = std::numeric_limits<double>::infinity();
  const std::size_t n = hull.size();
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec2 a = hull[i], b = hull[(i + 1) % n];
    best = std::min({best, tan2(a), tan2(b)});
    std::array<std::pair<glm::dvec2, glm::dvec2>, 2> parts{{{a, b}, {b, b}}};
    if ((a.y < 0.0 && b.y > 0.0) || (a.y > 0.0 && b.y < 0.0)) {
      const glm::dvec2 m = a + (b - a) * (a.y / (a.y - b.y));
      parts = {{{a, m}, {m, b}}};
    }
    for (const auto& [p, q] : parts) {
      double lo = 0.0, hi = 1.0;
      for (int it = 0; it < 100 && hi - lo > 1e-15; ++it) { // golden section on a quasi-convex function
        const double m1 = lo + 0.381966011250105 * (hi - lo), m2 = hi - 0.381966011250105 * (hi - lo);
        if (tan2(p + m1 * (q - p)) < tan2(p + m2 * (q - p)))
          hi = m2;
        else
          lo = m1;
      }
      best = std::min(best, tan2(p + 0.5 * (lo + hi) * (q - p)));
    }
  }
  return std::atan(std::sqrt(best));
}

/// Fractions f_j in [0, 1] of the zeta range at the split boundaries (f_0 = 0 at zetaMax, f_K = 1 at
/// zetaMin), for boundaries placed in xh = 1 / (zeta + offset) by the scheme. Written with the relative
/// offsets g_j = x_j / x_0 - 1 so that a very narrow or very wide range loses no precision.
std::vector<double> splitFractions(double zetaMax, double zetaMin, double offset, const RectifyOptions& o) {
  const int K = o.splits;
  const double q = (zetaMax - zetaMin) / (zetaMin + offset); // x_K / x_0 - 1
  const double logRatio = std::log1p(q);
  const double lambda = o.scheme == SplitScheme::Uniform       ? 0.0
                        : o.scheme == SplitScheme::Logarithmic ? 1.0
                                                               : o.blend;
  std::vector<double> f(static_cast<std::size_t>(K) + 1);
  f.front() = 0.0;
  f.back() = 1.0;
  for (int j = 1; j < K; ++j) {
    const double t = static_cast<double>(j) / K;
    const double g = lambda * std::expm1(logRatio * t) + (1.0 - lambda) * q * t;
    double fj = (g / (1.0 + g)) * ((1.0 + q) / q);
    if (!(fj > f[static_cast<std::size_t>(j) - 1]) || !(fj < 1.0)) fj = t; // rounding on a degenerate range
    f[static_cast<std::size_t>(j)] = fj;
  }
  return f;
}

/// The region's angles (degrees) known when a result is made: see Rectification::span and epipoleAngle.
struct RegionAngles {
  double span = 0.0;
  double epipoleAngle = 0.0;
};

/// The fields every result carries: the region, the options' layout and reference ray, and
/// maxSpanDegrees as the threshold.
Rectification baseResult(const std::vector<glm::dvec3>& region, const RectifyOptions& options) {
  Rectification r;
  r.threshold = options.maxSpanDegrees;
  r.layout = options.layout;
  r.referenceRay = options.referenceRay;
  r.regionVertices = region;
  return r;
}

/// The one constructor of non-projective results: status Empty for FallbackReason::EmptyRegion, else
/// Fallback, with the measure that decided, its threshold, the message and the angles known so far;
/// frame, splits and slope hull stay empty.
Rectification fallbackResult(FallbackReason reason, double measure, double threshold, std::string message,
                             RegionAngles angles, const std::vector<glm::dvec3>& region,
                             const RectifyOptions& options) {
  Rectification r = baseResult(region, options);
  r.status = reason == FallbackReason::EmptyRegion ? RectifyStatus::Empty : RectifyStatus::Fallback;
  r.reason = reason;
  r.message = std::move(message);
  r.measure = measure;
  r.threshold = threshold;
  r.span = angles.span;
  r.epipoleAngle = angles.epipoleAngle;
  return r;
}

/// The directions of the region's vertices seen from the camera and projected along the light, and the
/// smallest sector holding them (Klehm et al. 2014, Sec. 4.2: "find the 2D vectors ... that span the
/// biggest angle"). Angles are in radians in the basis (b1, b2) of the plane orthogonal to the light.
struct ProjectedSector {
  glm::dvec3 b1{0.0}, b2{0.0};
  double start = 0.0, span = 0.0; ///< the sector [start, start + span]
  /// Not inside an open half-plane (up to rounding): some view ray through the region is a light ray.
  bool impossible = false;
};

/// Klehm et al. 2014, Sec. 4.2: the sector of the region's projected view directions. Any basis of
/// the plane will do: the bisectrix does not depend on it, so the result is continuous in the light
/// direction.
ProjectedSector projectedSector(const glm::dvec3& c, const std::vector<glm::dvec3>& region,
                                const glm::dvec3& lightDir) {
  ProjectedSector s;
  s.b1 = anyOrthogonal(lightDir);
  s.b2 = glm::cross(lightDir, s.b1);
  std::vector<double> angles;
  angles.reserve(region.size());
  bool onLightLine = false;
  for (const auto& v : region) {
    const glm::dvec3 d = v - c;
    const double q1 = glm::dot(d, s.b1), q2 = glm::dot(d, s.b2);
    // A vertex on the camera's light line: its view ray is a light ray (relative 1e-12 ~ rounding).
    if (!(std::hypot(q1, q2) > 1e-12 * glm::length(d))) {
      onLightLine = true;
      break;
    }
    angles.push_back(std::atan2(q2, q1));
  }
  s.span = kPi;
  s.start = 0.0;
  if (!onLightLine) {
    std::sort(angles.begin(), angles.end());
    // The largest circular gap between consecutive directions; the span is its complement.
    double gap = angles.front() + 2.0 * kPi - angles.back();
    s.start = angles.front();
    for (std::size_t i = 1; i < angles.size(); ++i) {
      const double g = angles[i] - angles[i - 1];
      if (g > gap) {
        gap = g;
        s.start = angles[i];
      }
    }
    s.span = 2.0 * kPi - gap;
  }
  s.impossible = onLightLine || s.span >= kPi * (1.0 - 1e-12);
  return s;
}

/// Klehm et al. 2014, Sec. 4.2: the rectified light view, X along the sector's bisectrix (orthogonal
/// to the light), Z along the light, Y = Z x X; its bounds are set later (frameBounds).
RectifiedFrame bisectrixFrame(const glm::dvec3& c, const glm::dvec3& lightDir, const ProjectedSector& sector,
                              double rho, const glm::dvec3& lightPos) {
  const double mid = sector.start + 0.5 * sector.span;
  RectifiedFrame f;
  f.origin = c;
  f.axisZ = lightDir;
  f.axisX = glm::normalize(std::cos(mid) * sector.b1 + std::sin(mid) * sector.b2);
  f.axisY = glm::cross(f.axisZ, f.axisX);
  f.inverseLightDistance = rho;
  f.lightPosition = lightPos;
  return f;
}

/// Bounds of the row slope y, the depth slope z and the column parameter zeta over the region's
/// vertices, and their (y, z) slopes.
struct SlopeBounds {
  double yMin, yMax, zMin, zMax, zetaMin, zetaMax;
  std::vector<glm::dvec2> slopes;
};

/// The region's bounds in the frame from the *slopes* of its vertices (the camera is the centre of
/// projection, Klehm et al. 2014, Sec. 4.2), and of zeta.
SlopeBounds slopeBounds(const RectifiedFrame& f, const std::vector<glm::dvec3>& region) {
  const double inf = std::numeric_limits<double>::infinity();
  const double rho = f.inverseLightDistance;
  SlopeBounds b{inf, -inf, inf, -inf, inf, -inf, {}};
  b.slopes.reserve(region.size());
  for (const auto& v : region) {
    const glm::dvec3 d = v - f.origin;
    const double X = glm::dot(f.axisX, d), Y = glm::dot(f.axisY, d), Z = glm::dot(f.axisZ, d);
    const double y = Y / X, z = Z / X;
    // 1 + rho Z = rho dot(axisZ, p - L), evaluated from L for precision next to the light.
    const double zeta = rho == 0.0 ? 1.0 / X : rho * glm::dot(f.axisZ, v - f.lightPosition) / X;
    b.slopes.emplace_back(y, z);
    b.yMin = std::min(b.yMin, y);
    b.yMax = std::max(b.yMax, y);
    b.zMin = std::min(b.zMin, z);
    b.zMax = std::max(b.zMax, z);
    b.zetaMin = std::min(b.zetaMin, zeta);
    b.zetaMax = std::max(b.zetaMax, zeta);
  }
  return b;
}

/// True when the region is flat in y, z or zeta up to rounding. Only a spot/point region can be flat
/// (the frusta touch along a face, an edge or a point).
bool isFlat(const SlopeBounds& b) {
  const double yScale = 1.0 + std::max(std::abs(b.yMin), std::abs(b.yMax));
  const double zScale = 1.0 + std::max(std::abs(b.zMin), std::abs(b.zMax));
  const double zetaScale = std::max(std::abs(b.zetaMin), std::abs(b.zetaMax));
  return !(b.yMax - b.yMin > 1e-12 * yScale) || !(b.zMax - b.zMin > 1e-12 * zScale) ||
         !(b.zetaMax - b.zetaMin > 1e-12 * zetaScale);
}

/// Stores the bounds in the frame and returns the offset -rho zMin of xh = 1 / (zeta + offset), which
/// is > 0 on the region.
double frameBounds(RectifiedFrame& f, const SlopeBounds& b) {
  f.rowSlopeMin = b.yMin;
  f.rowSlopeMax = b.yMax;
  f.depthSlopeMin = b.zMin;
  f.depthSlopeMax = b.zMax;
  const double offset = -f.inverseLightDistance * b.zMin;
  f.axisMin = 1.0 / (b.zetaMax + offset);
  f.axisMax = 1.0 / (b.zetaMin + offset);
  return offset;
}

/// Klehm et al. 2014, Sec. 4.2 "Non-linearity": the K splits of a bounded frame, sharing the row and
/// depth slopes, each with its own column projection.
std::vector<Split> splitProjections(const RectifiedFrame& f, const SlopeBounds& b, double offset,
                                    const RectifyOptions& options) {
  const int K = options.splits;
  const double rho = f.inverseLightDistance;
  const std::vector<double> frac = splitFractions(b.zetaMax, b.zetaMin, offset, options);
  std::vector<double> zeta(frac.size());
  for (std::size_t j = 0; j < frac.size(); ++j)
    zeta[j] = b.zetaMax - frac[j] * (b.zetaMax - b.zetaMin);
  zeta.front() = b.zetaMax;
  zeta.back() = b.zetaMin;
  const glm::dmat4 frameFromWorld = f.frameFromWorld();
  const double alpha = 2.0 / (b.yMax - b.yMin), beta = -1.0 - alpha * b.yMin;
  const double gamma = 2.0 / (b.zMax - b.zMin), delta = -1.0 - gamma * b.zMin;
  std::vector<Split> splits(static_cast<std::size_t>(K));
  for (int k = 0; k < K; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    Split& s = splits[ku];
    s.zetaBegin = zeta[ku];
    s.zetaEnd = zeta[ku + 1];
    s.rangeBegin = k == 0 ? f.axisMin : splits[ku - 1].rangeEnd;
    s.rangeEnd = k == K - 1 ? f.axisMax : 1.0 / (s.zetaEnd + offset);
    const double bz = 2.0 / (s.zetaEnd - s.zetaBegin), a = -1.0 - bz * s.zetaBegin; // ndc.x = a + bz zeta
    glm::dmat4 S(0.0); // frame (X, Y, Z, 1) -> clip; S[column][row]
    S[0][0] = a;
    S[2][0] = bz * rho;
    S[3][0] = bz;
    S[0][1] = beta;
    S[1][1] = alpha;
    S[0][2] = delta;
    S[2][2] = gamma;
    S[0][3] = 1.0;
    s.rectClipFromWorld = S * frameFromWorld;
    if (options.layout == SplitLayout::Regions) {
      s.layer = 0;
      s.columnBegin = static_cast<double>(k) / K;
      s.columnEnd = static_cast<double>(k + 1) / K;
    } else {
      s.layer = k;
      s.columnBegin = 0.0;
      s.columnEnd = 1.0;
    }
  }
  return splits;
}

/// The common construction (Klehm et al. 2014, Sec. 4.2). `region` are the vertices of the convex
/// region to cover, `lightDir` the direction light travels at the camera (unit), `rho` =
/// 1 / |camera - light| (0: directional) and `lightPos` the light's position (point-like lights only).
/// Decides in this order (crep/rectify/rectify.h, "Fallback decision"): empty, impossible, flat, too
/// non-linear, epipole too close.
Rectification build(const Camera& camera, const std::vector<glm::dvec3>& region, const glm::dvec3& lightDir,
                    double rho, const glm::dvec3& lightPos, const RectifyOptions& options, bool pointLike) {
  if (region.empty())
    return fallbackResult(FallbackReason::EmptyRegion, 0.0, options.maxSpanDegrees,
                          "the light's frustum does not intersect the camera frustum: nothing is lit", {},
                          region, options);

  const ProjectedSector sector = projectedSector(camera.position(), region, lightDir);
  if (sector.impossible)
    return fallbackResult(FallbackReason::ViewRayParallelToLight, 180.0, options.maxSpanDegrees,
                          pointLike ? "a view ray through the lit region passes through the light (the "
                                      "camera-light line crosses it): projective rectification impossible"
                                    : "a view ray is parallel to the light direction (epipole on screen): "
                                      "projective rectification impossible",
                          {180.0, 0.0}, region, options);
  RegionAngles angles{sector.span * kDeg, 0.0};

  RectifiedFrame f = bisectrixFrame(camera.position(), lightDir, sector, rho, lightPos);
  const SlopeBounds bounds = slopeBounds(f, region);
  if (isFlat(bounds))
    return fallbackResult(
        FallbackReason::EmptyRegion, 0.0, options.maxSpanDegrees,
        "the lit part of the camera frustum is flat (the frusta only touch): nothing is lit", angles, region,
        options);
  std::vector<glm::dvec2> hull = rectify_detail::convexHull(bounds.slopes);
  angles.epipoleAngle = epipoleAngle(hull) * kDeg;

  if (angles.span >= options.maxSpanDegrees)
    return fallbackResult(
        FallbackReason::NonLinearity, angles.span, options.maxSpanDegrees,
        fmt("angular span of the lit region around the light axis %.6g deg >= threshold %.6g deg: "
            "rectification too non-linear",
            angles.span, options.maxSpanDegrees),
        angles, region, options);
  if (angles.epipoleAngle < options.minEpipoleAngleDegrees)
    return fallbackResult(
        FallbackReason::EpipoleTooClose, angles.epipoleAngle, options.minEpipoleAngleDegrees,
        fmt("a view ray of the lit region is %.6g deg from the light line < threshold %.6g deg: "
            "step ratios too large",
            angles.epipoleAngle, options.minEpipoleAngleDegrees),
        angles, region, options);

  const double offset = frameBounds(f, bounds);
  Rectification r = baseResult(region, options);
  r.status = RectifyStatus::Projective;
  r.reason = FallbackReason::None;
  r.message =
      fmt("projective: angular span %.6g deg < %.6g deg", angles.span, options.maxSpanDegrees) +
      fmt(", epipole angle %.6g deg >= %.6g deg", angles.epipoleAngle, options.minEpipoleAngleDegrees);
  r.measure = angles.span;
  r.span = angles.span;
  r.epipoleAngle = angles.epipoleAngle;
  r.frame = f;
  r.splits = splitProjections(f, bounds, offset, options);
  r.slopeHull = std::move(hull);
  return r;
}

/// Klehm et al. 2014, Sec. 3.2: a spot light or point-light face, over the camera frustum intersected
/// with the light's frustum, in the perspective space centred at the light.
Rectification buildPointLike(const Camera& camera, const glm::dvec3& lightPos, const Pyramid& lightFrustum,
                             const RectifyOptions& options) {
  const Pyramid cam = cameraPyramid(camera);
  std::vector<glm::dvec3> region = rectify_detail::intersectionVertices(cam, lightFrustum);
  const glm::dvec3 toCamera = camera.position() - lightPos;
  const double dist = glm::length(toCamera);
  const double scale = std::max({1.0, glm::length(camera.position()), glm::length(lightPos)});
  if (!region.empty() && !(dist > 1e-12 * scale))
    return fallbackResult(FallbackReason::ViewRayParallelToLight, 180.0, options.maxSpanDegrees,
                          "the camera is at the light position: every view ray is a light ray", {180.0, 0.0},
                          region, options);
  const glm::dvec3 lightDir = dist > 0.0 ? toCamera / dist : lightFrustum.axis;
  return build(camera, region, lightDir, dist > 0.0 ? 1.0 / dist : 0.0, lightPos, options, true);
}

} // namespace

Rectification rectify(const Camera& camera, const DirectionalLight& light, const RectifyOptions& options) {
  validate(options);
  const auto corners = camera.frustumCorners();
  const std::vector<glm::dvec3> region(corners.begin(), corners.end());
  return build(camera, region, light.direction(), 0.0, glm::dvec3(0.0), options, false);
}

Rectification rectify(const Camera& camera, const SpotLight& light, const RectifyOptions& options) {
  validate(options);
  // The spot's shadow frustum, oriented exactly as its lightViewFromWorld (square, half angle coneAngle).
  const glm::dmat4 lightFromWorld = light.lightViewFromWorld();
  const glm::dmat3 worldFromLightRot = glm::transpose(glm::dmat3(lightFromWorld));
  const glm::dvec3 right = worldFromLightRot[0], up = worldFromLightRot[1], axis = -worldFromLightRot[2];
  const Pyramid frustum = lightPyramid(light.position(), axis, right, up, std::tan(light.coneAngle()),
                                       light.nearPlane(), light.range());
  return buildPointLike(camera, light.position(), frustum, options);
}

std::array<Rectification, 6> rectifyPointLight(const Camera& camera, const glm::dvec3& position, double range,
                                               const RectifyOptions& options, double nearPlane) {
  validate(options);
  requireFinite("PointLight.position", position);
  requirePositive("PointLight.range", range);
  const double near = nearPlane <= 0.0 ? range * 1e-3 : nearPlane;
  if (!std::isfinite(near) || !(near < range))
    throw InvalidArgument("PointLight.nearPlane", detail::formatValue(nearPlane), "must be < range");
  std::array<Rectification, 6> faces;
  for (int i = 0; i < 6; ++i) {
    glm::dvec3 axis(0.0);
    axis[i / 2] = (i % 2 == 0) ? 1.0 : -1.0;
    glm::dvec3 u(0.0), v(0.0);
    u[(i / 2 + 1) % 3] = 1.0;
    v[(i / 2 + 2) % 3] = 1.0;
    faces[static_cast<std::size_t>(i)] =
        buildPointLike(camera, position, lightPyramid(position, axis, u, v, 1.0, near, range), options);
  }
  return faces;
}

std::array<Rectification, 6> rectifyPointLight(const Camera& camera, const PointLight& light,
                                               const RectifyOptions& options) {
  return rectifyPointLight(camera, light.position(), light.range(), options, light.nearPlane());
}

} // namespace crep
