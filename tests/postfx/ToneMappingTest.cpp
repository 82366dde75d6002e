// Tone mapping's CPU reference (crep/postfx/tone_mapping.h): each operator against its formula written
// here from the papers (Reinhard et al. 2002 Eq. 3-4, Hable 2010, Hejl and Burgess-Dawson, Drago et al.
// 2003), monotonicity and range over L in [0, 1e6], the saturation rule, the log-average luminance with
// non-finite pixels, light adaptation's time constant and frame-rate independence, sRGB encoding, names and
// validation naming the field.
#include <crep/core/error.h>
#include <crep/postfx/tone_mapping.h>

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

using namespace crep;

namespace {

/// The formulas, written independently of the library (scaled luminance L, white point W).
double expectedCurve(ToneMapOperator op, double L, double W) {
  switch (op) {
  case ToneMapOperator::Exponential:
    return 1.0 - std::exp(-L);
  case ToneMapOperator::Reinhard: // Reinhard et al. 2002, Eq. 3
    return L / (1.0 + L);
  case ToneMapOperator::ModifiedReinhard: // Reinhard et al. 2002, Eq. 4
    return L * (1.0 + L / (W * W)) / (1.0 + L);
  case ToneMapOperator::Uncharted2: { // Hable 2010: exposure bias 2, A..F = .15 .5 .1 .2 .02 .3
    const auto h = [](double x) {
      return ((x * (0.15 * x + 0.10 * 0.50) + 0.20 * 0.02) / (x * (0.15 * x + 0.50) + 0.20 * 0.30)) -
             0.02 / 0.30;
    };
    return h(2.0 * L) / h(W);
  }
  case ToneMapOperator::FilmicALU: { // Hejl / Burgess-Dawson; their output is gamma 1/2.2 encoded
    const double x = L > 0.004 ? L - 0.004 : 0.0;
    const double encoded = (x * (6.2 * x + 0.5)) / (x * (6.2 * x + 1.7) + 0.06);
    return std::pow(encoded, 2.2);
  }
  case ToneMapOperator::Logarithmic: // Drago et al. 2003: log base (1 + Lmax)
    return std::log10(1.0 + L) / std::log10(1.0 + W);
  case ToneMapOperator::AdaptiveLogarithmic: { // Drago et al. 2003, b = 0.85, Ldmax 100 cd/m^2
    const double exponent = std::log(0.85) / std::log(0.5);
    return (100.0 * 0.01 / std::log10(W + 1.0)) * std::log(L + 1.0) /
           std::log(2.0 + 8.0 * std::pow(L / W, exponent));
  }
  }
  return -1.0;
}

double clamp01(double v) {
  return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
}

ToneMapOptions withOperator(ToneMapOperator op) {
  ToneMapOptions o;
  o.op = op;
  return o;
}

/// A sweep of luminances over [0, 1e6]: 0, then log-spaced from 1e-6 (60 per decade).
std::vector<double> luminanceSweep() {
  std::vector<double> L = {0.0};
  for (int i = 0; i <= 12 * 60; ++i)
    L.push_back(std::pow(10.0, -6.0 + i / 60.0));
  return L;
}

} // namespace

TEST_CASE("tone mapping: names parse back, unknown names list the operators") {
  CHECK(kToneMapOperators.size() == 7);
  const std::vector<std::string> expected = {"exp",        "reinhard", "reinhard-mod", "uncharted2",
                                             "filmic-alu", "log",      "adaptive-log"};
  for (std::size_t i = 0; i < kToneMapOperators.size(); ++i) {
    CHECK(std::string(toneMapOperatorName(kToneMapOperators[i])) == expected[i]);
    CHECK(findToneMapOperator(expected[i]) == kToneMapOperators[i]);
    CHECK(parseToneMapOperator(expected[i], "x") == kToneMapOperators[i]);
  }
  CHECK_FALSE(findToneMapOperator("Reinhard").has_value()); // case-sensitive
  CHECK_FALSE(findToneMapOperator("").has_value());
  try {
    parseToneMapOperator("aces", "--tonemap");
    FAIL("no exception");
  } catch (const InvalidArgument& e) {
    CHECK(e.parameter() == "--tonemap");
    const std::string what = e.what();
    for (const std::string& name : expected)
      CHECK(what.find(name) != std::string::npos);
    CHECK(what.find("aces") != std::string::npos);
  }
}

