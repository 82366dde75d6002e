// VisibilityReconstruction::Exact (prefilter.h), CPU reference: its region table is the exact weighted
// average of the depth test at each sample depth; without an occluder it is the closed form; on the analytic
// scene with the ground in the map (the receiver's own texels, the case the truncated series gets wrong) it
// is within the error budget's figure of the closed form, where the series is not (docs/MEASUREMENTS.md,
// "Error budget").
#include <crep/core/error.h>
#include <crep/prefilter/prefilter.h>
#include <crep/prefilter/weights.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/ray.h>
#include <crep/scatter/rectified_march.h>

#include "common/analytic_reference.h"
#include "common/error_checks.h"

#include <doctest/doctest.h>

#include <cmath>
#include <optional>
#include <vector>

using namespace crep;

namespace {

/// The analytic scene's casters as an engine's map holds them: the occluder's plane and the ground.
RectifiedMap groundAndPlaneMap(std::shared_ptr<const ProjectiveLayout> layout, const test::HalfSpace& plane,
                               int size) {
  return castRectifiedMap(layout, size, size, [&](const LightRay& ray) {
    double t = 1e300;
    if (const double dn = glm::dot(plane.normal, ray.direction); dn > 0.0)
      t = glm::dot(plane.normal, plane.point - ray.origin) / dn;
    if (ray.direction.y < 0.0) t = std::min(t, -ray.origin.y / ray.direction.y);
    return t == 1e300 ? std::nullopt : std::optional<glm::dvec3>(ray.origin + t * ray.direction);
  });
}

PrefilterOptions exactOptions() {
  PrefilterOptions o;
  o.regionsPerSplit = 2;
  o.reconstruction = VisibilityReconstruction::Exact;
  return o;
}

} // namespace

TEST_CASE("prefilter, exact reconstruction: the region table is the weighted average of the depth test") {
  // Identity: V(j, r, s) = sum_i w_i [z_i >= s / (Z - 1)] / sum_i w_i over region r of row j ([z_i > 0] for
  // s = 0), the weights w_i from weights.h along the region's reference ray (regionWeights), independent of
  // the mix factors. The map has texels at exactly 0 (clamped casters) and 1 (empty).
  const Camera camera = test::groundCamera();
  const DirectionalLight light = test::sideLight();
  const Medium medium = test::colouredMedium();
  const auto layout = test::projectiveLayout(camera, light);
  Image runs = test::randomRunsDepth(128, 16, 46);
  for (int j = 0; j < 16; ++j)
    runs.at(5 * j % 128, j) = 0.0f; // a clamped caster in every row
  const RectifiedMap map = makeRectifiedMap(layout, runs);
  const FilteredBasis basis = prefilter(map, medium, exactOptions());
  CHECK(basis.texels.empty());
  REQUIRE(basis.depth.size() == 128u * 16u);
  const int Z = 9, R = basis.regions, n = basis.regionWidth();
  const std::vector<double> table = visibilityTable(basis, Z, RingingFilter::None);
  double worst = 0.0;
  std::vector<double> w(static_cast<std::size_t>(n));
  for (int j = 0; j < basis.height; ++j)
    for (int r = 0; r < R; ++r) {
      regionWeights(basis.weights, basis.extinction, basis.profiles[static_cast<std::size_t>(j * R + r)], n,
                    w);
      for (int s = 0; s < Z; ++s) {
        double lit = 0.0, total = 0.0;
        for (int i = 0; i < n; ++i) {
          total += w[static_cast<std::size_t>(i)];
          const double z = map.depth.at(r * n + i, j);
          if (s == 0 ? z > 0.0 : z >= static_cast<double>(s) / (Z - 1)) lit += w[static_cast<std::size_t>(i)];
        }
        worst = std::max(worst, std::abs(table[static_cast<std::size_t>((j * R + r) * Z + s)] - lit / total));
      }
    }
  MESSAGE("largest difference from the direct weighted sum: " << worst);
  CHECK(worst < 1e-6); // the cumulative weights are stored as float
}

