// The world-space reference march for local lights (crep::worldSpaceMarch with a LocalLight) against the
// closed form of the analytic scene: a camera over the ground, a plane occluder (half-space shadow) and a
// spot or point light on its lit side. The lit part of every view ray is known exactly (the plane), and
// its in-scattering is RayScattering::segment (tested against an independent quadrature in
// RayScatteringTest), so the march's own error is its shadow-map visibility.
#include "common/analytic_reference.h"
#include "common/analytic_scene.h"
#include "common/local_light_scene.h"

#include <crep/scatter/ray_scattering.h>
#include <crep/scatter/world_march.h>

#include <doctest/doctest.h>

#include <cmath>

using namespace crep;
using namespace crep::test;

namespace {
constexpr int kW = 96, kH = 54, kShadow = 1024;
} // namespace

TEST_CASE("world march, spot light: the half-space shadow's closed form within 0.5%, unoccluded exactly") {
  const auto [camera, depth, medium, ro] = localLightView(kW, kH);
  const SpotLight spot = analyticSpot();
  const LocalLight light = LocalLight::spot(spot);
  const glm::dmat4 M = spot.lightClipFromWorld();

  // No occluder: every section lit, the march sums RayScattering over them.
  const MarchResult open =
      worldSpaceMarch(Image(64, 64, 1, 1.0f), M, depth, camera, light, medium, {.steps = 16});
  const Image unoccluded = closedFormLocal(depth, camera, {light}, medium);
  double worst = 0.0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const glm::dvec3 v = camera.rayDirection(2.0 * (x + 0.5) / kW - 1.0, 2.0 * (y + 0.5) / kH - 1.0);
      const double s = camera.surfaceViewDepth(depth.at(x, y)) / glm::dot(v, camera.forward());
      const glm::dvec3 all = RayScattering(light, medium, camera.position(), v).segment(0.0, s);
      for (int c = 0; c < 3; ++c)
        worst = std::max(worst, std::abs(open.scattering.at(x, y, c) - all[c]) / std::max(all[c], 1e-30));
    }
  MESSAGE("unoccluded: max relative difference to one section " << worst);
  CHECK(worst < 1e-5); // float storage of the output

  const Image shadow = halfSpaceShadowMap(wall(), M, kShadow);
  const MarchResult march =
      worldSpaceMarch(shadow, M, depth, camera, light, medium, {.steps = 256, .bias = 1e-5});
  const ImageMetrics m = rgbMetrics(march.scattering, closedFormLocal(depth, camera, {light}, medium));
  report("spot light, half-space shadow: world march vs closed form", m);
  CHECK(m.nanCount == 0);
  CHECK(m.relativeRmse < 0.005);
}

TEST_CASE("world march, point light: six faces add up to the closed form, no seam at the face borders") {
  const auto [camera, depth, medium, ro] = localLightView(kW, kH);
  const PointLight point = analyticPoint();
  std::vector<LocalLight> faces;
  Image sum(kW, kH, 4);
  for (int face = 0; face < 6; ++face) {
    faces.push_back(LocalLight::pointFace(point, face));
    const glm::dmat4 M = point.faceClipFromWorld(face);
    const MarchResult r = worldSpaceMarch(halfSpaceShadowMap(wall(), M, kShadow / 2), M, depth, camera,
                                          faces.back(), medium, {.steps = 256, .bias = 1e-5});
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x)
        for (int c = 0; c < 3; ++c)
          sum.at(x, y, c) += r.scattering.at(x, y, c);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x)
        sum.at(x, y, 3) = r.scattering.at(x, y, 3);
  }
  const Image expected = closedFormLocal(depth, camera, faces, medium);
  const ImageMetrics m = rgbMetrics(sum, expected);
  report("point light (six faces), half-space shadow: world march vs closed form", m);
  CHECK(m.nanCount == 0);
  CHECK(m.relativeRmse < 0.005);
}
