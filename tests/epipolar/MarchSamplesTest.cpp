// CPU marches at continuous screen positions (crep::screenRay, the sample overloads of crep::minMaxMarch and
// crep::bruteForceMarch): the rays of epipolar sampling's marched samples (Yusov 2012, Sec. 6.1 and 6.4).
// At pixel centres they are the per-pixel functions bit for bit; anywhere else the tree march equals the
// brute-force march of the same rays; bad samples get a named InvalidArgument.
#include "common/analytic_reference.h"
#include "common/error_checks.h"

#include <crep/core/error.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/march.h>

#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kW = 96, kH = 54; // camera image

/// The maps of the tests: the half-space occluder cast exactly and random runs, on a projective layout (4
/// splits) and on the epipolar layout of the camera image.
struct NamedMap {
  std::string name;
  RectifiedMap map;
};

std::vector<NamedMap> testMaps(const Camera& camera, const DirectionalLight& light) {
  const auto projective = projectiveLayout(camera, light, 4);
  const auto epipolar = std::make_shared<const EpipolarLayout>(camera, light, kW, kH);
  const int He = epipolar->sliceCount();
  const auto plane = [](const LightRay& r) { return planeHit(HalfSpace{}, r); };
  return {{"projective half-space", castRectifiedMap(projective, 256, 96, plane)},
          {"projective random runs", makeRectifiedMap(projective, randomRunsDepth(256, 96, 11))},
          {"epipolar half-space", castRectifiedMap(epipolar, 128, He, plane)},
          {"epipolar random runs", makeRectifiedMap(epipolar, randomRunsDepth(128, He, 12))}};
}

/// Every pixel centre of `depth` with its depth-buffer value, row by row.
std::vector<ScreenSample> pixelCentres(const Image& depth) {
  std::vector<ScreenSample> s;
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x)
      s.push_back({x + 0.5, y + 0.5, depth.at(x, y)});
  return s;
}

bool sameBits(float a, float b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

/// Texels of `image` (w x h) that differ bitwise from texel i = x + y w of the samples.size() x 1 `samples`.
int bitDifferences(const Image& image, const Image& samples) {
  int differ = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < image.channels(); ++c)
        if (!sameBits(image.at(x, y, c), samples.at(x + y * image.width(), 0, c))) ++differ;
  return differ;
}

} // namespace

TEST_CASE("march samples: screenRay at a pixel centre is pixelRay bit for bit") {
  const Camera camera = groundCamera(kW, kH);
  const Image depth = groundDepth(camera, kW, kH);
  int differ = 0;
  for (const bool near : {false, true})
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const PixelRay a = pixelRay(camera, depth, x, y, near);
        const PixelRay b = screenRay(camera, kW, kH, x + 0.5, y + 0.5, depth.at(x, y), near);
        if (std::memcmp(&a, &b, sizeof a) != 0) ++differ;
      }
  CHECK(differ == 0);
  // Between pixels: the ray moves continuously (the direction of (x, y) is the NDC's).
  const PixelRay mid = screenRay(camera, kW, kH, 10.0, 20.0, 1.0);
  const glm::dvec3 expected = camera.rayDirection(2.0 * 10.0 / kW - 1.0, 2.0 * 20.0 / kH - 1.0);
  CHECK(glm::length(mid.direction - expected) < 1e-15);
  CHECK(mid.surface == doctest::Approx(camera.far() / glm::dot(expected, camera.forward())).epsilon(1e-14));
}

TEST_CASE("march samples: at pixel centres the sample marches equal the per-pixel marches bit for bit") {
  const Camera camera = groundCamera(kW, kH);
  const DirectionalLight light = sideLight();
  const Medium medium = colouredMedium();
  const Image depth = groundDepth(camera, kW, kH);
  const std::vector<ScreenSample> samples = pixelCentres(depth);
  for (const NamedMap& m : testMaps(camera, light)) {
    CAPTURE(m.name);
    const MinMaxTrees trees(m.map.depth);
    for (const bool near : {false, true}) {
      CAPTURE(near);
      MarchOptions o;
      o.nearPlaneCorrection = near;
      const MarchResult treeImage = minMaxMarch(m.map, trees, depth, camera, light, medium, o);
      const MarchResult treeSamples = minMaxMarch(m.map, trees, samples, kW, kH, camera, light, medium, o);
      const MarchResult bruteImage = bruteForceMarch(m.map, depth, camera, light, medium, o);
      const MarchResult bruteSamples = bruteForceMarch(m.map, samples, kW, kH, camera, light, medium, o);
      REQUIRE(treeSamples.scattering.width() == kW * kH);
      REQUIRE(treeSamples.scattering.height() == 1);
      CHECK(bitDifferences(treeImage.scattering, treeSamples.scattering) == 0);
      CHECK(bitDifferences(treeImage.steps, treeSamples.steps) == 0);
      CHECK(bitDifferences(bruteImage.scattering, bruteSamples.scattering) == 0);
      CHECK(bitDifferences(bruteImage.steps, bruteSamples.steps) == 0);
      CHECK(treeImage.meanSteps() < bruteImage.meanSteps()); // the tree skips texels
    }
  }
}

