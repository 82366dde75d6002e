// The CPU atmosphere tables (crep/atmosphere/atmosphere.h; Yusov 2013, Bruneton and Neyret 2008): the
// parameterisation hits the texel centres exactly and keeps the side of the horizon (Listing 2), the
// look-ups reproduce stored texels and interpolate linearly (Listing 1), the horizon and the directions
// match the geometry, the optical depth table and the transmittances match independent density integrals,
// the precomputation is deterministic and consistent (L_M = L1 + L_H), and bad fields are named.
#include <crep/atmosphere/atmosphere.h>
#include <crep/core/error.h>
#include <crep/core/medium.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

using namespace crep;

namespace {

constexpr double kPi = std::numbers::pi;

/// Texel centre of texel i of n: (i + 0.5) / n.
double centre(int i, int n) {
  return (i + 0.5) / n;
}

/// Independent evaluation of Eq. 6 (Bruneton's form) for the one clamped texel.
double phiU(double c) {
  const double t = std::tan(1.26 * 1.1);
  return 0.5 * (std::atan(std::max(c, -0.1975) * t) / 1.1 + 0.74);
}

/// Fills every texel with a distinct value derived from its indices.
AtmosphereTable4D indexTable(const AtmosphereTableSize& s) {
  AtmosphereTable4D t;
  t.size = s;
  t.rgba.assign(t.texels() * 4, 0.0f);
  for (int it = 0; it < s.sunView; ++it)
    for (int ip = 0; ip < s.sunZenith; ++ip)
      for (int ia = 0; ia < s.viewZenith; ++ia)
        for (int ih = 0; ih < s.height; ++ih) {
          const float v = static_cast<float>(ih + 10 * ia + 100 * ip + 1000 * it);
          t.at(ih, ia, ip, it) = glm::vec4(v, 0.5f * v + 1.0f, std::sqrt(v + 3.0f), 0.0f);
        }
  return t;
}

double relErr(double a, double b) {
  return std::abs(a - b) / std::max(std::abs(b), 1e-300);
}

template <class F>
void expectThrowsNaming(F&& f, const std::string& name) {
  bool thrown = false;
  try {
    f();
  } catch (const InvalidArgument& e) {
    thrown = true;
    INFO("message: " << e.what());
    CHECK(std::string(e.what()).find(name) != std::string::npos);
  }
  INFO("expected InvalidArgument naming " << name);
  CHECK(thrown);
}

/// Small options for precomputations inside the tests.
AtmospherePrecomputeOptions smallOptions() {
  AtmospherePrecomputeOptions o;
  o.size = {8, 16, 8, 4};
  o.orders = 4;
  o.singleSteps = 100;
  o.orderSteps = 64;
  o.sphereSamples = 64;
  o.opticalDepthHeight = 64;
  o.opticalDepthZenith = 256;
  o.opticalDepthSteps = 256;
  o.ambientSize = 16;
  return o;
}

/// The tables with only the optical depth table worth testing (tiny 4D tables, single scattering).
AtmosphereTables opticalDepthTables(const AtmosphereParameters& p) {
  AtmospherePrecomputeOptions o;
  o.size = {2, 4, 2, 2};
  o.orders = 1;
  o.singleSteps = 4;
  o.sphereSamples = 4;
  o.ambientSize = 2;
  o.opticalDepthHeight = 64;
  o.opticalDepthZenith = 256;
  o.opticalDepthSteps = 256;
  return precomputeAtmosphere(p, o);
}

} // namespace

TEST_CASE("Atmosphere parameterisation maps texel params to the texel centres") {
  const AtmosphereParameters p;
  const AtmosphereTableSize s{5, 8, 6, 4};
  const int half = s.viewZenith / 2;
  double worst = 0.0;
  for (int it = 0; it < s.sunView; ++it)
    for (int ip = 0; ip < s.sunZenith; ++ip)
      for (int ia = 0; ia < s.viewZenith; ++ia)
        for (int ih = 0; ih < s.height; ++ih) {
          const glm::dvec4 w = atmosphereTexelParams(p, s, ih, ia, ip, it);
          // Listing 2: a previous look-up in the texel's half keeps it there (both horizon texels).
          const glm::dvec4 previous(-1.0, ia < half ? 0.25 : 0.75, -1.0, -1.0);
          const glm::dvec4 u = atmosphereTableCoords(p, s, w.x, w.y, w.z, w.w, previous);
          CHECK(u.x == doctest::Approx(centre(ih, s.height)).epsilon(1e-9));
          CHECK(std::abs(u.y - centre(ia, s.viewZenith)) < 1e-9);
          CHECK(std::abs(u.w - centre(it, s.sunView)) < 1e-9);
          if (ip > 0) {
            CHECK(std::abs(u.z - centre(ip, s.sunZenith)) < 1e-9);
          } else {
            // Texel 0 of Eq. 6's inverse is c_phi = -0.19794 < -0.1975, which the forward law clamps:
            // the coordinate is u(-0.1975) = 5.05e-4 of the range above the centre.
            CHECK(w.z < -0.1975);
            CHECK(std::abs(u.z - (0.5 + phiU(-0.1975) * (s.sunZenith - 1)) / s.sunZenith) < 1e-9);
          }
          worst = std::max({worst, std::abs(u.x - centre(ih, s.height)),
                            std::abs(u.y - centre(ia, s.viewZenith)), std::abs(u.w - centre(it, s.sunView))});
          // A first look-up (no previous) agrees, except the upper half's horizon texel (c_alpha = c_h
          // is not above the horizon: it goes to the lower half's horizon texel).
          const glm::dvec4 first = atmosphereTableCoords(p, s, w.x, w.y, w.z, w.w);
          if (ia == half)
            CHECK(std::abs(first.y - centre(0, s.viewZenith)) < 1e-9);
          else
            CHECK(std::abs(first.y - centre(ia, s.viewZenith)) < 1e-9);
        }
  MESSAGE("largest texel-centre round-trip error (h, alpha, theta): " << worst);
  // Texel-centre params at the ends: h from 0 to H_Atm, alpha from straight down to the zenith.
  CHECK(atmosphereTexelParams(p, s, 0, 0, 1, 1).x == 0.0);
  CHECK(atmosphereTexelParams(p, s, s.height - 1, 0, 1, 1).x == doctest::Approx(p.atmosphereHeight));
  CHECK(atmosphereTexelParams(p, s, 2, half - 1, 1, 1).y == doctest::Approx(-1.0));
  CHECK(atmosphereTexelParams(p, s, 2, s.viewZenith - 1, 1, 1).y == doctest::Approx(1.0));
  CHECK(atmosphereTexelParams(p, s, 2, 0, s.sunZenith - 1, 0).z == doctest::Approx(1.0));
  CHECK(atmosphereTexelParams(p, s, 2, 0, 1, 0).w == doctest::Approx(1.0));
  CHECK(atmosphereTexelParams(p, s, 2, 0, 1, s.sunView - 1).w == doctest::Approx(-1.0));
}