TEST_CASE("tone mapping: each operator matches its formula at 0, middle grey, the white point and large L") {
  for (const ToneMapOperator op : kToneMapOperators) {
    for (const double W : {3.0, 11.2}) {
      ToneMapOptions o = withOperator(op);
      o.whitePoint = W;
      for (const double L : {0.0, 1e-5, 0.18, 0.5, 1.0, W / 2.0, W, 2.0 * W, 100.0, 1e6}) {
        const std::string opName = toneMapOperatorName(op);
        CAPTURE(opName);
        CAPTURE(W);
        CAPTURE(L);
        // Grey input (R = G = B = L): the luminance is L up to the weights' rounding, every channel equal.
        const glm::dvec3 out = toneMapColor(glm::dvec3(L), 1.0, o);
        const double expected = clamp01(expectedCurve(op, L, W));
        // Double evaluations of algebraically equal forms (log1p vs log10(1 + L), expm1): 1e-12 absolute.
        CHECK(std::abs(out.r - expected) <= 1e-12);
        CHECK(out.g == out.r);
        CHECK(out.b == out.r);
        // The exposure scale multiplies the input before the curve.
        const glm::dvec3 scaled = toneMapColor(glm::dvec3(L / 4.0), 4.0, o);
        CHECK(std::abs(scaled.r - expected) <= 1e-12);
      }
    }
  }
}

TEST_CASE("tone mapping: anchors of the curves (white points reach 1, Reinhard halves at 1)") {
  ToneMapOptions o;
  o.whitePoint = 5.0;
  const auto curve = [&](ToneMapOperator op, double L) { return toneMapCurve(op, L, o); };
  CHECK(curve(ToneMapOperator::Reinhard, 1.0) == doctest::Approx(0.5).epsilon(1e-15));
  // Reinhard et al. 2002, Eq. 4: L_white maps to exactly 1, brighter burns out (clamped afterwards).
  CHECK(curve(ToneMapOperator::ModifiedReinhard, 5.0) == doctest::Approx(1.0).epsilon(1e-14));
  CHECK(curve(ToneMapOperator::ModifiedReinhard, 6.0) > 1.0);
  // Drago et al. 2003: Lw = Lwmax gives Ldmax (1 here), for both forms.
  CHECK(curve(ToneMapOperator::Logarithmic, 5.0) == doctest::Approx(1.0).epsilon(1e-14));
  CHECK(curve(ToneMapOperator::AdaptiveLogarithmic, 5.0) == doctest::Approx(1.0).epsilon(1e-14));
  // Hable 2010: the linear white W after the exposure bias 2 maps to 1.
  CHECK(curve(ToneMapOperator::Uncharted2, 2.5) == doctest::Approx(1.0).epsilon(1e-14));
  CHECK(curve(ToneMapOperator::Uncharted2, 0.0) == doctest::Approx(0.0).scale(1.0).epsilon(1e-15));
  // Filmic ALU: black below the 0.004 toe offset, approaches 1 from below.
  CHECK(curve(ToneMapOperator::FilmicALU, 0.004) == 0.0);
  CHECK(curve(ToneMapOperator::FilmicALU, 1e6) < 1.0);
  CHECK(curve(ToneMapOperator::FilmicALU, 1e6) > 0.999);
  CHECK(curve(ToneMapOperator::Exponential, 1e-3) == doctest::Approx(1e-3 - 0.5e-6).epsilon(1e-6));
}

