// Per-frame use of the atmosphere tables (crep/atmosphere/atmosphere.h "Per-frame use"): atmosphereRay's sky
// and aerial perspective (Yusov 2013, Eq. 8) and its three kinds of light shafts against each other, against
// an independent brute-force single-scattering integral (densityIntegral for both transmittances, no tables),
// exact identities of lit sections and lit lengths, prefilteredVisibility's closed form, and atmosphereImage
// against atmosphereRay per pixel.
#include "common/error_checks.h"

#include "atmosphere/atmosphere_test_util.h"

#include <crep/atmosphere/atmosphere.h>
#include <crep/core/error.h>
#include <crep/scatter/ray.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace crep;
using crep::test::invalidParameter;

namespace {

/// The small tables of crep::test::smallAtmosphereTables: orders 1 and 2, or single scattering only.
const AtmosphereTables& tables(int orders = 2) {
  return test::smallAtmosphereTables(orders);
}

/// The sun 30 degrees above the horizon, coloured irradiance.
DirectionalLight sun() {
  const double e = glm::radians(30.0);
  return DirectionalLight(-glm::dvec3(std::cos(e) * 0.6, std::sin(e), std::cos(e) * 0.8),
                          glm::dvec3(1.5, 1.2, 1.0));
}

double maxRelative(const glm::dvec3& a, const glm::dvec3& b) {
  double worst = 0.0;
  for (int c = 0; c < 3; ++c)
    worst = std::max(worst, std::abs(a[c] - b[c]) / std::max(std::abs(b[c]), 1e-300));
  return worst;
}

/// Distance from P along unit d to the top of the atmosphere, or -1 when the ray hits the ground first.
double distanceToTop(const AtmosphereParameters& p, const glm::dvec3& P, const glm::dvec3& d) {
  const double b = glm::dot(P, d), r = glm::length(P);
  const double R = p.earthRadius, top = R + p.atmosphereHeight;
  const double discGround = b * b - (r - R) * (r + R);
  if (b < 0.0 && discGround >= 0.0 && -b - std::sqrt(discGround) > 0.0) return -1.0;
  return -b + std::sqrt(std::max(0.0, b * b - (r - top) * (r + top)));
}

/// exp(-(beta_R I_R + beta_Me I_M)) of a density integral I.
glm::dvec3 extinctionOf(const AtmosphereParameters& p, const glm::dvec2& I) {
  return glm::exp(-(p.rayleighScattering * I.x + (p.mieScattering + p.mieAbsorption) * I.y));
}

/// Independent single scattering per unit sun irradiance along C + v t, t in [0, length] (Bruneton and Neyret
/// 2008, Eq. 1 of single scattering): trapezoid rule with n steps, the camera transmittance by
/// densityIntegral from C (256 steps), the sun's by densityIntegral to the top (256 steps, 0 when the sun ray
/// hits the ground).
glm::dvec3 bruteSingle(const AtmosphereParameters& p, const glm::dvec3& C, const glm::dvec3& v,
                       const glm::dvec3& l, double length, int n) {
  const double c = glm::dot(v, l);
  const double pR = rayleighPhase(c), pM = henyeyGreenstein(p.mieG, c);
  glm::dvec3 sum(0.0);
  for (int k = 0; k <= n; ++k) {
    const double t = length * k / n;
    const glm::dvec3 P = C + v * t;
    const double h = std::max(0.0, glm::length(P) - p.earthRadius);
    const glm::dvec3 scattering = p.rayleighScattering * (std::exp(-h / p.rayleighScaleHeight) * pR) +
                                  p.mieScattering * (std::exp(-h / p.mieScaleHeight) * pM);
    const glm::dvec3 camera = t > 0.0 ? extinctionOf(p, densityIntegral(p, C, P, 256)) : glm::dvec3(1.0);
    const double toTop = distanceToTop(p, P, l);
    const glm::dvec3 sunT =
        toTop < 0.0 ? glm::dvec3(0.0) : extinctionOf(p, densityIntegral(p, P, P + l * toTop, 256));
    sum += (k == 0 || k == n ? 0.5 : 1.0) * scattering * camera * sunT;
  }
  return sum * (length / n);
}

/// A test ray: camera at world `origin`, direction, world distance to the surface (or the far plane).
struct TestRay {
  std::string name;
  glm::dvec3 origin;
  glm::dvec3 direction;
  double surface;
  bool sky;
};

AtmospherePlacement placement() {
  AtmospherePlacement pl;
  pl.metersPerUnit = 10.0;
  pl.originAltitude = 300.0;
  return pl;
}

/// Aerial perspective over 5 km 4.5 degrees down (the ray would hit the ground beyond), a ray 2 degrees up
/// over 4 km, and a sky ray 20 degrees up with its far plane at 5 km (world units of 10 m); all outside the
/// horizon's blend band (horizonBlendWidth), which AtmosphereHorizonTest covers.
std::vector<TestRay> testRays() {
  return {{"aerial 5 km", {0.0, 20.0, 0.0}, glm::normalize(glm::dvec3(0.2, -0.08, -1.0)), 500.0, false},
          {"up 2 degrees 4 km",
           {0.0, 5.0, 0.0},
           glm::normalize(glm::dvec3(-1.0, std::tan(glm::radians(2.0)) * std::sqrt(1.09), 0.3)),
           400.0,
           false},
          {"sky 20 degrees",
           {0.0, 20.0, 0.0},
           glm::normalize(
               glm::dvec3(std::cos(0.35), std::tan(glm::radians(20.0)) * std::cos(0.35), std::sin(0.35))),
           500.0,
           true}};
}

AtmosphereRay run(const TestRay& r, AtmosphereShafts shafts, const AtmosphereShadowing& shadowing,
                  int steps = 64, int skySteps = 16, int orders = 2,
                  const AtmosphereTables* other = nullptr) {
  AtmosphereRayOptions o;
  o.shafts = shafts;
  o.integrationSteps = steps;
  o.skySteps = skySteps;
  return atmosphereRay(other ? *other : tables(orders), placement(), sun(), r.origin, r.direction, r.surface,
                       r.sky, shadowing, o);
}

/// The single-scattering tables with a black ground (no light reflected by a sky ray's ground hit).
const AtmosphereTables& blackGroundTables() {
  static const AtmosphereTables t = [] {
    AtmosphereTables copy = tables(1);
    copy.parameters.groundAlbedo = 0.0; // the Orders tables do not depend on it
    return copy;
  }();
  return t;
}

AtmosphereShadowing sections(std::vector<glm::dvec2> s) {
  return shadowingFromSections(std::move(s));
}

AtmosphereShadowing litLength(double first, double length) {
  AtmosphereShadowing s;
  s.firstLit = first;
  s.litLength = length;
  return s;
}

AtmosphereShadowing visibility(double v) {
  AtmosphereShadowing s;
  s.visibility = v;
  return s;
}

/// The public look-ups of one ray with Listing 2's shared side (the test's own Eq. 8).
struct LookUps {
  glm::dvec3 C, v, l;
  glm::dvec4 first{-1.0};
  glm::dvec3 at(const AtmosphereTable4D& table, double t) {
    glm::dvec4 coords = first;
    const glm::dvec3 value = lookUpAtmosphere(tables(), table, C + v * t, v, l, coords);
    if (first.x < 0.0) first = coords;
    return value;
  }
  /// L1 (the phase-free single tables with the ray's phase functions).
  glm::dvec3 single(double t) {
    glm::dvec4 coords = first;
    const glm::dvec3 value = lookUpSingleScattering(tables(), C + v * t, v, l, coords);
    if (first.x < 0.0) first = coords;
    return value;
  }
  /// The segment's transmittance of Eq. 8 (atmosphere_ray.cpp's rule: 16 trapezoid steps of the densities).
  glm::dvec3 T(double t) const {
    return t > 0.0 ? extinctionOf(tables().parameters, densityIntegral(tables().parameters, C, C + v * t, 16))
                   : glm::dvec3(1.0);
  }
};

LookUps lookUpsOf(const TestRay& r) {
  LookUps u;
  u.C = atmospherePosition(placement(), tables().parameters, r.origin);
  u.v = r.direction;
  u.l = -sun().direction();
  u.single(0.0); // the first look-up at C
  return u;
}

} // namespace

