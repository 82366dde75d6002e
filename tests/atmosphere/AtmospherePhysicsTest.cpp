// Physics of the CPU atmosphere tables (crep/atmosphere/atmosphere.h): the single scattering of a thin
// homogeneous Rayleigh layer against its closed form written here, the energy of the scattering orders and
// the convergence of their sum, look-ups at texel centres reproduce the table, the sky is continuous on each
// side of the horizon in a sweep of view directions through it, and the colours and ambient light are
// physically sane (blue zenith at noon, red horizon next to a low sun, twilight zenith darker than the
// horizon below the sun, no ambient light at night).
#include <crep/atmosphere/atmosphere.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

using namespace crep;

namespace {

constexpr double kPi = std::numbers::pi;

double degrees(double d) {
  return d * kPi / 180.0;
}

/// Rec. 709 luminance of an RGB radiance.
double luminance(const glm::dvec3& c) {
  return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
}

/// The Rayleigh phase function, 3 / (16 pi) (1 + c^2) (Bruneton and Neyret 2008, Eq. 2), written here.
double rayleighPhaseHere(double c) {
  return 3.0 / (16.0 * kPi) * (1.0 + c * c);
}

/// The small Earth table of these tests (default parameters): 16x32x16x8, orders 1..6 kept, 64 sphere
/// samples. Computed once for every test case of this file.
const AtmosphereTables& earthTables() {
  static const AtmosphereTables tables = [] {
    AtmospherePrecomputeOptions o;
    o.size = {16, 32, 16, 8};
    o.orders = 6;
    o.sphereSamples = 64;
    o.keepOrders = true;
    return precomputeAtmosphere(AtmosphereParameters{}, o);
  }();
  return tables;
}

/// Distance from radius r along a direction of cosine mu (to the local zenith) to the sphere of radius
/// `top` (r <= top): the far root of r^2 + 2 r mu s + s^2 = top^2.
double distanceToSphere(double r, double mu, double top) {
  return -r * mu + std::sqrt(std::max(0.0, r * r * (mu * mu - 1.0) + top * top));
}

} // namespace

