// Convex regions for the rectification (see region.h).
#include "region.h"

#include <algorithm>
#include <cmath>

namespace crep::rectify_detail {

const std::array<std::array<int, 4>, 6>& Pyramid::faces() {
  static const std::array<std::array<int, 4>, 6> f{{
      {0, 1, 5, 4},
      {1, 2, 6, 5},
      {2, 3, 7, 6},
      {3, 0, 4, 7}, // sides, same order as the side planes
      {0, 1, 2, 3}, // near
      {4, 5, 6, 7}, // far
  }};
  return f;
}

std::array<glm::dvec3, 4> Pyramid::sideNormals() const {
  std::array<glm::dvec3, 4> n;
  for (unsigned i = 0; i < 4; ++i) {
    // The side plane through the apex spanned by two consecutive edges; oriented toward the axis.
    glm::dvec3 m = glm::normalize(glm::cross(edges[i], edges[(i + 1) % 4]));
    if (glm::dot(m, axis) < 0.0) m = -m;
    n[i] = m;
  }
  return n;
}

namespace {

using Polygon = std::vector<glm::dvec3>;

/// Sutherland-Hodgman: keeps the part of a convex polygon where dist >= 0.
template <class Dist>
Polygon clip(const Polygon& poly, Dist dist) {
  Polygon out;
  const std::size_t n = poly.size();
  if (n == 0) return out;
  std::vector<double> d(n);
  for (std::size_t i = 0; i < n; ++i)
    d[i] = dist(poly[i]);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    const bool inI = d[i] >= 0.0, inJ = d[j] >= 0.0;
    if (inI) out.push_back(poly[i]);
    if (inI != inJ) {
      // Interpolate from the inside end so the new vertex is exact on the plane up to rounding.
      const double t = d[i] / (d[i] - d[j]);
      out.push_back(poly[i] + t * (poly[j] - poly[i]));
    }
  }
  return out;
}

/// Signed distances (>= 0 inside) to the 6 bounding planes of a pyramid: 0..3 sides, 4 near, 5 far.
struct PlaneSet {
  std::array<glm::dvec3, 4> normals;
  const Pyramid* pyramid;
  double operator()(int plane, const glm::dvec3& p) const {
    const glm::dvec3 d = p - pyramid->apex;
    if (plane < 4) return glm::dot(normals[static_cast<unsigned>(plane)], d);
    const double t = glm::dot(pyramid->axis, d);
    return plane == 4 ? t - pyramid->near : pyramid->far - t;
  }
};

void clipFacesInto(const Pyramid& a, const Pyramid& b, std::vector<glm::dvec3>& out) {
  const PlaneSet planes{b.sideNormals(), &b};
  for (const auto& face : Pyramid::faces()) {
    Polygon poly;
    for (int idx : face)
      poly.push_back(a.corner(idx));
    for (int plane = 0; plane < 6 && !poly.empty(); ++plane)
      poly = clip(poly, [&](const glm::dvec3& p) { return planes(plane, p); });
    out.insert(out.end(), poly.begin(), poly.end());
  }
}

} // namespace

std::vector<glm::dvec3> intersectionVertices(const Pyramid& a, const Pyramid& b) {
  std::vector<glm::dvec3> out;
  clipFacesInto(a, b, out);
  clipFacesInto(b, a, out);
  return out;
}

std::vector<glm::dvec2> convexHull(std::vector<glm::dvec2> pts) {
  std::sort(pts.begin(), pts.end(),
            [](const glm::dvec2& p, const glm::dvec2& q) { return p.x < q.x || (p.x == q.x && p.y < q.y); });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return pts;
  const auto cross = [](const glm::dvec2& o, const glm::dvec2& p, const glm::dvec2& q) {
    return (p.x - o.x) * (q.y - o.y) - (p.y - o.y) * (q.x - o.x);
  };
  std::vector<glm::dvec2> hull(2 * pts.size());
  std::size_t k = 0;
  for (const auto& p : pts) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p) <= 0.0)
      --k;
    hull[k++] = p;
  }
  for (std::size_t i = pts.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0.0)
      --k;
    hull[k++] = pts[i];
  }
  hull.resize(k - 1);
  return hull;
}

} // namespace crep::rectify_detail