TEST_CASE("Atmosphere ray: every section lit, (a), (b), (c) and None agree") {
  for (const TestRay& r : testRays()) {
    CAPTURE(r.name);
    const AtmosphereRay none = run(r, AtmosphereShafts::None, {});
    const AtmosphereRay a = run(r, AtmosphereShafts::Integrated, sections({{0.0, r.surface}}), 256, 64);
    const AtmosphereRay b = run(r, AtmosphereShafts::LitLengthTable, litLength(0.0, r.surface));
    const AtmosphereRay c = run(r, AtmosphereShafts::PrefilteredVisibility, visibility(1.0));
    // (b) and (c) with everything lit are the same formula on the same look-ups.
    CHECK(maxRelative(b.inscattering, c.inscattering) <= 1e-14);
    // None reads L_M = L1 + L_H stored as one float table, (b) reads L1 and L_H: float rounding only.
    const double noneVsB = maxRelative(b.inscattering, none.inscattering);
    // (a) integrates single scattering numerically (table transmittances), (b) reads L1 at both ends: they
    // differ by the 16x32x16x8 L1 table's own error (the next test: (a) is within 0.3% of a brute-force
    // integral, the table's Eq. 8 within 11% / 24% / 23% on these rays). Measured |(a) - (b)| relative to
    // (b), higher orders included: 10.0% (aerial 5 km), 15.0% (up 2 degrees 4 km), 16.5% (sky).
    const double aVsB = maxRelative(a.inscattering, b.inscattering);
    MESSAGE(r.name << ": relative |None - (b)| " << noneVsB << ", |(a) - (b)| " << aVsB);
    CHECK(noneVsB < 1e-6); // measured 1.5e-8 .. 4.0e-8
    CHECK(aVsB < 0.2);
    for (const AtmosphereRay* x : {&a, &b, &c})
      CHECK(maxRelative(x->transmittance, none.transmittance) == 0.0);
    CHECK(glm::all(glm::greaterThan(none.inscattering, glm::dvec3(0.0))));
  }
}