TEST_CASE("Atmosphere u_alpha keeps the side of the previous look-up (Listing 2)") {
  const AtmosphereParameters p;
  const AtmosphereTableSize s{8, 16, 8, 4};
  const double h = 3000.0;
  const double ch = cosHorizon(p, h);
  const double upperHorizon = (s.viewZenith / 2 + 0.5) / s.viewZenith;
  const double lowerHorizon = 0.5 / s.viewZenith;
  const auto ua = [&](double ca, double prev) {
    return atmosphereTableCoords(p, s, h, ca, 0.3, 0.2, glm::dvec4(-1.0, prev, -1.0, -1.0)).y;
  };
  // First look-up: the side is the ray's own.
  CHECK(ua(ch + 0.05, -1.0) > 0.5);
  CHECK(ua(ch - 0.05, -1.0) < 0.5);
  CHECK(ua(ch, -1.0) == doctest::Approx(lowerHorizon));
  // A previous look-up above the horizon keeps a below-horizon direction in the upper half, at its
  // horizon texel; one below keeps an above-horizon direction in the lower half.
  CHECK(ua(ch - 0.05, 0.5) == doctest::Approx(upperHorizon));
  CHECK(ua(ch - 0.05, 0.9) == doctest::Approx(upperHorizon));
  CHECK(ua(ch + 0.05, 0.0) == doctest::Approx(lowerHorizon));
  CHECK(ua(ch + 0.05, 0.4999) == doctest::Approx(lowerHorizon));
  // And the same direction stays where it is when the previous agrees.
  CHECK(ua(ch + 0.05, 0.7) == doctest::Approx(ua(ch + 0.05, -1.0)));
  CHECK(ua(ch - 0.05, 0.2) == doctest::Approx(ua(ch - 0.05, -1.0)));
  // Ranges of the halves: [0.5/N, 0.5 - 0.5/N] and [0.5 + 0.5/N, 1 - 0.5/N].
  CHECK(ua(-1.0, -1.0) == doctest::Approx(0.5 - 0.5 / s.viewZenith));
  CHECK(ua(1.0, -1.0) == doctest::Approx(1.0 - 0.5 / s.viewZenith));
}

TEST_CASE("Atmosphere parameterisation is monotonic in each parameter") {
  const AtmosphereParameters p;
  const AtmosphereTableSize s{32, 128, 64, 16};
  const int n = 2000;
  double prev = -1.0;
  for (int i = 0; i <= n; ++i) { // u_h increases with h
    const double u = atmosphereTableCoords(p, s, p.atmosphereHeight * i / n, 0.5, 0.5, 0.5).x;
    CHECK(u > prev);
    prev = u;
  }
  const double h = 5000.0;
  const double ch = cosHorizon(p, h);
  prev = -1.0;
  for (int i = 1; i <= n; ++i) { // upper half: increases with c_alpha from the horizon to the zenith
    const double ca = ch + (1.0 - ch) * i / n;
    const double u = atmosphereTableCoords(p, s, h, ca, 0.5, 0.5).y;
    CHECK(u > prev);
    CHECK(u > 0.5);
    prev = u;
  }
  prev = -1.0;
  for (int i = 0; i <= n; ++i) { // lower half: increases from the horizon down to the nadir
    const double ca = ch - (ch + 1.0) * i / n;
    const double u = atmosphereTableCoords(p, s, h, ca, 0.5, 0.5).y;
    CHECK(u > prev);
    CHECK(u < 0.5);
    prev = u;
  }
  prev = -1.0;
  for (int i = 0; i <= n; ++i) { // u_phi: constant below -0.1975, then increasing
    const double cp = -1.0 + 2.0 * i / n;
    const double u = atmosphereTableCoords(p, s, h, 0.5, cp, 0.5).z;
    if (cp <= -0.1975)
      CHECK(u == doctest::Approx(prev < 0.0 ? u : prev));
    else
      CHECK(u > prev);
    prev = u;
  }
  prev = -1.0;
  for (int i = 0; i <= n; ++i) { // u_theta increases with the angle (decreasing c_theta)
    const double ct = 1.0 - 2.0 * i / n;
    const double u = atmosphereTableCoords(p, s, h, 0.5, 0.5, ct).w;
    CHECK(u > prev);
    prev = u;
  }
  // Ends of every coordinate are the first and last texel centres.
  const glm::dvec4 lo = atmosphereTableCoords(p, s, 0.0, 0.5, -1.0, 1.0);
  const glm::dvec4 hi = atmosphereTableCoords(p, s, p.atmosphereHeight, 0.5, 1.0, -1.0);
  CHECK(lo.x == doctest::Approx(0.5 / s.height));
  CHECK(hi.x == doctest::Approx(1.0 - 0.5 / s.height));
  CHECK(hi.z == doctest::Approx(1.0 - 0.5 / s.sunZenith));
  CHECK(lo.w == doctest::Approx(0.5 / s.sunView));
  CHECK(hi.w == doctest::Approx(1.0 - 0.5 / s.sunView));
  // Out-of-range inputs are clamped.
  CHECK(atmosphereTableCoords(p, s, -50.0, 0.5, 0.5, 0.5).x == doctest::Approx(lo.x));
  CHECK(atmosphereTableCoords(p, s, 2.0 * p.atmosphereHeight, 0.5, 0.5, 0.5).x == doctest::Approx(hi.x));
}

