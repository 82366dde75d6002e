// The RectifiedMap contract and the projective layout (rectified_map.h). Distances along view rays are
// the closed form of rectify.h ("The math"): s = sqrt(1 + y^2 + z^2) / (zeta - rho z), and zeta is
// linear in the column within a split, so s is a 1D projective function of that column (the weights of
// Klehm et al. 2014, Sec. 3.2, need it per row; the Sec. 4.2 splits are the regions).
#include <crep/core/error.h>
#include <crep/core/parallel.h>
#include <crep/rectify/rectified_map.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <string>
#include <thread>
#include <vector>

namespace crep {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double rowSlope(const RectifiedFrame& f, double row) {
  return f.rowSlopeMin + row * (f.rowSlopeMax - f.rowSlopeMin);
}
double depthSlope(const RectifiedFrame& f, double depth) {
  return f.depthSlopeMin + depth * (f.depthSlopeMax - f.depthSlopeMin);
}

std::string texelString(int x, int y) {
  return "texel (" + std::to_string(x) + ", " + std::to_string(y) + ")";
}

} // namespace

// ---------------------------------------------------------------------------------------------------
// DistanceProfile

double DistanceProfile::operator()(double u) const {
  const double den = c + d * u;
  if (!(den > 0.0)) return kInf;
  return (a + b * u) / den;
}

double DistanceProfile::fromStart(double u) const {
  const double den = c + d * u;
  if (!(den > 0.0) || !(c > 0.0)) return kInf;
  // (a + b u) / (c + d u) - a / c = u (b c - a d) / (c (c + d u)).
  return u * (b * c - a * d) / (c * den);
}

DistanceProfile DistanceProfile::sub(double u0, double u1) const {
  const double w = u1 - u0;
  return {a + b * u0, b * w, c + d * u0, d * w};
}

bool DistanceProfile::valid() const {
  return std::isfinite(a) && std::isfinite(b) && std::isfinite(c) && std::isfinite(d) && c > 0.0 &&
         c + d > 0.0 && a >= 0.0 && a + b >= 0.0;
}

// ---------------------------------------------------------------------------------------------------
// ProjectiveLayout

ProjectiveLayout::ProjectiveLayout(Rectification rectification) : rect_(std::move(rectification)) {
  if (!rect_.projective() || rect_.splits.empty())
    throw InvalidArgument("Rectification.status", statusToken(rect_.status),
                          "a ProjectiveLayout needs a projective rectification");
  if (rect_.layout != SplitLayout::Regions)
    throw InvalidArgument("Rectification.layout", "Layers",
                          "a RectifiedMap holds the splits side by side: use SplitLayout::Regions");
}

int ProjectiveLayout::regionCount() const {
  return rect_.splitCount();
}
glm::dvec3 ProjectiveLayout::origin() const {
  return rect_.frame.origin;
}
RectPoint ProjectiveLayout::toRectified(const glm::dvec3& world) const {
  return rect_.toRectified(world);
}
LightRay ProjectiveLayout::lightRay(double column, double row) const {
  return rect_.lightRay(column, row);
}
glm::dvec3 ProjectiveLayout::viewRayDirection(double row, double depth) const {
  return rect_.viewRayDirection(row, depth);
}
double ProjectiveLayout::rayDistance(double row, double depth, double column) const {
  return rect_.rayDistance(row, depth, column);
}
double ProjectiveLayout::referenceDistance(double row, double column) const {
  return rect_.referenceDistance(row, column);
}
double ProjectiveLayout::referenceDepth(double row) const {
  return rect_.rowReference(row).depth;
}

DistanceProfile ProjectiveLayout::rayProfile(double row, double depth, int region) const {
  const int K = regionCount();
  if (region < 0 || region >= K)
    throw InvalidArgument("ProjectiveLayout.region", detail::formatValue(region),
                          "must be in [0, " + std::to_string(K) + ")");
  if (!std::isfinite(row) || !std::isfinite(depth))
    throw InvalidArgument("ProjectiveLayout.rayProfile",
                          "row " + detail::formatValue(row) + ", depth " + detail::formatValue(depth),
                          "must be finite");
  const RectifiedFrame& f = rect_.frame;
  const double y = rowSlope(f, row), z = depthSlope(f, depth);
  const Split& s = rect_.splits[static_cast<std::size_t>(region)];
  // s(u) = sqrt(1 + y^2 + z^2) / (zeta(u) - rho z), zeta(u) = zetaBegin + u (zetaEnd - zetaBegin).
  return {std::sqrt(1.0 + y * y + z * z), 0.0, s.zetaBegin - f.inverseLightDistance * z,
          s.zetaEnd - s.zetaBegin};
}

