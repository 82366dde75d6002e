// The resampling fallback end to end on the CPU (Klehm et al. 2014 Sec. 4.1; crep/epipolar/resample.h):
// a standard shadow map of an analytic occluder (an infinite plane) resampled into the epipolar layout and
// into the projective layout, marched and prefiltered (prefilter/'s evaluation, unchanged), against the
// closed form and against the projective pipeline on a configuration where both are valid.
#include "common/analytic_reference.h"
#include "common/error_checks.h"
#include "common/image_check.h"

#include <crep/core/error.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/march.h>
#include <crep/epipolar/resample.h>
#include <crep/prefilter/prefilter.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

struct Setup {
  Camera camera = groundCamera();
  DirectionalLight light = sideLight();
  Medium medium = colouredMedium();
  HalfSpace plane;
  Image depth = groundDepth(camera, 160, 90);
  glm::dmat4 lightMatrix = analyticLightMatrix(light);
  Image shadow = halfSpaceShadowMap(plane, lightMatrix, 2048);
  Image truth = closedForm(depth, camera, light, medium, plane);
};

} // namespace

TEST_CASE(
    "epipolar fallback: the resampled epipolar map against the closed form and the projective pipeline") {
  const Setup s;
  // The epipolar layout of the 160 x 90 screen: the epipole is off screen (light from the side), so the
  // rows cover the exit arc only.
  const auto epipolar = std::make_shared<const EpipolarLayout>(s.camera, s.light, 160, 90);
  MESSAGE("epipolar layout: " << epipolar->sliceCount() << " slices, exit arc " << epipolar->arcLength()
                              << " of " << epipolar->perimeter() << " border pixels");
  const RectifiedMap fallbackMap =
      resampleShadowMap(epipolar, 512, epipolar->sliceCount(), s.shadow, s.lightMatrix);
  const MarchResult fallback = minMaxMarch(fallbackMap, s.depth, s.camera, s.light, s.medium);
  const ImageMetrics vsTruth = rgbMetrics(fallback.scattering, s.truth);
  report("epipolar fallback (resampled 2048^2 -> 512 x slices), min/max march vs closed form", vsTruth);

  // The projective pipeline: the same plane rasterized exactly into a 512 x 256 map (4 splits).
  const auto projective = projectiveLayout(s.camera, s.light, 4);
  const RectifiedMap exactMap =
      castRectifiedMap(projective, 512, 256, [&](const LightRay& r) { return planeHit(s.plane, r); });
  const MarchResult projectiveMarch = minMaxMarch(exactMap, s.depth, s.camera, s.light, s.medium);
  report("projective (exact map), min/max march vs closed form",
         rgbMetrics(projectiveMarch.scattering, s.truth));
  const ImageMetrics vsProjective = rgbMetrics(fallback.scattering, projectiveMarch.scattering);
  report("fallback vs projective (marches)", vsProjective);

  // Measured (relative RMSE, RGB): fallback vs closed form 4.2e-3, projective vs closed form 3.7e-3,
  // fallback vs projective 5.8e-3.
  ImageTolerance t;
  t.relativeRmse = 0.01;
  CHECK(checkImage(rgb(fallback.scattering), rgb(s.truth), t, "epipolar_fallback_vs_truth"));
  CHECK(checkImage(rgb(fallback.scattering), rgb(projectiveMarch.scattering), t,
                   "epipolar_fallback_vs_projective"));

  // prefilter/'s CPU prefilter and evaluation run unchanged on the epipolar map (weights: constant world
  // step along each row's reference ray).
  const FilteredBasis basis = prefilter(fallbackMap, s.medium);
  const Image prefiltered = evaluate(basis, s.depth, s.camera, s.light, s.medium);
  const Image projectivePrefiltered =
      evaluate(prefilter(exactMap, s.medium), s.depth, s.camera, s.light, s.medium);
  const ImageMetrics pf = rgbMetrics(prefiltered, s.truth);
  report("epipolar fallback, prefiltered (M = 32, RGBA8) vs closed form", pf);
  report("projective, prefiltered vs closed form", rgbMetrics(projectivePrefiltered, s.truth));
  const ImageMetrics pfVsProjective = rgbMetrics(prefiltered, projectivePrefiltered);
  report("fallback vs projective (prefiltered)", pfVsProjective);
  report(
      "fallback prefiltered vs the brute-force march of the same map",
      rgbMetrics(prefiltered, bruteForceMarch(fallbackMap, s.depth, s.camera, s.light, s.medium).scattering));
  // Measured: 1.26e-2 vs closed form (projective: 0.91e-2), 1.04e-2 vs the projective prefiltered image,
  // 1.33e-2 vs the march of the same map. With the default 4 logarithmic regions; uniform regions give
  // 2.6e-2 vs the march, one region 4.9e-2 (the grey transmittance weights of the coloured medium and the
  // one reference ray per row matter less over shorter regions, as for the projective splits).
  t.relativeRmse = 0.02;
  CHECK(checkImage(rgb(prefiltered), rgb(projectivePrefiltered), t,
                   "epipolar_fallback_prefiltered_vs_projective"));
}

