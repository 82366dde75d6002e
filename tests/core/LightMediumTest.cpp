#include "common/error_checks.h"

#include <crep/core/error.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

using crep::test::requireNamedInMessage;

namespace {
const double kNan = std::numeric_limits<double>::quiet_NaN();

// Integral of a phase function over the sphere, 2 pi * int_{-1}^{1} p(mu) d mu (Simpson, 20000 panels).
template <class P>
double sphereIntegral(P&& p) {
  const int n = 20000;
  const double h = 2.0 / n;
  double sum = p(-1.0) + p(1.0);
  for (int i = 1; i < n; ++i)
    sum += (i % 2 ? 4.0 : 2.0) * p(-1.0 + i * h);
  return 2.0 * std::numbers::pi * sum * h / 3.0;
}
} // namespace

TEST_CASE("DirectionalLight: directions of any finite non-zero length normalise without under/overflow") {
  // |(1e-300, 0, 0)|^2 underflows and |(1e300, 1e300, 0)|^2 overflows in double: both are valid directions.
  const crep::DirectionalLight tiny({1e-300, 0, 0}, {1, 1, 1});
  CHECK(tiny.direction() == glm::dvec3(1, 0, 0));
  const crep::DirectionalLight huge({1e300, -1e300, 0}, {1, 1, 1});
  CHECK(huge.direction().x == doctest::Approx(std::sqrt(0.5)).epsilon(1e-15));
  CHECK(huge.direction().y == doctest::Approx(-std::sqrt(0.5)).epsilon(1e-15));
  const crep::DirectionalLight subnormal({0, 0, -4.9e-324}, {1, 1, 1});
  CHECK(subnormal.direction() == glm::dvec3(0, 0, -1));
}

TEST_CASE("DirectionalLight: direction normalized, invalid input named") {
  const crep::DirectionalLight light({0, -3, 4}, {1, 2, 3});
  CHECK(glm::length(light.direction()) == doctest::Approx(1.0).epsilon(1e-15));
  CHECK(light.direction().y == doctest::Approx(-0.6));
  requireNamedInMessage([] { crep::DirectionalLight({0, 0, 0}); }, "DirectionalLight.direction");
  requireNamedInMessage([] { crep::DirectionalLight({kNan, 1, 0}); }, "DirectionalLight.direction");
  requireNamedInMessage(
      [] {
        crep::DirectionalLight({0, -1, 0}, {-1, 0, 0});
      },
      "DirectionalLight.irradiance");
}

TEST_CASE("anyOrthogonal: unit and orthogonal for every axis and sign") {
  for (glm::dvec3 n : {glm::dvec3(0, 0, 1), glm::dvec3(0, 0, -1), glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0),
                       glm::normalize(glm::dvec3(1, 2, -3)), glm::normalize(glm::dvec3(1e-9, 0, -1))}) {
    const glm::dvec3 t = crep::anyOrthogonal(n);
    CHECK(glm::length(t) == doctest::Approx(1.0).epsilon(1e-12));
    CHECK(std::abs(glm::dot(t, n)) < 1e-12);
  }
}