// A homogeneous layer (scale height 1e9 m: density within 1e-6 of 1 over 1 km), 1 km thick, on a planet
// of 6360 km, Mie off. Plane-parallel closed form for a point at height h looking up with zenith cosine
// mu, the sun at zenith cosine mu_s: with s_max = (H - h) / mu,
//   L1 = beta p_R(c_theta) int_0^s_max exp(-beta t) exp(-beta (H - h - t mu) / mu_s) dt
//      = beta p_R(c_theta) exp(-beta (H - h) / mu_s) (1 - exp(-k s_max)) / k,  k = beta (1 - mu / mu_s).
TEST_CASE("AtmospherePhysics: thin homogeneous Rayleigh layer, single scattering against its closed form") {
  AtmosphereParameters p;
  p.earthRadius = 6360.0e3;
  p.atmosphereHeight = 1000.0;
  p.rayleighScaleHeight = 1.0e9;
  p.rayleighScattering = glm::dvec3(2.0e-5, 5.0e-5, 1.0e-4); // optical depths 0.02, 0.05, 0.1 vertically
  p.mieScattering = glm::dvec3(0.0);
  p.mieAbsorption = glm::dvec3(0.0);
  AtmospherePrecomputeOptions o;
  o.size = {8, 64, 16, 8};
  o.orders = 1;
  const AtmosphereTables tables = precomputeAtmosphere(p, o);
  const double H = p.atmosphereHeight;
  const double R = p.earthRadius;
  const double minCos = 0.3; // mu and mu_s well above the horizon

  double worstPlane = 0.0, worstSphere = 0.0, worstCurvature = 0.0;
  int compared = 0;
  for (int ih = 0; ih < o.size.height - 1; ++ih) // the top texel has no path (L1 = 0)
    for (int ia = o.size.viewZenith / 2; ia < o.size.viewZenith; ++ia)
      for (int ip = 0; ip < o.size.sunZenith; ++ip)
        for (int it = 0; it < o.size.sunView; ++it) {
          const glm::dvec4 w = atmosphereTexelParams(p, o.size, ih, ia, ip, it);
          const double h = w.x, mu = w.y, muS = w.z, c = w.w;
          if (mu < minCos || muS < minCos) continue;
          // The sun direction of these three cosines (built here): skip incompatible triples.
          const double sa = std::sqrt(1.0 - mu * mu);
          const double lx = (c - mu * muS) / sa;
          const double lz2 = 1.0 - lx * lx - muS * muS;
          if (lz2 < 0.0) continue;
          const glm::dvec3 v(sa, mu, 0.0), l(lx, muS, std::sqrt(lz2));
          const glm::vec4 texel = tables.single.at(ih, ia, ip, it);
          for (int ch = 0; ch < 3; ++ch) {
            const double beta = p.rayleighScattering[ch];
            // Plane-parallel closed form.
            const double sMax = (H - h) / mu;
            const double k = beta * (1.0 - mu / muS);
            const double integral = std::abs(k * sMax) < 1e-12 ? sMax : -std::expm1(-k * sMax) / k;
            const double plane = beta * rayleighPhaseHere(c) * std::exp(-beta * (H - h) / muS) * integral;
            // The same layer on the sphere (midpoint rule, 4000 steps, exact path lengths to the top): the
            // size of the curvature effect the plane-parallel form leaves out.
            const glm::dvec3 C(0.0, R + h, 0.0);
            const double sEnd = distanceToSphere(R + h, mu, R + H);
            const int n = 4000;
            double sphere = 0.0;
            for (int k2 = 0; k2 < n; ++k2) {
              const double t = (k2 + 0.5) * sEnd / n;
              const glm::dvec3 P = C + t * v;
              const double r = glm::length(P);
              const double sunPath = distanceToSphere(r, glm::dot(P / r, l), R + H);
              sphere += std::exp(-beta * t) * std::exp(-beta * sunPath);
            }
            sphere *= beta * rayleighPhaseHere(c) * sEnd / n;
            // The table holds S_R without its phase function (Mie off: S_M's red in A is 0).
            const double got = texel[ch] * rayleighPhaseHere(c);
            worstPlane = std::max(worstPlane, std::abs(got - plane) / plane);
            worstSphere = std::max(worstSphere, std::abs(got - sphere) / sphere);
            worstCurvature = std::max(worstCurvature, std::abs(sphere - plane) / plane);
          }
          ++compared;
        }
  MESSAGE("thin layer: " << compared << " texels (mu, mu_s >= " << minCos
                         << "): max relative error vs the plane-parallel closed form " << worstPlane
                         << ", vs the spherical layer " << worstSphere
                         << "; curvature effect (sphere vs plane) " << worstCurvature);
  CHECK(compared >= 50);
  // The curvature of a 1 km layer on a 6360 km planet changes L1 by ~1e-3 at mu = 0.3 (measured above);
  // the table's own error (trapezoid rule, optical depth table, float) is far below it.
  CHECK(worstCurvature < 3e-3);
  CHECK(worstPlane < worstCurvature + 2e-4);
  CHECK(worstSphere < 2e-4);
}