TEST_CASE("Atmosphere ray: (a) against a brute-force single-scattering integral without tables") {
  // Tables of single scattering only (L_H = 0), a black ground: (a) with every section lit is the whole ray's
  // single scattering (the sky's part beyond the far plane included), to the ground or the top.
  const AtmosphereParameters& p = tables(1).parameters;
  std::vector<TestRay> rays = testRays();
  // A sky ray 11 degrees down from 500 m: it reaches the ground (2.6 km) before its far plane (5 km).
  rays.push_back(
      {"sky to the ground", {0.0, 20.0, 0.0}, glm::normalize(glm::dvec3(0.0, -0.2, -1.0)), 500.0, true});
  for (const TestRay& r : rays) {
    CAPTURE(r.name);
    const glm::dvec3 a =
        run(r, AtmosphereShafts::Integrated, sections({{0.0, r.surface}}), 256, 256, 1, &blackGroundTables())
            .inscattering;
    const glm::dvec3 b =
        run(r, AtmosphereShafts::LitLengthTable, litLength(0.0, r.surface), 64, 16, 1, &blackGroundTables())
            .inscattering;
    const glm::dvec3 C = atmospherePosition(placement(), p, r.origin);
    double length = r.surface * placement().metersPerUnit;
    if (r.sky) length = distanceToTop(p, C, r.direction);
    if (length < 0.0) { // the ground hit
      const double cv = glm::dot(C, r.direction), rc = glm::length(C);
      length = -cv - std::sqrt(cv * cv - (rc - p.earthRadius) * (rc + p.earthRadius));
      CHECK(length < r.surface * placement().metersPerUnit);
    }
    REQUIRE(length > 0.0);
    const glm::dvec3 reference =
        sun().irradiance() * bruteSingle(p, C, r.direction, -sun().direction(), length, 2048);
    const double rel = maxRelative(a, reference);
    // For comparison, the 16x32x16x8 L1 table's Eq. 8 on the same ray ((b) all lit).
    MESSAGE(r.name << ": (a) single scattering vs brute force, max relative error over RGB " << rel
                   << "; (b) from the L1 table vs brute force " << maxRelative(b, reference));
    // Measured 0.024%, 0.024%, 0.05%, 0.025% (rays in order; 0.71%, 0.20%, 0.04%, 0.08% with the optical
    // depth table's transmittance); the small table: 11.8%, 5.2%, 3.3%, 8.0% (with L1's phase functions
    // stored: 9.3%, 24%, 23%, 8.0%).
    CHECK(rel < 0.015);
    CHECK(maxRelative(b, reference) < 0.3);
  }
}

TEST_CASE("Atmosphere ray: (a)'s sky beyond the far plane at its default steps against brute force") {
  // Sky rays 20, 5 and 1 degrees up from 500 m, the far plane at 5 km: (a)'s default skySteps (16) over the
  // rest of the ray (80 to ~1000 km) in the substitution t = s_F + (t_X - s_F) u^3. Measured 0.16%, 0.40%,
  // 0.47% (16 uniform steps, before the substitution: 3.4%, 8.2%, 29%).
  const AtmosphereParameters& p = tables(1).parameters;
  const AtmosphereRayOptions defaults;
  for (double degrees : {20.0, 5.0, 1.0}) {
    CAPTURE(degrees);
    const double e = glm::radians(degrees);
    const TestRay r{
        "sky", {0.0, 50.0, 0.0}, {std::cos(e) * 0.6, std::sin(e), -std::cos(e) * 0.8}, 500.0, true};
    const glm::dvec3 a = run(r, AtmosphereShafts::Integrated, sections({{0.0, r.surface}}),
                             defaults.integrationSteps, defaults.skySteps, 1, &blackGroundTables())
                             .inscattering;
    const glm::dvec3 C = atmospherePosition(placement(), p, r.origin);
    const double length = distanceToTop(p, C, r.direction);
    REQUIRE(length > 0.0);
    const glm::dvec3 reference =
        sun().irradiance() * bruteSingle(p, C, r.direction, -sun().direction(), length, 8192);
    const double rel = maxRelative(a, reference);
    MESSAGE(degrees << " degrees up: (a) at default steps vs brute force, max relative error " << rel);
    CHECK(rel < 0.01);
  }
}