DistanceProfile ProjectiveLayout::referenceProfile(double row, int region) const {
  return rayProfile(row, referenceDepth(row), region);
}

std::optional<glm::dvec3> ProjectiveLayout::localLightPosition() const {
  if (rect_.frame.inverseLightDistance > 0.0) return rect_.frame.lightPosition;
  return std::nullopt;
}

double ProjectiveLayout::regionReferenceDepth(double row, int region) const {
  const RowReference ref = rect_.rowReference(row);
  if (rect_.frame.inverseLightDistance == 0.0)
    return ref.depth; // directional: every ray reaches every column
  const DistanceProfile lo = rayProfile(row, ref.depthLo, region), hi = rayProfile(row, ref.depthHi, region);
  return lo.c + lo.d >= hi.c + hi.d ? ref.depthLo : ref.depthHi;
}

// ---------------------------------------------------------------------------------------------------
// RectifiedMap

void validate(const RectifiedMap& map) {
  if (!map.layout) throw InvalidArgument("RectifiedMap.layout", "null", "must be set");
  const Image& d = map.depth;
  if (d.empty()) throw InvalidArgument("RectifiedMap.depth", "empty", "must be a W x H 1-channel image");
  if (d.channels() != 1)
    throw InvalidArgument("RectifiedMap.depth", std::to_string(d.channels()) + " channels",
                          "must have 1 channel");
  const int K = map.layout->regionCount();
  if (K < 1 || d.width() % K != 0)
    throw InvalidArgument("RectifiedMap.depth", "width " + std::to_string(d.width()),
                          "must be a multiple of the region count " + std::to_string(K));
  for (int y = 0; y < d.height(); ++y)
    for (int x = 0; x < d.width(); ++x) {
      const float v = d.at(x, y);
      if (!(v >= 0.0f && v <= 1.0f))
        throw InvalidArgument("RectifiedMap.depth", texelString(x, y) + " = " + detail::formatValue(v),
                              "depth values must be in [0, 1]");
    }
}

RectifiedMap makeRectifiedMap(std::shared_ptr<const RectifiedLayout> layout, Image depth) {
  RectifiedMap map{std::move(layout), std::move(depth)};
  validate(map);
  return map;
}

RectifiedMap castRectifiedMap(std::shared_ptr<const RectifiedLayout> layout, int width, int height,
                              const std::function<std::optional<glm::dvec3>(const LightRay&)>& firstHit,
                              int threads) {
  if (!layout) throw InvalidArgument("castRectifiedMap.layout", "null", "must be set");
  if (width <= 0 || height <= 0)
    throw InvalidArgument("castRectifiedMap.size", std::to_string(width) + " x " + std::to_string(height),
                          "must be positive");
  const int K = layout->regionCount();
  if (width % K != 0)
    throw InvalidArgument("castRectifiedMap.width", std::to_string(width),
                          "must be a multiple of the region count " + std::to_string(K));
  if (threads < 0) throw InvalidArgument("castRectifiedMap.threads", std::to_string(threads), "must be >= 0");
  Image depth(width, height, 1, 1.0f);
  const RectifiedLayout& l = *layout;
  const auto doRow = [&](int j) {
    const double row = (j + 0.5) / height;
    for (int i = 0; i < width; ++i) {
      const double column = (i + 0.5) / width;
      if (const auto hit = firstHit(l.lightRay(column, row)))
        depth.at(i, j) = static_cast<float>(std::clamp(l.toRectified(*hit).depth, 0.0, 1.0));
    }
  };
  parallelRows(height, threads, doRow); // rows interleaved; every texel written by exactly one worker
  return RectifiedMap{std::move(layout), std::move(depth)};
}

} // namespace crep