TEST_CASE("AtmospherePhysics: each scattering order carries less energy and the sum converges") {
  const AtmosphereTables& t = earthTables();
  REQUIRE(t.orders.size() == 6u);
  std::vector<double> energy;
  for (const AtmosphereTable4D& order : t.orders) {
    double e = 0.0;
    for (std::size_t i = 0; i < order.rgba.size(); i += 4)
      e += static_cast<double>(order.rgba[i]) + order.rgba[i + 1] + order.rgba[i + 2];
    energy.push_back(e);
  }
  double sum = 0.0;
  int convergedAt = 0;
  for (std::size_t n = 0; n < energy.size(); ++n) {
    sum += energy[n];
    const double change = energy[n] / sum; // relative change of the total of L_M from n to n + 1 orders
    MESSAGE("order " << n + 1 << ": energy " << energy[n]
                     << (n > 0 ? ", ratio to the previous " + std::to_string(energy[n] / energy[n - 1]) : "")
                     << ", relative change of the sum " << change);
    if (n > 0) {
      CHECK(energy[n] < energy[n - 1]);
      if (convergedAt == 0 && change < 0.01) convergedAt = static_cast<int>(n) + 1;
    }
  }
  MESSAGE("the total energy of L_M changes by less than 1% from order " << convergedAt << " on");
  CHECK(convergedAt >= 2);
  CHECK(convergedAt <= 6);

  // L_H = L2 + ... + L6 (float sums of double values: a few float ulps), and the kept L1 is the single
  // tables' parts with each texel's phase functions.
  double worst = 0.0;
  for (std::size_t i = 0; i < t.higherOrders.rgba.size(); ++i) {
    double higher = 0.0;
    for (std::size_t n = 1; n < t.orders.size(); ++n)
      higher += t.orders[n].rgba[i];
    const double scale = std::max(1e-12, static_cast<double>(std::abs(t.higherOrders.rgba[i])));
    worst = std::max(worst, std::abs(t.higherOrders.rgba[i] - higher) / scale);
  }
  MESSAGE("L_H vs sum L_n: max relative difference " << worst);
  CHECK(worst < 1e-5);
  const AtmosphereTableSize& s = t.options.size;
  double worstL1 = 0.0;
  for (int ih = 0; ih < s.height; ++ih)
    for (int ia = 0; ia < s.viewZenith; ++ia)
      for (int ip = 0; ip < s.sunZenith; ++ip)
        for (int it = 0; it < s.sunView; ++it) {
          glm::dvec3 v, l;
          const glm::dvec4 w = atmosphereTexelParams(t.parameters, s, ih, ia, ip, it);
          atmosphereDirections(w.y, w.z, w.w, v, l);
          const double c = glm::dot(v, l);
          const glm::dvec4 parts(t.single.at(ih, ia, ip, it));
          const glm::dvec3 mie(t.singleMie.at(ih, ia, ip, it));
          CHECK(parts.w == doctest::Approx(mie.x).epsilon(1e-6)); // A: S_M's red
          const glm::dvec3 expected =
              glm::dvec3(parts) * rayleighPhaseHere(c) + mie * henyeyGreenstein(t.parameters.mieG, c);
          const glm::dvec3 kept(t.orders[0].at(ih, ia, ip, it));
          worstL1 = std::max(worstL1, glm::length(kept - expected) / (glm::length(expected) + 1e-30));
        }
  MESSAGE("kept L1 vs S_R p_R + S_M p_HG at the texel: max relative difference " << worstL1);
  CHECK(worstL1 < 1e-5);
}