TEST_CASE("Atmosphere look-ups at texel centres return the stored texels and interpolate linearly") {
  const AtmosphereTableSize s{4, 8, 5, 3};
  const AtmosphereTable4D t = indexTable(s);
  CHECK(t.texels() == 4u * 8u * 5u * 3u);
  CHECK(t.rgba.size() == 4 * t.texels());
  // Packed order: ((it * N_phi + ip) * N_alpha + ia) * N_h + ih.
  CHECK(t.rgba[4 * (((2 * 5 + 3) * 8 + 6) * 4 + 1)] == t.at(1, 6, 3, 2).x);
  for (int it = 0; it < s.sunView; ++it)
    for (int ip = 0; ip < s.sunZenith; ++ip)
      for (int ia = 0; ia < s.viewZenith; ++ia)
        for (int ih = 0; ih < s.height; ++ih) {
          const glm::dvec4 c(centre(ih, s.height), centre(ia, s.viewZenith), centre(ip, s.sunZenith),
                             centre(it, s.sunView));
          const glm::dvec3 v = sampleAtmosphereTable(t, c);
          const glm::vec4 e = t.at(ih, ia, ip, it);
          CHECK(v.x == doctest::Approx(e.x).epsilon(1e-6));
          CHECK(v.y == doctest::Approx(e.y).epsilon(1e-6));
          CHECK(v.z == doctest::Approx(e.z).epsilon(1e-6));
        }
  // Between two theta slices: linear in u_theta's texel space.
  const glm::dvec4 c0(centre(1, s.height), centre(5, s.viewZenith), centre(2, s.sunZenith),
                      centre(0, s.sunView));
  for (double f : {0.0, 0.125, 0.5, 0.8, 1.0}) {
    glm::dvec4 c = c0;
    c.w = (0.5 + f) / s.sunView;
    const glm::dvec3 v = sampleAtmosphereTable(t, c);
    const glm::dvec3 e =
        glm::mix(glm::dvec3(glm::vec3(t.at(1, 5, 2, 0))), glm::dvec3(glm::vec3(t.at(1, 5, 2, 1))), f);
    CHECK(v.x == doctest::Approx(e.x).epsilon(1e-9));
    CHECK(v.z == doctest::Approx(e.z).epsilon(1e-9));
  }
  // Between texels of a packed dimension: GL linear (here u_h, half way).
  {
    glm::dvec4 c = c0;
    c.x = 2.0 / s.height; // between ih = 1 and 2
    const glm::dvec3 v = sampleAtmosphereTable(t, c);
    CHECK(v.x == doctest::Approx(0.5 * (t.at(1, 5, 2, 0).x + t.at(2, 5, 2, 0).x)));
  }
  // The phi coordinate stays inside its theta slice: beyond the last texel centre, no bleeding into the
  // next slice (clamped to the slice's last texel).
  {
    glm::dvec4 c = c0;
    c.z = 1.0;
    CHECK(sampleAtmosphereTable(t, c).x == doctest::Approx(t.at(1, 5, s.sunZenith - 1, 0).x));
    c.z = 0.0;
    c.w = centre(1, s.sunView);
    CHECK(sampleAtmosphereTable(t, c).x == doctest::Approx(t.at(1, 5, 0, 1).x));
  }
  // Clamp to edge in theta: coordinates beyond the last slice's centre read the last slice.
  {
    glm::dvec4 c = c0;
    c.w = 1.0;
    CHECK(sampleAtmosphereTable(t, c).x == doctest::Approx(t.at(1, 5, 2, s.sunView - 1).x));
    c.w = 0.0;
    CHECK(sampleAtmosphereTable(t, c).x == doctest::Approx(t.at(1, 5, 2, 0).x));
  }
  // End to end (Listing 1): the texel's own point and directions (compatible cosines) read the texel.
  const AtmosphereParameters p;
  AtmosphereTables tables;
  tables.parameters = p;
  int checked = 0;
  for (int it = 0; it < s.sunView; ++it)
    for (int ip = 1; ip < s.sunZenith; ++ip)
      for (int ia = 0; ia < s.viewZenith; ++ia)
        for (int ih = 0; ih < s.height; ++ih) {
          const glm::dvec4 w = atmosphereTexelParams(p, s, ih, ia, ip, it);
          const double sa = std::sqrt(1.0 - w.y * w.y);
          const double lx = (w.w - w.y * w.z) / sa;
          if (sa < 1e-6 || lx * lx + w.z * w.z > 1.0) continue; // incompatible cosines
          glm::dvec3 v, l;
          atmosphereDirections(w.y, w.z, w.w, v, l);
          glm::dvec4 coords(-1.0, ia < s.viewZenith / 2 ? 0.25 : 0.75, -1.0, -1.0);
          const glm::dvec3 got =
              lookUpAtmosphere(tables, t, glm::dvec3(0.0, p.earthRadius + w.x, 0.0), v, l, coords);
          const glm::vec4 e = t.at(ih, ia, ip, it);
          if (ia == 0 || ia == s.viewZenith / 2) {
            // The horizon texels: Eq. 5's power 0.2 turns the rounding of |P| - R and of the cosines
            // (~1e-16) into ~(1e-16)^0.2 = 6e-4 of the half's coordinate range.
            CHECK(std::abs(coords.y - centre(ia, s.viewZenith)) < 1e-3);
            continue;
          }
          CHECK(got.x == doctest::Approx(e.x).epsilon(1e-6));
          CHECK(got.y == doctest::Approx(e.y).epsilon(1e-6));
          CHECK(std::abs(coords.y - centre(ia, s.viewZenith)) < 1e-9);
          ++checked;
        }
  MESSAGE("end-to-end texel look-ups checked: " << checked);
  CHECK(checked > 40);
}

TEST_CASE("Atmosphere cosHorizon is the tangent to the ground") {
  const AtmosphereParameters p;
  CHECK(cosHorizon(p, 0.0) == 0.0);
  for (double h : {1.0, 100.0, 2000.0, 30000.0, 80000.0}) {
    const double c = cosHorizon(p, h);
    CHECK(c < 0.0);
    // Closest approach of the ray from (0, R + h, 0) with cos zenith c to the centre: (R + h) sin = R.
    const double r0 = p.earthRadius + h;
    const double closest = r0 * std::sqrt(1.0 - c * c);
    CHECK(std::abs(closest - p.earthRadius) < 1e-6);
    // And at that point the ray runs along the ground: the distance to it is sqrt(r0^2 - R^2).
    const double along = -r0 * c;
    CHECK(along == doctest::Approx(std::sqrt(r0 * r0 - p.earthRadius * p.earthRadius)).epsilon(1e-12));
  }
}

TEST_CASE("Atmosphere directions have the requested cosines") {
  double worst = 0.0;
  for (double ca : {-1.0, -0.7, -0.1, 0.0, 0.3, 0.9, 1.0})
    for (double cp : {-1.0, -0.5, 0.0, 0.2, 0.95})
      for (double dphi : {0.0, 0.4, 1.5, 2.5, kPi}) {
        const double sa = std::sqrt(1.0 - ca * ca), sp = std::sqrt(1.0 - cp * cp);
        const double ct = ca * cp + sa * sp * std::cos(dphi); // compatible by construction
        glm::dvec3 v, l;
        atmosphereDirections(ca, cp, ct, v, l);
        CHECK(glm::length(v) == doctest::Approx(1.0).epsilon(1e-12));
        CHECK(glm::length(l) == doctest::Approx(1.0).epsilon(1e-12));
        CHECK(v.y == doctest::Approx(ca).epsilon(1e-12));
        CHECK(v.z == 0.0);
        if (sa >= 1e-6) {
          worst = std::max({worst, std::abs(glm::dot(v, l) - ct), std::abs(l.y - cp)});
          CHECK(std::abs(glm::dot(v, l) - ct) < 1e-7);
          CHECK(std::abs(l.y - cp) < 1e-7);
        }
      }
  MESSAGE("largest |v.l - c_theta|, |l.y - c_phi| for compatible cosines: " << worst);
  // Incompatible cosines (v straight up, c_theta != c_phi): still unit vectors.
  glm::dvec3 v, l;
  atmosphereDirections(1.0, 0.2, -0.9, v, l);
  CHECK(glm::length(l) == doctest::Approx(1.0));
  atmosphereDirections(0.0, 0.9, -0.9, v, l);
  CHECK(glm::length(l) == doctest::Approx(1.0));
  // Fibonacci directions are unit and their mean is the centre (a balanced sphere).
  glm::dvec3 mean(0.0);
  for (int i = 0; i < 256; ++i) {
    const glm::dvec3 w = fibonacciSphereDirection(i, 256);
    CHECK(glm::length(w) == doctest::Approx(1.0));
    mean += w / 256.0;
  }
  CHECK(glm::length(mean) < 0.01);
}

