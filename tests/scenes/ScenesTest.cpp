#include <crep/core/error.h>
#include <crep/scenes/scene.h>

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <random>

using namespace crep::scenes;

namespace {
// Brute-force first hit over every triangle (independent of the BVH): plane intersection, then
// barycentric inside test by edge-function signs.
std::optional<double> bruteForceHit(const Mesh& mesh, const glm::dvec3& o, const glm::dvec3& d, double tMax) {
  std::optional<double> best;
  for (std::size_t i = 0; i < mesh.triangleCount(); ++i) {
    const glm::dvec3 a(mesh.positions[mesh.indices[3 * i]]), b(mesh.positions[mesh.indices[3 * i + 1]]),
        c(mesh.positions[mesh.indices[3 * i + 2]]);
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double denom = glm::dot(n, d);
    if (std::abs(denom) < 1e-14) continue;
    const double t = glm::dot(n, a - o) / denom;
    if (!(t > 0.0 && t < tMax)) continue;
    const glm::dvec3 p = o + t * d;
    const double e0 = glm::dot(glm::cross(b - a, p - a), n), e1 = glm::dot(glm::cross(c - b, p - b), n),
                 e2 = glm::dot(glm::cross(a - c, p - c), n);
    if (e0 >= 0 && e1 >= 0 && e2 >= 0 && (!best || t < *best)) best = t;
  }
  return best;
}
} // namespace

TEST_CASE("Scenes: every built-in scene is a valid mesh with its documented character") {
  for (const std::string& name : sceneNames()) {
    INFO("scene " << name);
    const Scene s = makeScene(name, 16.0 / 9.0);
    CHECK(s.name == name);
    REQUIRE(s.mesh.positions.size() == s.mesh.normals.size());
    REQUIRE(s.mesh.indices.size() % 3 == 0);
    CHECK(s.mesh.triangleCount() > 0);
    for (std::uint32_t i : s.mesh.indices) REQUIRE(i < s.mesh.positions.size());
    for (const auto& n : s.mesh.normals) REQUIRE(std::abs(glm::length(glm::dvec3(n)) - 1.0) < 1e-5);
    for (const auto& p : s.mesh.positions) REQUIRE((std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)));
    // The default camera sees the scene: the bounds centre is in front of it.
    CHECK(glm::dot(0.5 * (s.boundsMin + s.boundsMax) - s.camera.position(), s.camera.forward()) > 0.0);
    CHECK(s.camera.aspect() == doctest::Approx(16.0 / 9.0));
    // The sun shines downward.
    CHECK(s.sun.direction().y < 0.0);
  }
  // Forest: hundreds of trunks (12 triangles each) and thousands of leaf quads (2 each).
  const Scene forest = makeScene("forest");
  CHECK(forest.mesh.triangleCount() > 300 * 12 + 2000 * 2);
  // Deterministic generation.
  CHECK(makeScene("forest").mesh.positions == forest.mesh.positions);
}

TEST_CASE("Scenes: unknown name names the parameter") {
  try {
    makeScene("cathedral");
    FAIL("expected InvalidArgument");
  } catch (const crep::InvalidArgument& e) {
    CHECK(e.parameter() == "scene");
    CHECK(std::string(e.what()).find("cathedral") != std::string::npos);
  }
}

TEST_CASE("RayCaster: BVH first hit equals a brute-force loop over all triangles") {
  for (const std::string& name : {std::string("boxes"), std::string("colonnade"), std::string("forest")}) {
    INFO("scene " << name);
    const Scene s = makeScene(name);
    const RayCaster caster(s.mesh);
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const int rays = name == "forest" ? 40 : 300;
    int hits = 0;
    for (int i = 0; i < rays; ++i) {
      const glm::dvec3 o = s.camera.position();
      const glm::dvec3 d = s.camera.rayDirection(u(rng), u(rng));
      const auto fast = caster.firstHit(o, d, 0.0, 1e6);
      const auto slow = bruteForceHit(s.mesh, o, d, 1e6);
      REQUIRE(fast.has_value() == slow.has_value());
      if (fast) {
        ++hits;
        CHECK(*fast == doctest::Approx(*slow).epsilon(1e-9));
      }
    }
    CHECK(hits > rays / 4);
  }
}

TEST_CASE("standardLightClipFromWorld encloses the scene bounds") {
  for (const std::string& name : sceneNames()) {
    const Scene s = makeScene(name);
    const glm::dmat4 m = standardLightClipFromWorld(s.sun, s.boundsMin, s.boundsMax);
    for (int i = 0; i < 8; ++i) {
      const glm::dvec3 c((i & 1) ? s.boundsMax.x : s.boundsMin.x, (i & 2) ? s.boundsMax.y : s.boundsMin.y,
                         (i & 4) ? s.boundsMax.z : s.boundsMin.z);
      const glm::dvec4 clip = m * glm::dvec4(c, 1.0);
      CHECK(clip.w == doctest::Approx(1.0)); // orthographic
      for (int k = 0; k < 3; ++k) CHECK(std::abs(clip[k]) <= 1.0);
    }
    // Points further along the light direction get larger depth.
    const glm::dvec3 centre = 0.5 * (s.boundsMin + s.boundsMax);
    const double z0 = (m * glm::dvec4(centre, 1.0)).z, z1 = (m * glm::dvec4(centre + s.sun.direction(), 1.0)).z;
    CHECK(z1 > z0);
  }
}