// Sun zenith texel 0 (the sun ~11.4 degrees below the horizon) is left to the next test case: its c_phi,
// the inverse of Eq. 6 at u_phi = 0, is below Eq. 6's clamp -0.1975, so a look-up does not land on it.
TEST_CASE("AtmospherePhysics: look-ups at texel centres reproduce the table") {
  const AtmosphereTables& t = earthTables();
  const AtmosphereParameters& p = t.parameters;
  const AtmosphereTableSize& s = t.options.size;
  const AtmosphereTable4D& table = t.higherOrders; // any 4D table
  double maxValue = 0.0;
  for (float v : table.rgba)
    maxValue = std::max(maxValue, static_cast<double>(std::abs(v)));
  double worstCoords = 0.0, worstLookUp = 0.0;
  int endToEnd = 0, all = 0;
  glm::ivec4 worstTexel(-1);
  double worstHorizon = 0.0;
  glm::dvec2 worstCosines(0.0);
  for (int ih = 0; ih < s.height; ++ih)
    for (int ia = 0; ia < s.viewZenith; ++ia)
      for (int ip = 1; ip < s.sunZenith; ++ip)
        for (int it = 0; it < s.sunView; ++it) {
          const glm::dvec4 w = atmosphereTexelParams(p, s, ih, ia, ip, it);
          const glm::vec4 texel = table.at(ih, ia, ip, it);
          const glm::dvec3 expected(texel);
          const bool below = ia < s.viewZenith / 2;
          // The side of the horizon as a ray that stays on the texel's side would carry it.
          const glm::dvec4 side(0.0, below ? 0.25 : 0.75, 0.0, 0.0);
          const glm::dvec3 a =
              sampleAtmosphereTable(table, atmosphereTableCoords(p, s, w.x, w.y, w.z, w.w, side));
          worstCoords =
              std::max(worstCoords, glm::length(a - expected) / (glm::length(expected) + 1e-6 * maxValue));
          ++all;
          // End to end from the texel's own point and directions, where the cosines are compatible
          // (v . l = c_theta and l.y = c_phi); first look-ups (fresh coordinates) except at the two horizon
          // texels, whose side a first look-up cannot know (they are the limits from below and above).
          glm::dvec3 v, l;
          atmosphereDirections(w.y, w.z, w.w, v, l);
          if (std::abs(glm::dot(v, l) - w.w) > 1e-9 || std::abs(l.y - w.z) > 1e-9) continue;
          const bool horizon = ia == 0 || ia == s.viewZenith / 2;
          glm::dvec4 coords = horizon ? side : glm::dvec4(-1.0);
          const glm::dvec3 b =
              lookUpAtmosphere(t, table, glm::dvec3(0.0, p.earthRadius + w.x, 0.0), v, l, coords);
          const double e = glm::length(b - expected) / (glm::length(expected) + 1e-6 * maxValue);
          if (horizon) {
            worstHorizon = std::max(worstHorizon, e);
          } else if (e > worstLookUp) {
            worstLookUp = e;
            worstTexel = glm::ivec4(ih, ia, ip, it);
            worstCosines = glm::dvec2(w.y, w.w);
          }
          ++endToEnd;
        }
  MESSAGE("texel centres (sun zenith texels 1..N-1): sampleAtmosphereTable(atmosphereTableCoords) at "
          << all << " texels, max relative difference " << worstCoords << "; lookUpAtmosphere at " << endToEnd
          << " compatible texels, " << worstLookUp << " at texel (" << worstTexel.x << ", " << worstTexel.y
          << ", " << worstTexel.z << ", " << worstTexel.w << "), c_alpha " << worstCosines.x << ", c_theta "
          << worstCosines.y);
  CHECK(endToEnd > 1000);
  CHECK(worstCoords < 1e-5);
  CHECK(worstLookUp < 1e-5);
  // At the two horizon texels c_h - c_alpha is 0 up to double rounding (~1e-17), which Eq. 5's power 0.2
  // turns into ~4e-4 of the half's texel range: the look-up lands ~0.006 texels off the centre.
  MESSAGE("horizon texels (ia = 0 and N_alpha / 2, side given): lookUpAtmosphere max relative difference "
          << worstHorizon);
  CHECK(worstHorizon < 1e-3);
}