TEST_CASE("Atmosphere optical depth table matches the density integrals") {
  const AtmosphereParameters p;
  const AtmosphereTables t = opticalDepthTables(p);
  const int w = t.opticalDepth.width(), hgt = t.opticalDepth.height();
  REQUIRE(w == 64);
  REQUIRE(hgt == 256);
  REQUIRE(t.opticalDepth.channels() == 2);
  const double R = p.earthRadius, top = R + p.atmosphereHeight;
  const auto reference = [&](double h, double c, int steps) {
    const double r0 = R + h;
    const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
    const double len = -r0 * c + std::sqrt(r0 * r0 * (c * c - 1.0) + top * top);
    const glm::dvec3 a(0.0, r0, 0.0);
    return densityIntegral(p, a, a + glm::dvec3(s, c, 0.0) * len, steps);
  };
  const auto occluded = [&](double h, double c) {
    const double r0 = R + h;
    return c < 0.0 && r0 * r0 * (c * c - 1.0) + R * R >= 0.0;
  };
  // At the texel centres: the stored (float) integrals (relative, with a floor of 1 m of sea-level air for
  // the rays that start at the top of the atmosphere and integrate nothing).
  double worstCentre = 0.0;
  int occludedTexels = 0;
  for (int j = 0; j < hgt; ++j)
    for (int i = 0; i < w; ++i) {
      const double u = static_cast<double>(i) / (w - 1);
      const double h = p.atmosphereHeight * u * u;
      const double c = -1.0 + 2.0 * j / (hgt - 1);
      const glm::dvec2 got = lookUpDensityToTop(t, h, c);
      if (occluded(h, c)) {
        ++occludedTexels;
        CHECK(t.opticalDepth.at(i, j, 0) == static_cast<float>(kOccludedDensity));
        CHECK(t.opticalDepth.at(i, j, 1) == static_cast<float>(kOccludedDensity));
        CHECK(got.x == doctest::Approx(kOccludedDensity).epsilon(1e-9));
        continue;
      }
      const glm::dvec2 ref = reference(h, c, t.options.opticalDepthSteps);
      worstCentre = std::max({worstCentre, std::abs(got.x - ref.x) / std::max(ref.x, 1.0),
                              std::abs(got.y - ref.y) / std::max(ref.y, 1.0)});
    }
  MESSAGE("optical depth table at texel centres vs densityIntegral (256 steps): largest relative error "
          << worstCentre << " (" << occludedTexels << " occluded texels)");
  CHECK(worstCentre < 1e-6);
  CHECK(occludedTexels > 0);
  // Occluded rays: the sun's transmittance is 0 in every channel.
  CHECK(sunTransmittance(t, glm::dvec3(0.0, R + 10.0, 0.0), glm::dvec3(0.0, -1.0, 0.0)) == glm::dvec3(0.0));
  CHECK(sunTransmittance(t, glm::dvec3(0.0, R + 30000.0, 0.0), glm::dvec3(0.0, -0.5, std::sqrt(0.75))) ==
        glm::dvec3(0.0));

  // Between texels (half-way in both dimensions, where bilinear is worst), skipping footprints with an
  // occluded texel. The table is linear in c (2/255 per texel): just above the horizon the integrals vary
  // far faster than that, so the errors are measured in bands of the distance to the horizon, in texels.
  const glm::dvec3 betaMe = p.mieScattering + p.mieAbsorption;
  double worstT = 0.0, worstT8 = 0.0, worstTau16 = 0.0, worstTau32 = 0.0, worstTau = 0.0;
  int count = 0, count32 = 0;
  for (int j = 0; j + 1 < hgt; ++j)
    for (int i = 0; i + 1 < w; ++i) {
      const double u = (i + 0.5) / (w - 1);
      const double h = p.atmosphereHeight * u * u;
      const double c = -1.0 + 2.0 * (j + 0.5) / (hgt - 1);
      const glm::dvec2 got = lookUpDensityToTop(t, h, c);
      if (got.x >= kOccludedDensity * 1e-3) continue; // a footprint with an occluded texel
      const glm::dvec2 ref = reference(h, c, t.options.opticalDepthSteps);
      const double aboveHorizon = (c - cosHorizon(p, h)) / (2.0 / (hgt - 1)); // texels
      const glm::dvec3 tauGot = p.rayleighScattering * got.x + betaMe * got.y;
      const glm::dvec3 tauRef = p.rayleighScattering * ref.x + betaMe * ref.y;
      for (int ch = 0; ch < 3; ++ch) {
        const double eT = std::abs(std::exp(-tauGot[ch]) - std::exp(-tauRef[ch]));
        worstT = std::max(worstT, eT);
        if (aboveHorizon >= 8.0) worstT8 = std::max(worstT8, eT);
        if (tauRef[ch] > 1e-3) {
          const double eTau = relErr(tauGot[ch], tauRef[ch]);
          worstTau = std::max(worstTau, eTau);
          if (aboveHorizon >= 16.0) worstTau16 = std::max(worstTau16, eTau);
          if (aboveHorizon >= 32.0) worstTau32 = std::max(worstTau32, eTau);
        }
      }
      ++count;
      if (aboveHorizon >= 32.0) ++count32;
    }
  MESSAGE("optical depth table between texels (64x256, bilinear) vs densityIntegral over "
          << count << " points: transmittance exp(-tau) largest absolute error " << worstT << " (all), "
          << worstT8 << " (>= 8 texels above the horizon); optical depth tau > 1e-3 largest relative error "
          << worstTau << " (all), " << worstTau16 << " (>= 16 texels above the horizon), " << worstTau32
          << " (>= 32 texels = 0.25 in cos above the horizon, " << count32 << " points)");
  CHECK(count > 5000);
  CHECK(worstT < 0.15);     // the band just above the horizon (measured 0.108)
  CHECK(worstT8 < 0.01);    // measured 0.0054
  CHECK(worstTau16 < 0.03); // measured 0.0252
  CHECK(worstTau32 < 0.02); // measured 0.0103
}