TEST_CASE("Atmosphere ray: the aerial perspective volume at its froxel centres against brute force") {
  // A camera 500 m up looking 5 degrees down, far plane at 8 km, an 8 x 8 x 8 volume: at each froxel
  // centre the volume is its own column's ray integrated to the slice's depth, so it equals the brute-force
  // single scattering of that ray up to the slices' trapezoid steps and the optical depth table's sun
  // transmittance. Measured: worst 0.026% (single-scattering tables, 4 steps per slice).
  const AtmosphereTables& t = blackGroundTables();
  const AtmosphereParameters& p = t.parameters;
  const Camera camera = Camera::lookAt({0.0, 20.0, 0.0}, {0.0, 20.0 - std::tan(glm::radians(5.0)), -1.0},
                                       {0.0, 1.0, 0.0}, glm::radians(60.0), 16.0 / 9.0, 0.5, 800.0);
  AtmosphereRayOptions o;
  o.volumeSize = {8, 8, 8};
  const AtmosphereViewTables view = atmosphereViewTables(t, placement(), camera, sun(), o);
  const glm::dvec3 C = atmospherePosition(placement(), p, camera.position()), l = -sun().direction();
  double worst = 0.0;
  // Froxels whose rays stay above the ground to the far plane (or, (5, 1, 1), to their slice).
  for (const glm::ivec3 f : {glm::ivec3(0, 4, 7), glm::ivec3(3, 4, 2), glm::ivec3(7, 7, 5),
                             glm::ivec3(5, 1, 1), glm::ivec3(2, 6, 7)}) {
    const glm::dvec3 v = camera.rayDirection(2.0 * (f.x + 0.5) / 8 - 1.0, 2.0 * (f.y + 0.5) / 8 - 1.0);
    const double u = f.z / 7.0, distance = camera.far() * u * u / glm::dot(v, camera.forward());
    const double c = glm::dot(v, l);
    const glm::dvec3 fromVolume = sampleAerialPerspective(view, p, v, distance, c);
    const glm::dvec3 reference = bruteSingle(p, C, v, l, distance * placement().metersPerUnit, 2048);
    const std::size_t index = (static_cast<std::size_t>(f.z) * 8 + f.y) * 8 + f.x;
    // The stored texel with the phases applied is the look-up at the centre.
    const glm::dvec3 texel = glm::dvec3(view.volumeRayleigh[index]) * rayleighPhase(c) +
                             glm::dvec3(view.volumeMie[index]) * henyeyGreenstein(p.mieG, c);
    CHECK(maxRelative(fromVolume, texel) < 1e-6);
    worst = std::max(worst, maxRelative(fromVolume, reference));
  }
  MESSAGE("aerial perspective volume at froxel centres vs brute force: worst relative error " << worst);
  CHECK(worst < 0.005);
  // Slice 0 is the camera: nothing in-scattered.
  CHECK(glm::length(sampleAerialPerspective(view, p, camera.forward(), 0.0, 0.5)) == 0.0);
}

TEST_CASE("Atmosphere ray: the sky-view table against brute force, on and between its texels") {
  // The camera 500 m up: rays at the sky-view table's texel centres (above and below the horizon, the
  // horizon rows from both sides) and halfway between rows, each against the brute-force single scattering
  // of the same ray to the ground or the top. Measured: texel centres worst 0.19%, between rows 0.45% (with
  // t = t_end u^2: 0.81%, 0.76%).
  const AtmosphereTables& t = blackGroundTables();
  const AtmosphereParameters& p = t.parameters;
  const Camera camera = Camera::lookAt({0.0, 20.0, 0.0}, {0.0, 20.0, -1.0}, {0.0, 1.0, 0.0},
                                       glm::radians(60.0), 16.0 / 9.0, 0.5, 800.0);
  AtmosphereRayOptions o;
  o.volumeSize = {4, 4, 4};
  const AtmosphereViewTables view = atmosphereViewTables(t, placement(), camera, sun(), o);
  const glm::dvec3 C = atmospherePosition(placement(), p, camera.position()), l = -sun().direction();
  const int W = o.skyViewSize.x, half = o.skyViewSize.y / 2;
  const double pi = glm::pi<double>(), eh = view.horizonElevation;
  // The ray at azimuth phi and elevation e, and its length to the ground (lower half) or the top.
  const auto ray = [&](double phi, double e, bool below, glm::dvec3& v) {
    v = std::cos(e) *
            (std::cos(phi) * view.sunAzimuth + std::sin(phi) * glm::cross(view.zenith, view.sunAzimuth)) +
        std::sin(e) * view.zenith;
    const double b = glm::dot(C, v), rc = glm::length(C), R = p.earthRadius, top = R + p.atmosphereHeight;
    if (below) return -b - std::sqrt(std::max(0.0, b * b - (rc - R) * (rc + R)));
    return -b + std::sqrt(b * b - (rc - top) * (rc + top));
  };
  double worstCentre = 0.0, worstBetween = 0.0;
  for (const int i : {0, W / 3, W - 1})
    for (const int j : {half - 6, half - 1, half, half + 1, half + 10, 2 * half - 1})
      for (const double offset : {0.0, 0.5}) {
        const bool above = j >= half;
        const double s = (above ? j - half : j) + offset;
        if (s > half - 1) continue;
        const double u = s / (half - 1);
        // Row half - 1 is straight down, row 0 the horizon from below (offsets go up the rows).
        const double e = above ? eh + u * u * (0.5 * pi - eh) : eh - u * u * (eh + 0.5 * pi);
        const double phi = pi * i / (W - 1);
        glm::dvec3 v;
        const double length = ray(phi, e, !above, v);
        if (!(length > 0.0)) continue;
        const double c = glm::dot(v, l);
        const glm::dvec3 table = sampleSkyView(view, p, v, c);
        const glm::dvec3 reference = bruteSingle(p, C, v, l, length, 4096);
        const double error = maxRelative(table, reference);
        CAPTURE(i);
        CAPTURE(j);
        CAPTURE(offset);
        (offset == 0.0 ? worstCentre : worstBetween) =
            std::max(offset == 0.0 ? worstCentre : worstBetween, error);
      }
  MESSAGE("sky-view table vs brute force: worst relative error at texel centres "
          << worstCentre << ", between rows " << worstBetween);
  CHECK(worstCentre < 0.005);
  CHECK(worstBetween < 0.01);
}

