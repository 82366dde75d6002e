// The froxel fog's CPU references (crep/postfx/froxel_fog.h; Wronski 2014): the accumulation is exact at
// the sample points of a homogeneous unshadowed medium, the applied image converges to the closed form
// (crep::unshadowedScattering) at second order in the slice spacing, the ESM reproduces the exponential
// test on a constant map, the temporal blend keeps a static history and never propagates NaN, bad options
// are named.
#include "common/error_checks.h"

#include <crep/core/error.h>
#include <crep/postfx/froxel_fog.h>
#include <crep/scatter/ray.h>

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

using namespace crep;
using crep::test::requireNamed;

namespace {

Camera fogCamera() {
  return Camera::lookAt(glm::dvec3(0.0, 2.0, 0.0), glm::dvec3(0.3, 1.5, -10.0), glm::dvec3(0.0, 1.0, 0.0),
                        0.9, 16.0 / 9.0, 0.1, 100.0);
}

Medium fogMedium() {
  return Medium({.mieScattering = glm::dvec3(0.02, 0.025, 0.03), .hgG = 0.0, .absorption = glm::dvec3(0.01)});
}

/// A camera depth image whose surfaces lie at view depths between zLo and zHi (varying across the image).
Image depthRamp(const Camera& cam, int w, int h, double zLo, double zHi) {
  Image d(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double s = (x + 0.37 * y) / (w + 0.37 * h);
      d.at(x, y) = static_cast<float>(cam.depthBufferValue(zLo + (zHi - zLo) * s));
    }
  return d;
}

} // namespace

TEST_CASE("Froxel accumulation: exact closed form and transmittance at the sample points") {
  const Camera cam = fogCamera();
  const Medium medium = fogMedium();
  const DirectionalLight light(glm::dvec3(0.3, -0.6, -0.5), glm::dvec3(1.0, 0.9, 0.8));
  FroxelGrid grid{16, 9, 12, 0.5, 60.0};
  const glm::dvec3 jitter(0.2, -0.3, 0.4);
  const FroxelVolume lit = froxelLighting(grid, cam, light, medium, [&] {
    FroxelLightingInputs in;
    in.jitter = jitter;
    return in;
  }());
  const FroxelVolume acc = froxelAccumulate(lit, grid, cam, medium, jitter);
  const FroxelDepthRange r = froxelDepthRange(grid, cam, "grid");
  const glm::dvec3 sigma = medium.extinction();
  const double sbar = weightExtinction(medium);
  double worstRgb = 0.0, worstA = 0.0;
  for (int z = 0; z < grid.depth; ++z)
    for (int y = 0; y < grid.height; y += 2)
      for (int x = 0; x < grid.width; x += 3) {
        const glm::dvec3 uvw((x + 0.5 + jitter.x) / grid.width, (y + 0.5 + jitter.y) / grid.height,
                             (z + 0.5 + jitter.z) / grid.depth);
        // independent: distance to the sample point from its world position, the closed form of Eq. 1 with
        // V = 1: C (1 - exp(-sigma t)) / sigma per channel
        const glm::dvec3 p = froxelWorldPoint(cam, r, uvw);
        const double t = glm::length(p - cam.position());
        const glm::dvec3 v = (p - cam.position()) / t;
        const glm::dvec3 C =
            light.irradiance() * medium.scatteringTimesPhase(glm::dot(light.direction(), -v));
        const glm::dvec4 a = acc.at(x, y, z);
        for (int c = 0; c < 3; ++c) {
          const double expected = C[c] * (1.0 - std::exp(-sigma[c] * t)) / sigma[c];
          worstRgb = std::max(worstRgb, std::abs(a[c] - expected) / expected);
        }
        worstA = std::max(worstA, std::abs(a.w - std::exp(-sbar * t)));
      }
  MESSAGE(std::string(std::string("accumulated vs closed form at the sample points: RGB relative ") +
                      std::to_string(worstRgb) + ", transmittance absolute " + std::to_string(worstA)));
  // exact up to double rounding over 2 x 12 pieces
  CHECK(worstRgb < 1e-12);
  CHECK(worstA < 1e-13);
}