TEST_CASE("Atmosphere transmittance between two points matches the density integral") {
  const AtmosphereParameters p;
  const AtmosphereTables t = opticalDepthTables(p);
  const double R = p.earthRadius;
  const glm::dvec3 betaMe = p.mieScattering + p.mieAbsorption;
  const auto exact = [&](const glm::dvec3& a, const glm::dvec3& b) {
    const glm::dvec2 d = densityIntegral(p, a, b, 4096);
    return glm::exp(-(p.rayleighScattering * d.x + betaMe * d.y));
  };
  struct Case {
    const char* name;
    double h, c, length, tolerance;
  };
  // Tolerances: absolute per channel, from the table's bilinear error (see the optical depth test).
  const Case cases[] = {
      {"horizontal-ish, upwards", 1000.0, 0.05, 20000.0, 0.01},
      // c = 0 at 500 m is 1.6 texels of the table's c above the horizon, where its bilinear error is largest
      // (measured 0.034).
      {"horizontal, near the horizon band", 500.0, 0.0, 30000.0, 0.05},
      {"downward (hits the ground)", 5000.0, -0.3, 10000.0, 0.01},
      {"steeply down to near the ground", 3000.0, -0.9, 3000.0, 0.01},
  };
  for (const Case& k : cases) {
    const glm::dvec3 a(0.0, R + k.h, 0.0);
    const glm::dvec3 v(std::sqrt(1.0 - k.c * k.c), k.c, 0.0);
    const glm::dvec3 b = a + v * k.length;
    const glm::dvec3 got = atmosphereTransmittance(t, a, b);
    const glm::dvec3 ref = exact(a, b);
    const double err = glm::length(got - ref) / std::sqrt(3.0);
    double maxErr = 0.0;
    for (int ch = 0; ch < 3; ++ch)
      maxErr = std::max(maxErr, std::abs(got[ch] - ref[ch]));
    MESSAGE(std::string(k.name) << ": transmittance " << got.x << " " << got.y << " " << got.z << " vs exact "
                                << ref.x << " " << ref.y << " " << ref.z << ", largest absolute error "
                                << maxErr << " (rms " << err << ", tolerance " << k.tolerance << ")");
    CHECK(maxErr < k.tolerance);
    CHECK(ref.z < 0.95); // a meaningful amount of extinction
  }
  // Identity: a zero-length segment transmits everything.
  const glm::dvec3 a(0.0, R + 100.0, 0.0);
  CHECK(atmosphereTransmittance(t, a, a) == glm::dvec3(1.0));
}

TEST_CASE("Atmosphere precomputation is deterministic, consistent and fast") {
  const AtmosphereParameters p;
  AtmospherePrecomputeOptions o = smallOptions();
  o.keepOrders = true;
  const auto t0 = std::chrono::steady_clock::now();
  const AtmosphereTables a = precomputeAtmosphere(p, o, 2);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  MESSAGE("precomputeAtmosphere 8x16x8x4, 4 orders, 64 sphere samples, 2 threads: " << seconds << " s");
  CHECK(seconds < 10.0); // well under a second on an idle machine; generous for a shared one
  const AtmosphereTables b = precomputeAtmosphere(p, o, 1);
  CHECK(a.single.rgba == b.single.rgba);
  CHECK(a.singleMie.rgba == b.singleMie.rgba);
  CHECK(a.higherOrders.rgba == b.higherOrders.rgba);
  CHECK(a.ambient.data().size() == b.ambient.data().size());
  CHECK(std::equal(a.ambient.data().begin(), a.ambient.data().end(), b.ambient.data().begin()));

  REQUIRE(a.orders.size() == 4u);
  double worstSum = 0.0, l1 = 0.0, l2 = 0.0, l3 = 0.0;
  bool finite = true, nonNegative = true;
  for (std::size_t i = 0; i < a.single.texels(); ++i)
    for (int ch = 0; ch < 3; ++ch) {
      const std::size_t k = 4 * i + static_cast<std::size_t>(ch);
      const double hsum = double(a.orders[1].rgba[k]) + a.orders[2].rgba[k] + a.orders[3].rgba[k];
      worstSum = std::max(worstSum, std::abs(hsum - a.higherOrders.rgba[k]) / std::max(1e-12, hsum));
      for (const AtmosphereTable4D* table : {&a.single, &a.singleMie, &a.higherOrders}) {
        finite = finite && std::isfinite(table->rgba[k]);
        nonNegative = nonNegative && table->rgba[k] >= 0.0f;
      }
      l1 += a.orders[0].rgba[k];
      l2 += a.orders[1].rgba[k];
      l3 += a.orders[2].rgba[k];
    }
  MESSAGE("sum of L1, L2, L3 over the table: " << l1 << " " << l2 << " " << l3
                                               << "; L_H vs L2 + L3 + L4 largest relative difference "
                                               << worstSum);
  CHECK(finite);
  CHECK(nonNegative);
  CHECK(worstSum < 1e-5);
  // Each order carries less light than the one before.
  CHECK(l2 < l1);
  CHECK(l3 < l2);
  CHECK(l2 > 0.0);
  // The A channel is 0 but in the single table, where it is S_M's red.
  CHECK(a.higherOrders.at(3, 9, 4, 2).w == 0.0f);
  CHECK(a.singleMie.at(3, 9, 4, 2).w == 0.0f);
  CHECK(a.single.at(3, 9, 4, 2).w == a.singleMie.at(3, 9, 4, 2).x);
  CHECK(a.single.at(3, 9, 4, 2).w > 0.0f);
  // Ambient sky light: positive by day, larger with a higher sun; the look-up reads the texels.
  const glm::dvec3 noon = lookUpAmbientSkyLight(a, 1.0), low = lookUpAmbientSkyLight(a, 0.1);
  CHECK(noon.z > low.z);
  CHECK(low.z > 0.0);
  CHECK(noon.x == doctest::Approx(a.ambient.at(o.ambientSize - 1, 0, 0)));
  CHECK(lookUpAmbientSkyLight(a, -1.0).x == doctest::Approx(a.ambient.at(0, 0, 0)));

  // Single scattering only: L_H = 0 and the same L1.
  AtmospherePrecomputeOptions one = smallOptions();
  one.orders = 1;
  const AtmosphereTables s = precomputeAtmosphere(p, one);
  CHECK(s.single.rgba == a.single.rgba);
  CHECK(s.singleMie.rgba == a.singleMie.rgba);
  CHECK(
      std::all_of(s.higherOrders.rgba.begin(), s.higherOrders.rgba.end(), [](float x) { return x == 0.0f; }));
  CHECK(s.orders.empty());
}