TEST_CASE("Atmosphere ray: None through the volume against (a) converged, Eq. 8 for comparison") {
  // A 48 x 27 image 500 m up looking 2 degrees down: surfaces from 300 m to 8 km in the lower half (the
  // short segments where Eq. 8's two look-ups nearly cancel), the sky above; the 16x32x16x8 tables with
  // orders 1-2. (a) with every section lit and 512 / 256 steps is the reference (its L_H is Eq. 8's, as
  // None's). Measured on the surfaces: relative RMSE None through the volume 0.043%, through Eq. 8 53%.
  const int w = 48, h = 27;
  const Camera camera =
      Camera::lookAt({0.0, 20.0, 0.0}, {0.0, 20.0 - std::tan(glm::radians(2.0)), -1.0}, {0.0, 1.0, 0.0},
                     glm::radians(60.0), static_cast<double>(w) / h, 0.5, 800.0);
  Image depth(w, h, 1, 1.0f);
  for (int y = 0; y < h / 2; ++y)
    for (int x = 0; x < w; ++x) {
      const double distance = 30.0 + 770.0 * std::pow((x + 0.5) / w, 2.0) * (1.0 - 0.5 * y / h);
      depth.at(x, y) = static_cast<float>(camera.depthBufferValue(distance));
    }
  std::vector<AtmosphereShadowing> lit;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      lit.push_back(sections({{0.0, pixelRay(camera, depth, x, y).surface}}));
  AtmosphereRayOptions a;
  a.shafts = AtmosphereShafts::Integrated;
  a.integrationSteps = 512;
  a.skySteps = 256;
  const Image reference = atmosphereImage(tables(), placement(), camera, sun(), depth, lit, a).inscattering;
  AtmosphereRayOptions none;
  const Image volume = atmosphereImage(tables(), placement(), camera, sun(), depth, {}, none).inscattering;
  none.single = AtmosphereSingleScattering::Table4D;
  const Image eq8 = atmosphereImage(tables(), placement(), camera, sun(), depth, {}, none).inscattering;
  // Relative RMSE over the surface pixels (the sky beyond the far plane is the small table's L1 in both).
  const auto surfaceRmse = [&](const Image& x) {
    double error = 0.0, energy = 0.0;
    for (int y = 0; y < h / 2; ++y)
      for (int i = 0; i < w; ++i)
        for (int c = 0; c < 3; ++c) {
          error += std::pow(x.at(i, y, c) - reference.at(i, y, c), 2.0);
          energy += std::pow(reference.at(i, y, c), 2.0);
        }
    return std::sqrt(error / energy);
  };
  const double fromVolume = surfaceRmse(volume), fromEq8 = surfaceRmse(eq8);
  MESSAGE("None vs (a) converged on the surfaces, relative RMSE: volume " << fromVolume << ", Eq. 8 "
                                                                          << fromEq8);
  CHECK(fromVolume < 0.01);
  CHECK(fromVolume < 0.25 * fromEq8);
}

TEST_CASE("Atmosphere ray: shadowed halves add up, (b) gives Eq. 8 of the lit part") {
  for (const TestRay& r : testRays()) {
    CAPTURE(r.name);
    const double s = r.surface, half = 0.5 * s;
    const glm::dvec3 full = run(r, AtmosphereShafts::Integrated, sections({{0.0, s}})).inscattering;
    const glm::dvec3 first = run(r, AtmosphereShafts::Integrated, sections({{0.0, half}})).inscattering;
    const glm::dvec3 second = run(r, AtmosphereShafts::Integrated, sections({{half, s}})).inscattering;
    const glm::dvec3 unlit = run(r, AtmosphereShafts::Integrated, sections({})).inscattering;
    // The halves' trapezoid points are the full range's (32 + 32 of 64 steps), but T(C->P) is marched: the
    // second half starts from the segment rule's 16 steps over [0, s/2], the full range from its own 32, so
    // the halves add up to that quadrature's difference (measured 8e-9 to 4e-7 on these rays).
    const double split = maxRelative(first + second - unlit, full);
    MESSAGE(r.name << ": (a) halves vs all lit, relative " << split);
    CHECK(split < 1e-5);
    CHECK(glm::all(glm::lessThan(first - unlit, full - unlit)));

    // (b): Eq. 8 with L1 over [s/2, s] from the public look-ups, plus the unoccluded higher orders.
    const AtmosphereShadowing lit = litLength(half, half);
    const glm::dvec3 b = run(r, AtmosphereShafts::LitLengthTable, lit).inscattering;
    LookUps u = lookUpsOf(r);
    const double m = placement().metersPerUnit;
    double end = s * m;
    if (r.sky) end = std::min(end, distanceToTop(tables().parameters, u.C, u.v));
    const glm::dvec3 higher =
        r.sky ? u.at(tables().higherOrders, 0.0)
              : u.at(tables().higherOrders, 0.0) - u.T(end) * u.at(tables().higherOrders, end);
    glm::dvec3 single =
        glm::max(u.T(half * m) * u.single(half * m) - u.T(end) * u.single(end), glm::dvec3(0.0));
    if (r.sky) single += u.T(end) * u.single(end);
    const double eq8 = maxRelative(b, sun().irradiance() * (single + higher));
    MESSAGE(r.name << ": (b) lit half vs Eq. 8 from the look-ups, relative " << eq8);
    CHECK(eq8 < 1e-12);
    // Eq. 8 telescopes: the two halves add up to the whole lit ray.
    const glm::dvec3 bFirst = run(r, AtmosphereShafts::LitLengthTable, litLength(0.0, half)).inscattering;
    const glm::dvec3 bNone = run(r, AtmosphereShafts::LitLengthTable, litLength(0.0, 0.0)).inscattering;
    const glm::dvec3 bFull = run(r, AtmosphereShafts::LitLengthTable, litLength(0.0, s)).inscattering;
    if (!r.sky) CHECK(maxRelative(bFirst + b - bNone, bFull) < 1e-12);
    // shadowingFromSections: D_lit and D_start of the sections.
    const AtmosphereShadowing fromSections = shadowingFromSections({{0.1 * s, 0.2 * s}, {half, s}});
    CHECK(fromSections.firstLit == 0.1 * s);
    CHECK(fromSections.litLength == doctest::Approx(0.1 * s + half).epsilon(1e-15));
    CHECK(fromSections.litSections.size() == 2);
  }
}

