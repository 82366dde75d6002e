// Mesh building helpers and the exact CPU ray cast (BVH over triangles, Moller-Trumbore in double).
#include <crep/scenes/scene.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace crep::scenes {

void appendQuad(Mesh& mesh, const glm::dvec3& corner, const glm::dvec3& edgeU, const glm::dvec3& edgeV) {
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  const glm::vec3 n(glm::normalize(glm::cross(edgeU, edgeV)));
  const glm::dvec3 p[4] = {corner, corner + edgeU, corner + edgeU + edgeV, corner + edgeV};
  for (const auto& q : p) {
    mesh.positions.emplace_back(q);
    mesh.normals.push_back(n);
  }
  for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(base + i);
}

void appendBox(Mesh& mesh, const Box& b) {
  const glm::dvec3 e = b.max - b.min;
  const glm::dvec3 ex(e.x, 0, 0), ey(0, e.y, 0), ez(0, 0, e.z);
  appendQuad(mesh, b.min, ey, ex);                       // -z
  appendQuad(mesh, b.min + ez, ex, ey);                  // +z
  appendQuad(mesh, b.min, ez, ey);                       // -x
  appendQuad(mesh, b.min + ex, ey, ez);                  // +x
  appendQuad(mesh, b.min, ex, ez);                       // -y
  appendQuad(mesh, b.min + ey, ez, ex);                  // +y
}

// ---------------------------------------------------------------------------------------------------
struct RayCaster::Impl {
  struct Node {
    glm::dvec3 lo, hi;
    std::uint32_t first, count; // leaf: triangles [first, first+count); inner: count == 0, children first, first+1
  };
  std::vector<std::array<glm::dvec3, 3>> tris;
  std::vector<Node> nodes;

  void build(std::uint32_t nodeIndex, std::uint32_t first, std::uint32_t count, std::vector<glm::dvec3>& centroids) {
    Node node{glm::dvec3(std::numeric_limits<double>::max()), glm::dvec3(-std::numeric_limits<double>::max()), first,
              count};
    glm::dvec3 clo(std::numeric_limits<double>::max()), chi(-std::numeric_limits<double>::max());
    for (std::uint32_t i = first; i < first + count; ++i) {
      for (const auto& v : tris[i]) {
        node.lo = glm::min(node.lo, v);
        node.hi = glm::max(node.hi, v);
      }
      clo = glm::min(clo, centroids[i]);
      chi = glm::max(chi, centroids[i]);
    }
    if (count <= 4) {
      nodes[nodeIndex] = node;
      return;
    }
    const glm::dvec3 ext = chi - clo;
    const int axis = ext.x > ext.y ? (ext.x > ext.z ? 0 : 2) : (ext.y > ext.z ? 1 : 2);
    const std::uint32_t mid = first + count / 2;
    // Median split on the widest centroid axis: sort triangles and centroids together.
    std::vector<std::uint32_t> order(count);
    for (std::uint32_t i = 0; i < count; ++i) order[i] = first + i;
    std::nth_element(order.begin(), order.begin() + (mid - first), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
    std::vector<std::array<glm::dvec3, 3>> t2(count);
    std::vector<glm::dvec3> c2(count);
    for (std::uint32_t i = 0; i < count; ++i) {
      t2[i] = tris[order[i]];
      c2[i] = centroids[order[i]];
    }
    std::copy(t2.begin(), t2.end(), tris.begin() + first);
    std::copy(c2.begin(), c2.end(), centroids.begin() + first);
    const auto left = static_cast<std::uint32_t>(nodes.size());
    nodes.resize(nodes.size() + 2);
    node.first = left;
    node.count = 0;
    nodes[nodeIndex] = node;
    build(left, first, mid - first, centroids);
    build(left + 1, mid, first + count - mid, centroids);
  }

  static bool hitBox(const Node& n, const glm::dvec3& o, const glm::dvec3& inv, double tMin, double tMax) {
    for (int a = 0; a < 3; ++a) {
      double t0 = (n.lo[a] - o[a]) * inv[a], t1 = (n.hi[a] - o[a]) * inv[a];
      if (t0 > t1) std::swap(t0, t1);
      if (std::isnan(t0) || std::isnan(t1)) continue; // ray in the slab plane: treat as inside
      tMin = std::max(tMin, t0);
      tMax = std::min(tMax, t1);
      if (tMin > tMax) return false;
    }
    return true;
  }
};

RayCaster::RayCaster(const Mesh& mesh) : impl_(std::make_unique<Impl>()) {
  const std::size_t n = mesh.triangleCount();
  impl_->tris.resize(n);
  std::vector<glm::dvec3> centroids(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) impl_->tris[i][static_cast<std::size_t>(k)] = glm::dvec3(mesh.positions[mesh.indices[3 * i + static_cast<std::size_t>(k)]]);
    centroids[i] = (impl_->tris[i][0] + impl_->tris[i][1] + impl_->tris[i][2]) / 3.0;
  }
  impl_->nodes.resize(1);
  if (n > 0) impl_->build(0, 0, static_cast<std::uint32_t>(n), centroids);
}
RayCaster::~RayCaster() = default;
RayCaster::RayCaster(RayCaster&&) noexcept = default;
RayCaster& RayCaster::operator=(RayCaster&&) noexcept = default;

std::optional<double> RayCaster::firstHit(const glm::dvec3& o, const glm::dvec3& d, double tMin, double tMax) const {
  if (impl_->tris.empty()) return std::nullopt;
  const glm::dvec3 inv(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
  double best = tMax;
  bool found = false;
  std::uint32_t stack[128];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const Impl::Node& node = impl_->nodes[stack[--sp]];
    if (!Impl::hitBox(node, o, inv, tMin, best)) continue;
    if (node.count == 0) {
      stack[sp++] = node.first;
      stack[sp++] = node.first + 1;
      continue;
    }
    for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
      // Moller-Trumbore, two-sided.
      const auto& t = impl_->tris[i];
      const glm::dvec3 e1 = t[1] - t[0], e2 = t[2] - t[0];
      const glm::dvec3 p = glm::cross(d, e2);
      const double det = glm::dot(e1, p);
      if (std::abs(det) < 1e-300) continue;
      const double invDet = 1.0 / det;
      const glm::dvec3 s = o - t[0];
      const double u = glm::dot(s, p) * invDet;
      if (u < 0.0 || u > 1.0) continue;
      const glm::dvec3 q = glm::cross(s, e1);
      const double v = glm::dot(d, q) * invDet;
      if (v < 0.0 || u + v > 1.0) continue;
      const double tt = glm::dot(e2, q) * invDet;
      if (tt > tMin && tt < best) {
        best = tt;
        found = true;
      }
    }
  }
  if (!found) return std::nullopt;
  return best;
}

} // namespace crep::scenes

namespace crep::scenes {

glm::dmat4 standardLightClipFromWorld(const DirectionalLight& light, const glm::dvec3& boundsMin,
                                      const glm::dvec3& boundsMax) {
  std::array<glm::dvec3, 8> corners;
  for (int i = 0; i < 8; ++i)
    corners[static_cast<std::size_t>(i)] =
        glm::dvec3((i & 1) ? boundsMax.x : boundsMin.x, (i & 2) ? boundsMax.y : boundsMin.y,
                   (i & 4) ? boundsMax.z : boundsMin.z);
  return orthographicLightClipFromWorld(light, corners);
}

} // namespace crep::scenes
