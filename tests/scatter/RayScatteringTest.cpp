// crep::RayScattering (crep/scatter/ray_scattering.h): the in-scattering of a view ray section for local
// lights, against (a) the closed form of a thin isotropic medium (Sun et al. 2005's airlight integral
// without extinction: sigma_s I / (4 pi h) (atan((tb - t0) / h) - atan((ta - t0) / h)) inside the full cone),
// (b) an adaptive Simpson quadrature in t of the integrand written here from Eq. 1 (its own phase
// functions and falloff), (c) the six faces of a point light adding up to the light without sectors.
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/scatter/ray.h>
#include <crep/scatter/ray_scattering.h>

#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <string>

using namespace crep;

namespace {

constexpr double kPi = std::numbers::pi;

/// The integrand of Eq. 1 for a local light, written independently of the code under test.
struct Integrand {
  glm::dvec3 o{0.0}, v{0.0}, L{0.0}, intensity{0.0};
  glm::dvec3 mie{0.0}, rayleigh{0.0}, sigma{0.0};
  double g = 0.0, near = 0.0;
  bool cone = false;
  glm::dvec3 axis{0.0};
  double inner = 0.0, outer = 0.0;

  glm::dvec3 operator()(double t) const {
    const glm::dvec3 p = o + t * v - L;
    const double d = std::sqrt(glm::dot(p, p));
    const glm::dvec3 w = p / d;
    const double mu = glm::dot(w, -v);
    const double hg = (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g - 2.0 * g * mu, 1.5));
    const double ray = 3.0 / (16.0 * kPi) * (1.0 + mu * mu);
    double falloff = 1.0;
    if (cone) {
      const double x =
          std::clamp((glm::dot(w, axis) - std::cos(outer)) / (std::cos(inner) - std::cos(outer)), 0.0, 1.0);
      falloff = x * x * (3.0 - 2.0 * x);
    }
    const double dc = std::max(d, near);
    glm::dvec3 out;
    for (int c = 0; c < 3; ++c)
      out[c] = std::exp(-sigma[c] * t) * (mie[c] * hg + rayleigh[c] * ray) * intensity[c] * falloff *
               std::exp(-sigma[c] * dc) / (dc * dc);
    return out;
  }
};

/// Adaptive Simpson on [a, b] per channel (the sum of the channels drives the refinement).
glm::dvec3 simpson(const std::function<glm::dvec3(double)>& f, double a, double b, double tolerance) {
  struct Rec {
    static glm::dvec3 run(const std::function<glm::dvec3(double)>& f, double a, double b, glm::dvec3 fa,
                          glm::dvec3 fm, glm::dvec3 fb, glm::dvec3 whole, double tol, int depth) {
      const double m = 0.5 * (a + b);
      const glm::dvec3 flm = f(0.5 * (a + m)), frm = f(0.5 * (m + b));
      const glm::dvec3 left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
      const glm::dvec3 right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
      const glm::dvec3 diff = left + right - whole;
      if (depth <= 0 || std::abs(diff.x + diff.y + diff.z) <= 15.0 * tol) return left + right + diff / 15.0;
      return run(f, a, m, fa, flm, fm, left, 0.5 * tol, depth - 1) +
             run(f, m, b, fm, frm, fb, right, 0.5 * tol, depth - 1);
    }
  };
  // Start from 256 panels so that narrow features are seen; the tolerance is relative to a first estimate.
  constexpr int kPanels = 256;
  glm::dvec3 coarse(0.0);
  for (int i = 0; i < kPanels; ++i) {
    const double x0 = a + (b - a) * i / kPanels, x1 = a + (b - a) * (i + 1) / kPanels;
    coarse += (x1 - x0) / 6.0 * (f(x0) + 4.0 * f(0.5 * (x0 + x1)) + f(x1));
  }
  const double absolute = tolerance * std::abs(coarse.x + coarse.y + coarse.z);
  glm::dvec3 total(0.0);
  for (int i = 0; i < kPanels; ++i) {
    const double x0 = a + (b - a) * i / kPanels, x1 = a + (b - a) * (i + 1) / kPanels;
    const glm::dvec3 f0 = f(x0), fm = f(0.5 * (x0 + x1)), f1 = f(x1);
    total += Rec::run(f, x0, x1, f0, fm, f1, (x1 - x0) / 6.0 * (f0 + 4.0 * fm + f1), absolute / kPanels, 24);
  }
  return total;
}