TEST_CASE("Atmosphere ray: zero lit length gives zero single scattering and keeps the higher orders") {
  for (const TestRay& r : testRays()) {
    CAPTURE(r.name);
    const glm::dvec3 b =
        run(r, AtmosphereShafts::LitLengthTable, litLength(0.3 * r.surface, 0.0)).inscattering;
    const glm::dvec3 a = run(r, AtmosphereShafts::Integrated, sections({})).inscattering;
    const glm::dvec3 c = run(r, AtmosphereShafts::PrefilteredVisibility, visibility(0.0)).inscattering;
    LookUps u = lookUpsOf(r);
    const double end = r.surface * placement().metersPerUnit;
    glm::dvec3 higher = u.at(tables().higherOrders, 0.0);
    if (!r.sky) higher -= u.T(end) * u.at(tables().higherOrders, end);
    glm::dvec3 expected = sun().irradiance() * higher;
    if (r.sky) {
      // The sky keeps its unshadowed single scattering beyond the far plane.
      const glm::dvec3 beyond = sun().irradiance() * u.T(end) * u.single(end);
      CHECK(maxRelative(b, expected + beyond) < 1e-12);
      CHECK(maxRelative(c, expected + beyond) < 1e-12);
      continue;
    }
    CHECK(glm::all(glm::greaterThan(expected, glm::dvec3(0.0))));
    CHECK(maxRelative(b, expected) < 1e-12);
    CHECK(maxRelative(a, expected) < 1e-12);
    CHECK(maxRelative(c, expected) < 1e-12);
  }
}

TEST_CASE("Atmosphere ray: transmittance against exp(-beta . densityIntegral)") {
  const AtmosphereParameters& p = tables().parameters;
  for (const TestRay& r : testRays()) {
    CAPTURE(r.name);
    const glm::dvec3 C = atmospherePosition(placement(), p, r.origin);
    const AtmosphereRay ray = run(r, AtmosphereShafts::None, {});
    const double length = r.sky ? distanceToTop(p, C, r.direction) : r.surface * placement().metersPerUnit;
    const glm::dvec3 reference = extinctionOf(p, densityIntegral(p, C, C + r.direction * length, 4096));
    const double rel = maxRelative(ray.transmittance, reference);
    MESSAGE(r.name << ": transmittance vs densityIntegral, max relative error " << rel);
    // Measured 3.0e-6 (aerial 5 km) and 2.4e-7 (up 2 degrees: the segment's 16-step integral), 4.1e-4 (sky:
    // the optical depth table to the top).
    CHECK(rel < 2e-3);
  }
  // A sky ray that hits the ground has transmittance 0.
  const TestRay down{"sky down", {0.0, 20.0, 0.0}, glm::normalize(glm::dvec3(0.0, -0.2, -1.0)), 500.0, true};
  CHECK(run(down, AtmosphereShafts::None, {}).transmittance == glm::dvec3(0.0));
}

TEST_CASE("Atmosphere ray: prefilteredVisibility of the closed form") {
  const DirectionalLight light(glm::dvec3(0.3, -1.0, 0.2), glm::dvec3(2.0, 1.5, 1.0));
  const Medium proxy(
      {.mieScattering = glm::dvec3(0.02), .hgG = 0.5, .rayleighScattering = glm::dvec3(0.01, 0.02, 0.04)});
  const glm::dvec3 v = glm::normalize(glm::dvec3(0.5, 0.1, -1.0));
  const double s = 37.0;
  const glm::dvec3 closed =
      scatteringConstant(light, proxy, v) * transmittanceIntegral(proxy.extinction(), 0.0, s);
  CHECK(prefilteredVisibility(closed, light, proxy, v, s) == doctest::Approx(1.0).epsilon(1e-14));
  CHECK(prefilteredVisibility(0.5 * closed, light, proxy, v, s) == doctest::Approx(0.5).epsilon(1e-14));
  CHECK(prefilteredVisibility(3.0 * closed, light, proxy, v, s) == 1.0);
  CHECK(prefilteredVisibility(-closed, light, proxy, v, s) == 0.0);
  CHECK(prefilteredVisibility(closed, light, proxy, v, 0.0) == 1.0); // no unshadowed light: visible
  const DirectionalLight dark(glm::dvec3(0.3, -1.0, 0.2), glm::dvec3(0.0));
  CHECK(prefilteredVisibility(closed, dark, proxy, v, s) == 1.0);
}