TEST_CASE("Atmosphere single scattering matches an independent integral with exact sun transmittance") {
  const AtmosphereParameters p;
  AtmospherePrecomputeOptions o = smallOptions();
  o.orders = 1;
  const AtmosphereTables t = precomputeAtmosphere(p, o);
  const AtmosphereTableSize& s = o.size;
  const double R = p.earthRadius, top = R + p.atmosphereHeight;
  const glm::dvec3 betaMe = p.mieScattering + p.mieAbsorption;
  // Reference: 2000 midpoint steps, T_cam and T_sun from densityIntegral (no tables).
  const auto reference = [&](int ih, int ia, int ip, int it) {
    const glm::dvec4 w = atmosphereTexelParams(p, s, ih, ia, ip, it);
    glm::dvec3 v, l;
    atmosphereDirections(w.y, w.z, w.w, v, l);
    const glm::dvec3 c(0.0, R + w.x, 0.0);
    const double r0 = R + w.x;
    const double len = ia < s.viewZenith / 2
                           ? -r0 * w.y - std::sqrt(std::max(0.0, r0 * r0 * (w.y * w.y - 1.0) + R * R))
                           : -r0 * w.y + std::sqrt(r0 * r0 * (w.y * w.y - 1.0) + top * top);
    const int n = 2000;
    glm::dvec3 sumR(0.0), sumM(0.0);
    for (int k = 0; k < n; ++k) {
      const glm::dvec3 pk = c + v * (len * (k + 0.5) / n);
      const double rk = glm::length(pk);
      const double hk = std::max(rk - R, 0.0);
      const glm::dvec2 dc = densityIntegral(p, c, pk, 200);
      const glm::dvec3 up = pk / rk;
      const double cs = glm::dot(up, l);
      glm::dvec3 tSun(0.0);
      if (!(cs < 0.0 && rk * rk * (cs * cs - 1.0) + R * R >= 0.0)) {
        const double ls = -rk * cs + std::sqrt(rk * rk * (cs * cs - 1.0) + top * top);
        const glm::dvec2 ds = densityIntegral(p, pk, pk + l * ls, 400);
        tSun = glm::exp(-(p.rayleighScattering * ds.x + betaMe * ds.y));
      }
      const glm::dvec3 tCam = glm::exp(-(p.rayleighScattering * dc.x + betaMe * dc.y));
      sumR += p.rayleighScattering * std::exp(-hk / p.rayleighScaleHeight) * tCam * tSun * (len / n);
      sumM += p.mieScattering * std::exp(-hk / p.mieScaleHeight) * tCam * tSun * (len / n);
    }
    return std::pair(sumR, sumM);
  };
  struct Texel {
    int ih, ia, ip, it;
  };
  // Daylight texels away from the terminator (the sun's transmittance is smooth there).
  const Texel texels[] = {{0, 12, 6, 1}, {2, 10, 7, 0}, {3, 14, 5, 2}, {1, 4, 6, 1}, {5, 9, 7, 3}};
  double worst = 0.0, worstR = 0.0, worstM = 0.0;
  for (const Texel& x : texels) {
    // L1 at the texel's own c_theta (S_R p_R + S_M p_HG, the quantity the table's look-ups give), and the
    // phase-free parts S_R (RGB), S_M (the single Mie table, its red in the single table's A) on their own.
    const auto [refR, refM] = reference(x.ih, x.ia, x.ip, x.it);
    const glm::vec4 gotR = t.single.at(x.ih, x.ia, x.ip, x.it);
    const glm::vec4 gotM = t.singleMie.at(x.ih, x.ia, x.ip, x.it);
    const glm::dvec4 w = atmosphereTexelParams(p, s, x.ih, x.ia, x.ip, x.it);
    glm::dvec3 v, l;
    atmosphereDirections(w.y, w.z, w.w, v, l);
    const double ct = glm::dot(v, l);
    const glm::dvec3 ref = refR * rayleighPhase(ct) + refM * henyeyGreenstein(p.mieG, ct);
    const glm::dvec3 got =
        glm::dvec3(gotR) * rayleighPhase(ct) + glm::dvec3(gotM) * henyeyGreenstein(p.mieG, ct);
    for (int ch = 0; ch < 3; ++ch) {
      const double e = relErr(got[ch], ref[ch]);
      worst = std::max(worst, e);
      CHECK(e < 0.03);
      worstR = std::max(worstR, relErr(gotR[ch], refR[ch]));
      worstM = std::max(worstM, relErr(gotM[ch], refM[ch]));
    }
    CHECK(gotR.w == gotM.x);
  }
  MESSAGE("L1 texels vs an independent single-scattering integral (exact transmittances): largest relative "
          "error "
          << worst << " (tolerance 3%); its parts: S_R " << worstR << ", S_M " << worstM);
  // The Mie part alone carries the trapezoid rule's error of 100 steps over rays whose Mie density falls
  // within the first 1.2 km (measured 3.2%); Rayleigh dominates L1 at these texels.
  CHECK(worstR < 0.03);
  CHECK(worstM < 0.05);
}

