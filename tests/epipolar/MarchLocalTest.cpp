// The rectified marches for a local light on the CPU (crep/scatter/rectified_march.h bruteForceMarch,
// crep/epipolar/march.h minMaxMarch): the analytic spot light's map (common/local_light_scene.h), cast
// exactly, against the closed form of the wall's half-space shadow; the min/max tree against the brute force.
#include "common/analytic_reference.h"
#include "common/local_light_scene.h"

#include <crep/epipolar/march.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/rectified_march.h>

#include <doctest/doctest.h>

#include <memory>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kW = 160, kH = 90;

} // namespace

TEST_CASE("rectified marches, spot light: brute force and min/max on the same map against the closed form") {
  const auto [camera, depth, medium, ro] = localLightView(kW, kH);
  const SpotLight spot = analyticSpot();
  const auto layout = std::make_shared<const ProjectiveLayout>(rectify(camera, spot, ro));
  const RectifiedMap map = castRectifiedMap(layout, 1024, 512, wallHitFromLight);
  const LocalLight light = LocalLight::spot(spot);
  const MarchResult brute = bruteForceMarch(map, depth, camera, light, medium);
  const MarchResult tree = minMaxMarch(map, depth, camera, light, medium);
  const Image truth = closedFormLocal(depth, camera, {light}, medium, true);
  const ImageMetrics mb = rgbMetrics(brute.scattering, truth), mt = rgbMetrics(tree.scattering, truth);
  report("spot light, half-space shadow: brute-force march over the rectified map vs closed form", mb);
  report("spot light, half-space shadow: min/max march vs closed form", mt);
  MESSAGE("steps per pixel: brute force " << brute.meanSteps() << ", min/max " << tree.meanSteps());
  CHECK(mb.relativeRmse < 0.005);
  CHECK(mt.relativeRmse < 0.005);
  // The tree only skips texels of equal visibility: the same lit sections, summed in larger pieces.
  CHECK(rgbMetrics(tree.scattering, brute.scattering).relativeRmse < 1e-6);
  CHECK(tree.meanSteps() < brute.meanSteps());
}
