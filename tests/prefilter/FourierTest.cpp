// Fourier expansion of the shadow test (Klehm et al. 2014, Eq. 8-9): the identity with the independently
// computed sine series of the step, convergence with M, the Gibbs bound, the float path, and the
// depth margin that keeps the period-2 jumps away (fourier.h).
#include <crep/core/error.h>
#include <crep/prefilter/fourier.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

using namespace crep;

namespace {

/// The truncated Fourier series of the period-2 square wave H(d) - 0.5 (d = zTexel - zRay), summed
/// directly from its sine series: sum_{k=1}^{M/2} 2 / (pi (2k - 1)) sin(pi (2k - 1) d).
double sineSeries(double d, int bases) {
  double s = 0.0;
  for (int k = 1; k <= bases / 2; ++k) {
    const double ck = std::numbers::pi * (2 * k - 1);
    s += 2.0 / ck * std::sin(ck * d);
  }
  return 0.5 + s;
}

double stepOf(double d) {
  return d > 0.0 ? 1.0 : (d < 0.0 ? 0.0 : 0.5);
}

} // namespace

TEST_CASE("fourier: 0.5 + a(zr).B(zi) equals the sine series of the step to 1e-12 (double)") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  double worst = 0.0;
  for (int bases = 4; bases <= 128; bases += 2) {
    for (int trial = 0; trial < 200; ++trial) {
      const double zr = uni(rng), zi = uni(rng);
      const double v = fourierVisibility(zr, zi, bases);
      worst = std::max(worst, std::abs(v - sineSeries(zi - zr, bases)));
    }
  }
  MESSAGE("worst |recurrence - direct| over M = 4..128: " << worst);
  CHECK(worst < 1e-12);
}

TEST_CASE("fourier: coefficients and basis match Eq. 8 term by term, double and float") {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uni(-1.0, 2.0); // also outside [0, 1]: the recurrence is general
  for (const int M : {4, 6, 32, 128}) {
    std::vector<double> a(static_cast<std::size_t>(M)), b(static_cast<std::size_t>(M));
    std::vector<float> af(static_cast<std::size_t>(M)), bf(static_cast<std::size_t>(M));
    double worstD = 0.0, worstF = 0.0;
    for (int trial = 0; trial < 100; ++trial) {
      const double z = uni(rng);
      fourierCoefficients(z, std::span<double>(a));
      fourierBasis(z, std::span<double>(b));
      fourierCoefficients(static_cast<float>(z), std::span<float>(af));
      fourierBasis(static_cast<float>(z), std::span<float>(bf));
      for (int k = 1; k <= M / 2; ++k) {
        const double ck = std::numbers::pi * (2 * k - 1);
        const double expect[4] = {2.0 * std::cos(ck * z) / ck, -2.0 * std::sin(ck * z) / ck, std::sin(ck * z),
                                  std::cos(ck * z)};
        const std::size_t i0 = static_cast<std::size_t>(2 * k - 2), i1 = i0 + 1;
        const double got[4] = {a[i0], a[i1], b[i0], b[i1]};
        const double gotF[4] = {af[i0], af[i1], bf[i0], bf[i1]};
        for (int q = 0; q < 4; ++q) {
          worstD = std::max(worstD, std::abs(got[q] - expect[q]));
          worstF = std::max(worstF, std::abs(gotF[q] - expect[q]));
        }
      }
    }
    MESSAGE("M = " << M << ": worst term error double " << worstD << ", float " << worstF);
    CHECK(worstD < 1e-12);
    // float: the argument pi z itself carries ~1e-7 relative error, amplified by (M - 1) in the top
    // harmonic, plus the recurrence's ~M float epsilons.
    CHECK(worstF < 2e-5 * M);
  }
}

TEST_CASE("fourier: the reconstruction error of the step decreases with M") {
  // L1 error of the truncated series against the step over d in [-1, 1] (midpoint rule, 20000 samples).
  double previous = 1e9;
  for (const int M : {4, 8, 16, 32, 64, 128}) {
    double l1 = 0.0;
    const int samples = 20000;
    for (int i = 0; i < samples; ++i) {
      const double d = -1.0 + 2.0 * (i + 0.5) / samples;
      l1 += std::abs(fourierVisibility(0.0, d, M) - stepOf(d)) * (2.0 / samples);
    }
    MESSAGE("M = " << M << ": L1 error of the step over d in [-1, 1] = " << l1);
    CHECK(l1 < previous);
    previous = l1;
  }
}

TEST_CASE("fourier: Gibbs overshoot stays within its known bound") {
  // The partial sums of a square wave overshoot each jump by a fraction of the jump that decreases with
  // the number of harmonics N = M / 2 toward the Gibbs constant Si(pi) / pi - 1/2 = 8.949%; measured:
  // 10.02% (M = 4), 9.21% (8), 9.01% (16), 8.965% (32), 8.953% (64), 8.950% (128), i.e. within 0.05 / N^2
  // of the constant. Both sides of the jump (lit side above 1, shadowed side below 0) are symmetric.
  const double gibbs = 0.0894898722;
  double previous = 1.0;
  for (const int M : {4, 8, 16, 32, 64, 128}) {
    const int N = M / 2;
    double overshoot = 0.0, undershoot = 0.0;
    const int samples = 200000;
    for (int i = 0; i <= samples; ++i) {
      const double d = static_cast<double>(i) / samples;
      overshoot = std::max(overshoot, fourierVisibility(0.0, d, M) - 1.0);
      undershoot = std::max(undershoot, -fourierVisibility(0.0, -d, M));
    }
    MESSAGE("M = " << M << ": overshoot " << overshoot << ", undershoot " << undershoot << " of the jump");
    CHECK(overshoot >= gibbs - 1e-6);
    CHECK(overshoot <= gibbs + 0.05 / (N * N));
    CHECK(undershoot == doctest::Approx(overshoot).epsilon(1e-9));
    CHECK(overshoot < previous);
    previous = overshoot;
  }
}

