// CPU references of the ray marches (crep/epipolar/march.h, crep/scatter/rectified_march.h,
// crep/scatter/world_march.h): min/max trees, the tree march against the brute-force march of the same
// rows (Yusov 2012, Algorithm 2), both against closed forms (Klehm et al. 2014, Eq. 1, 3); the world-space
// reference march against the closed forms of an empty medium and of a half-space shadow.
#include "common/analytic_reference.h"
#include "common/error_checks.h"
#include "common/image_check.h"

#include <crep/core/error.h>
#include <crep/epipolar/march.h>
#include <crep/prefilter/prefilter.h>
#include <crep/scenes/scene.h>

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <vector>

using namespace crep;
using namespace crep::test;

TEST_CASE("epipolar march: every min/max tree node stores the min and max of the texels it covers") {
  for (const int W : {1, 2, 3, 7, 64, 100, 129}) {
    CAPTURE(W);
    const Image depth = randomRunsDepth(W, 3, static_cast<std::uint64_t>(W));
    const MinMaxTrees trees(depth, 2);
    REQUIRE(trees.levels() == (W == 1 ? 0 : static_cast<int>(std::ceil(std::log2(W)))));
    CHECK(trees.data().size() == static_cast<std::size_t>(trees.rowStride()) * 3 * 2);
    for (int j = 0; j < 3; ++j)
      for (int l = 1; l <= trees.levels(); ++l) {
        CHECK(MinMaxTrees::levelSize(W, l) == (W + (1 << l) - 1) / (1 << l));
        for (int m = 0; m < MinMaxTrees::levelSize(W, l); ++m) {
          float mn = 2.0f, mx = -1.0f;
          for (int i = m << l; i < std::min(W, (m + 1) << l); ++i) {
            mn = std::min(mn, depth.at(i, j));
            mx = std::max(mx, depth.at(i, j));
          }
          const glm::vec2 node = trees.node(l, j, m);
          CHECK(node.x == mn);
          CHECK(node.y == mx);
        }
      }
    if (trees.levels() > 0) CHECK(MinMaxTrees::levelSize(W, trees.levels()) == 1);
  }
}

TEST_CASE("epipolar march: the min/max march equals the brute-force march of the same map") {
  const Camera camera = groundCamera(96, 54);
  const DirectionalLight light = sideLight();
  const Medium medium = colouredMedium();
  const Image depth = groundDepth(camera, 96, 54);
  for (const int splits : {1, 3, 4}) {
    const auto layout = projectiveLayout(camera, light, splits);
    const int W = splits == 3 ? 3 * 67 : 256; // 201: not a power of two
    for (const bool analytic : {true, false}) {
      CAPTURE(splits);
      CAPTURE(analytic);
      const RectifiedMap map =
          analytic
              ? castRectifiedMap(layout, W, 96, [](const LightRay& r) { return planeHit(HalfSpace{}, r); })
              : makeRectifiedMap(layout, randomRunsDepth(W, 96, 7));
      const MarchResult tree = minMaxMarch(map, depth, camera, light, medium);
      const MarchResult brute = bruteForceMarch(map, depth, camera, light, medium);
      // Same lit texels, sums in a different grouping (double): equal to float precision.
      const double rel = maxRelativeDifference(tree.scattering, brute.scattering, 1e-6);
      MESSAGE("max relative difference " << rel << "; mean steps: tree " << tree.meanSteps() << ", brute "
                                         << brute.meanSteps());
      CHECK(rel < 1e-6);
      CHECK(tree.meanSteps() < brute.meanSteps());
      CHECK(compareImages(tree.scattering, brute.scattering).maxAbsError < 1e-6);
      // Alpha is the same transmittance in both.
      CHECK(tree.scattering.at(10, 10, 3) == brute.scattering.at(10, 10, 3));
    }
  }
}

