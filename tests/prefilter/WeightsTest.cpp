// Prefilter weights (Klehm et al. 2014, Sec. 3.1-3.2 Eq. 11, Sec. 4.2 Eq. 12; weights.h) and the distance
// profiles of the rectified map contract (rectified_map.h) they are computed from.
#include <crep/core/error.h>
#include <crep/prefilter/weights.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

using namespace crep;

namespace {

/// A 60 degree camera (near 0.1, far 80) and a light from the side: a strongly projective layout.
ProjectiveLayout sideLitLayout(int splits = 4, SplitScheme scheme = SplitScheme::Logarithmic) {
  const Camera camera =
      Camera::lookAt({0, 2, 0}, {0, 1.5, -10}, {0, 1, 0}, glm::radians(60.0), 16.0 / 9.0, 0.1, 80.0);
  const DirectionalLight light(glm::dvec3(1.0, -1.0, -0.3));
  RectifyOptions options;
  options.splits = splits;
  options.scheme = scheme;
  Rectification r = rectify(camera, light, options);
  REQUIRE(r.projective());
  return ProjectiveLayout(std::move(r));
}

std::vector<double> weightsOf(WeightMode mode, double s, const DistanceProfile& p, int n) {
  std::vector<double> w(static_cast<std::size_t>(n));
  regionWeights(mode, s, p, n, w);
  return w;
}

std::vector<double> tauOf(WeightMode mode, const DistanceProfile& p, int n) {
  std::vector<double> t(static_cast<std::size_t>(n) + 1);
  regionDistances(mode, p, n, t);
  return t;
}

} // namespace

TEST_CASE("weights: DistanceProfile evaluates t(u), its difference from t(0) and sub-ranges") {
  const DistanceProfile p{2.0, 0.5, 1.5, -0.7};
  REQUIRE(p.valid());
  for (int i = 0; i <= 10; ++i) {
    const double u = i / 10.0;
    CHECK(p(u) == doctest::Approx((2.0 + 0.5 * u) / (1.5 - 0.7 * u)).epsilon(1e-15));
    CHECK(p.fromStart(u) == doctest::Approx(p(u) - p(0.0)).epsilon(1e-13));
    const DistanceProfile s = p.sub(0.25, 0.75);
    CHECK(s(u) == doctest::Approx(p(0.25 + 0.5 * u)).epsilon(1e-14));
  }
  CHECK(std::isinf(DistanceProfile{1.0, 0.0, 1.0, -2.0}(0.75)));
  CHECK_FALSE(DistanceProfile{1.0, 0.0, 1.0, -2.0}.valid());
}

TEST_CASE("weights: the projective layout's profiles are the rectification's closed-form distances") {
  const ProjectiveLayout layout = sideLitLayout();
  const Rectification& r = layout.rectification();
  const int K = layout.regionCount();
  double worst = 0.0;
  for (const double row : {0.01, 0.3, 0.5, 0.77, 0.99})
    for (int k = 0; k < K; ++k) {
      const DistanceProfile ref = layout.referenceProfile(row, k);
      const DistanceProfile ray = layout.rayProfile(row, 0.2, k);
      REQUIRE(ref.valid());
      for (int i = 0; i <= 8; ++i) {
        const double u = i / 8.0, column = (k + u) / K;
        const double t = r.referenceDistance(row, column);
        worst = std::max(worst, std::abs(ref(u) - t) / t);
        const double tr = r.rayDistance(row, 0.2, column);
        worst = std::max(worst, std::abs(ray(u) - tr) / tr);
      }
    }
  MESSAGE("worst relative difference profile vs Rectification distances: " << worst);
  CHECK(worst < 1e-12);
  // The profile's distance is the world distance along the ray to the point it maps to.
  const double row = 0.4, depth = layout.referenceDepth(row);
  const glm::dvec3 dir = layout.viewRayDirection(row, depth);
  const double t = layout.referenceProfile(row, 2)(0.3);
  const RectPoint p = layout.toRectified(layout.origin() + t * dir);
  CHECK(p.split == 2);
  CHECK(p.splitColumn == doctest::Approx(0.3).epsilon(1e-9));
  CHECK(p.row == doctest::Approx(row).epsilon(1e-9));
}

