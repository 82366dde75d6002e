// Point resampling of a local light's perspective shadow map into its projective rectified map (Klehm et al.
// 2014, Sec. 4.1's rule on the layout of Sec. 3.2 "Local Lights"; crep/epipolar/resample.h), on the CPU:
// the analytic scene's wall (a half-space, common/local_light_scene.h) seen by the spot light and a
// point-light face, its perspective map computed in closed form, resampled, against the exact rectified depth
// of the wall's hit on every texel's light ray; and validateLocalLightMatrix / the layout's choice of check,
// bad matrices named.
#include "common/analytic_reference.h"
#include "common/analytic_scene.h"
#include "common/error_checks.h"
#include "common/local_light_scene.h"

#include <crep/core/error.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/resample.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

struct Agreement {
  int compared = 0, excluded = 0, differing = 0, hits = 0;
  /// |difference| over the texels whose exact depth is not clamped (the wall's hit within the region's
  /// depth range: most hits lie between the light and the region and clamp to 0 in both maps)
  double median = 0.0, p99 = 0.0, worst = 0.0;
};

/// The resampled map against the exact depth of the wall's first hit on each texel's light ray (1 without a
/// hit), over the texels whose ray lies inside the light's map (NDC x, y in [-1, 1]) and whose hit, if any,
/// is inside its depth range (the map's far plane clamps farther hits to "nothing": those are excluded).
Agreement againstExact(const RectifiedMap& map, const glm::dmat4& M, double tolerance) {
  Agreement a;
  std::vector<double> hitDiffs;
  const RectifiedLayout& L = *map.layout;
  for (int j = 0; j < map.height(); ++j)
    for (int i = 0; i < map.width(); ++i) {
      const LightRay ray = L.lightRay((i + 0.5) / map.width(), (j + 0.5) / map.height());
      const glm::dvec4 q = M * glm::dvec4(ray.origin + ray.direction, 1.0);
      const bool inside = q.w > 0.0 && std::abs(q.x / q.w) <= 1.0 && std::abs(q.y / q.w) <= 1.0;
      const std::optional<glm::dvec3> hit = wallHitFromLight(ray);
      bool inRange = true;
      double exact = 1.0;
      if (hit) {
        const glm::dvec4 h = M * glm::dvec4(*hit, 1.0);
        inRange = h.z / h.w <= 1.0;
        exact = std::clamp(L.toRectified(*hit).depth, 0.0, 1.0);
      }
      if (!inside || !inRange) {
        ++a.excluded;
        continue;
      }
      ++a.compared;
      const double d = std::abs(map.depth.at(i, j) - exact);
      if (d > tolerance) ++a.differing;
      if (exact > 0.0 && exact < 1.0) {
        ++a.hits;
        hitDiffs.push_back(d);
      }
      if (exact > 0.0 && exact < 1.0) a.worst = std::max(a.worst, d);
    }
  if (!hitDiffs.empty()) {
    std::sort(hitDiffs.begin(), hitDiffs.end());
    a.median = hitDiffs[hitDiffs.size() / 2];
    a.p99 = hitDiffs[hitDiffs.size() * 99 / 100];
  }
  return a;
}

} // namespace

TEST_CASE("resample local lights: the wall's perspective map resampled into the spot's and a point face's "
          "rectified maps equals the exact hits up to point resampling") {
  const Camera camera = groundCamera(160, 90);
  RectifyOptions options;
  options.splits = 8;
  const SpotLight spot = analyticSpot();
  const PointLight point = analyticPoint();
  const std::array<Rectification, 6> faces = rectifyPointLight(camera, point, options);
  struct Case {
    std::string name;
    Rectification rect;
    glm::dmat4 M;
  };
  std::vector<Case> cases{{"spot", rectify(camera, spot, options), spot.lightClipFromWorld()}};
  for (int k = 0; k < 6; ++k)
    if (faces[std::size_t(k)].projective())
      cases.push_back({"point face " + std::to_string(k), faces[std::size_t(k)], point.faceClipFromWorld(k)});
  REQUIRE(cases.size() >= 2);
  for (const Case& c : cases) {
    CAPTURE(c.name);
    REQUIRE(c.rect.projective());
    const auto layout = std::make_shared<const ProjectiveLayout>(c.rect);
    REQUIRE(localLightPosition(*layout).has_value());
    const Image shadow = halfSpaceShadowMap(wall(), c.M, 1024);
    const RectifiedMap map = resampleShadowMap(layout, 256, 256, shadow, c.M);
    // The nearest standard texel's ray is at most half a texel (0.8e-3 rad for the spot, 1e-3 for a face)
    // from the texel's own: its hit, unprojected onto the own ray, differs in depth by the wall's slope
    // over that angle.
    const Agreement a = againstExact(map, c.M, 1e-2);
    MESSAGE(c.name << ": " << a.compared << " texels compared (" << a.excluded << " outside the map), "
                   << a.hits << " unclamped hits; their |difference| median " << a.median
                   << ", 99th percentile " << a.p99 << ", max " << a.worst << "; " << a.differing
                   << " differ by more than 1e-2");
    // Measured (1024^2 map, 256^2 rectified): spot: median 3.6e-4, 99th percentile 2.2e-3 over 24868
    // unclamped texels, 3 of 59212 beyond 1e-2 (max 0.72: where the nearest texel's hit clamps); face +X
    // (the wall facing it: equal depth on neighbouring rays) 7.8e-7 at most; face -Z median 1.5e-4,
    // max 3.6e-4.
    CHECK(a.compared > 256 * 256 / 4);
    CHECK(a.median < 1e-3);
    CHECK(a.p99 < 5e-3);
    CHECK(double(a.differing) / a.compared < 1e-3);
    // The threaded result is the single-threaded one.
    const RectifiedMap single = resampleShadowMap(layout, 256, 256, shadow, c.M, {.threads = 1});
    CHECK(std::equal(single.depth.data().begin(), single.depth.data().end(), map.depth.data().begin(),
                     map.depth.data().end()));
  }
}

