// crep::AirlightScattering and its table (crep/scatter/airlight.h; Sun et al. 2005 extended): (a) the
// substitution itself, exact tails against RayScattering's exact quadrature; (b) the tail against a direct
// quadrature in xi; (c) the tabulated rule's error over random rays, spots and point faces, against
// RayScattering (the figure the header states); (d) bad table parameters named.
#include <crep/core/error.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/scatter/airlight.h>
#include <crep/scatter/ray_scattering.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

using namespace crep;

namespace {

constexpr double kHalfPi = 0.5 * std::numbers::pi;

double maxRelative(const glm::dvec3& a, const glm::dvec3& b, double scale) {
  return std::max({std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(a.z - b.z)}) / scale;
}

} // namespace

TEST_CASE("Airlight: the tail against a direct quadrature in xi") {
  for (const double g : {0.0, 0.5, 0.85})
    for (const bool rayleigh : {false, true})
      for (const double u : {0.0, 0.01, 0.3, 2.0, 15.0})
        for (const double xi : {0.0, 0.2, 0.7, 1.3, 1.55}) {
          // Midpoint rule on 200000 panels of exp(-u (tan xi' - tan xi)) p(cos 2 xi') (the integrand is <= 1
          // times the phase, smooth; the rule's error is far below the tolerance).
          constexpr int kPanels = 200000;
          double sum = 0.0;
          const double h = (kHalfPi - xi) / kPanels, t0 = std::tan(xi);
          for (int k = 0; k < kPanels; ++k) {
            const double x = xi + (k + 0.5) * h;
            const double c = std::cos(2.0 * x);
            sum += std::exp(-u * (std::tan(x) - t0)) * (rayleigh ? rayleighPhase(c) : henyeyGreenstein(g, c));
          }
          sum *= h;
          CAPTURE(g);
          CAPTURE(rayleigh);
          CAPTURE(u);
          CAPTURE(xi);
          CHECK(airlightTail(g, rayleigh, u, xi) == doctest::Approx(sum).epsilon(1e-6));
        }
}

TEST_CASE("Airlight: the substitution with exact tails equals the exact quadrature") {
  // A point light's whole sphere (no sector: face -1) and sections outside its near ball: S = I (2 / h)
  // sum_p sigma_s,p [E(ta) - E(tb)] with T from airlightTail (no table).
  const Medium medium({.mieScattering = glm::dvec3(0.03, 0.05, 0.08),
                       .hgG = 0.6,
                       .rayleighScattering = glm::dvec3(0.004, 0.008, 0.016),
                       .absorption = glm::dvec3(0.01)});
  LocalLight light;
  light.position = {1.0, 4.0, -2.0};
  light.intensity = {3.0, 2.0, 1.0};
  light.nearPlane = 0.05;
  const glm::dvec3 o(-5.0, 0.5, 3.0);
  for (const glm::dvec3& target :
       {glm::dvec3(1.0, 3.0, -2.0), glm::dvec3(4.0, 8.0, 1.0), glm::dvec3(-9, 1, 7)}) {
    const glm::dvec3 v = glm::normalize(target - o);
    const RayScattering exact(light, medium, o, v);
    const glm::dvec3 p = o - light.position;
    const double t0 = -glm::dot(p, v), h = glm::length(p + t0 * v);
    const auto E = [&](double t) {
      const double w = t - t0, d = std::sqrt(h * h + w * w);
      const double xi = std::atan2(w + d, h), eta = kHalfPi - xi;
      glm::dvec3 e;
      for (int c = 0; c < 3; ++c) {
        const double u = medium.extinction()[c] * h;
        e[c] = std::exp(-medium.extinction()[c] * (t + d)) *
               (medium.mieScattering()[c] * airlightTail(0.6, false, u, xi) +
                medium.rayleighScattering()[c] * airlightTail(0.6, true, u, xi));
        (void)eta;
      }
      return e;
    };
    for (const auto& [ta, tb] : {std::pair{0.0, 4.0}, std::pair{2.0, 9.0}, std::pair{0.0, 60.0}}) {
      const glm::dvec3 expected = exact.segment(ta, tb);
      const glm::dvec3 closed = light.intensity * (2.0 / h) * (E(ta) - E(tb));
      CAPTURE(ta);
      CAPTURE(tb);
      CHECK(maxRelative(closed, expected, std::max({expected.x, expected.y, expected.z})) < 1e-8);
    }
  }
}