TEST_CASE("Froxel apply: converges to the closed form at second order in the slice spacing") {
  const Camera cam = fogCamera();
  const Medium medium = fogMedium();
  const DirectionalLight light(glm::dvec3(0.3, -0.6, -0.5), glm::dvec3(1.0, 0.9, 0.8));
  const double zLo = 1.0, zHi = 40.0;
  const Image depth = depthRamp(cam, 64, 36, zLo, zHi);
  const Image closed = unshadowedScattering(depth, cam, light, medium);
  double previous = 0.0;
  for (int slices : {16, 32, 64}) {
    FroxelGrid grid{32, 18, slices, 0.5, 60.0};
    const FroxelVolume acc = froxelAccumulate(
        froxelLighting(grid, cam, light, medium, FroxelLightingInputs{}), grid, cam, medium, glm::dvec3(0.0));
    const Image fog = froxelApply(acc, grid, cam, depth, glm::dvec3(0.0));
    // Tolerance from the slice count: linear interpolation of f(t) = C (1 - exp(-sigma t)) / sigma between
    // samples dt apart errs by at most dt^2 / 8 max|f''| = C sigma dt^2 / 8, with dt = t (r - 1), r = the
    // slice ratio (far / near)^(1 / D), here at the deepest surface t_max = zHi / cos(the widest ray) (< 1.2
    // zHi). Across (u, v) the same rule applies to the cell width; the isotropic phase keeps C constant, so a
    // factor 2 covers the (u, v) and w interpolations together. Alpha: exp(-sbar t) alike.
    const double ratio = std::pow(60.0 / 0.5, 1.0 / slices);
    const double dtMax = 1.2 * zHi * (ratio - 1.0);
    double worst = 0.0, worstRel = 0.0;
    bool within = true;
    for (int y = 0; y < depth.height(); ++y)
      for (int x = 0; x < depth.width(); ++x)
        for (int c = 0; c < 4; ++c) {
          const double e = closed.at(x, y, c), g = fog.at(x, y, c);
          const double sigma = c < 3 ? medium.extinction()[c] : weightExtinction(medium);
          const double scale = c < 3 ? light.irradiance()[c] * medium.scattering()[c] / (4.0 * M_PI) : 1.0;
          const double bound = 2.0 * scale * sigma * dtMax * dtMax / 8.0 + 1e-6;
          worst = std::max(worst, std::abs(g - e) / bound);
          worstRel = std::max(worstRel, std::abs(g - e) / std::max(std::abs(e), 1e-12));
          within = within && std::abs(g - e) <= bound;
        }
    MESSAGE(std::string(std::string("slices ") + std::to_string(slices) +
                        ": max relative error vs closed form " + std::to_string(worstRel) +
                        ", worst fraction of the derived bound " + std::to_string(worst)));
    CHECK(within);
    if (previous > 0.0) CHECK(worstRel < 0.5 * previous); // second order: 2x slices -> about 4x smaller
    previous = worstRel;
  }
}