TEST_CASE("march samples: at arbitrary positions the tree march equals the brute-force march") {
  const Camera camera = groundCamera(kW, kH);
  const DirectionalLight light = sideLight();
  const Medium medium = colouredMedium();
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::vector<ScreenSample> samples;
  for (int i = 0; i < 3000; ++i) // continuous positions on the screen and a little beyond, any depth
    samples.push_back(
        {uni(rng) * (kW + 2.0) - 1.0, uni(rng) * (kH + 2.0) - 1.0, i % 7 == 0 ? 1.0 : 0.9 + 0.1 * uni(rng)});
  samples.push_back({0.0, 0.0, 0.0}); // corner, on the near plane
  samples.push_back({static_cast<double>(kW), static_cast<double>(kH), 1.0});
  for (const NamedMap& m : testMaps(camera, light)) {
    CAPTURE(m.name);
    const MinMaxTrees trees(m.map.depth);
    const MarchResult tree = minMaxMarch(m.map, trees, samples, kW, kH, camera, light, medium);
    const MarchResult brute = bruteForceMarch(m.map, samples, kW, kH, camera, light, medium);
    // The same lit texels, summed in a different grouping (double).
    const double rel = maxRelativeDifference(tree.scattering, brute.scattering, 1e-12);
    MESSAGE(m.name << ": max relative difference " << rel << "; mean steps tree " << tree.meanSteps()
                   << ", brute " << brute.meanSteps());
    CHECK(rel < 1e-9);
    int alpha = 0, lit = 0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const int x = static_cast<int>(i);
      if (!sameBits(tree.scattering.at(x, 0, 3), brute.scattering.at(x, 0, 3))) ++alpha;
      if (tree.scattering.at(x, 0, 0) > 0.0f) ++lit;
    }
    CHECK(alpha == 0);                                 // the same transmittance
    CHECK(lit > static_cast<int>(samples.size()) / 4); // a meaningful comparison: lit rays
    CHECK(tree.meanSteps() < brute.meanSteps());
  }
}

TEST_CASE("march samples: bad samples get a named InvalidArgument") {
  const Camera camera = groundCamera(16, 9);
  const DirectionalLight light = sideLight();
  const Medium medium = colouredMedium();
  const RectifiedMap map = makeRectifiedMap(projectiveLayout(camera, light, 2), Image(32, 8, 1, 1.0f));
  const MinMaxTrees trees(map.depth);
  std::vector<ScreenSample> samples(5, ScreenSample{4.0, 3.0, 0.5});
  CHECK(minMaxMarch(map, trees, samples, 16, 9, camera, light, medium).scattering.width() == 5);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const ScreenSample bad :
       {ScreenSample{nan, 3.0, 0.5}, ScreenSample{4.0, inf, 0.5}, ScreenSample{4.0, 3.0, nan},
        ScreenSample{4.0, 3.0, 1.5}, ScreenSample{4.0, 3.0, -0.1}}) {
    samples[3] = bad;
    CHECK(invalidParameter([&] { minMaxMarch(map, trees, samples, 16, 9, camera, light, medium); }) ==
          "samples[3]");
    CHECK(invalidParameter([&] { bruteForceMarch(map, samples, 16, 9, camera, light, medium); }) ==
          "samples[3]");
  }
  samples[3] = {4.0, 3.0, 0.5};
  CHECK(invalidParameter([&] { bruteForceMarch(map, samples, 0, 9, camera, light, medium); }) == "width");
  CHECK(invalidParameter([&] { minMaxMarch(map, trees, samples, 16, -1, camera, light, medium); }) ==
        "height");
  CHECK(invalidParameter([&] {
          minMaxMarch(map, MinMaxTrees(Image(16, 8, 1)), samples, 16, 9, camera, light, medium);
        }) == "MinMaxTrees");
  const std::vector<ScreenSample> tooMany(static_cast<std::size_t>(Image::kMaxDimension) + 1);
  CHECK(invalidParameter([&] { bruteForceMarch(map, tooMany, 16, 9, camera, light, medium); }) == "samples");
  // No samples: an empty result.
  CHECK(
      bruteForceMarch(map, std::span<const ScreenSample>(), 16, 9, camera, light, medium).scattering.empty());
}