TEST_CASE("fourier: Lanczos sigma factors damp the ringing (evaluation default)") {
  // sigma_k = sinc(pi (2k - 1) / M). Measured overshoot of the damped series: 1.19% of the jump for
  // M = 32 (paper's Eq. 8: 8.97%), and the worst error farther than 3 / M from the jumps drops by an
  // order of magnitude or more.
  for (const int M : {8, 32, 128}) {
    std::vector<double> a(static_cast<std::size_t>(M)), b(static_cast<std::size_t>(M)), a0(a);
    double overshoot = 0.0, farPlain = 0.0, farDamped = 0.0;
    const int samples = 20000;
    for (int i = 0; i <= samples; ++i) {
      const double d = static_cast<double>(i) / samples; // lit side, zr = 0.25, zi = 0.25 + d (mod period)
      fourierCoefficients(0.25, std::span<double>(a));
      a0 = a;
      applyRingingFilter(RingingFilter::Lanczos, std::span<double>(a));
      fourierBasis(0.25 + d, std::span<double>(b));
      double v = 0.5, v0 = 0.5;
      for (std::size_t j = 0; j < a.size(); ++j) {
        v += a[j] * b[j];
        v0 += a0[j] * b[j];
      }
      overshoot = std::max(overshoot, v - 1.0);
      if (d > 3.0 / M && d < 1.0 - 3.0 / M) {
        farPlain = std::max(farPlain, std::abs(v0 - 1.0));
        farDamped = std::max(farDamped, std::abs(v - 1.0));
      }
    }
    MESSAGE("M = " << M << ": Lanczos overshoot " << overshoot
                   << "; worst error beyond 3/M of the jumps: Eq. 8 " << farPlain << ", Lanczos "
                   << farDamped);
    CHECK(overshoot < 0.0125);
    CHECK(farDamped < farPlain / 5.0);
  }
  CHECK(ringingFactor(RingingFilter::None, 3, 32) == 1.0);
  CHECK(ringingFactor(RingingFilter::Lanczos, 1, 32) ==
        doctest::Approx(std::sin(std::numbers::pi / 32) / (std::numbers::pi / 32)));
  std::vector<float> af(32, 1.0f);
  applyRingingFilter(RingingFilter::Lanczos, std::span<float>(af));
  CHECK(af[31] == doctest::Approx(ringingFactor(RingingFilter::Lanczos, 16, 32)));
  CHECK(af[30] == af[31]);
}

TEST_CASE("fourier: clamped visibility stays in [0, 1] and the basis in [-1, 1]") {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::vector<double> b(32);
  for (int trial = 0; trial < 10000; ++trial) {
    const double zr = uni(rng), zi = uni(rng);
    const double v = std::clamp(fourierVisibility(zr, zi, 32), 0.0, 1.0);
    REQUIRE(v >= 0.0);
    REQUIRE(v <= 1.0);
    fourierBasis(zi, std::span<double>(b));
    for (const double x : b)
      REQUIRE(std::abs(x) <= 1.0 + 1e-15);
  }
}

TEST_CASE("fourier: the depth margin keeps empty texels lit and clamped casters shadowing") {
  // Without the margin (the trap in fourier.h), a ray at depth 0 against an empty texel (depth 1) sees
  // the series at its period-2 jump: 0.5.
  CHECK(fourierVisibility(0.0, 1.0, 32) == doctest::Approx(0.5).epsilon(1e-9));
  const double m = 0.0625;
  double worstEmpty = 0.0, worstClamped = 0.0;
  for (int i = 0; i <= 1000; ++i) {
    const double zr = rayBasisDepth(i / 1000.0, m);
    worstEmpty =
        std::max(worstEmpty, 1.0 - std::clamp(fourierVisibility(zr, texelBasisDepth(1.0, m), 32), 0.0, 1.0));
    worstClamped =
        std::max(worstClamped, std::clamp(fourierVisibility(zr, texelBasisDepth(0.0, m), 32), 0.0, 1.0));
  }
  MESSAGE("margin 1/16, M = 32: worst visibility error of any ray against an empty texel "
          << worstEmpty << ", against a clamped caster " << worstClamped);
  // At the margin the series is one ringing period past its jump (the first undershoot, ~4.9%).
  CHECK(worstEmpty < 0.06);
  CHECK(worstClamped < 0.06);
  CHECK(texelBasisDepth(1.0, m) == 1.0);
  CHECK(texelBasisDepth(0.0, m) == 0.0);
  CHECK(texelBasisDepth(0.5, m) == doctest::Approx(0.5));
  CHECK(rayBasisDepth(1.0, m) == doctest::Approx(1.0 - m));
  CHECK(rayBasisDepth(-3.0, m) == doctest::Approx(m));
}

TEST_CASE("fourier: invalid basis counts are rejected naming bases") {
  for (const int bad : {-2, 0, 2, 3, 5, 33, 130, 256}) {
    CAPTURE(bad);
    try {
      validateBases(bad);
      FAIL("no exception");
    } catch (const InvalidArgument& e) {
      CHECK(e.parameter() == "bases");
    }
  }
  std::vector<double> a(7);
  CHECK_THROWS_AS(fourierCoefficients(0.3, std::span<double>(a)), InvalidArgument);
  for (int ok = 4; ok <= 128; ok += 2)
    CHECK_NOTHROW(validateBases(ok));
}