TEST_CASE("Atmosphere validation names the bad field") {
  const AtmosphereParameters good;
  CHECK_NOTHROW(validate(good));
  const auto badParams = [&](auto change, const std::string& name) {
    AtmosphereParameters p = good;
    change(p);
    expectThrowsNaming([&] { validate(p); }, name);
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  badParams([](AtmosphereParameters& p) { p.earthRadius = -1.0; }, "AtmosphereParameters.earthRadius");
  badParams([&](AtmosphereParameters& p) { p.earthRadius = nan; }, "AtmosphereParameters.earthRadius");
  badParams([](AtmosphereParameters& p) { p.atmosphereHeight = 0.0; },
            "AtmosphereParameters.atmosphereHeight");
  badParams([&](AtmosphereParameters& p) { p.rayleighScaleHeight = nan; },
            "AtmosphereParameters.rayleighScaleHeight");
  badParams([](AtmosphereParameters& p) { p.mieScaleHeight = -3.0; }, "AtmosphereParameters.mieScaleHeight");
  badParams([](AtmosphereParameters& p) { p.rayleighScattering.y = -1e-6; },
            "AtmosphereParameters.rayleighScattering");
  badParams([&](AtmosphereParameters& p) { p.mieScattering.x = nan; }, "AtmosphereParameters.mieScattering");
  badParams([](AtmosphereParameters& p) { p.mieAbsorption.z = std::numeric_limits<double>::infinity(); },
            "AtmosphereParameters.mieAbsorption");
  badParams([](AtmosphereParameters& p) { p.mieG = 1.0; }, "AtmosphereParameters.mieG");
  badParams([](AtmosphereParameters& p) { p.mieG = -1.5; }, "AtmosphereParameters.mieG");
  badParams([](AtmosphereParameters& p) { p.groundAlbedo = -0.1; }, "AtmosphereParameters.groundAlbedo");
  badParams([](AtmosphereParameters& p) { p.groundAlbedo = 1.5; }, "AtmosphereParameters.groundAlbedo");
  badParams([&](AtmosphereParameters& p) { p.groundAlbedo = nan; }, "AtmosphereParameters.groundAlbedo");
  badParams(
      [](AtmosphereParameters& p) {
        p.rayleighScattering = glm::dvec3(0.0);
        p.mieScattering = glm::dvec3(0.0);
      },
      "AtmosphereParameters.rayleighScattering");

  const AtmospherePrecomputeOptions ok;
  CHECK_NOTHROW(validate(ok));
  const auto badOptions = [&](auto change, const std::string& name) {
    AtmospherePrecomputeOptions o = ok;
    change(o);
    expectThrowsNaming([&] { validate(o); }, name);
    expectThrowsNaming([&] { (void)precomputeAtmosphere(good, o); }, name);
  };
  badOptions([](AtmospherePrecomputeOptions& o) { o.size.viewZenith = 31; },
             "AtmospherePrecomputeOptions.size.viewZenith");
  badOptions([](AtmospherePrecomputeOptions& o) { o.size.viewZenith = 2; },
             "AtmospherePrecomputeOptions.size.viewZenith");
  badOptions([](AtmospherePrecomputeOptions& o) { o.size.height = 0; },
             "AtmospherePrecomputeOptions.size.height");
  badOptions([](AtmospherePrecomputeOptions& o) { o.size.height = 2049; },
             "AtmospherePrecomputeOptions.size.height");
  badOptions([](AtmospherePrecomputeOptions& o) { o.size.sunZenith = 1; },
             "AtmospherePrecomputeOptions.size.sunZenith");
  badOptions([](AtmospherePrecomputeOptions& o) { o.size.sunView = 0; },
             "AtmospherePrecomputeOptions.size.sunView");
  badOptions(
      [](AtmospherePrecomputeOptions& o) {
        o.size.sunZenith = 64;
        o.size.sunView = 64; // packed depth 4096 > 2048
      },
      "AtmospherePrecomputeOptions.size.sunView");
  badOptions([](AtmospherePrecomputeOptions& o) { o.orders = 0; }, "AtmospherePrecomputeOptions.orders");
  badOptions([](AtmospherePrecomputeOptions& o) { o.orders = 17; }, "AtmospherePrecomputeOptions.orders");
  badOptions([](AtmospherePrecomputeOptions& o) { o.singleSteps = 0; },
             "AtmospherePrecomputeOptions.singleSteps");
  badOptions([](AtmospherePrecomputeOptions& o) { o.orderSteps = 4097; },
             "AtmospherePrecomputeOptions.orderSteps");
  badOptions([](AtmospherePrecomputeOptions& o) { o.sphereSamples = 0; },
             "AtmospherePrecomputeOptions.sphereSamples");
  badOptions([](AtmospherePrecomputeOptions& o) { o.opticalDepthHeight = 1; },
             "AtmospherePrecomputeOptions.opticalDepthHeight");
  badOptions([](AtmospherePrecomputeOptions& o) { o.opticalDepthZenith = 4096; },
             "AtmospherePrecomputeOptions.opticalDepthZenith");
  badOptions([](AtmospherePrecomputeOptions& o) { o.opticalDepthSteps = 0; },
             "AtmospherePrecomputeOptions.opticalDepthSteps");
  badOptions([](AtmospherePrecomputeOptions& o) { o.ambientSize = 0; },
             "AtmospherePrecomputeOptions.ambientSize");
  badOptions([](AtmospherePrecomputeOptions& o) { o.multipleScatteringSize = 1; },
             "AtmospherePrecomputeOptions.multipleScatteringSize");
  badOptions([](AtmospherePrecomputeOptions& o) { o.multipleScatteringSteps = 0; },
             "AtmospherePrecomputeOptions.multipleScatteringSteps");
  badOptions(
      [](AtmospherePrecomputeOptions& o) {
        o.multipleScattering = static_cast<AtmosphereMultipleScattering>(7);
      },
      "AtmospherePrecomputeOptions.multipleScattering");
  // precomputeAtmosphere validates the parameters too.
  AtmosphereParameters bad = good;
  bad.mieG = 2.0;
  expectThrowsNaming([&] { (void)precomputeAtmosphere(bad, ok); }, "AtmosphereParameters.mieG");

  AtmospherePlacement place;
  CHECK_NOTHROW(validate(place, good));
  place.metersPerUnit = 0.0;
  expectThrowsNaming([&] { validate(place, good); }, "AtmospherePlacement.metersPerUnit");
  place.metersPerUnit = 2.0;
  place.originAltitude = good.atmosphereHeight;
  expectThrowsNaming([&] { validate(place, good); }, "AtmospherePlacement.originAltitude");
  place.originAltitude = -1.0;
  expectThrowsNaming([&] { validate(place, good); }, "AtmospherePlacement.originAltitude");
}

TEST_CASE("Atmosphere placement puts world points around the planet centre") {
  const AtmosphereParameters p;
  const AtmospherePlacement place{2.5, 300.0};
  // World origin: altitude originAltitude straight above the centre.
  const glm::dvec3 o = atmospherePosition(place, p, glm::dvec3(0.0));
  CHECK(o.y == doctest::Approx(p.earthRadius + 300.0));
  // One world unit is metersPerUnit metres; world +Y is the zenith.
  const glm::dvec3 q = atmospherePosition(place, p, glm::dvec3(1.0, 4.0, -2.0));
  CHECK(q.x == doctest::Approx(2.5));
  CHECK(q.y - o.y == doctest::Approx(10.0));
  CHECK(q.z == doctest::Approx(-5.0));
  // The planet centre in world units maps to the origin.
  const glm::dvec3 c = atmospherePosition(place, p, glm::dvec3(0.0, -(p.earthRadius + 300.0) / 2.5, 0.0));
  CHECK(glm::length(c) < 1e-6);
}

// The orders' ground term (Bruneton 2017: the ground's first bounce of the sunlight in J_2).
TEST_CASE("Atmosphere orders: the ground's bounce is linear in the albedo and follows the sunlit ground") {
  // With two orders L_H = L_2 is a linear function of J_2, and only J_2's ground term depends on the albedo:
  // L_H(a) = L_H(0) + a (L_H(1) - L_H(0)) texel by texel (float storage: relative 1e-6 of the texel).
  AtmosphereParameters p;
  AtmospherePrecomputeOptions o = smallOptions();
  o.orders = 2;
  const auto withAlbedo = [&](double a) {
    AtmosphereParameters q = p;
    q.groundAlbedo = a;
    return precomputeAtmosphere(q, o);
  };
  const AtmosphereTables black = withAlbedo(0.0), white = withAlbedo(1.0), grey = withAlbedo(0.3),
                         earth = withAlbedo(0.1);
  CHECK(black.single.rgba == white.single.rgba); // single scattering has no ground
  double worst = 0.0, added = 0.0, total = 0.0;
  for (std::size_t i = 0; i < black.higherOrders.rgba.size(); ++i) {
    if (i % 4 == 3) continue;
    const double b = black.higherOrders.rgba[i], w = white.higherOrders.rgba[i],
                 g = grey.higherOrders.rgba[i];
    worst = std::max(worst, std::abs(g - (b + 0.3 * (w - b))) / std::max(std::abs(g), 1e-12));
    CHECK(w >= b);
    added += earth.higherOrders.rgba[i] - b;
    total += b;
  }
  MESSAGE("L_H linear in the albedo: largest relative deviation "
          << worst << "; albedo 0.1 adds " << added / total << " of L_H summed over the table");
  CHECK(worst < 1e-5);
  CHECK(added > 0.0);
  // The bounce follows the sunlit ground: a white ground adds more to L_H with the sun at the zenith than
  // with the sun at Eq. 6's clamp, 11 degrees below the horizon (summed over the other coordinates).
  const auto gain = [&](int ip) {
    double sum = 0.0;
    for (int ih = 0; ih < o.size.height; ++ih)
      for (int ia = 0; ia < o.size.viewZenith; ++ia)
        for (int it = 0; it < o.size.sunView; ++it)
          sum += white.higherOrders.at(ih, ia, ip, it).g - black.higherOrders.at(ih, ia, ip, it).g;
    return sum;
  };
  MESSAGE("white ground's gain in L_H (green): sun at the zenith " << gain(o.size.sunZenith - 1)
                                                                   << ", 11 degrees below " << gain(0));
  CHECK(gain(o.size.sunZenith - 1) > 10.0 * gain(0));
}

// Hillaire 2020, Sec. 5.5: Psi_ms and the L_H it gives, against the orders' reference on the same small
// table.
TEST_CASE("Atmosphere multiple scattering LUT: Psi_ms, the ground's bounce and L_H against the orders") {
  AtmosphereParameters p;
  p.groundAlbedo = 0.0;
  AtmospherePrecomputeOptions o = smallOptions();
  o.orders = 8; // the orders' sum within 0.1% of its limit (AtmospherePhysicsTest)
  const AtmosphereTables orders = precomputeAtmosphere(p, o);
  o.multipleScattering = AtmosphereMultipleScattering::Lut;
  const AtmosphereTables lut = precomputeAtmosphere(p, o);
  REQUIRE(usesMultipleScatteringLut(o));
  REQUIRE(lut.multipleScatteringLut.width() == o.multipleScatteringSize);
  REQUIRE(lut.multipleScatteringLut.height() == o.multipleScatteringSize);
  CHECK(orders.multipleScatteringLut.data().empty());
  for (float v : lut.multipleScatteringLut.data()) {
    REQUIRE(std::isfinite(v));
    REQUIRE(v >= 0.0f);
  }
  // The same single scattering: L_H is the only table the method changes.
  CHECK(lut.single.rgba == orders.single.rgba);
  // By day Psi_ms grows with the sun's height at the ground; a sun far below the horizon leaves ~nothing.
  const glm::dvec3 low = lookUpMultipleScatteringLut(lut, 0.0, 0.1),
                   high = lookUpMultipleScatteringLut(lut, 0.0, 1.0);
  const glm::dvec3 night = lookUpMultipleScatteringLut(lut, 0.0, -0.8);
  MESSAGE("Psi_ms at the ground: sun 6 degrees up " << low.b << ", at the zenith " << high.b
                                                    << ", 53 degrees below " << night.b << " (blue)");
  CHECK(high.b > low.b);
  CHECK(night.b < 1e-3 * high.b);

  // L_H against the orders' (no ground in either): per channel, the sums over the table and the relative
  // RMS difference of the texels. The isotropic scattering at the table's point misses the Mie lobe's
  // forward peak of the second scattering (the red channel, Mie's share of the scattering largest, the
  // furthest off). Bounds: 10% around the measured values (see the MESSAGE).
  double sumLut[3] = {0.0, 0.0, 0.0}, sumOrders[3] = {0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < lut.higherOrders.rgba.size(); i += 4)
    for (int c = 0; c < 3; ++c) {
      sumLut[c] += lut.higherOrders.rgba[i + static_cast<std::size_t>(c)];
      sumOrders[c] += orders.higherOrders.rgba[i + static_cast<std::size_t>(c)];
    }
  const glm::dvec3 ratio(sumLut[0] / sumOrders[0], sumLut[1] / sumOrders[1], sumLut[2] / sumOrders[2]);
  MESSAGE("L_H of the LUT over the 8 orders', summed over the table: RGB " << ratio.r << " " << ratio.g << " "
                                                                           << ratio.b);
  CHECK(ratio.r > 0.5);
  CHECK(ratio.b > 0.8);
  CHECK(ratio.r < ratio.g);
  CHECK(ratio.g < ratio.b);
  CHECK(ratio.b < 1.0);

  // The ground's bounce: a white ground adds light where the sun is up; with the sun 53 degrees below the
  // horizon no ground point within reach is lit, so the albedo changes nothing there.
  AtmosphereParameters white = p;
  white.groundAlbedo = 1.0;
  const AtmosphereTables bright = precomputeAtmosphere(white, o);
  const glm::dvec3 dayWhite = lookUpMultipleScatteringLut(bright, 0.0, 1.0);
  MESSAGE("Psi_ms at the ground, sun at the zenith: albedo 0 " << high.g << ", albedo 1 " << dayWhite.g);
  CHECK(dayWhite.g > 1.2 * high.g);
  const int m = o.multipleScatteringSize;
  const int below = static_cast<int>(std::floor(0.1 * (m - 1))); // c_phi = -0.8 and lower
  for (int j = 0; j <= below; ++j)
    for (int c = 0; c < 3; ++c)
      CHECK(bright.multipleScatteringLut.at(0, j, c) == lut.multipleScatteringLut.at(0, j, c));

  // One order only: no LUT and no L_H.
  o.orders = 1;
  const AtmosphereTables single = precomputeAtmosphere(p, o);
  CHECK(single.multipleScatteringLut.data().empty());
  CHECK(std::all_of(single.higherOrders.rgba.begin(), single.higherOrders.rgba.end(),
                    [](float x) { return x == 0.0f; }));
}