TEST_CASE("tone mapping: every operator is non-decreasing, finite and in [0, 1] over L in [0, 1e6]") {
  const std::vector<double> sweep = luminanceSweep();
  const std::vector<glm::dvec3> chromaticities = {glm::dvec3(1.0), glm::dvec3(1.0, 0.5, 0.2),
                                                  glm::dvec3(0.0, 0.0, 1.0), glm::dvec3(1.0, 0.0, 0.0)};
  for (const ToneMapOperator op : kToneMapOperators)
    for (const double saturation : {0.0, 1.0, 2.0, 8.0})
      for (const glm::dvec3& c : chromaticities) {
        const std::string opName = toneMapOperatorName(op);
        CAPTURE(opName);
        CAPTURE(saturation);
        ToneMapOptions o = withOperator(op);
        o.saturation = saturation;
        const glm::dvec3 unit = c / luminance(c); // luminance 1
        glm::dvec3 previous(0.0);
        bool monotone = true, inRange = true;
        for (const double L : sweep) {
          const glm::dvec3 out = toneMapColor(unit * L, 1.0, o);
          for (int k = 0; k < 3; ++k) {
            inRange = inRange && std::isfinite(out[k]) && out[k] >= 0.0 && out[k] <= 1.0;
            // Where Ld has saturated at 1, the ratio rgb / Y of the rounded inputs moves by an ulp either
            // way: 1e-15 absolute allows that rounding, nothing a display could show.
            if (out[k] < previous[k] - 1e-15 && monotone) {
              MESSAGE((std::string("decreasing at L = ") + std::to_string(L) + " channel " +
                       std::to_string(k) + ": " + std::to_string(out[k] - previous[k])));
              monotone = false;
            }
          }
          previous = out;
        }
        CHECK(inRange);
        CHECK(monotone);
        CHECK(previous.r + previous.g + previous.b > 0.0); // 1e6 is not black
      }
}

TEST_CASE("tone mapping: the saturation rule (rgb / Y)^s Ld of the luminance operators") {
  const glm::dvec3 rgb(0.3, 0.2, 0.05);
  const double Y = 0.2126 * 0.3 + 0.7152 * 0.2 + 0.0722 * 0.05;
  for (const ToneMapOperator op :
       {ToneMapOperator::Exponential, ToneMapOperator::Reinhard, ToneMapOperator::ModifiedReinhard,
        ToneMapOperator::Logarithmic, ToneMapOperator::AdaptiveLogarithmic})
    for (const double s : {0.0, 0.5, 1.0, 1.5}) {
      const std::string opName = toneMapOperatorName(op);
      CAPTURE(opName);
      CAPTURE(s);
      ToneMapOptions o = withOperator(op);
      o.saturation = s;
      const double Ld = expectedCurve(op, 2.0 * Y, o.whitePoint);
      const glm::dvec3 out = toneMapColor(rgb, 2.0, o);
      for (int k = 0; k < 3; ++k)
        CHECK(std::abs(out[k] - clamp01(std::pow(rgb[k] / Y, s) * Ld)) <= 1e-12);
    }
  // s = 1 keeps the chromaticity (unclamped); s = 0 is grey.
  ToneMapOptions o = withOperator(ToneMapOperator::Reinhard);
  const glm::dvec3 kept = toneMapColor(rgb, 1.0, o);
  CHECK(kept.r / kept.g == doctest::Approx(rgb.r / rgb.g).epsilon(1e-12));
  o.saturation = 0.0;
  const glm::dvec3 grey = toneMapColor(rgb, 1.0, o);
  CHECK(grey.r == grey.g);
  CHECK(grey.g == grey.b);
  // The colour operators work per channel and ignore the saturation.
  ToneMapOptions u = withOperator(ToneMapOperator::Uncharted2);
  u.saturation = 3.0;
  const glm::dvec3 perChannel = toneMapColor(rgb, 1.0, u);
  for (int k = 0; k < 3; ++k)
    CHECK(std::abs(perChannel[k] -
                   clamp01(expectedCurve(ToneMapOperator::Uncharted2, rgb[k], u.whitePoint))) <= 1e-12);
}

TEST_CASE("tone mapping: non-finite pixels are black, negative channels count as 0, alpha is 1") {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
  for (const ToneMapOperator op : kToneMapOperators) {
    const ToneMapOptions o = withOperator(op);
    CHECK(toneMapColor(glm::dvec3(nan, 1.0, 1.0), 1.0, o) == glm::dvec3(0.0));
    CHECK(toneMapColor(glm::dvec3(1.0, inf, 1.0), 1.0, o) == glm::dvec3(0.0));
    CHECK(toneMapColor(glm::dvec3(1.0, 1.0, -inf), 1.0, o) == glm::dvec3(0.0));
    CHECK(toneMapColor(glm::dvec3(-1.0, 0.5, 0.5), 1.0, o) ==
          toneMapColor(glm::dvec3(0.0, 0.5, 0.5), 1.0, o));
    CHECK(toneMapColor(glm::dvec3(0.0), 1.0, o) == glm::dvec3(0.0));
  }
  Image hdr(2, 1, 3, 0.5f);
  hdr.at(1, 0, 1) = std::nanf("");
  const Image out = toneMapImage(hdr, 1.0, ToneMapOptions{});
  REQUIRE(out.channels() == 4);
  CHECK(out.at(0, 0, 0) > 0.0f);
  CHECK(out.at(1, 0, 0) == 0.0f);
  CHECK(out.at(0, 0, 3) == 1.0f);
  CHECK(out.at(1, 0, 3) == 1.0f);
}

