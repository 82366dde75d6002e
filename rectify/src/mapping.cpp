// Mapping helpers of a projective rectification: world <-> (split, column, row, depth), light and view
// rays, world distances along view rays (closed form), reference rays (Klehm et al. 2014, Sec. 3.2) and
// the Eq. 12 step factor. Formulas at the top of crep/rectify/rectify.h.
#include <crep/core/error.h>
#include <crep/rectify/rectify.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace crep {

namespace {

std::string vecString(const glm::dvec3& v) {
  return "(" + detail::formatValue(v.x) + ", " + detail::formatValue(v.y) + ", " + detail::formatValue(v.z) +
         ")";
}

void requireProjective(const Rectification& r) {
  if (!r.projective() || r.splits.empty())
    throw InvalidArgument("Rectification.status", statusToken(r.status),
                          "the mapping helpers need a projective rectification");
}

double rowSlope(const RectifiedFrame& f, double row) {
  return f.rowSlopeMin + row * (f.rowSlopeMax - f.rowSlopeMin);
}
double depthSlope(const RectifiedFrame& f, double depth) {
  return f.depthSlopeMin + depth * (f.depthSlopeMax - f.depthSlopeMin);
}

/// zeta of a global column (the end splits extrapolate beyond [0, 1]).
double zetaOfColumn(const Rectification& r, double column) {
  const int K = r.splitCount();
  const double scaled = column * K;
  const int k = std::clamp(static_cast<int>(std::floor(scaled)), 0, K - 1);
  const double u = scaled - k;
  const Split& s = r.splits[static_cast<std::size_t>(k)];
  return s.zetaBegin + u * (s.zetaEnd - s.zetaBegin);
}

/// 1 / X of the point with column parameter zeta on the view ray of depth slope z (> 0 if it exists).
double inverseX(const RectifiedFrame& f, double zeta, double z) {
  return zeta - f.inverseLightDistance * z;
}

} // namespace

RectPoint Rectification::toRectified(const glm::dvec3& world) const {
  requireProjective(*this);
  const RectifiedFrame& f = frame;
  const glm::dvec3 d = world - f.origin;
  const double X = glm::dot(f.axisX, d), Y = glm::dot(f.axisY, d), Z = glm::dot(f.axisZ, d);
  if (!(X > 0.0) || !std::isfinite(X) || !std::isfinite(Y) || !std::isfinite(Z))
    throw InvalidArgument("Rectification.toRectified.world", vecString(world),
                          "must be finite and in front of the rectification (X > 0)");
  const double y = Y / X, z = Z / X;
  // zeta = (1 + rho Z) / X with 1 + rho Z = rho dot(axisZ, p - L) (precise next to the light).
  const double rho = f.inverseLightDistance;
  const double zeta = rho == 0.0 ? 1.0 / X : rho * glm::dot(f.axisZ, world - f.lightPosition) / X;
  RectPoint p;
  p.row = (y - f.rowSlopeMin) / (f.rowSlopeMax - f.rowSlopeMin);
  p.depth = (z - f.depthSlopeMin) / (f.depthSlopeMax - f.depthSlopeMin);
  // Split k covers zeta in [zetaEnd, zetaBegin]; on a shared boundary take the lower split.
  const int K = splitCount();
  int k = 0;
  while (k < K - 1 && zeta < splits[static_cast<std::size_t>(k)].zetaEnd)
    ++k;
  const Split& s = splits[static_cast<std::size_t>(k)];
  p.split = k;
  p.splitColumn = (s.zetaBegin - zeta) / (s.zetaBegin - s.zetaEnd);
  p.column = (k + p.splitColumn) / K;
  return p;
}

glm::dvec3 Rectification::toWorld(double column, double row, double depth) const {
  requireProjective(*this);
  requireFinite("Rectification.toWorld.column", column);
  requireFinite("Rectification.toWorld.row", row);
  requireFinite("Rectification.toWorld.depth", depth);
  const RectifiedFrame& f = frame;
  const double y = rowSlope(f, row), z = depthSlope(f, depth);
  const double den = inverseX(f, zetaOfColumn(*this, column), z);
  if (!(den > 0.0))
    throw InvalidArgument("Rectification.toWorld.column", detail::formatValue(column),
                          "no world point has this column at depth " + detail::formatValue(depth) +
                              " (beyond that view ray's horizon)");
  const double X = 1.0 / den;
  return f.origin + X * (f.axisX + y * f.axisY + z * f.axisZ);
}

LightRay Rectification::lightRay(double column, double row) const {
  requireProjective(*this);
  requireFinite("Rectification.lightRay.column", column);
  requireFinite("Rectification.lightRay.row", row);
  const RectifiedFrame& f = frame;
  const double y = rowSlope(f, row), zeta = zetaOfColumn(*this, column);
  const double rho = f.inverseLightDistance;
  if (rho == 0.0) {
    if (!(zeta > 0.0))
      throw InvalidArgument("Rectification.lightRay.column", detail::formatValue(column),
                            "beyond the far end of the map");
    const double X = 1.0 / zeta;
    return {f.origin + X * (f.axisX + y * f.axisY), f.axisZ};
  }
  // Point light at L: the points L + X (axisX + y axisY + (zeta / rho) axisZ), X >= 0.
  const glm::dvec3 dir = f.axisX + y * f.axisY + (zeta / rho) * f.axisZ;
  return {f.lightPosition, glm::normalize(dir)};
}

glm::dvec3 Rectification::viewRayDirection(double row, double depth) const {
  requireProjective(*this);
  const RectifiedFrame& f = frame;
  return glm::normalize(f.axisX + rowSlope(f, row) * f.axisY + depthSlope(f, depth) * f.axisZ);
}