TEST_CASE("epipolar fallback: a standard shadow map resampled into the projective layout") {
  const Setup s;
  const auto projective = projectiveLayout(s.camera, s.light, 4);
  const RectifiedMap resampled = resampleShadowMap(projective, 512, 256, s.shadow, s.lightMatrix);
  const RectifiedMap exact =
      castRectifiedMap(projective, 512, 256, [&](const LightRay& r) { return planeHit(s.plane, r); });
  // The resampled depths are the exact ones up to the standard map's point sampling: the plane's depth at
  // the nearest standard texel centre instead of at the light ray.
  // Most texels agree exactly (both 0, both 1, or the same plane depth to float precision). The others
  // (3.9%) are light rays that meet the plane outside the standard map's depth range (the light box spans
  // y in [-1, 40] around the visible scene, the rectified map the whole frustum, partly under the ground):
  // the standard map stores the clamped range end there. The marches below show they do not matter.
  double median = 0.0;
  std::vector<double> d;
  int switched = 0;
  for (int j = 0; j < 256; ++j)
    for (int i = 0; i < 512; ++i) {
      d.push_back(std::abs(resampled.depth.at(i, j) - exact.depth.at(i, j)));
      switched += d.back() > 0.01;
    }
  std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
  median = d[d.size() / 2];
  MESSAGE("resampled vs exact projective map: median |depth difference| "
          << median << ", " << switched << " of 131072 texels differ by > 0.01");
  CHECK(median < 1e-4);
  CHECK(switched < 131072 / 20);
  const MarchResult march = minMaxMarch(resampled, s.depth, s.camera, s.light, s.medium);
  const ImageMetrics m = rgbMetrics(march.scattering, s.truth);
  report("projective layout, resampled map, min/max march vs closed form", m);
  ImageTolerance t;
  t.relativeRmse = 0.01; // measured 4.2e-3
  CHECK(checkImage(rgb(march.scattering), rgb(s.truth), t, "epipolar_resampled_projective_vs_truth"));
}

TEST_CASE("epipolar fallback: blockers between the light and the frustum are clamped, not lost") {
  // A plane far up the light, outside every slice's psi range: its depth is < 0 and must clamp to 0 so
  // that it shadows every ray of the texel (Sec. 4.1).
  const Setup s;
  HalfSpace high;
  high.normal = -s.light.direction(); // facing the light: everything behind it (the whole scene) is shadowed
  high.point = s.camera.position() - 500.0 * s.light.direction(); // psi <= atan(80 / 500): above every slice
  const glm::dmat4 M =
      scenes::standardLightClipFromWorld(s.light, {-600.0, -1.0, -600.0}, {600.0, 600.0, 600.0});
  const Image shadow = halfSpaceShadowMap(high, M, 256);
  const auto layout = std::make_shared<const EpipolarLayout>(s.camera, s.light, 160, 90);
  const RectifiedMap map = resampleShadowMap(layout, 128, layout->sliceCount(), shadow, M);
  int zero = 0;
  for (float v : map.depth.data())
    zero += v == 0.0f;
  CHECK(zero == static_cast<int>(map.depth.pixelCount()));
  const MarchResult r = bruteForceMarch(map, s.depth, s.camera, s.light, s.medium);
  CHECK(rgbMetrics(r.scattering, Image(160, 90, 4)).maxAbsError == 0.0); // everything shadowed
}