// Sun zenith texel 0 (the algorithm contract's clamp). The inverse of Eq. 6 at u_phi = 0 is c_phi =
// tan(-0.74 * 1.1) / tan(1.26 * 1.1) = -0.19794..., below the clamp max(c_phi, -0.1975) of the forward map,
// so the texel's own cosine maps to u_phi = u(-0.1975) = 5.05e-4, not 0: a look-up there lands
// 5.05e-4 (N_phi - 1) texels (0.0076 at N_phi = 16) above the centre and mixes in that much of texel 1
// (the sun ~5 degrees below the horizon, far brighter than texel 0, ~11.4 degrees below). Measured and
// printed; the offset is asserted to be that of the documented clamp (a clamp at the exact -0.19794 would
// make texel 0 reachable and these look-ups exact).
TEST_CASE("AtmospherePhysics: sun zenith texel 0 look-ups are off by the Eq. 6 clamp") {
  const AtmosphereTables& t = earthTables();
  const AtmosphereParameters& p = t.parameters;
  const AtmosphereTableSize& s = t.options.size;
  const double cosPhi0 = atmosphereTexelParams(p, s, 0, 0, 0, 0).z;
  const double centre = 0.5 / s.sunZenith;
  const double u = atmosphereTableCoords(p, s, 0.0, 0.5, cosPhi0, 0.0).z;
  const double T = std::tan(1.26 * 1.1);
  const double clampU = 0.5 * (std::atan(-0.1975 * T) / 1.1 + 0.74); // Eq. 6 at the clamp, written here
  const double offsetTexels = (u - centre) * s.sunZenith;
  MESSAGE("sun zenith texel 0: c_phi " << cosPhi0 << ", texture coordinate " << u << " instead of the centre "
                                       << centre << ": " << offsetTexels << " texels off");
  CHECK(cosPhi0 < -0.1975);
  CHECK(offsetTexels == doctest::Approx(clampU * (s.sunZenith - 1)).epsilon(1e-6));
  CHECK(offsetTexels < 0.01);
  double worstRelative = 0.0, worstOfMax = 0.0, maxValue = 0.0;
  for (float v : t.higherOrders.rgba)
    maxValue = std::max(maxValue, static_cast<double>(std::abs(v)));
  for (int ih = 0; ih < s.height; ++ih)
    for (int ia = 0; ia < s.viewZenith; ++ia)
      for (int it = 0; it < s.sunView; ++it) {
        const glm::dvec4 w = atmosphereTexelParams(p, s, ih, ia, 0, it);
        const glm::dvec3 expected(t.higherOrders.at(ih, ia, 0, it));
        const glm::dvec3 next(t.higherOrders.at(ih, ia, 1, it));
        const glm::dvec4 side(0.0, ia < s.viewZenith / 2 ? 0.25 : 0.75, 0.0, 0.0);
        const glm::dvec3 a =
            sampleAtmosphereTable(t.higherOrders, atmosphereTableCoords(p, s, w.x, w.y, w.z, w.w, side));
        worstRelative = std::max(worstRelative, glm::length(a - expected) / (glm::length(expected) + 1e-30));
        worstOfMax = std::max(worstOfMax, glm::length(a - expected) / maxValue);
        // The look-up is the blend of texels 0 and 1 at the offset: it stays between them.
        CHECK(glm::length(a - glm::mix(expected, next, offsetTexels)) <= 1e-6 * (glm::length(next) + 1e-30));
      }
  MESSAGE("sun zenith texel 0: look-ups at its centres differ from the texel by up to "
          << worstRelative << " relative, " << worstOfMax << " of the table's largest value");
}