TEST_CASE("Airlight: the tabulated rule over random rays of spots and point faces") {
  std::mt19937 rng(30);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double worst = 0.0, sumSq = 0.0, worstBand = 0.0;
  int count = 0;
  for (int m = 0; m < 6; ++m) {
    const double g = 0.9 * U(rng);
    const double s = std::exp(std::log(0.003) + U(rng) * std::log(100.0));
    const Medium medium({.mieScattering = glm::dvec3(s, 1.2 * s, 1.5 * s),
                         .hgG = g,
                         .rayleighScattering = glm::dvec3(0.1 * s, 0.2 * s, 0.4 * s),
                         .absorption = glm::dvec3(0.3 * s)});
    const AirlightTable table = makeAirlightTable(g);
    for (int k = 0; k < 300; ++k) {
      LocalLight light;
      light.position = {0.0, 0.0, 0.0};
      light.intensity = {1.0, 1.0, 1.0};
      light.nearPlane = 0.05;
      const bool spot = k % 2 == 0;
      if (spot) {
        light.cone = true;
        light.axis = glm::normalize(glm::dvec3(U(rng) - 0.5, -1.0, U(rng) - 0.5));
        const double outer = 0.2 + 0.6 * U(rng), inner = outer * U(rng);
        light.cosInner = std::cos(inner);
        light.cosOuter = std::cos(outer);
      } else {
        light.face = k % 6;
        light.axis = PointLight::faceAxis(light.face);
      }
      const glm::dvec3 o = 30.0 * glm::dvec3(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5);
      const glm::dvec3 target = 6.0 * glm::dvec3(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5);
      const glm::dvec3 v = glm::normalize(target - o);
      const double len = 60.0 * U(rng) + 1.0;
      const RayScattering exact(light, medium, o, v);
      const AirlightScattering closed(light, medium, table, o, v);
      // A view ray's regions: 16 consecutive sections; the error of each relative to the ray's total.
      glm::dvec3 total(0.0);
      double ray = 0.0;
      std::vector<glm::dvec3> e, c;
      for (int r = 0; r < 16; ++r) {
        const double ta = len * r / 16.0, tb = len * (r + 1) / 16.0;
        e.push_back(exact.segment(ta, tb));
        c.push_back(closed.segment(ta, tb));
        total += e.back();
      }
      ray = std::max({total.x, total.y, total.z});
      if (!(ray > 0.0)) continue;
      glm::dvec3 sumC(0.0);
      for (std::size_t r = 0; r < e.size(); ++r)
        sumC += c[r];
      const double err = maxRelative(sumC, total, ray);
      worst = std::max(worst, err);
      if (spot) worstBand = std::max(worstBand, err);
      sumSq += err * err;
      ++count;
    }
  }
  const double rms = std::sqrt(sumSq / count);
  MESSAGE("airlight table " << AirlightTable::kDefaultUSamples << "x" << AirlightTable::kDefaultXiSamples
                            << ": worst relative error of a ray's sum " << worst << " (spots " << worstBand
                            << "), RMS " << rms << " over " << count << " rays");
  CHECK(worst < 5e-3);
  CHECK(rms < 1e-3);
}

TEST_CASE("Airlight: bad table parameters are named") {
  CHECK_THROWS_WITH_AS(makeAirlightTable(1.0), doctest::Contains("g"), InvalidArgument);
  CHECK_THROWS_WITH_AS(makeAirlightTable(std::nan(""), 8, 8), doctest::Contains("g"), InvalidArgument);
  CHECK_THROWS_WITH_AS(makeAirlightTable(0.5, 1, 8), doctest::Contains("uSamples"), InvalidArgument);
  CHECK_THROWS_WITH_AS(makeAirlightTable(0.5, 8, 0), doctest::Contains("xiSamples"), InvalidArgument);
}