TEST_CASE("tone mapping: log-average luminance exp(mean log(delta + Y)), non-finite pixels skipped") {
  Image image(3, 2, 4);
  const double values[6][3] = {{0.0, 0.0, 0.0},   {1.0, 1.0, 1.0},    {2.0, 0.5, 0.1},
                               {10.0, 20.0, 5.0}, {0.01, 0.02, 0.03}, {-1.0, 0.3, 0.3}};
  double logSum = 0.0;
  for (int i = 0; i < 6; ++i) {
    for (int c = 0; c < 3; ++c)
      image.at(i % 3, i / 3, c) = static_cast<float>(values[i][c]);
    image.at(i % 3, i / 3, 3) = -5.0f; // alpha is ignored
    const double r = std::max(0.0, double(static_cast<float>(values[i][0])));
    const double g = double(static_cast<float>(values[i][1])), b = double(static_cast<float>(values[i][2]));
    logSum += std::log(1e-4 + 0.2126 * r + 0.7152 * g + 0.0722 * b);
  }
  const LuminanceStats stats = luminanceStats(image);
  CHECK(stats.count == 6);
  REQUIRE(stats.logAverage().has_value());
  CHECK(*stats.logAverage() == doctest::Approx(std::exp(logSum / 6.0)).epsilon(1e-14));
  // A black image's log-average is delta (Reinhard's guard against log 0).
  CHECK(*luminanceStats(Image(4, 4, 3)).logAverage() == doctest::Approx(1e-4).epsilon(1e-12));

  // Rule: pixels with a NaN or infinite channel are skipped (neither summed nor counted).
  Image poisoned(4, 2, 3);
  for (int i = 0; i < 6; ++i)
    for (int c = 0; c < 3; ++c)
      poisoned.at(i % 3, i / 3, c) = image.at(i % 3, i / 3, c);
  poisoned.at(3, 0, 0) = std::nanf("");
  poisoned.at(3, 1, 2) = std::numeric_limits<float>::infinity();
  const LuminanceStats p = luminanceStats(poisoned);
  CHECK(p.count == 6);
  CHECK(p.logSum == stats.logSum);
  Image allNan(2, 2, 3, std::nanf(""));
  CHECK(luminanceStats(allNan).count == 0);
  CHECK_FALSE(luminanceStats(allNan).logAverage().has_value());
  CHECK_THROWS_AS(luminanceStats(Image(2, 2, 1)), InvalidArgument);
}

TEST_CASE("tone mapping: light adaptation has time constant tau and does not depend on the frame rate") {
  const double tau = 0.4, start = 2.0, target = 0.25;
  // After tau seconds, exp(-1) of the initial gap remains.
  const double after = adaptLuminance(start, target, tau, tau);
  CHECK((after - target) / (start - target) == doctest::Approx(std::exp(-1.0)).epsilon(1e-14));
  // 1 s in frames of 1/30 s and 1/120 s: the same state up to rounding, and the closed form.
  double a30 = start, a120 = start;
  for (int i = 0; i < 30; ++i)
    a30 = adaptLuminance(a30, target, 1.0 / 30.0, tau);
  for (int i = 0; i < 120; ++i)
    a120 = adaptLuminance(a120, target, 1.0 / 120.0, tau);
  const double closed = target + (start - target) * std::exp(-1.0 / tau);
  CHECK(a30 == doctest::Approx(closed).epsilon(1e-13));
  CHECK(a120 == doctest::Approx(closed).epsilon(1e-13));
  CHECK(adaptLuminance(start, target, 0.01, 0.0) == target); // tau 0: no lag
  CHECK(adaptLuminance(start, target, 0.0, tau) == start);   // no time, no change
  CHECK_THROWS_AS(adaptLuminance(start, target, -0.1, tau), InvalidArgument);
  CHECK_THROWS_AS(adaptLuminance(start, target, std::nan(""), tau), InvalidArgument);

  // LightAdaptation: the first finite frame sets the state, a frame without finite pixels keeps it.
  LightAdaptation adaptation;
  CHECK(adaptation.adapted() == 1.0);
  LuminanceStats bright{std::log(4.0) * 10.0, 10}, dark{std::log(0.5) * 10.0, 10}, none{};
  CHECK(adaptation.update(bright, 1.0 / 60.0, tau) == doctest::Approx(4.0).epsilon(1e-14));
  CHECK(adaptation.update(none, 1.0 / 60.0, tau) == doctest::Approx(4.0).epsilon(1e-14));
  CHECK(adaptation.update(dark, 0.1, tau) ==
        doctest::Approx(0.5 + 3.5 * std::exp(-0.1 / tau)).epsilon(1e-13));
  adaptation.reset();
  CHECK(adaptation.update(dark, 0.1, tau) == doctest::Approx(0.5).epsilon(1e-14));
  // Auto exposure maps the adapted luminance to middle grey (Reinhard et al. 2002, Eq. 2).
  ToneMapOptions o;
  CHECK(exposureScale(o, 0.5) == doctest::Approx(0.18 / 0.5));
  o.autoExposure = false;
  o.exposure = 3.0;
  CHECK(exposureScale(o, 0.5) == 3.0);
}