TEST_CASE("epipolar march: closed forms (no occluder, half-space shadow) on a projective map") {
  // 160 x 90 ground-plane view, 512 x 256 map, 4 logarithmic splits, coloured medium.
  const Camera camera = groundCamera();
  const DirectionalLight light = sideLight();
  const Medium medium = colouredMedium();
  const Image depth = groundDepth(camera, 160, 90);
  const auto layout = projectiveLayout(camera, light, 4);
  // (a) No occluder: every texel lit, the sections add up to the closed form exactly.
  const RectifiedMap empty = castRectifiedMap(layout, 512, 256, [](const LightRay&) { return std::nullopt; });
  const Image truthA = closedForm(depth, camera, light, medium, std::nullopt);
  for (const MarchResult& r : {minMaxMarch(empty, depth, camera, light, medium),
                               bruteForceMarch(empty, depth, camera, light, medium)}) {
    const ImageMetrics m = rgbMetrics(r.scattering, truthA);
    report("(a) no occluder", m);
    CHECK(m.relativeRmse < 1e-6);
  }
  // (b) Half-space shadow: the map's own discretization (one texel of the ray at each shadow boundary,
  // nearest slice) is the only error. Measured (RGB): relative RMSE 3.7e-3, max abs 1.8e-3 (peak 0.12).
  const HalfSpace plane;
  const RectifiedMap map =
      castRectifiedMap(layout, 512, 256, [&](const LightRay& r) { return planeHit(plane, r); });
  const Image truthB = closedForm(depth, camera, light, medium, plane);
  REQUIRE(rgbMetrics(truthA, truthB).relativeRmse > 0.2); // there is a lot of shadow
  const MarchResult tree = minMaxMarch(map, depth, camera, light, medium);
  const ImageMetrics m = rgbMetrics(tree.scattering, truthB);
  report("(b) half-space, min/max march", m);
  ImageTolerance t;
  t.relativeRmse = 6e-3;
  t.maxAbsError = 5e-3;
  CHECK(checkImage(rgb(tree.scattering), rgb(truthB), t, "epipolar_march_half_space"));
  MESSAGE("mean steps: " << tree.meanSteps() << " (map width 512)");
}

TEST_CASE("epipolar march: results do not depend on the thread count") {
  const Camera camera = groundCamera(40, 30);
  const DirectionalLight light = sideLight();
  const Medium medium = colouredMedium();
  const Image depth = groundDepth(camera, 40, 30);
  const RectifiedMap map = makeRectifiedMap(projectiveLayout(camera, light, 2), randomRunsDepth(128, 64, 3));
  MarchOptions one;
  one.threads = 1;
  const MarchResult a = minMaxMarch(map, depth, camera, light, medium, one);
  MarchOptions three;
  three.threads = 3;
  const MarchResult b = minMaxMarch(map, depth, camera, light, medium, three);
  CHECK(compareImages(a.scattering, b.scattering).maxAbsError == 0.0);
  CHECK(compareImages(a.steps, b.steps).maxAbsError == 0.0);
}