TEST_CASE("weights: partial sums equal 1 - exp(-sigma tau_s) for the exponential modes") {
  const ProjectiveLayout layout = sideLitLayout();
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  double worst = 0.0;
  for (const WeightMode mode : {WeightMode::Exact, WeightMode::ConstantStep, WeightMode::ConstantRatio})
    for (int trial = 0; trial < 40; ++trial) {
      const DistanceProfile p = layout.referenceProfile(uni(rng), trial % layout.regionCount());
      const double s = std::pow(10.0, -3.0 + 4.0 * uni(rng)); // 1e-3 .. 10 per world unit
      const int n = 7 + trial * 3;
      const auto w = weightsOf(mode, s, p, n);
      const auto tau = tauOf(mode, p, n);
      double sum = 0.0;
      for (int q = 0; q < n; ++q) {
        sum += w[static_cast<std::size_t>(q)];
        const double expect = -std::expm1(-s * tau[static_cast<std::size_t>(q) + 1]);
        worst = std::max(worst, std::abs(sum - expect) / std::max(expect, 1e-300));
      }
    }
  MESSAGE("worst relative error of the partial sums: " << worst);
  CHECK(worst < 1e-12);
}

TEST_CASE("weights: exact weights along a projective row are positive, sums and distances monotone") {
  const ProjectiveLayout layout = sideLitLayout();
  for (int k = 0; k < layout.regionCount(); ++k) {
    const DistanceProfile p = layout.referenceProfile(0.5, k);
    const int n = 64;
    const auto tau = tauOf(WeightMode::Exact, p, n);
    const auto w = weightsOf(WeightMode::Exact, 0.05, p, n);
    std::vector<double> mix(static_cast<std::size_t>(n));
    regionMixFactors(WeightMode::Exact, 0.05, p, n, mix);
    CHECK(mix[0] == 1.0);
    for (int i = 0; i < n; ++i) {
      const auto ii = static_cast<std::size_t>(i);
      CHECK(tau[ii + 1] > tau[ii]);
      CHECK(w[ii] > 0.0);
      CHECK(mix[ii] > 0.0);
      CHECK(mix[ii] <= 1.0);
      // The projective row's texels grow along the ray (columns spend texels like a depth buffer).
      if (i > 0) CHECK(tau[ii + 1] - tau[ii] > tau[ii] - tau[ii - 1]);
    }
  }
  // Constant step: the exponential weights decrease geometrically.
  const DistanceProfile constant{0.0, 10.0, 1.0, 0.0};
  const auto w = weightsOf(WeightMode::Exact, 0.3, constant, 20);
  for (std::size_t i = 1; i < w.size(); ++i)
    CHECK(w[i] / w[i - 1] == doctest::Approx(std::exp(-0.3 * 10.0 / 20)).epsilon(1e-12));
}

TEST_CASE("weights: exact, constant-step and constant-ratio coincide when the step is constant") {
  const DistanceProfile constant{3.0, 12.5, 1.0, 0.0}; // a constant-step layout: t = 3 + 12.5 u
  for (const int n : {1, 2, 3, 16, 100}) {
    for (const double s : {0.0, 1e-9, 0.02, 1.0, 30.0}) {
      const auto e = weightsOf(WeightMode::Exact, s, constant, n);
      const auto c = weightsOf(WeightMode::ConstantStep, s, constant, n);
      const auto r = weightsOf(WeightMode::ConstantRatio, s, constant, n);
      std::vector<double> me(static_cast<std::size_t>(n)), mc(me), mr(me);
      regionMixFactors(WeightMode::Exact, s, constant, n, me);
      regionMixFactors(WeightMode::ConstantStep, s, constant, n, mc);
      regionMixFactors(WeightMode::ConstantRatio, s, constant, n, mr);
      for (std::size_t i = 0; i < e.size(); ++i) {
        CHECK(c[i] == doctest::Approx(e[i]).epsilon(1e-12));
        CHECK(r[i] == doctest::Approx(e[i]).epsilon(1e-12));
        CHECK(mc[i] == doctest::Approx(me[i]).epsilon(1e-12));
        CHECK(mr[i] == doctest::Approx(me[i]).epsilon(1e-12));
      }
    }
  }
}