TEST_CASE("SpotLight: cone maps to the NDC square, invalid input named") {
  const double cone = 0.4;
  const crep::SpotLight spot({.position = {1, 5, 2},
                              .direction = {0.2, -1, 0.1},
                              .innerConeAngle = 0.3,
                              .outerConeAngle = cone,
                              .range = 50.0});
  const glm::dmat4 m = spot.lightClipFromWorld();
  // A point on the axis maps to the NDC centre; a point at the cone edge (rotated about an axis
  // orthogonal to the light's up/right frame) maps to |x| or |y| = 1.
  const glm::dvec3 onAxis = spot.position() + 10.0 * spot.direction();
  glm::dvec4 c = m * glm::dvec4(onAxis, 1.0);
  CHECK(std::abs(c.x / c.w) < 1e-12);
  CHECK(std::abs(c.y / c.w) < 1e-12);
  const glm::dmat4 viewFromWorld = spot.lightViewFromWorld();
  const glm::dvec3 edgeView(std::tan(cone) * 10.0, 0.0, -10.0);
  const glm::dvec3 edgeWorld(glm::inverse(viewFromWorld) * glm::dvec4(edgeView, 1.0));
  c = m * glm::dvec4(edgeWorld, 1.0);
  CHECK(c.x / c.w == doctest::Approx(1.0).epsilon(1e-12));
  // Near and far planes map to -1 and 1.
  c = m * glm::dvec4(spot.position() + spot.range() * spot.direction(), 1.0);
  CHECK(c.z / c.w == doctest::Approx(1.0).epsilon(1e-12));
  using P = crep::SpotLightParams;
  const auto spotWith = [](auto edit) {
    return [edit] {
      P p{.position = {0, 0, 0},
          .direction = {0, -1, 0},
          .innerConeAngle = 0.3,
          .outerConeAngle = 0.5,
          .range = 10.0};
      edit(p);
      crep::SpotLight{p};
    };
  };
  requireNamedInMessage(spotWith([](P& p) { p.outerConeAngle = 0.0; }), "SpotLight.outerConeAngle");
  requireNamedInMessage(spotWith([](P& p) { p.outerConeAngle = 1.6; }), "SpotLight.outerConeAngle");
  requireNamedInMessage(spotWith([](P& p) { p.outerConeAngle = kNan; }), "SpotLight.outerConeAngle");
  requireNamedInMessage(spotWith([](P& p) { p.innerConeAngle = 0.6; }),
                        "SpotLight.innerConeAngle"); // out of order
  requireNamedInMessage(spotWith([](P& p) { p.innerConeAngle = 0.5; }), "SpotLight.innerConeAngle");
  requireNamedInMessage(spotWith([](P& p) { p.innerConeAngle = 0.0; }), "SpotLight.innerConeAngle");
  requireNamedInMessage(spotWith([](P& p) { p.intensity = 0.0; }), "SpotLight.intensity");
  requireNamedInMessage(spotWith([](P& p) { p.intensity = kNan; }), "SpotLight.intensity");
  requireNamedInMessage(spotWith([](P& p) { p.color = {0, 0, 0}; }), "SpotLight.color");
  requireNamedInMessage(spotWith([](P& p) { p.color = {1, -1, 0}; }), "SpotLight.color");
  requireNamedInMessage(spotWith([](P& p) { p.range = 0.0; }), "SpotLight.range");
  requireNamedInMessage(spotWith([](P& p) { p.direction = {0, 0, 0}; }), "SpotLight.direction");
  requireNamedInMessage(spotWith([](P& p) { p.position = {kNan, 0, 0}; }), "SpotLight.position");
  requireNamedInMessage(spotWith([](P& p) { p.nearPlane = 20.0; }), "SpotLight.nearPlane");
}

TEST_CASE("Phase functions are normalized over the sphere") {
  for (double g : {-0.9, -0.3, 0.0, 0.5, 0.8}) {
    INFO("g = " << g);
    // g = +-0.9 is sharply peaked; Simpson with 20000 panels still gets 1e-6.
    CHECK(sphereIntegral([g](double mu) { return crep::henyeyGreenstein(g, mu); }) ==
          doctest::Approx(1.0).epsilon(1e-6));
    // Mean cosine of HG equals g: 2 pi int mu p(mu) dmu.
    CHECK(sphereIntegral([g](double mu) { return mu * crep::henyeyGreenstein(g, mu); }) ==
          doctest::Approx(g).epsilon(1e-6).scale(1.0));
  }
  CHECK(crep::henyeyGreenstein(0.0, 0.3) == doctest::Approx(1.0 / (4.0 * std::numbers::pi)).epsilon(1e-15));
  CHECK(sphereIntegral([](double mu) { return crep::rayleighPhase(mu); }) ==
        doctest::Approx(1.0).epsilon(1e-10));
  CHECK(crep::rayleighPhase(1.0) == doctest::Approx(2.0 * crep::rayleighPhase(0.0)));
}