TEST_CASE("Atmosphere ray: atmosphereImage equals atmosphereRay per pixel") {
  const int w = 16, h = 9;
  const Camera camera = Camera::lookAt({0.0, 20.0, 0.0}, {0.0, 20.0, -10.0}, {0.0, 1.0, 0.0},
                                       glm::radians(60.0), static_cast<double>(w) / h, 0.5, 800.0);
  Image depth(w, h, 1, 1.0f); // upper half sky
  for (int y = 0; y < h / 2; ++y)
    for (int x = 0; x < w; ++x)
      depth.at(x, y) = 0.95f + 0.001f * static_cast<float>(x + y);
  std::vector<AtmosphereShadowing> shadowing;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double s = pixelRay(camera, depth, x, y).surface;
      shadowing.push_back(shadowingFromSections({{0.0, 0.3 * s}, {0.5 * s, 0.9 * s}}));
      shadowing.back().visibility = 0.6;
    }
  for (const AtmosphereShafts shafts :
       {AtmosphereShafts::None, AtmosphereShafts::Integrated, AtmosphereShafts::LitLengthTable,
        AtmosphereShafts::PrefilteredVisibility}) {
    CAPTURE(static_cast<int>(shafts));
    AtmosphereRayOptions o;
    o.shafts = shafts;
    o.integrationSteps = 16;
    o.skySteps = 8;
    const bool none = shafts == AtmosphereShafts::None;
    const AtmosphereImage image =
        atmosphereImage(tables(), placement(), camera, sun(), depth,
                        none ? std::vector<AtmosphereShadowing>{} : shadowing, o, 3);
    REQUIRE(image.inscattering.channels() == 4);
    REQUIRE(image.transmittance.channels() == 3);
    // None, (b), (c) read the camera's view tables (the default).
    const AtmosphereViewTables view = atmosphereViewTables(tables(), placement(), camera, sun(), o);
    const bool integrated = shafts == AtmosphereShafts::Integrated;
    int mismatches = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const PixelRay pr = pixelRay(camera, depth, x, y);
        const AtmosphereRay r = atmosphereRay(
            tables(), placement(), sun(), camera.position(), pr.direction, pr.surface, depth.at(x, y) >= 1.0f,
            none ? AtmosphereShadowing{} : shadowing[static_cast<std::size_t>(y * w + x)], o,
            integrated ? nullptr : &view);
        for (int c = 0; c < 3; ++c) {
          if (image.inscattering.at(x, y, c) != static_cast<float>(r.inscattering[c])) ++mismatches;
          if (image.transmittance.at(x, y, c) != static_cast<float>(r.transmittance[c])) ++mismatches;
        }
        const float alpha =
            static_cast<float>((r.transmittance.x + r.transmittance.y + r.transmittance.z) / 3.0);
        if (image.inscattering.at(x, y, 3) != alpha) ++mismatches;
      }
    CHECK(mismatches == 0);
  }
  // Validation names the parameter.
  AtmosphereRayOptions a;
  a.shafts = AtmosphereShafts::Integrated;
  CHECK(invalidParameter([&] { atmosphereImage(tables(), placement(), camera, sun(), depth, {}, a); }) ==
        "atmosphereImage.shadowing");
  CHECK(invalidParameter([&] {
          atmosphereImage(tables(), placement(), camera, sun(), depth, std::vector<AtmosphereShadowing>(5),
                          {});
        }) == "atmosphereImage.shadowing");
  CHECK(invalidParameter([&] { atmosphereImage(tables(), placement(), camera, sun(), Image(), {}, {}); }) ==
        "cameraDepth");
  CHECK(invalidParameter([&] {
          atmosphereImage(tables(), placement(), camera, sun(), Image(w, h, 2), {}, {});
        }) == "cameraDepth");
  AtmospherePlacement bad;
  bad.metersPerUnit = 0.0;
  CHECK(invalidParameter([&] { atmosphereImage(tables(), bad, camera, sun(), depth, {}, {}); }) ==
        "AtmospherePlacement.metersPerUnit");
  AtmosphereRayOptions zero;
  zero.integrationSteps = 0;
  CHECK(invalidParameter([&] { atmosphereImage(tables(), placement(), camera, sun(), depth, {}, zero); }) ==
        "AtmosphereRayOptions.integrationSteps");
  AtmosphereRayOptions flat;
  flat.volumeSize.z = 1;
  CHECK(invalidParameter([&] { atmosphereImage(tables(), placement(), camera, sun(), depth, {}, flat); }) ==
        "AtmosphereRayOptions.volumeSize.z");
  AtmosphereRayOptions huge;
  huge.volumeSize.x = 4096;
  CHECK(invalidParameter([&] { atmosphereViewTables(tables(), placement(), camera, sun(), huge); }) ==
        "AtmosphereRayOptions.volumeSize.x");
  AtmosphereRayOptions noSteps;
  noSteps.volumeSteps = 0;
  CHECK(invalidParameter([&] { atmosphereViewTables(tables(), placement(), camera, sun(), noSteps); }) ==
        "AtmosphereRayOptions.volumeSteps");
  AtmosphereRayOptions badMode;
  badMode.single = static_cast<AtmosphereSingleScattering>(7);
  CHECK(invalidParameter([&] {
          atmosphereImage(tables(), placement(), camera, sun(), depth, {}, badMode);
        }) == "AtmosphereRayOptions.single");
  AtmosphereRayOptions odd;
  odd.skyViewSize.y = 7;
  CHECK(invalidParameter([&] { atmosphereViewTables(tables(), placement(), camera, sun(), odd); }) ==
        "AtmosphereRayOptions.skyViewSize.y");
}