TEST_CASE("tone mapping: sRGB encoding (IEC 61966-2-1)") {
  CHECK(srgbEncode(0.0) == 0.0);
  CHECK(srgbEncode(1.0) == doctest::Approx(1.0).epsilon(1e-15));
  CHECK(srgbEncode(0.002) == doctest::Approx(12.92 * 0.002).epsilon(1e-15));
  CHECK(srgbEncode(0.5) == doctest::Approx(1.055 * std::pow(0.5, 1.0 / 2.4) - 0.055).epsilon(1e-15));
  // The two pieces meet at the threshold (to the standard's 4 digits).
  CHECK(srgbEncode(0.0031308) == doctest::Approx(0.04045).epsilon(1e-4));
  CHECK(srgbEncode(2.0) == srgbEncode(1.0));
  CHECK(srgbEncode(-1.0) == 0.0);
  CHECK(srgbEncode(std::nan("")) == 0.0);
}

TEST_CASE("tone mapping: bad options name the field") {
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  struct Case {
    const char* field;
    void (*set)(ToneMapOptions&, double);
    std::vector<double> bad;
  };
  const std::vector<Case> cases = {
      {"middleGrey", [](ToneMapOptions& o, double v) { o.middleGrey = v; }, {0.0, -0.18, nan, inf, 1e4}},
      {"whitePoint", [](ToneMapOptions& o, double v) { o.whitePoint = v; }, {0.0, -1.0, nan, inf, 1e7}},
      {"saturation", [](ToneMapOptions& o, double v) { o.saturation = v; }, {-0.1, 8.5, nan, inf}},
      {"exposure", [](ToneMapOptions& o, double v) { o.exposure = v; }, {0.0, -1.0, nan, inf}},
      {"adaptationTau", [](ToneMapOptions& o, double v) { o.adaptationTau = v; }, {-0.1, nan, inf}},
  };
  CHECK_NOTHROW(validate(ToneMapOptions{}));
  for (const Case& c : cases)
    for (const double v : c.bad) {
      ToneMapOptions o;
      c.set(o, v);
      CAPTURE(c.field);
      CAPTURE(v);
      try {
        validate(o);
        FAIL("no exception");
      } catch (const InvalidArgument& e) {
        CHECK(e.parameter() == std::string("ToneMapOptions.") + c.field);
      }
      try {
        validate(o, "ToneMapPass::CreateInfo.options");
        FAIL("no exception");
      } catch (const InvalidArgument& e) {
        CHECK(e.parameter() == std::string("ToneMapPass::CreateInfo.options.") + c.field);
      }
    }
  ToneMapOptions badOp;
  badOp.op = static_cast<ToneMapOperator>(42);
  CHECK_THROWS_WITH_AS(validate(badOp), doctest::Contains("ToneMapOptions.op"), InvalidArgument);
  // Boundary values are accepted.
  ToneMapOptions edge;
  edge.saturation = 0.0;
  edge.adaptationTau = 0.0;
  edge.whitePoint = 1e-3;
  CHECK_NOTHROW(validate(edge));
  CHECK_THROWS_AS(toneMapImage(Image(2, 2, 3), 0.0, ToneMapOptions{}), InvalidArgument);
}