double relativeError(const glm::dvec3& a, const glm::dvec3& b) {
  const double scale = std::max({std::abs(b.x), std::abs(b.y), std::abs(b.z)});
  return std::max({std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(a.z - b.z)}) / scale;
}

} // namespace

TEST_CASE("RayScattering: a thin isotropic medium inside the full cone gives the closed-form airlight") {
  const double sigma = 1e-9;
  const Medium medium({.mieScattering = glm::dvec3(sigma), .hgG = 0.0});
  const SpotLight spot({.position = {0, 10, 0},
                        .direction = {0, -1, 0},
                        .innerConeAngle = 1.2,
                        .outerConeAngle = 1.3,
                        .color = {1, 2, 3},
                        .intensity = 5.0,
                        .range = 50.0});
  const glm::dvec3 o(-6, 1, 2), v = glm::normalize(glm::dvec3(1, 0.05, -0.1));
  const RayScattering rs(LocalLight::spot(spot), medium, o, v);
  const glm::dvec3 toLight = spot.position() - o;
  const double t0 = glm::dot(toLight, v), h = glm::length(toLight - t0 * v);
  for (const auto& [ta, tb] : {std::pair{0.0, 12.0}, std::pair{2.0, 5.0}, std::pair{5.5, 6.5}}) {
    // Every point of these sections is within 1.2 rad of the axis (checked), so s = 1.
    for (double t = ta; t <= tb; t += 0.01)
      REQUIRE(std::acos(glm::dot(glm::normalize(o + t * v - spot.position()), spot.direction())) < 1.2);
    const glm::dvec3 expected =
        sigma / (4.0 * kPi * h) * spot.intensity() * (std::atan((tb - t0) / h) - std::atan((ta - t0) / h));
    const double error = relativeError(rs.segment(ta, tb), expected);
    CAPTURE(ta);
    CAPTURE(tb);
    CHECK(error < 1e-7); // exp(-sigma (t + d)) = 1 - O(1e-8) over these distances
  }
}

TEST_CASE("RayScattering: a spot light against an independent quadrature of Eq. 1") {
  const Medium medium({.mieScattering = glm::dvec3(0.03, 0.04, 0.05),
                       .hgG = 0.6,
                       .rayleighScattering = glm::dvec3(0.002, 0.004, 0.008),
                       .absorption = glm::dvec3(0.01)});
  const SpotLight spot({.position = {1, 6, -3},
                        .direction = {0.2, -1, 0.1},
                        .innerConeAngle = 0.3,
                        .outerConeAngle = 0.55,
                        .color = {1, 0.8, 0.6},
                        .intensity = 20.0,
                        .range = 40.0,
                        .nearPlane = 0.05});
  Integrand f{.o = {},
              .v = {},
              .L = spot.position(),
              .intensity = spot.intensity(),
              .mie = medium.mieScattering(),
              .rayleigh = medium.rayleighScattering(),
              .sigma = medium.extinction(),
              .g = 0.6,
              .near = spot.nearPlane(),
              .cone = true,
              .axis = spot.direction(),
              .inner = 0.3,
              .outer = 0.55};
  struct Case {
    const char* name;
    glm::dvec3 o, target;
    double ta, tb;
  };
  const glm::dvec3 L = spot.position(), axisPoint = L + 5.0 * spot.direction();
  for (const Case& k : {
           Case{"across the cone", {-8, 0, -2}, axisPoint, 0.0, 25.0},
           Case{"toward the light", {3, -2, 1}, L + glm::dvec3(0.3, 0.0, 0.2), 0.0, 30.0},
           Case{"through the near ball", {3, -2, 1}, L + glm::dvec3(0.01, 0.0, 0.0), 0.0, 20.0},
           Case{"just outside the near ball", {3, -2, 1}, L + glm::dvec3(0.06, 0.0, 0.0), 2.0, 14.0},
           Case{"from inside the cone, far", axisPoint, axisPoint + glm::dvec3(1, -0.2, 0.3), 0.0, 500.0},
           Case{"outside the cone", {-20, 6, -3}, {-10, 7, -3}, 0.0, 10.0},
       }) {
    CAPTURE(k.name);
    f.o = k.o;
    f.v = glm::normalize(k.target - k.o);
    const RayScattering rs(LocalLight::spot(spot), medium, f.o, f.v);
    const glm::dvec3 expected = simpson(f, k.ta, k.tb, 1e-11);
    const glm::dvec3 actual = rs.segment(k.ta, k.tb);
    MESSAGE(std::string(k.name) << ": " << actual.x << " vs " << expected.x << ", relative error "
                                << (expected.x > 0.0 ? relativeError(actual, expected) : 0.0));
    if (std::string(k.name) == "outside the cone") {
      CHECK(actual == glm::dvec3(0.0));
      CHECK(expected == glm::dvec3(0.0));
      continue;
    }
    CHECK(relativeError(actual, expected) < 1e-7);
    // Additive over a cut anywhere.
    const double cut = k.ta + 0.37 * (k.tb - k.ta);
    CHECK(relativeError(rs.segment(k.ta, cut) + rs.segment(cut, k.tb), actual) < 1e-9);
  }
}