// A camera at altitude h sweeps its view direction through the horizon in the vertical plane towards the
// sun and away from it, 201 directions with the zenith cosine uniform in [c_h - 0.05, c_h + 0.05], each a
// first look-up (fresh coordinates) into L_M, as a camera sees the sky. Measured and printed: the largest
// luminance step between neighbouring directions on each side of the horizon and across it, over the
// sweep's median step. The median is not a usable bound on one side (the sky brightens steeply but smoothly
// near the horizon: up to ~54 median steps, with neighbouring steps within a factor 1.5 of each other), so
// the assertion is on jumps, i.e. isolated steps: on each side every step is within K = 3 of the larger
// of its two neighbours. The one step across the horizon is reported, not bounded: below it the tables'
// rays end on the ground (no albedo in the tables: only the air in front of it glows), above it they run
// through the atmosphere, so the radiance has a physical sky/ground edge there, the difference of the two
// horizon texels (measured: up to ~1000 median steps at 10 m, 17-92 at 1 km, 3-35 at 10 km).
TEST_CASE("AtmospherePhysics: the sky has no jump on either side of the horizon") {
  const AtmosphereTables& t = earthTables();
  const AtmosphereParameters& p = t.parameters;
  const double K = 3.0;
  const int n = 201;
  double worstSideRatio = 0.0, worstCrossingRatio = 0.0, worstLocalRatio = 0.0;
  for (double h : {10.0, 1000.0, 10000.0})
    for (double sunElevation : {60.0, 5.0, -2.0})
      for (double side : {1.0, -1.0}) {
        const double ch = cosHorizon(p, h);
        const glm::dvec3 C(0.0, p.earthRadius + h, 0.0);
        const glm::dvec3 toSun(std::cos(degrees(sunElevation)), std::sin(degrees(sunElevation)), 0.0);
        std::vector<double> y(n);
        std::vector<bool> above(n);
        bool finite = true;
        for (int i = 0; i < n; ++i) {
          const double ca = ch - 0.05 + 0.1 * i / (n - 1);
          const glm::dvec3 v(side * std::sqrt(1.0 - ca * ca), ca, 0.0);
          glm::dvec4 coords(-1.0);
          const auto k = static_cast<std::size_t>(i);
          y[k] = luminance(lookUpMultipleScattering(t, C, v, toSun, coords));
          above[k] = coords.y >= 0.5; // the side the look-up chose
          finite = finite && std::isfinite(y[k]);
        }
        CHECK(finite);
        std::vector<double> steps;
        double sideMax = 0.0, crossing = 0.0;
        int crossings = 0;
        for (std::size_t i = 0; i + 1 < y.size(); ++i) {
          const double d = std::abs(y[i + 1] - y[i]);
          steps.push_back(d);
          if (above[i] != above[i + 1]) {
            crossing = d;
            ++crossings;
          } else {
            sideMax = std::max(sideMax, d);
          }
        }
        CHECK(crossings == 1);
        // A jump is an isolated step: compare each step on one side with its neighbours on the same side.
        double localRatio = 0.0;
        for (std::size_t i = 1; i + 1 < steps.size(); ++i)
          if (above[i - 1] == above[i] && above[i] == above[i + 1] && above[i + 1] == above[i + 2])
            localRatio = std::max(localRatio, steps[i] / std::max({steps[i - 1], steps[i + 1], 1e-300}));
        worstLocalRatio = std::max(worstLocalRatio, localRatio);
        std::vector<double> sorted = steps;
        std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2),
                         sorted.end());
        const double median = std::max(sorted[sorted.size() / 2], 1e-300);
        worstSideRatio = std::max(worstSideRatio, sideMax / median);
        worstCrossingRatio = std::max(worstCrossingRatio, crossing / median);
        MESSAGE("h " << h << " m, sun " << sunElevation << " deg, "
                     << std::string(side > 0 ? "towards" : "away from") << " the sun: luminance " << y.front()
                     << " .. " << y[n / 2] << " .. " << y.back() << "; median step " << median
                     << ", largest step on one side " << sideMax / median
                     << " x median, step across the horizon " << crossing / median
                     << " x median; largest step over its neighbours' on one side " << localRatio);
        CHECK(localRatio <= K);
      }
  MESSAGE("horizon sweeps: largest step on one side of the horizon "
          << worstSideRatio << " x median, across it " << worstCrossingRatio
          << " x median; largest step over its "
             "neighbours' on one side "
          << worstLocalRatio << " (bound K = " << K << ")");
}

