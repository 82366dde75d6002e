// Internal to rectify/: the convex region a rectification must cover (the camera frustum, or its
// intersection with a light's frustum) as a set of vertices, and the small 2D helpers on it.
#pragma once

#include <array>
#include <vector>

#include <glm/glm.hpp>

namespace crep::rectify_detail {

/// A truncated pyramid (a view frustum): the convex hull of apex + t * edges[i], t in {near, far}.
/// Every edge direction satisfies dot(axis, edge) == 1, so t is the distance along the axis.
/// Edges go around the axis in order (either orientation).
struct Pyramid {
  glm::dvec3 apex{0.0};
  glm::dvec3 axis{0.0, 0.0, -1.0};
  std::array<glm::dvec3, 4> edges{};
  double near = 0.0, far = 0.0;

  glm::dvec3 corner(int i) const { return apex + (i < 4 ? near : far) * edges[static_cast<unsigned>(i % 4)]; }
  /// The 6 faces as quads of corner indices (sides 0..3, near, far).
  static const std::array<std::array<int, 4>, 6>& faces();
  /// Unit normals of the 4 side planes (through the apex), pointing inside.
  std::array<glm::dvec3, 4> sideNormals() const;
};

/// The vertices of the convex polytope a intersected with b (possibly with duplicates; empty when the
/// intersection is empty or flat). Clips every face of each pyramid against the other's planes, so
/// every vertex is computed by interpolation along an edge of its own scale (no global tolerance).
std::vector<glm::dvec3> intersectionVertices(const Pyramid& a, const Pyramid& b);

/// Convex hull (counter-clockwise, no collinear points) of 2D points, Andrew's monotone chain.
std::vector<glm::dvec2> convexHull(std::vector<glm::dvec2> points);

} // namespace crep::rectify_detail