TEST_CASE("Medium: extinction derived, scatteringTimesPhase combines HG and Rayleigh") {
  const crep::Medium m({.mieScattering = {0.1, 0.2, 0.3},
                        .hgG = 0.7,
                        .rayleighScattering = {0.001, 0.002, 0.004},
                        .absorption = {0.01, 0.02, 0.03}});
  CHECK(m.extinction().x == doctest::Approx(0.111));
  CHECK(m.extinction().z == doctest::Approx(0.334));
  CHECK(m.scattering().y == doctest::Approx(0.202));
  const glm::dvec3 sp = m.scatteringTimesPhase(0.25);
  CHECK(sp.y == doctest::Approx(0.2 * crep::henyeyGreenstein(0.7, 0.25) + 0.002 * crep::rayleighPhase(0.25)));
}

TEST_CASE("Medium: invalid coefficients are named") {
  requireNamedInMessage([] { crep::Medium({.mieScattering = {-0.1, 0.1, 0.1}}); }, "Medium.mieScattering");
  requireNamedInMessage([] { crep::Medium({.mieScattering = {kNan, 0.1, 0.1}}); }, "Medium.mieScattering");
  requireNamedInMessage(
      [] {
        crep::Medium({.mieScattering = {0.1, 0.1, 0.1}, .absorption = {0, -1e-3, 0}});
      },
      "Medium.absorption");
  requireNamedInMessage(
      [] {
        crep::Medium({.mieScattering = {0.1, 0.1, 0.1},
                      .hgG = 0.0,
                      .rayleighScattering = {0, 0, -1},
                      .absorption = {0, 0, 0}});
      },
      "Medium.rayleighScattering");
  requireNamedInMessage(
      [] {
        crep::Medium({.mieScattering = {0.1, 0.1, 0.1}, .hgG = 1.0, .absorption = {0, 0, 0}});
      },
      "Medium.hgG");
  requireNamedInMessage(
      [] {
        crep::Medium({.mieScattering = {0.1, 0.1, 0.1}, .hgG = kNan, .absorption = {0, 0, 0}});
      },
      "Medium.hgG");
  requireNamedInMessage([] { crep::Medium({.mieScattering = {0.1, 0.0, 0.1}}); }, "Medium.extinction.g");
  requireNamedInMessage([] { crep::Medium({.mieScattering = {0, 0, 0}}); }, "Medium.extinction.r");
}

TEST_CASE("orthographicLightClipFromWorld: covers the points, looks along the light") {
  const crep::DirectionalLight light({0.3, -1.0, 0.2}, {1, 1, 1});
  const std::vector<glm::dvec3> points = {{-5, 0, -3}, {4, 2, 1}, {0, 7, -9}, {2, -1, 6}};
  const glm::dmat4 m = crep::orthographicLightClipFromWorld(light, points);
  for (const glm::dvec3& p : points) {
    const glm::dvec4 q = m * glm::dvec4(p, 1.0);
    for (int c = 0; c < 3; ++c) {
      CHECK(q[c] / q.w > -1.0);
      CHECK(q[c] / q.w < 1.0);
    }
  }
  // The light direction maps to a pure depth increase (every light ray is one texel).
  const glm::dvec4 d = m * glm::dvec4(light.direction(), 0.0);
  CHECK(std::abs(d.x) < 1e-12);
  CHECK(std::abs(d.y) < 1e-12);
  CHECK(d.z > 0.0);
}

TEST_CASE("Medium: the named form equals the deprecated positional one and reads back by name") {
  const crep::Medium named({.mieScattering = glm::dvec3(0.02, 0.03, 0.04),
                            .hgG = 0.76,
                            .rayleighScattering = glm::dvec3(0.001, 0.002, 0.005),
                            .absorption = glm::dvec3(0.003)});
  // The deprecated positional form (mie, absorption, g, rayleigh) still builds the same medium.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
  const crep::Medium positional({0.02, 0.03, 0.04}, glm::dvec3(0.003), 0.76, {0.001, 0.002, 0.005});
#pragma GCC diagnostic pop
  CHECK(named.mieScattering() == positional.mieScattering());
  CHECK(named.absorption() == positional.absorption());
  CHECK(named.hgG() == positional.hgG());
  CHECK(named.rayleighScattering() == positional.rayleighScattering());
  const crep::MediumCoefficients c = named.coefficients();
  CHECK(c.hgG == 0.76);
  CHECK(c.absorption == glm::dvec3(0.003));
  CHECK_THROWS_AS(crep::Medium({.mieScattering = glm::dvec3(0.1), .hgG = 1.0}), crep::InvalidArgument);
  CHECK_THROWS_AS(crep::Medium(crep::MediumCoefficients{}), crep::InvalidArgument); // zero extinction
}