TEST_CASE("RayScattering: the six faces of a point light add up to the light without sectors") {
  const Medium medium({.mieScattering = glm::dvec3(0.05), .hgG = 0.3, .absorption = glm::dvec3(0.02)});
  const PointLight light({.position = {0.5, 2, -1}, .color = {1, 1, 1}, .intensity = 10.0, .range = 30.0});
  Integrand f{.o = {},
              .v = {},
              .L = light.position(),
              .intensity = light.intensity(),
              .mie = medium.mieScattering(),
              .rayleigh = medium.rayleighScattering(),
              .sigma = medium.extinction(),
              .g = 0.3,
              .near = light.nearPlane()};
  for (const glm::dvec3& target : {glm::dvec3(0.6, 2.2, -0.9), glm::dvec3(3, 5, 2), glm::dvec3(-1, 2, -1)}) {
    f.o = glm::dvec3(-4, -1, 3);
    f.v = glm::normalize(target - f.o);
    glm::dvec3 sum(0.0);
    int lit = 0;
    for (int face = 0; face < 6; ++face) {
      const glm::dvec3 s =
          RayScattering(LocalLight::pointFace(light, face), medium, f.o, f.v).segment(0.0, 20.0);
      sum += s;
      lit += s.x > 0.0 ? 1 : 0;
    }
    CAPTURE(target.x);
    CHECK(lit >= 2); // the ray crosses sector borders
    CHECK(relativeError(sum, simpson(f, 0.0, 20.0, 1e-11)) < 1e-7);
  }
}

TEST_CASE("RayScattering: a directional light is the closed form of crep/scatter/ray.h") {
  const Medium medium({.mieScattering = glm::dvec3(0.03, 0.04, 0.05), .hgG = 0.7});
  const DirectionalLight sun({0.3, -1, 0.2}, {2, 2, 2});
  const glm::dvec3 v = glm::normalize(glm::dvec3(1, 0.1, 0.3));
  const RayScattering rs(sun, medium, glm::dvec3(0.0), v);
  const glm::dvec3 expected =
      scatteringConstant(sun, medium, v) * transmittanceIntegral(medium.extinction(), 2.0, 9.0);
  CHECK(relativeError(rs.segment(2.0, 9.0), expected) < 1e-15);
  CHECK(rs.segment(5.0, 5.0) == glm::dvec3(0.0));
  CHECK(rs.segment(6.0, 5.0) == glm::dvec3(0.0));
}