TEST_CASE("prefilter, exact reconstruction: without an occluder it is the closed form") {
  // The series rings against the empty texels here (0.84% with M = 32, PrefilterTest (a)); every texel is
  // lit, so the exact prefix is 1. What remains is the scattering prefix table's interpolation of whole
  // regions between its sample rays (measured 1.5e-5).
  const Camera camera = test::groundCamera();
  const DirectionalLight light = test::sideLight();
  const Medium medium = test::colouredMedium();
  const auto layout = test::projectiveLayout(camera, light);
  const RectifiedMap map = castRectifiedMap(layout, 256, 128, [](const LightRay&) { return std::nullopt; });
  const Image depth = test::groundDepth(camera, 160, 90);
  const Image truth = unshadowedScattering(depth, camera, light, medium);
  PrefilterOptions o = exactOptions();
  o.regionsPerSplit = 1;
  const ImageMetrics m =
      test::rgbMetrics(evaluate(prefilter(map, medium, o), depth, camera, light, medium), truth);
  test::report("exact, no occluder, vs closed form", m);
  CHECK(m.relativeRmse < 1e-4);
}

TEST_CASE(
    "prefilter, exact reconstruction: the ground in the map no longer darkens the rays (analytic scene)") {
  // The error budget's side case at test size: 160 x 90, a 512^2 map of 8 splits x 2 regions, the ground and
  // the occluder's plane as casters. Measured: Fourier (M = 32) 1.49%, exact 0.20% (nearest texel 0.25%), the
  // brute-force march over the same map 0.24% (per-texel visibility with the ray's own weights, nearest row).
  const Camera camera = test::groundCamera();
  const DirectionalLight light = test::sideLight();
  const Medium medium = test::colouredMedium();
  RectifyOptions ro;
  ro.splits = 8;
  Rectification rect = rectify(camera, light, ro);
  REQUIRE(rect.projective());
  const auto layout = std::make_shared<const ProjectiveLayout>(std::move(rect));
  test::HalfSpace plane;
  const RectifiedMap map = groundAndPlaneMap(layout, plane, 512);
  const Image depth = test::groundDepth(camera, 160, 90);
  const Image truth = test::closedForm(depth, camera, light, medium, plane);
  PrefilterOptions fourier;
  fourier.regionsPerSplit = 2;
  const ImageMetrics mf =
      test::rgbMetrics(evaluate(prefilter(map, medium, fourier), depth, camera, light, medium), truth);
  const FilteredBasis exact = prefilter(map, medium, exactOptions());
  const ImageMetrics me = test::rgbMetrics(evaluate(exact, depth, camera, light, medium), truth);
  EvaluateOptions nearest;
  nearest.sampling = Sampling::Nearest;
  const ImageMetrics mn = test::rgbMetrics(evaluate(exact, depth, camera, light, medium, nearest), truth);
  const ImageMetrics mb =
      test::rgbMetrics(bruteForceMarch(map, depth, camera, light, medium).scattering, truth);
  test::report("Fourier M = 32 vs closed form", mf);
  test::report("exact vs closed form", me);
  test::report("exact, nearest texel, vs closed form", mn);
  test::report("brute-force march over the same map vs closed form", mb);
  CHECK(me.relativeRmse < 0.25 * mf.relativeRmse);
  CHECK(me.relativeRmse < 0.003);
  CHECK(mn.relativeRmse < 0.0035);
}

TEST_CASE("prefilter, exact reconstruction: bad option and inconsistent basis are named") {
  PrefilterOptions o;
  o.reconstruction = static_cast<VisibilityReconstruction>(7);
  CHECK(test::invalidParameter([&] { validate(o); }) == "PrefilterOptions.reconstruction");
  const Camera camera = test::groundCamera();
  const auto layout = test::projectiveLayout(camera, test::sideLight());
  const RectifiedMap map = makeRectifiedMap(layout, test::randomRunsDepth(64, 8, 3));
  FilteredBasis b = prefilter(map, test::colouredMedium(), exactOptions());
  b.weight.pop_back();
  CHECK(test::invalidParameter([&] { visibilityTable(b, 4, RingingFilter::None); }) == "FilteredBasis");
}
