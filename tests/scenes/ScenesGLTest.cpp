#include "common/gl_fixture.h"

#include <crep/core/error.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <doctest/doctest.h>

#include <cmath>

using namespace crep::scenes;

namespace {
// Depth-buffer value of a world point under clipFromWorld (glDepthRange(0, 1)).
double depthBufferValue(const glm::dmat4& clipFromWorld, const glm::dvec3& p) {
  const glm::dvec4 c = clipFromWorld * glm::dvec4(p, 1.0);
  return 0.5 * c.z / c.w + 0.5;
}
} // namespace

TEST_CASE("SceneRenderer: camera depth equals the exact CPU ray cast at pixel centres") {
  CREP_REQUIRE_GL();
  const Scene s = makeScene("boxes", 160.0 / 90.0);
  SceneRenderer renderer(s.mesh);
  const int w = 160, h = 90;
  const glm::dmat4 clipFromWorld = s.camera.clipFromWorld();
  const crep::Image depth = renderer.renderDepthImage(clipFromWorld, w, h);
  const RayCaster caster(s.mesh);
  int compared = 0, background = 0, bad = 0;
  for (int y = 0; y < h; y += 3)
    for (int x = 0; x < w; x += 3) {
      const glm::dvec3 dir = s.camera.rayDirection((x + 0.5) / w * 2.0 - 1.0, (y + 0.5) / h * 2.0 - 1.0);
      const auto t = caster.firstHit(s.camera.position(), dir, 0.0, 1e9);
      const double stored = depth.at(x, y);
      if (!t || glm::dot(dir, s.camera.forward()) * *t > s.camera.far()) {
        ++background;
        if (stored != 1.0) ++bad;
        continue;
      }
      const double expected = depthBufferValue(clipFromWorld, s.camera.position() + *t * dir);
      // Compare in linear depth: pixels on silhouettes may legitimately hit the neighbour surface, so
      // allow a small fraction of outliers; elsewhere the error is float rasterization precision.
      const double zExpected = s.camera.linearDepth(expected), zStored = s.camera.linearDepth(stored);
      if (std::abs(zExpected - zStored) > 1e-3 * zExpected) ++bad;
      ++compared;
    }
  INFO("compared " << compared << ", background " << background << ", mismatches " << bad);
  CHECK(compared > 500);
  CHECK(bad <= compared / 50); // silhouette pixels only
}

TEST_CASE("SceneRenderer: depth clamp keeps casters in front of the near plane") {
  CREP_REQUIRE_GL();
  const Scene s = makeScene("boxes");
  SceneRenderer renderer(s.mesh);
  const glm::dmat4 light = standardLightClipFromWorld(s.sun, s.boundsMin, s.boundsMax);
  // Move the light's near plane past the top of the tallest box (1..3 x 0..5 x -9..-7): with
  // clamping it still casts (depth 0), without clamping its top is clipped away.
  const glm::dvec4 top = light * glm::dvec4(2.0, 5.0, -8.0, 1.0);
  const double dz = top.z / top.w + 1.0 + 0.05; // NDC units past the box top
  const glm::dmat4 shifted = glm::dmat4(1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -dz, 1) * light;
  const int n = 128;
  const crep::Image clamped = renderer.renderDepthImage(shifted, n, n, {.depthClamp = true});
  const crep::Image clipped = renderer.renderDepthImage(shifted, n, n, {.depthClamp = false});
  int recovered = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      // Clamping only adds casters (clipped triangles interpolate depth slightly differently).
      REQUIRE(clamped.at(x, y) <= clipped.at(x, y) + 1e-6f);
      // A caster cut away by the near plane comes back at depth 0 where something farther showed.
      recovered += clamped.at(x, y) == 0.0f && clipped.at(x, y) > 1e-3f;
    }
  INFO("texels recovered by depth clamping: " << recovered);
  CHECK(recovered > 20); // the box top covers ~2x2 of the ~40x40 world units mapped to the map
}

TEST_CASE("createDepthTexture: sizes beyond GL limits are errors naming the parameter") {
  CREP_REQUIRE_GL();
  CHECK_THROWS_AS(createDepthTexture(0, 16, "shadow map size"), crep::InvalidArgument);
  try {
    createDepthTexture(crep::gl::maxTextureSize() + 1, 16, "shadow map size");
    FAIL("expected GlError");
  } catch (const crep::GlError& e) {
    CHECK(std::string(e.what()).find("shadow map size") != std::string::npos);
  }
}