TEST_CASE("weights: sigma -> 0 reaches the length-weighted limit without dividing by zero") {
  const ProjectiveLayout layout = sideLitLayout();
  const DistanceProfile p = layout.referenceProfile(0.3, 1);
  const int n = 50;
  const auto tau = tauOf(WeightMode::Exact, p, n);
  std::vector<double> m0(static_cast<std::size_t>(n)), mSmall(m0), avg(m0);
  regionMixFactors(WeightMode::Exact, 0.0, p, n, m0);
  regionMixFactors(WeightMode::Exact, 1e-10, p, n, mSmall);
  regionMixFactors(WeightMode::AverageVisibility, 0.0, p, n, avg);
  for (int i = 0; i < n; ++i) {
    const auto ii = static_cast<std::size_t>(i);
    CHECK(std::isfinite(m0[ii]));
    CHECK(m0[ii] == doctest::Approx((tau[ii + 1] - tau[ii]) / tau[ii + 1]).epsilon(1e-12));
    CHECK(mSmall[ii] == doctest::Approx(m0[ii]).epsilon(1e-8));
    CHECK(avg[ii] == doctest::Approx(1.0 / (i + 1)).epsilon(1e-15));
  }
  CHECK(regionWeightTotal(WeightMode::Exact, 0.0, p, n, 0.5) ==
        doctest::Approx(p.fromStart(0.5)).epsilon(1e-14));
  CHECK(regionWeightTotal(WeightMode::Exact, 2.0, p, n, 0.5) ==
        doctest::Approx(-std::expm1(-2.0 * p.fromStart(0.5)) / 2.0).epsilon(1e-14));
  CHECK(oneMinusExpOverX(0.0) == 1.0);
  CHECK(oneMinusExpOverX(1e-6) == doctest::Approx(-std::expm1(-1e-6) / 1e-6).epsilon(1e-15));
  CHECK(oneMinusExpOverX(std::numeric_limits<double>::infinity()) == 0.0);
}

TEST_CASE("weights: constant-ratio error against the exact weights on a projective row (reported)") {
  // Eq. 12 assumes the world step grows by a constant factor per texel; a projective map preserves cross
  // ratios, not step ratios, so the assumption drifts along the row. Reported for the side-lit camera,
  // 4 logarithmic splits, 1024 x 512 map (256 texels per region), sigma = 0.05 / world unit, row 0.5:
  // measured max |sum_{i<q} w'_i - sum_{i<q} w_i| over the region (absolute, the sums are in [0, 1]) and
  // the worst relative error of the region's total length. Measured: 0.256 and 57% (the step ratio from
  // the first three texels, 1.0066, grows to 1.04 by the region's end); constant-step (one mean step per
  // region): 0.49. In the half-space ground truth (PrefilterTest.cpp (b)) this gives relative RMSE 5.3%
  // (constant-ratio) and 11.8% (constant-step) against 0.91% with the exact weights.
  const ProjectiveLayout layout = sideLitLayout();
  const int n = 256;
  const double s = 0.05;
  double worstSum = 0.0, worstLength = 0.0, worstSumStep = 0.0;
  for (int k = 0; k < layout.regionCount(); ++k) {
    const DistanceProfile p = layout.referenceProfile(0.5, k);
    const auto te = tauOf(WeightMode::Exact, p, n), tr = tauOf(WeightMode::ConstantRatio, p, n);
    const auto tc = tauOf(WeightMode::ConstantStep, p, n);
    for (int q = 1; q <= n; ++q) {
      const auto qq = static_cast<std::size_t>(q);
      worstSum = std::max(worstSum, std::abs(std::expm1(-s * tr[qq]) - std::expm1(-s * te[qq])));
      worstSumStep = std::max(worstSumStep, std::abs(std::expm1(-s * tc[qq]) - std::expm1(-s * te[qq])));
    }
    worstLength = std::max(worstLength,
                           std::abs(tr[static_cast<std::size_t>(n)] / te[static_cast<std::size_t>(n)] - 1.0));
    MESSAGE("region " << k << ": length " << te[static_cast<std::size_t>(n)] << " exact, "
                      << tr[static_cast<std::size_t>(n)] << " constant-ratio");
  }
  MESSAGE("constant-ratio vs exact: worst partial-sum error "
          << worstSum << ", worst region length error " << worstLength
          << "; constant-step vs exact: " << worstSumStep);
  CHECK(worstSum > 1e-6); // it is an approximation
  CHECK(worstSum < 0.5);
}

TEST_CASE("weights: invalid arguments are named") {
  const DistanceProfile p{0.0, 1.0, 1.0, 0.0};
  std::vector<double> w(4);
  CHECK_THROWS_AS(regionWeights(WeightMode::Exact, -1.0, p, 4, w), InvalidArgument);
  CHECK_THROWS_AS(regionWeights(WeightMode::Exact, std::nan(""), p, 4, w), InvalidArgument);
  CHECK_THROWS_AS(regionWeights(WeightMode::Exact, 1.0, p, 5, w), InvalidArgument);
  CHECK_THROWS_AS(regionWeights(WeightMode::Exact, 1.0, p, 0, std::span<double>()), InvalidArgument);
  const Medium medium({.mieScattering = glm::dvec3(0.1, 0.2, 0.3), .absorption = glm::dvec3(0.3, 0.0, 0.0)});
  CHECK(weightExtinction(medium) == doctest::Approx(0.3));
  CHECK(std::string(weightModeToken(WeightMode::Exact)) == "exact");
}