TEST_CASE("AtmospherePhysics: blue zenith at noon, red horizon by a low sun, dark twilight zenith, no "
          "ambient at night") {
  const AtmosphereTables& t = earthTables();
  const AtmosphereParameters& p = t.parameters;
  const glm::dvec3 ground(0.0, p.earthRadius + 1.0, 0.0);

  // Noon (sun zenith 30 degrees): the zenith sky is blue, B > G > R. (At the zenith texel row the sun's
  // direction is tied to c_phi, and this table's 16 sun zenith texels put the look-up between c_phi = 0.53
  // and 1, whose zenith texel holds the Mie forward peak: the zenith is much less blue than the direct
  // integral, which gives 0.010, 0.015, 0.025 single scattering against the table's L1 0.050, 0.053, 0.058
  // with 16 and 0.019, 0.024, 0.032 with 64 sun zenith texels: a resolution effect of the small table.)
  {
    glm::dvec4 coords(-1.0);
    const glm::dvec3 toSun(std::sin(degrees(30.0)), std::cos(degrees(30.0)), 0.0);
    const glm::dvec3 zenith = lookUpMultipleScattering(t, ground, glm::dvec3(0.0, 1.0, 0.0), toSun, coords);
    MESSAGE("noon zenith sky RGB " << zenith.r << " " << zenith.g << " " << zenith.b);
    CHECK(zenith.b > zenith.g);
    CHECK(zenith.g > zenith.r);
  }
  // Sun 2 degrees above the horizon: the horizon next to the sun (view 0.5 degrees up, same azimuth, so
  // c_theta = cos 1.5 degrees) is red, R > B.
  {
    glm::dvec4 coords(-1.0);
    const glm::dvec3 toSun(std::cos(degrees(2.0)), std::sin(degrees(2.0)), 0.0);
    const glm::dvec3 view(std::cos(degrees(0.5)), std::sin(degrees(0.5)), 0.0);
    const glm::dvec3 horizon = lookUpMultipleScattering(t, ground, view, toSun, coords);
    MESSAGE("sun 2 deg up, horizon next to the sun RGB " << horizon.r << " " << horizon.g << " "
                                                         << horizon.b);
    CHECK(horizon.r > horizon.b);
  }
  // Twilight (sun 2 degrees below the horizon): the zenith is darker than the horizon below the sun (view
  // 0.5 degrees up in the sun's azimuth).
  {
    const glm::dvec3 toSun(std::cos(degrees(-2.0)), std::sin(degrees(-2.0)), 0.0);
    glm::dvec4 c1(-1.0), c2(-1.0);
    const glm::dvec3 zenith = lookUpMultipleScattering(t, ground, glm::dvec3(0.0, 1.0, 0.0), toSun, c1);
    const glm::dvec3 horizon = lookUpMultipleScattering(
        t, ground, glm::dvec3(std::cos(degrees(0.5)), std::sin(degrees(0.5)), 0.0), toSun, c2);
    MESSAGE("twilight (sun -2 deg): zenith luminance " << luminance(zenith) << ", horizon below the sun "
                                                       << luminance(horizon));
    CHECK(luminance(zenith) < luminance(horizon));
  }
  // E_sky grows with the sun's elevation and is ~0 for the sun 10 degrees below the horizon (< 1% of noon).
  {
    const double noon = luminance(lookUpAmbientSkyLight(t, std::cos(degrees(30.0))));
    double previous = -1.0;
    for (double elevation : {-10.0, -5.0, -2.0, 0.0, 2.0, 5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 75.0, 90.0}) {
      const glm::dvec3 e = lookUpAmbientSkyLight(t, std::sin(degrees(elevation)));
      const double y = luminance(e);
      MESSAGE("E_sky at sun elevation " << elevation << " deg: RGB " << e.r << " " << e.g << " " << e.b
                                        << ", luminance / noon " << y / noon);
      CHECK(y > previous);
      previous = y;
    }
    const double night = luminance(lookUpAmbientSkyLight(t, std::sin(degrees(-10.0))));
    CHECK(night < 0.01 * noon);
  }
}