TEST_CASE("ESM: constant map, exponential test, step map") {
  EsmOptions o;
  o.exponent = 40.0;
  o.downsample = 4;
  o.blurRadius = 1;
  Image map(16, 10, 1, 0.4f);
  // an orthographic light looking down -Z of the unit cube: NDC = 2 world - 1, so depth = world z and the
  // exponent per world unit is the exponent per depth unit
  const glm::dmat4 clip =
      glm::translate(glm::dmat4(1.0), glm::dvec3(-1.0)) * glm::scale(glm::dmat4(1.0), glm::dvec3(2.0));
  CHECK(esmDepthExponent(o, clip) == doctest::Approx(40.0));
  const Image esm = buildEsm(map, clip, o);
  CHECK(esm.width() == 4);
  CHECK(esm.height() == 3); // ceil(10 / 4)
  for (float v : esm.data())
    CHECK(v == doctest::Approx(0.4).epsilon(1e-6)); // the log-space mean of a constant is the constant
  // receiver behind the occluder: exp(-c (d_r - d_o)); in front: 1 (clamped)
  CHECK(esmVisibility(esm, clip, glm::dvec3(0.5, 0.5, 0.45), o) == doctest::Approx(std::exp(-40.0 * 0.05)));
  CHECK(esmVisibility(esm, clip, glm::dvec3(0.5, 0.5, 0.3), o) == 1.0);
  CHECK(esmVisibility(esm, clip, glm::dvec3(1.5, 0.5, 0.9), o) == 1.0); // outside the map: lit
  o.bias = 0.05;
  CHECK(esmVisibility(esm, clip, glm::dvec3(0.5, 0.5, 0.45), o) == doctest::Approx(1.0));
  // a step: the left half occluded at 0.2, the right half empty; far from the edge the test is the
  // unfiltered one
  Image step(64, 64, 1, 1.0f);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 32; ++x)
      step.at(x, y) = 0.2f;
  EsmOptions s;
  s.exponent = 80.0;
  const Image e2 = buildEsm(step, clip, s);
  CHECK(esmVisibility(e2, clip, glm::dvec3(0.1, 0.5, 0.6), s) < 1e-12);
  CHECK(esmVisibility(e2, clip, glm::dvec3(0.9, 0.5, 0.6), s) == 1.0);
  // across the edge the filtered test rises monotonically from shadowed to lit
  double last = 0.0;
  for (double x = 0.3; x <= 0.7; x += 0.01) {
    const double v = esmVisibility(e2, clip, glm::dvec3(x, 0.5, 0.6), s);
    CHECK(v >= last);
    last = v;
  }
  CHECK(last == 1.0);
}

TEST_CASE("Froxel density: height fog and value noise") {
  FroxelDensity d;
  d.heightBase = 1.0;
  d.heightFalloff = 2.0;
  CHECK(froxelDensity(d, glm::dvec3(0.0, 1.0, 0.0), glm::dvec3(0.0)) == doctest::Approx(1.0));
  CHECK(froxelDensity(d, glm::dvec3(5.0, 3.0, 0.0), glm::dvec3(0.0)) == doctest::Approx(std::exp(-1.0)));
  double lo = 1.0, hi = 0.0, sum = 0.0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const double v = froxelValueNoise(glm::dvec3(0.37 * i, 0.11 * i - 50.0, -0.23 * i));
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    sum += v;
  }
  CHECK(lo >= 0.0);
  CHECK(hi <= 1.0);
  CHECK(hi - lo > 0.5);                  // it varies
  CHECK(std::abs(sum / n - 0.5) < 0.05); // a hash uniform in [0, 1): mean 1/2
  // at a lattice point the noise is the corner's hash: continuous across the cell faces
  CHECK(froxelValueNoise(glm::dvec3(3.0 - 1e-9, 2.0, 1.0)) ==
        doctest::Approx(froxelValueNoise(glm::dvec3(3.0, 2.0, 1.0))));
  d.noiseAmplitude = 0.5;
  const double rho = froxelDensity(d, glm::dvec3(0.3, 1.0, 0.2), glm::dvec3(0.0));
  CHECK(rho >= 0.5);
  CHECK(rho <= 1.5);
}