TEST_CASE("epipolar world march: closed forms without occluder and with a half-space shadow") {
  const Camera camera = groundCamera();
  const DirectionalLight light = sideLight();
  const Medium medium = colouredMedium();
  const Image depth = groundDepth(camera, 160, 90);
  const glm::dmat4 lightMatrix = analyticLightMatrix(light);
  // (a) Empty shadow map: C / sigma (1 - exp(-sigma s)) to double precision (sections integrated exactly).
  const Image emptyMap(64, 64, 1, 1.0f);
  WorldMarchOptions o;
  o.steps = 8;
  const MarchResult a = worldSpaceMarch(emptyMap, lightMatrix, depth, camera, light, medium, o);
  const Image truthA = closedForm(depth, camera, light, medium, std::nullopt);
  const double relA = maxRelativeDifference(a.scattering, truthA, 1e-9);
  MESSAGE("(a) no occluder: max relative difference " << relA);
  CHECK(relA < 1e-6);
  CHECK(a.meanSteps() == doctest::Approx(9.0));                  // N + 1 lookups, no change of visibility
  CHECK(compareImages(a.scattering, truthA).maxAbsError < 1e-6); // A channel too

  // (b) Half-space shadow: the only error is the nearest-texel shadow test next to the plane (the
  // shadow boundary moves by up to half a texel's depth slope). 2048^2 map over a 120 x 120 footprint.
  // Measured (RGB): relative RMSE 2.6e-3, max abs 7.0e-4 (peak 0.12): view rays graze the plane, so half
  // a texel across it moves the shadow boundary a long way along them.
  const HalfSpace plane;
  const Image shadow = halfSpaceShadowMap(plane, lightMatrix, 2048);
  o.steps = 64;
  const MarchResult b = worldSpaceMarch(shadow, lightMatrix, depth, camera, light, medium, o);
  const Image truthB = closedForm(depth, camera, light, medium, plane);
  const ImageMetrics m = rgbMetrics(b.scattering, truthB);
  report("(b) half-space, world-space march", m);
  ImageTolerance t;
  t.relativeRmse = 4e-3;
  t.maxAbsError = 1.5e-3;
  CHECK(checkImage(rgb(b.scattering), rgb(truthB), t, "epipolar_world_march_half_space"));
}

TEST_CASE("epipolar march: bad input gets a named InvalidArgument") {
  const Camera camera = groundCamera(16, 9);
  const DirectionalLight light = sideLight();
  const Medium medium = colouredMedium();
  Image depth = groundDepth(camera, 16, 9);
  const RectifiedMap map = makeRectifiedMap(projectiveLayout(camera, light, 2), Image(32, 8, 1, 1.0f));
  CHECK(invalidParameter([&] { minMaxMarch(map, Image(), camera, light, medium); }) == "cameraDepth");
  depth.at(3, 4) = std::numeric_limits<float>::quiet_NaN();
  CHECK(invalidParameter([&] { bruteForceMarch(map, depth, camera, light, medium); }) == "cameraDepth");
  depth.at(3, 4) = 0.5f;
  RectifiedMap bad = map;
  bad.depth.at(5, 5) = std::numeric_limits<float>::quiet_NaN();
  CHECK(invalidParameter([&] { minMaxMarch(bad, depth, camera, light, medium); }) == "RectifiedMap.depth");
  CHECK(invalidParameter([&] {
          minMaxMarch(map, MinMaxTrees(Image(16, 8, 1)), depth, camera, light, medium);
        }) == "MinMaxTrees");
  MarchOptions o;
  o.threads = -1;
  CHECK(invalidParameter([&] { bruteForceMarch(map, depth, camera, light, medium, o); }) ==
        "MarchOptions.threads");
  Image shadow(8, 8, 1, 1.0f);
  shadow.at(1, 2) = std::numeric_limits<float>::quiet_NaN();
  const glm::dmat4 M = analyticLightMatrix(light);
  CHECK(invalidParameter([&] { worldSpaceMarch(shadow, M, depth, camera, light, medium); }) == "shadowDepth");
  CHECK(invalidParameter([&] { worldSpaceMarch(Image(), M, depth, camera, light, medium); }) ==
        "shadowDepth");
  glm::dmat4 nanMatrix = M;
  nanMatrix[1][2] = std::numeric_limits<double>::infinity();
  CHECK(invalidParameter([&] {
          worldSpaceMarch(Image(8, 8, 1, 1.0f), nanMatrix, depth, camera, light, medium);
        }) == "lightClipFromWorld");
  WorldMarchOptions w;
  w.steps = 0;
  CHECK(invalidParameter([&] {
          worldSpaceMarch(Image(8, 8, 1, 1.0f), M, depth, camera, light, medium, w);
        }) == "WorldMarchOptions.steps");
  CHECK(invalidParameter([] { MinMaxTrees(Image(4, 4, 2)); }) == "MinMaxTrees.depth");
}
