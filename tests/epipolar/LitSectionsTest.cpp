// The lit sections of the min/max tree walk (crep/epipolar/march.h minMaxLitSections): the sections
// minMaxMarch integrates (Yusov 2012, Algorithm 2), checked by integrating them again (Klehm et al. 2014,
// Eq. 1 and 3 per section) against minMaxMarch's own image, and by their shape (ascending, disjoint,
// inside [start, surface]; a map without occluders gives each ray the single section [start, surface]).
#include "common/analytic_reference.h"
#include "common/error_checks.h"

#include <crep/core/error.h>
#include <crep/epipolar/march.h>
#include <crep/scatter/ray.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

/// Max over pixels and RGB of |float(C sum transmittanceIntegral over the sections) - image| / |image|
/// (floor 1e-30): the march stores float, so the re-integrated double value is rounded to float first.
double maxRelativeToMarch(const std::vector<std::vector<glm::dvec2>>& sections, const Image& march,
                          const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                          const Medium& medium, bool nearPlaneCorrection) {
  double worst = 0.0;
  const int w = cameraDepth.width();
  for (int y = 0; y < cameraDepth.height(); ++y)
    for (int x = 0; x < w; ++x) {
      const PixelRay ray = pixelRay(camera, cameraDepth, x, y, nearPlaneCorrection);
      glm::dvec3 sum(0.0);
      for (const glm::dvec2& s : sections[static_cast<std::size_t>(y * w + x)])
        sum += transmittanceIntegral(medium.extinction(), s.x, s.y);
      const glm::dvec3 L = scatteringConstant(light, medium, ray.direction) * sum;
      for (int c = 0; c < 3; ++c) {
        const double ref = march.at(x, y, c);
        const double mine = static_cast<float>(L[c]);
        worst = std::max(worst, std::abs(mine - ref) / std::max(std::abs(ref), 1e-30));
      }
    }
  return worst;
}

/// Every ray's sections are ascending, of positive length, separated by gaps (merged when touching) and
/// inside [start, surface].
void checkShape(const std::vector<std::vector<glm::dvec2>>& sections, const Image& cameraDepth,
                const Camera& camera, bool nearPlaneCorrection) {
  const int w = cameraDepth.width();
  int bad = 0;
  for (int y = 0; y < cameraDepth.height(); ++y)
    for (int x = 0; x < w; ++x) {
      const PixelRay ray = pixelRay(camera, cameraDepth, x, y, nearPlaneCorrection);
      const auto& s = sections[static_cast<std::size_t>(y * w + x)];
      for (std::size_t k = 0; k < s.size(); ++k) {
        if (!(s[k].x >= ray.start && s[k].y > s[k].x && s[k].y <= ray.surface)) ++bad;
        if (k > 0 && !(s[k].x > s[k - 1].y)) ++bad;
      }
    }
  CHECK(bad == 0);
}

} // namespace

TEST_CASE("epipolar lit sections: integrating them reproduces the min/max march (homogeneous, directional)") {
  const Camera camera = groundCamera(64, 36);
  const DirectionalLight light = sideLight();
  const Medium medium = colouredMedium();
  const Image depth = groundDepth(camera, 64, 36);
  for (const int splits : {1, 3}) {
    const auto layout = projectiveLayout(camera, light, splits);
    const int W = splits == 3 ? 3 * 67 : 256; // 201: not a power of two
    for (const bool analytic : {true, false})
      for (const bool nearPlane : {false, true}) {
        CAPTURE(splits);
        CAPTURE(analytic);
        CAPTURE(nearPlane);
        const RectifiedMap map =
            analytic
                ? castRectifiedMap(layout, W, 64, [](const LightRay& r) { return planeHit(HalfSpace{}, r); })
                : makeRectifiedMap(layout, randomRunsDepth(W, 64, 11));
        const MinMaxTrees trees(map.depth, 2);
        MarchOptions options;
        options.nearPlaneCorrection = nearPlane;
        const auto sections = minMaxLitSections(map, trees, depth, camera, options);
        REQUIRE(sections.size() == static_cast<std::size_t>(64 * 36));
        checkShape(sections, depth, camera, nearPlane);
        std::size_t count = 0, shadowedRays = 0;
        for (const auto& s : sections) {
          count += s.size();
          if (s.size() != 1) ++shadowedRays;
        }
        CHECK(shadowedRays > 0); // the maps do shadow parts of rays
        const MarchResult march = minMaxMarch(map, trees, depth, camera, light, medium, options);
        const double rel =
            maxRelativeToMarch(sections, march.scattering, depth, camera, light, medium, nearPlane);
        MESSAGE("sections per ray " << static_cast<double>(count) / sections.size()
                                    << ", max relative difference to minMaxMarch (float image) " << rel);
        CHECK(rel <= 1e-12);
      }
  }
}

TEST_CASE("epipolar lit sections: without occluders every ray is the one section [start, surface]") {
  const Camera camera = groundCamera(40, 24);
  const DirectionalLight light = sideLight();
  const Image depth = groundDepth(camera, 40, 24);
  const RectifiedMap empty = castRectifiedMap(projectiveLayout(camera, light, 2), 128, 64,
                                              [](const LightRay&) { return std::nullopt; });
  const MinMaxTrees trees(empty.depth, 1);
  for (const bool nearPlane : {false, true}) {
    MarchOptions options;
    options.nearPlaneCorrection = nearPlane;
    const auto sections = minMaxLitSections(empty, trees, depth, camera, options);
    int bad = 0;
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 40; ++x) {
        const PixelRay ray = pixelRay(camera, depth, x, y, nearPlane);
        const auto& s = sections[static_cast<std::size_t>(y * 40 + x)];
        if (s.size() != 1 || s[0].x != ray.start || s[0].y != ray.surface) ++bad;
      }
    CHECK(bad == 0);
  }
}

TEST_CASE("epipolar lit sections: validation names the parameter and threads do not change the result") {
  const Camera camera = groundCamera(24, 16);
  const DirectionalLight light = sideLight();
  const Image depth = groundDepth(camera, 24, 16);
  const RectifiedMap map = makeRectifiedMap(projectiveLayout(camera, light, 2), randomRunsDepth(64, 32, 5));
  const MinMaxTrees trees(map.depth, 1);
  CHECK(invalidParameter([&] { minMaxLitSections(map, trees, Image(), camera); }) == "cameraDepth");
  CHECK(invalidParameter([&] { minMaxLitSections(map, MinMaxTrees(Image(16, 8, 1)), depth, camera); }) ==
        "MinMaxTrees");
  MarchOptions one, three;
  one.threads = 1;
  three.threads = 3;
  CHECK(minMaxLitSections(map, trees, depth, camera, one) ==
        minMaxLitSections(map, trees, depth, camera, three));
}