TEST_CASE("epipolar fallback: bad input to the resampling gets a named InvalidArgument") {
  const Setup s;
  const auto layout = std::make_shared<const EpipolarLayout>(s.camera, s.light, 160, 90);
  const int H = layout->sliceCount();
  const Image shadow(64, 64, 1, 1.0f);
  CHECK(invalidParameter([&] { resampleShadowMap(nullptr, 64, H, shadow, s.lightMatrix); }) ==
        "resampleShadowMap.layout");
  CHECK(invalidParameter([&] { resampleShadowMap(layout, 0, H, shadow, s.lightMatrix); }) ==
        "resampleShadowMap.size");
  CHECK(invalidParameter([&] { resampleShadowMap(layout, 64, H + 1, shadow, s.lightMatrix); }) ==
        "resampleShadowMap.size");
  CHECK(invalidParameter([&] { resampleShadowMap(layout, 64, H, Image(), s.lightMatrix); }) == "shadowDepth");
  Image nan = shadow;
  nan.at(3, 3) = std::numeric_limits<float>::quiet_NaN();
  CHECK(invalidParameter([&] { resampleShadowMap(layout, 64, H, nan, s.lightMatrix); }) == "shadowDepth");
  CHECK(invalidParameter([&] { resampleShadowMap(layout, 64, H, shadow, s.camera.clipFromWorld()); }) ==
        "lightClipFromWorld"); // perspective
  const glm::dmat4 wrongDirection = analyticLightMatrix(DirectionalLight(glm::dvec3(0.0, -1.0, 0.0)));
  CHECK(invalidParameter([&] { resampleShadowMap(layout, 64, H, shadow, wrongDirection); }) ==
        "lightClipFromWorld");
}

TEST_CASE("epipolar fallback: the depth warp moves resolution, never the shadows (march identity)") {
  // The shadow test compares depths of one slice and g(psi) is increasing, so the exact visibility of the
  // brute-force march cannot depend on the warp: the same image with e = 0 (linear psi) and e = 0.3.
  const Setup s;
  // Light from ahead and above: the epipole on screen, the rays next to it nearly parallel to the light.
  const DirectionalLight ahead(-glm::normalize(s.camera.forward() + 0.3 * s.camera.up()),
                               s.light.irradiance());
  const glm::dmat4 lightMatrix = analyticLightMatrix(ahead);
  const Image shadow = halfSpaceShadowMap(s.plane, lightMatrix, 1024);
  std::vector<Image> images;
  for (const double warp : {0.0, 0.3, 2.0}) {
    EpipolarOptions o;
    o.depthWarp = warp;
    const auto layout = std::make_shared<const EpipolarLayout>(s.camera, ahead, 160, 90, o);
    CHECK(layout->epipoleOnScreen());
    // Round trip and ends of every slice's depth mapping.
    for (int j = 0; j < layout->sliceCount(); j += 37) {
      const EpipolarLayout::Slice& sl = layout->slices()[static_cast<std::size_t>(j)];
      CHECK(layout->depthOfPsi(j, sl.psiMin) == doctest::Approx(0.0).epsilon(1e-12));
      CHECK(layout->depthOfPsi(j, sl.psiMax) == doctest::Approx(1.0).epsilon(1e-12));
      for (const double d : {0.01, 0.3, 0.77})
        CHECK(layout->depthOfPsi(j, layout->psi(j, d)) == doctest::Approx(d).epsilon(1e-12));
    }
    const RectifiedMap map = resampleShadowMap(layout, 256, layout->sliceCount(), shadow, lightMatrix);
    images.push_back(bruteForceMarch(map, s.depth, s.camera, ahead, s.medium).scattering);
  }
  // Not bit-identical: the distances along a ray use sin(psi) of the unwarped depth (double rounding).
  CHECK(maxRelativeDifference(images[1], images[0], 1e-6) < 1e-9);
  CHECK(maxRelativeDifference(images[2], images[0], 1e-6) < 1e-9);
}