TEST_CASE("SpotLight: the smooth angular falloff t^2 (3 - 2 t) between the cone angles") {
  const double inner = 0.3, outer = 0.5;
  const crep::SpotLight spot({.direction = {0, 0, -1},
                              .innerConeAngle = inner,
                              .outerConeAngle = outer,
                              .color = {1.0, 0.5, 0.25},
                              .intensity = 8.0});
  CHECK(spot.intensity() == glm::dvec3(8.0, 4.0, 2.0));
  CHECK(spot.falloff(1.0) == 1.0);
  CHECK(spot.falloff(std::cos(inner)) == doctest::Approx(1.0).epsilon(1e-12));
  CHECK(spot.falloff(std::cos(outer)) == doctest::Approx(0.0).epsilon(1e-12));
  CHECK(spot.falloff(std::cos(0.7)) == 0.0);
  CHECK(spot.falloff(-1.0) == 0.0);
  // Half way in cosine: t = 1/2 gives s = 1/2; a quarter: 1/16 (3 - 1/2) = 5/32.
  const double ci = std::cos(inner), co = std::cos(outer);
  CHECK(spot.falloff(0.5 * (ci + co)) == doctest::Approx(0.5).epsilon(1e-12));
  CHECK(spot.falloff(co + 0.25 * (ci - co)) == doctest::Approx(5.0 / 32.0).epsilon(1e-12));
  // Monotonic in the angle.
  double previous = 1.0;
  for (int i = 0; i <= 100; ++i) {
    const double s = spot.falloff(std::cos(0.6 * i / 100.0));
    CHECK(s <= previous);
    previous = s;
  }
}

TEST_CASE("PointLight: faces partition the directions, face frusta look along their axes") {
  const crep::PointLight light({.position = {1, 2, 3}, .color = {1, 1, 1}, .intensity = 5.0, .range = 20.0});
  for (int face = 0; face < 6; ++face) {
    const glm::dvec3 axis = crep::PointLight::faceAxis(face);
    CHECK(crep::PointLight::faceOf(axis) == face);
    const glm::dvec4 c = light.faceClipFromWorld(face) * glm::dvec4(light.position() + 10.0 * axis, 1.0);
    CHECK(std::abs(c.x / c.w) < 1e-12);
    CHECK(std::abs(c.y / c.w) < 1e-12);
    // A direction in the face's sector projects inside the face's NDC square.
    glm::dvec3 w = axis;
    w[(face / 2 + 1) % 3] = 0.9;
    w[(face / 2 + 2) % 3] = -0.7;
    CHECK(crep::PointLight::faceOf(w) == face);
    const glm::dvec4 q = light.faceClipFromWorld(face) * glm::dvec4(light.position() + 3.0 * w, 1.0);
    CHECK(std::abs(q.x / q.w) <= 1.0);
    CHECK(std::abs(q.y / q.w) <= 1.0);
  }
  CHECK(crep::PointLight::faceOf({1, 1, 1}) == 0); // ties: the first face in cube-map order
  requireNamedInMessage([] { crep::PointLight({.intensity = -1.0}); }, "PointLight.intensity");
  requireNamedInMessage([] { crep::PointLight({.range = 0.0}); }, "PointLight.range");
  requireNamedInMessage([] { crep::PointLight({.range = 1.0, .nearPlane = 2.0}); }, "PointLight.nearPlane");
  requireNamedInMessage([] { crep::PointLight({.color = {0, 0, 0}}); }, "PointLight.color");
}