TEST_CASE("resample local lights: validateLocalLightMatrix accepts the lights' matrices stored in float and "
          "names bad ones") {
  // Far from the world origin, where float storage rounds most.
  const SpotLight spot({.position = {1000.0, 20.0, -3000.0},
                        .direction = {0.3, -1.0, 0.2},
                        .innerConeAngle = 0.3,
                        .outerConeAngle = 0.5,
                        .range = 80.0});
  const PointLight point({.position = {-250.0, 12.0, 75.0}, .range = 50.0});
  std::vector<std::pair<glm::dmat4, glm::dvec3>> good{{spot.lightClipFromWorld(), spot.position()}};
  for (int k = 0; k < 6; ++k)
    good.push_back({point.faceClipFromWorld(k), point.position()});
  // An engine's GL cube-map face matrices, built in float (glm::lookAt / perspective).
  const glm::vec3 p(point.position());
  const glm::vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const glm::vec3 ups[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
  for (int k = 0; k < 6; ++k)
    good.push_back({glm::dmat4(glm::perspective(glm::radians(90.0f), 1.0f, 0.05f, 50.0f) *
                               glm::lookAt(p, p + axes[k], ups[k])),
                    point.position()});
  for (const auto& [M, L] : good) {
    CHECK_NOTHROW(validateLocalLightMatrix(M, L));
    CHECK_NOTHROW(validateLocalLightMatrix(glm::dmat4(glm::mat4(M)), L)); // stored in float
  }
  const glm::dmat4 M = spot.lightClipFromWorld();
  const glm::dvec3 L = spot.position();
  // A centre 1 unit (3e-4 of |L|) off the light: rejected, as is one 1% off.
  CHECK(invalidParameter([&] { validateLocalLightMatrix(M, L + glm::dvec3(1.0, 0.0, 0.0)); }) ==
        "lightClipFromWorld");
  CHECK(invalidParameter([&] { validateLocalLightMatrix(M, L * 1.01); }) == "lightClipFromWorld");
  // An orthographic matrix (clip w = 1 everywhere) is not a perspective one.
  const glm::dmat4 ortho = glm::orthoRH_NO(-10.0, 10.0, -10.0, 10.0, 0.1, 100.0) *
                           glm::lookAtRH(L, L + glm::dvec3(0.3, -1.0, 0.2), glm::dvec3(1.0, 0.0, 0.0));
  CHECK(invalidParameter([&] { validateLocalLightMatrix(ortho, L); }) == "lightClipFromWorld");
  glm::dmat4 nan = M;
  nan[2][1] = std::nan("");
  CHECK(invalidParameter([&] { validateLocalLightMatrix(nan, L); }) == "lightClipFromWorld");
  glm::dmat4 singular = M;
  singular[2] = singular[0];
  CHECK(invalidParameter([&] { validateLocalLightMatrix(singular, L); }) == "lightClipFromWorld");
  CHECK(invalidParameter([&] { validateLocalLightMatrix(M, glm::dvec3(std::nan(""), 0.0, 0.0)); }) ==
        "lightPosition");
  const std::string message = [&] {
    try {
      validateLocalLightMatrix(M, L + glm::dvec3(1.0, 0.0, 0.0));
    } catch (const InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string();
  }();
  CHECK(message.find("centred at the light position") != std::string::npos);
}

TEST_CASE("resample local lights: resampleShadowMap takes the check of the layout's light") {
  const Camera camera = groundCamera(160, 90);
  const SpotLight spot = analyticSpot();
  const Rectification rect = rectify(camera, spot, {.splits = 4});
  REQUIRE(rect.projective());
  const auto local = std::make_shared<const ProjectiveLayout>(rect);
  const DirectionalLight sun = sideLight();
  const Rectification sunRect = rectify(camera, sun, {.splits = 4});
  REQUIRE(sunRect.projective());
  const auto directional = std::make_shared<const ProjectiveLayout>(sunRect);
  REQUIRE(!localLightPosition(*directional).has_value());
  REQUIRE(localLightPosition(*local).has_value());
  CHECK(glm::length(*localLightPosition(*local) - spot.position()) < 1e-9 * glm::length(spot.position()));
  const EpipolarLayout epipolar(camera, sun, 160, 90);
  CHECK(!localLightPosition(epipolar).has_value());

  const Image shadow(64, 64, 1, 1.0f);
  const glm::dmat4 ortho = analyticLightMatrix(sun);
  // A local light's layout wants a perspective matrix centred at the light, a directional one an
  // orthographic matrix along the light.
  CHECK(invalidParameter([&] { resampleShadowMap(local, 64, 64, shadow, ortho); }) == "lightClipFromWorld");
  CHECK(invalidParameter([&] { resampleShadowMap(local, 64, 64, shadow, camera.clipFromWorld()); }) ==
        "lightClipFromWorld");
  CHECK(invalidParameter([&] {
          resampleShadowMap(directional, 64, 64, shadow, spot.lightClipFromWorld());
        }) == "lightClipFromWorld");
  CHECK_NOTHROW(resampleShadowMap(local, 64, 64, shadow, spot.lightClipFromWorld()));
  CHECK_NOTHROW(resampleShadowMap(directional, 64, 64, shadow, ortho));
  // An empty map resamples to "nothing casts" everywhere.
  const RectifiedMap empty = resampleShadowMap(local, 64, 64, shadow, spot.lightClipFromWorld());
  CHECK(*std::min_element(empty.depth.data().begin(), empty.depth.data().end()) == 1.0f);
}