TEST_CASE("Atmosphere ray: a camera above the atmosphere") {
  // 1 unit = 1 km, the camera 120 km up (40 km above the top) looking down at 45 degrees.
  AtmospherePlacement pl;
  pl.metersPerUnit = 1000.0;
  const int w = 16, h = 9;
  const Camera camera = Camera::lookAt({0.0, 120.0, 0.0}, {0.0, 110.0, -10.0}, {0.0, 1.0, 0.0},
                                       glm::radians(60.0), static_cast<double>(w) / h, 1.0, 2000.0);
  Image depth(w, h, 1, 1.0f);
  for (const AtmosphereShafts shafts : {AtmosphereShafts::None, AtmosphereShafts::Integrated}) {
    AtmosphereRayOptions o;
    o.shafts = shafts;
    std::vector<AtmosphereShadowing> shadowing;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        shadowing.push_back(shadowingFromSections({{0.0, pixelRay(camera, depth, x, y).surface}}));
    const AtmosphereImage image = atmosphereImage(tables(), pl, camera, sun(), depth, shadowing, o, 2);
    int bad = 0, lit = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) {
          const float L = image.inscattering.at(x, y, c), T = image.transmittance.at(x, y, c);
          if (!std::isfinite(L) || !std::isfinite(T) || T < 0.0f || T > 1.0f) ++bad;
          if (L > 0.0f) ++lit;
        }
    CHECK(bad == 0);
    CHECK(lit > 0);
  }
  // A ray away from the planet misses the atmosphere: nothing scattered, everything transmitted.
  const AtmosphereRay miss =
      atmosphereRay(tables(), pl, sun(), {0.0, 120.0, 0.0}, {0.0, 1.0, 0.0}, 2000.0, true, {}, {});
  CHECK(miss.inscattering == glm::dvec3(0.0));
  CHECK(miss.transmittance == glm::dvec3(1.0));
  // From above the top, a ray that enters: the restrained camera gives the same result as a camera at the
  // entry point (distances shifted by the 40 km to the top).
  const glm::dvec3 down = glm::normalize(glm::dvec3(0.0, -1.0, -0.2));
  const AtmosphereRay outside =
      atmosphereRay(tables(), pl, sun(), {0.0, 120.0, 0.0}, down, 2000.0, true, {}, {});
  CHECK(std::isfinite(outside.inscattering.x));
  CHECK(outside.transmittance == glm::dvec3(0.0)); // straight down: hits the ground
  CHECK(outside.inscattering.x > 0.0);
}

TEST_CASE("Atmosphere ray: a sky ray that hits the ground adds the ground's reflected light") {
  // The ground term of atmosphereRay's rule, from the public look-ups: T(C->X) (the segment's 16 steps)
  // (albedo / pi) (T_sun(X) max(0, n . l) + E_sky(n . l)), times the sun's irradiance; the same ray with a
  // black ground lacks exactly it, and a ray above the horizon has none.
  const TestRay down{
      "sky to the ground", {0.0, 20.0, 0.0}, glm::normalize(glm::dvec3(0.0, -0.2, -1.0)), 500.0, true};
  const AtmosphereTables& t = tables(1);
  REQUIRE(t.parameters.groundAlbedo > 0.0);
  for (AtmosphereShafts mode : {AtmosphereShafts::None, AtmosphereShafts::Integrated}) {
    const AtmosphereShadowing lit = sections({{0.0, down.surface}});
    const glm::dvec3 with = run(down, mode, lit, 64, 16, 1).inscattering;
    const glm::dvec3 without = run(down, mode, lit, 64, 16, 1, &blackGroundTables()).inscattering;
    const glm::dvec3 C = atmospherePosition(placement(), t.parameters, down.origin);
    const double cv = glm::dot(C, down.direction), rc = glm::length(C);
    const double tX =
        -cv - std::sqrt(cv * cv - (rc - t.parameters.earthRadius) * (rc + t.parameters.earthRadius));
    const glm::dvec3 X = C + down.direction * tX, l = -sun().direction();
    const double cosSun = glm::dot(X / glm::length(X), l);
    REQUIRE(cosSun > 0.0);
    const glm::dvec3 T = extinctionOf(t.parameters, densityIntegral(t.parameters, C, X, 16));
    const glm::dvec3 ground = sun().irradiance() * T * (t.parameters.groundAlbedo / 3.14159265358979323846) *
                              (sunTransmittance(t, X, l) * cosSun + lookUpAmbientSkyLight(t, cosSun));
    MESSAGE("ground term " << ground.g << " of the pixel's " << with.g);
    CHECK(maxRelative(with - without, ground) < 1e-12);
    CHECK(ground.g > 0.01 * with.g);
  }
  const TestRay up{"sky up", {0.0, 20.0, 0.0}, glm::normalize(glm::dvec3(0.0, 0.2, -1.0)), 500.0, true};
  CHECK(run(up, AtmosphereShafts::None, {}, 64, 16, 1).inscattering ==
        run(up, AtmosphereShafts::None, {}, 64, 16, 1, &blackGroundTables()).inscattering);
}