double Rectification::rayDistance(double row, double depth, double column) const {
  requireProjective(*this);
  const RectifiedFrame& f = frame;
  const double y = rowSlope(f, row), z = depthSlope(f, depth);
  const double den = inverseX(f, zetaOfColumn(*this, column), z);
  if (!(den > 0.0)) return std::numeric_limits<double>::infinity();
  return std::sqrt(1.0 + y * y + z * z) / den;
}

RowReference Rectification::rowReference(double row) const {
  return rowReference(row, referenceRay);
}

RowReference Rectification::rowReference(double row, ReferenceRay choice) const {
  requireProjective(*this);
  requireFinite("Rectification.rowReference.row", row);
  const RectifiedFrame& f = frame;
  // The row's view rays: the slope hull cut by the line y = const (clamped onto the hull).
  double hy0 = std::numeric_limits<double>::infinity(), hy1 = -hy0;
  for (const auto& p : slopeHull) {
    hy0 = std::min(hy0, p.x);
    hy1 = std::max(hy1, p.x);
  }
  const double y = std::clamp(rowSlope(f, row), hy0, hy1);
  double zLo = std::numeric_limits<double>::infinity(), zHi = -zLo;
  const std::size_t n = slopeHull.size();
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec2 a = slopeHull[i], b = slopeHull[(i + 1) % n];
    if ((a.x - y) * (b.x - y) > 0.0) continue;
    if (a.x == b.x) {
      zLo = std::min({zLo, a.y, b.y});
      zHi = std::max({zHi, a.y, b.y});
    } else {
      const double t = std::clamp((y - a.x) / (b.x - a.x), 0.0, 1.0);
      const double z = a.y + t * (b.y - a.y);
      zLo = std::min(zLo, z);
      zHi = std::max(zHi, z);
    }
  }
  if (!(zLo <= zHi)) zLo = zHi = 0.5 * (f.depthSlopeMin + f.depthSlopeMax); // unreachable for a valid hull

  // Signed in-slice angles from the direction orthogonal to the light: tan(theta) = z / sqrt(1 + y^2);
  // k = cos(theta) (Sec. 3.2), the world step per texel is proportional to 1 / k.
  const double h = std::sqrt(1.0 + y * y);
  const double tLo = std::atan(zLo / h), tHi = std::atan(zHi / h);
  double tA, tB; // tA: w_min (largest k, smallest step), tB: w_max (smallest k, largest step)
  if (tLo <= 0.0 && tHi >= 0.0) {
    tA = 0.0;
    tB = -tLo > tHi ? tLo : tHi;
  } else if (tLo > 0.0) {
    tA = tLo;
    tB = tHi;
  } else {
    tA = tHi;
    tB = tLo;
  }
  RowReference ref;
  ref.row = row;
  ref.kMax = std::cos(tA);
  ref.kMin = std::cos(tB);
  double tRef;
  if (choice == ReferenceRay::Optimal) {
    // k_ref = sqrt(k_min k_max) (Sec. 3.2); the ray lies between w_min and w_max, on tB's side.
    ref.kRef = std::sqrt(ref.kMin * ref.kMax);
    tRef = std::copysign(std::acos(std::min(1.0, ref.kRef)), tB == 0.0 ? 1.0 : tB);
  } else {
    tRef = 0.5 * (tA + tB);
    ref.kRef = std::cos(tRef);
  }
  const double zRef = h * std::tan(tRef);
  const double zRange = f.depthSlopeMax - f.depthSlopeMin;
  ref.depthLo = (zLo - f.depthSlopeMin) / zRange;
  ref.depthHi = (zHi - f.depthSlopeMin) / zRange;
  ref.depth = (zRef - f.depthSlopeMin) / zRange;
  ref.direction = glm::normalize(f.axisX + y * f.axisY + zRef * f.axisZ);
  ref.ratioMin = ref.kRef / ref.kMax;
  ref.ratioMax = ref.kRef / ref.kMin;
  return ref;
}

double Rectification::referenceDistance(double row, double column) const {
  return rayDistance(row, rowReference(row).depth, column);
}

double Rectification::texelStepRatio(double row, int split, int texelsPerSplit) const {
  requireProjective(*this);
  if (split < 0 || split >= splitCount())
    throw InvalidArgument("Rectification.texelStepRatio.split", detail::formatValue(split),
                          "must be in [0, " + std::to_string(splitCount()) + ")");
  if (texelsPerSplit < 3)
    throw InvalidArgument("Rectification.texelStepRatio.texelsPerSplit", detail::formatValue(texelsPerSplit),
                          "must be >= 3");
  const double depth = rowReference(row).depth;
  const int K = splitCount();
  double t[3];
  for (int i = 0; i < 3; ++i)
    t[i] = rayDistance(row, depth, (split + (i + 0.5) / texelsPerSplit) / K);
  return (t[2] - t[1]) / (t[1] - t[0]);
}

SplitViewport Rectification::splitViewport(int split, int width, int height) const {
  requireProjective(*this);
  const int K = splitCount();
  if (split < 0 || split >= K)
    throw InvalidArgument("Rectification.splitViewport.split", detail::formatValue(split),
                          "must be in [0, " + std::to_string(K) + ")");
  if (width <= 0)
    throw InvalidArgument("Rectification.splitViewport.width", detail::formatValue(width), "must be > 0");
  if (height <= 0)
    throw InvalidArgument("Rectification.splitViewport.height", detail::formatValue(height), "must be > 0");
  if (layout == SplitLayout::Layers) return {split, 0, 0, width, height};
  if (width % K != 0)
    throw InvalidArgument("Rectification.splitViewport.width", detail::formatValue(width),
                          "must be a multiple of the split count " + std::to_string(K) + " (Regions layout)");
  const int w = width / K;
  return {0, split * w, 0, w, height};
}

} // namespace crep