TEST_CASE("Froxel temporal: static history kept, reprojection outside rejected, NaN never propagates") {
  const Camera cam = fogCamera();
  FroxelGrid grid{8, 6, 5, 0.5, 30.0};
  FroxelVolume cur(8, 6, 5), hist(8, 6, 5);
  for (int z = 0; z < 5; ++z)
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 8; ++x) {
        cur.at(x, y, z) = glm::dvec4(0.1 * z + 0.01 * x, 0.2, 0.3, 1.0 - 0.1 * z);
        hist.at(x, y, z) = cur.at(x, y, z) + glm::dvec4(0.001 * y, 0.0, 0.0, 0.0);
      }
  // static camera: history at the cell centre (within the neighbourhood's range) blended with weight 0.9
  const FroxelVolume out = froxelTemporal(cur, &hist, grid, cam, cam, 0.9);
  CHECK(out.at(3, 2, 2).x == doctest::Approx(cur.at(3, 2, 2).x + 0.9 * 0.002));
  // no history: the current volume
  CHECK(froxelTemporal(cur, nullptr, grid, cam, cam, 0.9).at(3, 2, 2).x == cur.at(3, 2, 2).x);
  // NaN current texel and NaN history texel
  const double nan = std::numeric_limits<double>::quiet_NaN();
  cur.at(4, 3, 2) = glm::dvec4(nan);
  hist.at(2, 2, 1) = glm::dvec4(nan, 0.0, 0.0, 1.0);
  const FroxelVolume o2 = froxelTemporal(cur, &hist, grid, cam, cam, 0.9);
  int nonFinite = 0;
  for (const glm::dvec4& c : o2.cells)
    for (int k = 0; k < 4; ++k)
      nonFinite += std::isfinite(c[k]) ? 0 : 1;
  CHECK(nonFinite == 0);
  // the NaN current texel became its neighbourhood's mean: between the neighbours' min and max
  CHECK(o2.at(4, 3, 2).x > cur.at(3, 3, 1).x - 1e-12);
  CHECK(o2.at(4, 3, 2).x < cur.at(5, 3, 3).x + 0.01);
  // a rotated camera: cells whose centre falls outside the previous volume take the current value
  const Camera turned = Camera::lookAt(glm::dvec3(0.0, 2.0, 0.0), glm::dvec3(10.0, 1.5, -1.0),
                                       glm::dvec3(0.0, 1.0, 0.0), 0.9, 16.0 / 9.0, 0.1, 100.0);
  const FroxelVolume o3 = froxelTemporal(cur, &hist, grid, turned, cam, 0.9);
  CHECK(o3.at(7, 3, 3).x == cur.at(7, 3, 3).x);
}

TEST_CASE("Froxel fog options: bad values are named") {
  EsmOptions o;
  o.exponent = 2e4;
  requireNamed([&] { validate(o, "X.esm"); }, "X.esm.exponent");
  o = {};
  o.downsample = 0;
  requireNamed([&] { validate(o, "X.esm"); }, "X.esm.downsample");
  o = {};
  o.blurRadius = -1;
  requireNamed([&] { validate(o, "X.esm"); }, "X.esm.blurRadius");
  o = {};
  o.bias = std::nan("");
  requireNamed([&] { validate(o, "X.esm"); }, "X.esm.bias");
  FroxelDensity d;
  d.heightFalloff = -1.0;
  requireNamed([&] { validate(d, "X.density"); }, "X.density.heightFalloff");
  d = {};
  d.noiseAmplitude = 2.0;
  requireNamed([&] { validate(d, "X.density"); }, "X.density.noiseAmplitude");
  d = {};
  d.noiseFrequency = 0.0;
  requireNamed([&] { validate(d, "X.density"); }, "X.density.noiseFrequency");
  Image bad(4, 4, 1, 0.5f);
  bad.at(1, 1) = std::nanf("");
  requireNamed([&] { buildEsm(bad, glm::dmat4(1.0), {}); }, "shadowDepth");
  requireNamed([&] { esmDepthExponent({}, glm::dmat4(0.0)); }, "lightClipFromWorld");
  const Camera cam = fogCamera();
  FroxelGrid grid{4, 4, 4, 0.0, 0.0};
  FroxelVolume v(4, 4, 3);
  requireNamed([&] { froxelAccumulate(v, grid, cam, fogMedium(), glm::dvec3(0.0)); },
               "froxelAccumulate.lighting");
  FroxelVolume ok(4, 4, 4);
  requireNamed([&] { froxelTemporal(ok, &ok, grid, cam, cam, 1.0); }, "froxelTemporal.historyWeight");
  requireNamed([&] { froxelAccumulate(ok, grid, cam, fogMedium(), glm::dvec3(0.7, 0.0, 0.0)); },
               "froxelAccumulate.jitter");
}
