// CPU reference prefilter and evaluation (Klehm et al. 2014, Sec. 3.1-3.3, Appendix A; prefilter.h):
// storage rules, the filter against direct sums, determinism across thread counts, and ground truth
// that does not depend on any shadow map: (a) no occluder: the closed form of a homogeneous medium;
// (b) one infinite plane occluder (half-space shadow): the closed form along each ray, with the
// rectified map made on the CPU by intersecting each texel's light ray with the plane.
#include <crep/core/error.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/rectified_march.h>
#include <crep/support/image_compare.h>

#include "common/analytic_scene.h"
#include "common/error_checks.h"
#include "common/image_check.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

using namespace crep;
using crep::test::invalidParameter;

namespace {

// ---------------------------------------------------------------------------------------------------
// The analytic setup: a 60 degree camera 2 units above a ground plane y = 0, near 0.1, far 80, light
// from the side and above; a coloured medium (optical depth ~5 along the far plane distance).

using test::groundDepth;
using test::HalfSpace;

RectifiedMap halfSpaceMap(std::shared_ptr<const ProjectiveLayout> layout, const HalfSpace& plane, int W,
                          int H) {
  return castRectifiedMap(layout, W, H, [&](const LightRay& ray) { return test::planeHit(plane, ray); });
}

/// exp(-sigma a) - exp(-sigma b), over sigma, per channel.
glm::dvec3 segmentIntegral(const glm::dvec3& sigma, double a, double b) {
  glm::dvec3 r(0.0);
  if (!(b > a)) return r;
  for (int c = 0; c < 3; ++c)
    r[c] = (std::exp(-sigma[c] * a) - std::exp(-sigma[c] * b)) / sigma[c];
  return r;
}

/// Closed-form single scattering with the half-space shadow, same rays and ranges as evaluate().
Image halfSpaceTruth(const Image& depth, const Camera& camera, const DirectionalLight& light,
                     const Medium& medium, const HalfSpace& plane, bool nearPlane = false) {
  Image out(depth.width(), depth.height(), 4);
  const glm::dvec3 sigma = medium.extinction();
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x) {
      const glm::dvec3 v =
          camera.rayDirection(2.0 * (x + 0.5) / depth.width() - 1.0, 2.0 * (y + 0.5) / depth.height() - 1.0);
      const double cosF = glm::dot(v, camera.forward());
      const double d = depth.at(x, y);
      const double s = (d >= 1.0 ? camera.far() : camera.linearDepth(d)) / cosF;
      const double a = nearPlane ? camera.near() / cosF : 0.0;
      const double f0 = glm::dot(plane.normal, camera.position() - plane.point),
                   fv = glm::dot(plane.normal, v);
      double lo = a, hi = s; // lit part: f0 + t fv <= 0
      if (fv > 0.0)
        hi = std::min(s, -f0 / fv);
      else if (fv < 0.0)
        lo = std::max(a, -f0 / fv);
      else if (f0 > 0.0)
        hi = lo;
      const glm::dvec3 L = scatteringConstant(light, medium, v) * segmentIntegral(sigma, lo, hi);
      for (int c = 0; c < 3; ++c)
        out.at(x, y, c) = static_cast<float>(L[c]);
      out.at(x, y, 3) = static_cast<float>(std::exp(-weightExtinction(medium) * s));
    }
  return out;
}

ImageMetrics rgbMetrics(const Image& actual, const Image& reference) {
  CompareOptions o;
  o.channels = 3;
  return compareImages(actual, reference, o);
}

void report(const char* what, const ImageMetrics& m) {
  MESSAGE(std::string(what) << ": relative RMSE " << m.relativeRmse << ", PSNR " << m.psnr << " dB, max abs "
                            << m.maxAbsError << " (peak " << m.peak << ")");
}

bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}
bool sameBits(const Image& a, const Image& b) {
  return a.sameShape(b) && std::memcmp(a.data().data(), b.data().data(), a.byteSize()) == 0;
}

} // namespace

// ---------------------------------------------------------------------------------------------------

TEST_CASE("prefilter: stored values follow the GPU's storage rules") {
  // RGBA8: e = 0.5 + 0.5 F, round(clamp(e, 0, 1) 255) / 255.
  CHECK(storeFiltered(-1.0, StorageFormat::RGBA8) == 0.0f);
  CHECK(storeFiltered(1.0, StorageFormat::RGBA8) == 1.0f);
  CHECK(storeFiltered(0.0, StorageFormat::RGBA8) == static_cast<float>(128.0 / 255.0)); // 127.5 rounds up
  CHECK(storeFiltered(3.0, StorageFormat::RGBA8) == 1.0f);
  for (int k = 0; k <= 255; ++k) {
    const double e = k / 255.0;
    CHECK(storeFiltered(2.0 * e - 1.0, StorageFormat::RGBA8) == static_cast<float>(e));
    CHECK(storeFiltered(2.0 * (e + 0.49 / 255.0) - 1.0, StorageFormat::RGBA8) == static_cast<float>(e));
  }
  // binary16: 11 significant bits, ties to even.
  CHECK(roundToHalf(1.0 / 3.0) == 0.333251953125f);
  CHECK(roundToHalf(1.0 + std::ldexp(1.0, -11)) == 1.0f);                              // tie -> even (1.0)
  CHECK(roundToHalf(1.0 + 3.0 * std::ldexp(1.0, -11)) == 1.0f + std::ldexp(1.0f, -9)); // tie -> even
  CHECK(roundToHalf(std::ldexp(1.0, -24) * 0.75) == std::ldexp(1.0f, -24));            // subnormal
  CHECK(roundToHalf(65504.0) == 65504.0f);
  CHECK(std::isinf(roundToHalf(70000.0)));
  CHECK(storeFiltered(0.123456789, StorageFormat::RGBA32F) == static_cast<float>(0.5 + 0.5 * 0.123456789));
  CHECK(std::string(storageFormatToken(StorageFormat::RGBA16F)) == "rgba16f");
}

TEST_CASE("prefilter: the filtered basis is the normalized weighted prefix of each region (Appendix A)") {
  const Camera camera = test::groundCamera();
  const auto layout = test::projectiveLayout(camera, test::sideLight(), 2);
  const int W = 48, H = 5, M = 6; // M not a multiple of 4: the second layer is half used
  Image depth(W, H, 1);
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      depth.at(x, y) = x % 7 == 0 ? 1.0f : static_cast<float>(uni(rng));
  const RectifiedMap map = makeRectifiedMap(layout, depth);
  for (const WeightMode mode : {WeightMode::Exact, WeightMode::ConstantRatio, WeightMode::ConstantStep,
                                WeightMode::AverageVisibility}) {
    CAPTURE(weightModeToken(mode));
    PrefilterOptions o;
    o.bases = M;
    o.weights = mode;
    o.format = StorageFormat::RGBA32F;
    o.regionsPerSplit = 3;
    o.depthMargin = 0.1;
    const FilteredBasis b8 = prefilter(map, 0.07, o);
    REQUIRE(b8.bases == M);
    const int R = b8.regions, n = b8.regionWidth();
    REQUIRE(R == 6);
    REQUIRE(b8.layers == 2);
    double worst = 0.0;
    std::vector<double> w(static_cast<std::size_t>(n)), B(M);
    for (int y = 0; y < H; ++y)
      for (int r = 0; r < R; ++r) {
        regionWeights(mode, 0.07, b8.profiles[static_cast<std::size_t>(y * R + r)], n, w);
        std::vector<double> sumWB(M, 0.0);
        double sumW = 0.0;
        for (int i = 0; i < n; ++i) {
          const int x = r * n + i;
          fourierBasis(texelBasisDepth(depth.at(x, y), 0.1), std::span<double>(B));
          sumW += w[static_cast<std::size_t>(i)];
          for (int k = 0; k < M; ++k) {
            sumWB[static_cast<std::size_t>(k)] +=
                w[static_cast<std::size_t>(i)] * B[static_cast<std::size_t>(k)];
            worst =
                std::max(worst, std::abs(b8.filtered(x, y, k) - sumWB[static_cast<std::size_t>(k)] / sumW));
          }
        }
      }
    MESSAGE(std::string(weightModeToken(mode)) << ": worst |stored - sum w B / sum w| = " << worst);
    CHECK(worst < 2e-7); // float storage of e, doubled by the decode
  }
  // M = 6: the channels beyond M hold F = 0 (encoded 0.5).
  PrefilterOptions o6;
  o6.bases = 6;
  o6.format = StorageFormat::RGBA32F;
  const FilteredBasis b6 = prefilter(map, 0.07, o6);
  CHECK(b6.stored(3, 2, 6) == 0.5f);
  CHECK(b6.stored(3, 2, 7) == 0.5f);
}

TEST_CASE("prefilter: output is bit-identical for any thread count") {
  const Camera camera = test::groundCamera(64, 36);
  const DirectionalLight light = test::sideLight();
  const Medium medium = test::colouredMedium();
  const auto layout = test::projectiveLayout(camera, light);
  const RectifiedMap map = halfSpaceMap(layout, HalfSpace{}, 128, 37);
  const Image depth = groundDepth(camera, 64, 36);
  PrefilterOptions o;
  o.threads = 1;
  const FilteredBasis one = prefilter(map, medium, o);
  EvaluateOptions e;
  e.threads = 1;
  const Image evalOne = evaluate(one, depth, camera, light, medium, e);
  MarchOptions m;
  m.threads = 1;
  const Image marchOne = bruteForceMarch(map, depth, camera, light, medium, m).scattering;
  for (const int threads : {2, 3, 8, 0}) {
    CAPTURE(threads);
    o.threads = threads;
    e.threads = threads;
    m.threads = threads;
    const FilteredBasis many = prefilter(map, medium, o);
    CHECK(sameBits(one.texels, many.texels));
    CHECK(sameBits(evalOne, evaluate(many, depth, camera, light, medium, e)));
    CHECK(sameBits(marchOne, bruteForceMarch(map, depth, camera, light, medium, m).scattering));
    const RectifiedMap again = castRectifiedMap(
        layout, 128, 37,
        [&](const LightRay& ray) -> std::optional<glm::dvec3> {
          const HalfSpace p;
          return ray.origin +
                 glm::dot(p.normal, p.point - ray.origin) / glm::dot(p.normal, ray.direction) * ray.direction;
        },
        threads);
    CHECK(sameBits(map.depth, again.depth));
  }
}

TEST_CASE("prefilter: ground truth (a) no occluder equals the closed form of the homogeneous medium") {
  // Defaults (M = 32, RGBA8, exact weights, bilinear, Eq. 8 undamped), 512 x 256 map (4 logarithmic
  // splits), 160 x 90 screen, ground plane and sky, coloured medium. Measured: relative RMSE 8.4e-3,
  // PSNR 50.3 dB, max abs 6.0e-3 (peak 0.134); with Lanczos damping 3.3e-4 / 78.6 dB / 2.7e-4. The march
  // over the same (empty) map is exact. The residual is the ringing of the series against empty texels
  // near the depth margin (fourier.h); without the margin it is 2.5e-2.
  const Camera camera = test::groundCamera();
  const DirectionalLight light = test::sideLight();
  const Medium medium = test::colouredMedium();
  const auto layout = test::projectiveLayout(camera, light);
  const RectifiedMap map = castRectifiedMap(layout, 512, 256, [](const LightRay&) { return std::nullopt; });
  const Image depth = groundDepth(camera, 160, 90);
  const Image truth = unshadowedScattering(depth, camera, light, medium);
  const FilteredBasis basis = prefilter(map, medium);
  const Image ours = evaluate(basis, depth, camera, light, medium);
  report("(a) prefiltered vs closed form", rgbMetrics(ours, truth));
  EvaluateOptions damped;
  damped.ringing = RingingFilter::Lanczos;
  const Image lanczos = evaluate(basis, depth, camera, light, medium, damped);
  report("(a) prefiltered with Lanczos damping vs closed form", rgbMetrics(lanczos, truth));
  PrefilterOptions noMargin;
  noMargin.depthMargin = 0.0;
  report("(a) prefiltered without the depth margin vs closed form",
         rgbMetrics(evaluate(prefilter(map, medium, noMargin), depth, camera, light, medium), truth));
  const ImageMetrics march = rgbMetrics(bruteForceMarch(map, depth, camera, light, medium).scattering, truth);
  report("(a) march vs closed form", march);
  CHECK(march.relativeRmse < 1e-6);
  ImageTolerance t;
  t.relativeRmse = 0.013;
  t.minPsnr = 47.0;
  t.maxAbsError = 0.009;
  CHECK(test::checkImage(ours, truth, t, "prefilter_a_no_occluder"));
  t.relativeRmse = 5e-4;
  t.minPsnr = 75.0;
  t.maxAbsError = 4e-4;
  CHECK(test::checkImage(lanczos, truth, t, "prefilter_a_no_occluder_lanczos"));
  // A channel: the grey transmittance to the surface.
  CHECK(ours.at(80, 10, 3) == truth.at(80, 10, 3));
}

TEST_CASE("prefilter: ground truth (b) half-space shadow equals the closed form along each ray") {
  // Same setup with one infinite tilted plane occluder (it casts only: the camera sees the ground); 72% of
  // the unshadowed radiance (relative RMSE) is shadowed. Defaults (M = 32, RGBA8, exact weights,
  // bilinear, Eq. 8 undamped), 512 x 256 map. Measured: relative RMSE 9.1e-3, PSNR 51.7 dB, max abs
  // 4.2e-3 (peak 0.122); Lanczos 7.5e-3 / 53.4 dB / 4.0e-3; nearest sampling 9.8e-3. The march over the
  // same map: 3.7e-3 (the map's own discretization); prefiltered vs march 9.7e-3. Of that, ~0.35% is the
  // grey weight extinction for this coloured medium (a grey medium gives 5.7e-3 against the closed form).
  const Camera camera = test::groundCamera();
  const DirectionalLight light = test::sideLight();
  const Medium medium = test::colouredMedium();
  const auto layout = test::projectiveLayout(camera, light);
  const HalfSpace plane;
  const RectifiedMap map = halfSpaceMap(layout, plane, 512, 256);
  const Image depth = groundDepth(camera, 160, 90);
  const Image truth = halfSpaceTruth(depth, camera, light, medium, plane);
  const Image unshadowed = unshadowedScattering(depth, camera, light, medium);
  const ImageMetrics contrast = rgbMetrics(unshadowed, truth);
  report("(b) unshadowed vs truth (how much shadow there is)", contrast);
  REQUIRE(contrast.relativeRmse > 0.2);
  const FilteredBasis basis = prefilter(map, medium);
  const Image ours = evaluate(basis, depth, camera, light, medium);
  report("(b) prefiltered vs closed form", rgbMetrics(ours, truth));
  EvaluateOptions variant;
  variant.ringing = RingingFilter::Lanczos;
  report("(b) Lanczos damping", rgbMetrics(evaluate(basis, depth, camera, light, medium, variant), truth));
  variant = {};
  variant.sampling = Sampling::Nearest;
  report("(b) nearest sampling", rgbMetrics(evaluate(basis, depth, camera, light, medium, variant), truth));
  for (const WeightMode mode :
       {WeightMode::ConstantRatio, WeightMode::ConstantStep, WeightMode::AverageVisibility}) {
    PrefilterOptions o;
    o.weights = mode;
    report((std::string("(b) weights ") + weightModeToken(mode)).c_str(),
           rgbMetrics(evaluate(prefilter(map, medium, o), depth, camera, light, medium), truth));
  }
  const Image march = bruteForceMarch(map, depth, camera, light, medium).scattering;
  report("(b) march vs closed form", rgbMetrics(march, truth));
  report("(b) prefiltered vs march (the method's own error)", rgbMetrics(ours, march));
  const Medium grey({.mieScattering = glm::dvec3(0.06), .hgG = 0.6, .absorption = glm::dvec3(0.0)});
  const Image greyTruth = halfSpaceTruth(depth, camera, light, grey, plane);
  const ImageMetrics greyMetrics =
      rgbMetrics(evaluate(prefilter(map, grey), depth, camera, light, grey), greyTruth);
  report("(b) grey medium vs closed form", greyMetrics);
  CHECK(greyMetrics.relativeRmse < 0.009);
  ImageTolerance t;
  t.relativeRmse = 0.014;
  t.minPsnr = 48.0;
  t.maxAbsError = 0.0065;
  CHECK(test::checkImage(ours, truth, t, "prefilter_b_half_space"));
}

TEST_CASE("prefilter: storage formats differ from RGBA32F only by their quantization") {
  const Camera camera = test::groundCamera();
  const DirectionalLight light = test::sideLight();
  const Medium medium = test::colouredMedium();
  const auto layout = test::projectiveLayout(camera, light);
  const RectifiedMap map = halfSpaceMap(layout, HalfSpace{}, 256, 128);
  const Image depth = groundDepth(camera, 160, 90);
  PrefilterOptions o;
  o.format = StorageFormat::RGBA32F;
  const FilteredBasis full = prefilter(map, medium, o);
  const Image ref = evaluate(full, depth, camera, light, medium);
  for (const StorageFormat f : {StorageFormat::RGBA16F, StorageFormat::RGBA8}) {
    o.format = f;
    const FilteredBasis q = prefilter(map, medium, o);
    double worstStored = 0.0;
    for (std::size_t i = 0; i < q.texels.size(); ++i)
      worstStored = std::max(worstStored, std::abs(static_cast<double>(q.texels[i]) - full.texels[i]));
    const ImageMetrics m = rgbMetrics(evaluate(q, depth, camera, light, medium), ref);
    MESSAGE(std::string(storageFormatToken(f)) << ": worst |stored - float| " << worstStored);
    report(storageFormatToken(f), m);
    // Rounding bound of the encoded value: half a quantum (RGBA8: 0.5 / 255; binary16 in [0.5, 1]: 2^-12).
    CHECK(worstStored <= (f == StorageFormat::RGBA8 ? 0.5 / 255.0 : std::ldexp(1.0, -12)) + 1e-7);
    // Visibility error bound: sum_j |a_j| * 2 * (half quantum); |a| sums to ~2.4 for M = 32, so <= 0.019 for
    // RGBA8; radiance is that times the unshadowed peak.
    CHECK(m.maxAbsError <= 0.019 * m.peak * 1.2);
    CHECK(m.relativeRmse < (f == StorageFormat::RGBA8 ? 0.01 : 1e-3));
  }
}

TEST_CASE("prefilter: near-plane correction integrates from the near plane (Sec. 3.1)") {
  const Camera camera = test::groundCamera(80, 45);
  const DirectionalLight light = test::sideLight();
  const Medium medium = test::colouredMedium();
  const auto layout = test::projectiveLayout(camera, light);
  const HalfSpace plane;
  const RectifiedMap map = halfSpaceMap(layout, plane, 512, 256);
  const Image depth = groundDepth(camera, 80, 45);
  EvaluateOptions e;
  e.nearPlaneCorrection = true;
  const FilteredBasis basis = prefilter(map, medium);
  const Image corrected = evaluate(basis, depth, camera, light, medium, e);
  const Image plain = evaluate(basis, depth, camera, light, medium);
  const Image truth = halfSpaceTruth(depth, camera, light, medium, plane, true);
  const ImageMetrics m = rgbMetrics(corrected, truth);
  report("(b) with near-plane correction vs closed form from the near plane", m);
  CHECK(m.relativeRmse < 0.014); // measured 9.1e-3
  // Without an occluder the corrected result is the closed form from the near plane.
  const RectifiedMap empty = castRectifiedMap(layout, 512, 256, [](const LightRay&) { return std::nullopt; });
  const Image emptyCorrected = evaluate(prefilter(empty, medium), depth, camera, light, medium, e);
  const ImageMetrics me = rgbMetrics(
      emptyCorrected, unshadowedScattering(depth, camera, light, medium, {.nearPlaneCorrection = true}));
  report("(a) with near-plane correction", me);
  CHECK(me.relativeRmse < 0.013); // measured 8.4e-3
  // The part before the near plane is small but positive.
  double removed = 0.0;
  for (int y = 0; y < 45; ++y)
    for (int x = 0; x < 80; ++x)
      removed += plain.at(x, y, 1) - corrected.at(x, y, 1);
  CHECK(removed > 0.0);
}

TEST_CASE("prefilter: sky pixels integrate to the far plane") {
  const Camera camera = test::groundCamera(64, 36);
  const DirectionalLight light = test::sideLight();
  const Medium medium = test::colouredMedium();
  const auto layout = test::projectiveLayout(camera, light);
  const RectifiedMap empty = castRectifiedMap(layout, 256, 128, [](const LightRay&) { return std::nullopt; });
  const Image sky(64, 36, 1, 1.0f);
  const Image ours = evaluate(prefilter(empty, medium), sky, camera, light, medium);
  const glm::dvec3 sigma = medium.extinction();
  Image truth(64, 36, 4);
  for (int y = 0; y < 36; ++y)
    for (int x = 0; x < 64; ++x) {
      const glm::dvec3 v = camera.rayDirection(2.0 * (x + 0.5) / 64 - 1.0, 2.0 * (y + 0.5) / 36 - 1.0);
      const double s = camera.far() / glm::dot(v, camera.forward());
      const glm::dvec3 L = scatteringConstant(light, medium, v) * segmentIntegral(sigma, 0.0, s);
      for (int c = 0; c < 3; ++c)
        truth.at(x, y, c) = static_cast<float>(L[c]);
    }
  const ImageMetrics m = rgbMetrics(ours, truth);
  report("sky, empty map", m);
  CHECK(m.relativeRmse < 0.012); // measured 7.9e-3
}

TEST_CASE("prefilter: clamped visibility keeps 0 <= L <= unshadowed for arbitrary maps") {
  const Camera camera = test::groundCamera(48, 27);
  const DirectionalLight light = test::sideLight();
  const Medium medium = test::colouredMedium();
  const auto layout = test::projectiveLayout(camera, light);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  Image random(128, 64, 1);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 128; ++x)
      random.at(x, y) = uni(rng) < 0.2 ? 1.0f : (uni(rng) < 0.1 ? 0.0f : static_cast<float>(uni(rng)));
  const RectifiedMap map = makeRectifiedMap(layout, random);
  const Image depth = groundDepth(camera, 48, 27);
  const Image bound = unshadowedScattering(depth, camera, light, medium);
  for (const Sampling sampling : {Sampling::Nearest, Sampling::Bilinear})
    for (const WeightMode mode :
         {WeightMode::Exact, WeightMode::AverageVisibility, WeightMode::ConstantRatio}) {
      PrefilterOptions o;
      o.weights = mode;
      o.bases = 16;
      EvaluateOptions e;
      e.sampling = sampling;
      const Image ours = evaluate(prefilter(map, medium, o), depth, camera, light, medium, e);
      for (int y = 0; y < 27; ++y)
        for (int x = 0; x < 48; ++x)
          for (int c = 0; c < 3; ++c) {
            REQUIRE(std::isfinite(ours.at(x, y, c)));
            REQUIRE(ours.at(x, y, c) >= 0.0f);
            REQUIRE(ours.at(x, y, c) <= bound.at(x, y, c) * (1.0f + 1e-5f));
          }
    }
}

TEST_CASE("prefilter: sigma -> 0 gives the linear limit without NaN") {
  const Camera camera = test::groundCamera(64, 36);
  const DirectionalLight light = test::sideLight();
  const Medium thin({.mieScattering = glm::dvec3(1e-14), .hgG = 0.3, .absorption = glm::dvec3(0.0)});
  const auto layout = test::projectiveLayout(camera, light);
  const RectifiedMap empty = castRectifiedMap(layout, 256, 128, [](const LightRay&) { return std::nullopt; });
  const Image depth = groundDepth(camera, 64, 36);
  const FilteredBasis basis = prefilter(empty, thin);
  const FilteredBasis zero = prefilter(empty, 0.0);
  CHECK(sameBits(basis.texels, zero.texels)); // 1e-14 is already the limit to double precision
  const Image ours = evaluate(basis, depth, camera, light, thin);
  const Image truth = unshadowedScattering(depth, camera, light, thin);
  // The closed form is C s in the limit: check one pixel by hand.
  const glm::dvec3 v = camera.rayDirection(2.0 * 20.5 / 64 - 1.0, 2.0 * 5.5 / 36 - 1.0);
  const double s = camera.linearDepth(depth.at(20, 5)) / glm::dot(v, camera.forward());
  CHECK(truth.at(20, 5, 0) == doctest::Approx(scatteringConstant(light, thin, v).x * s).epsilon(1e-6));
  const ImageMetrics m = rgbMetrics(ours, truth);
  report("thin medium, empty map", m);
  CHECK(m.nanCount == 0);
  CHECK(m.relativeRmse < 0.013); // measured 8.7e-3
}

TEST_CASE("prefilter: more prefilter regions per split (Sec. 3.3) keep the ground truth") {
  const Camera camera = test::groundCamera();
  const DirectionalLight light = test::sideLight();
  const Medium medium = test::colouredMedium();
  const auto layout = test::projectiveLayout(camera, light);
  const HalfSpace plane;
  const RectifiedMap map = halfSpaceMap(layout, plane, 768, 256);
  const Image depth = groundDepth(camera, 160, 90);
  const Image truth = halfSpaceTruth(depth, camera, light, medium, plane);
  for (const int P : {1, 3}) {
    PrefilterOptions o;
    o.regionsPerSplit = P;
    const FilteredBasis b = prefilter(map, medium, o);
    CHECK(b.regions == 4 * P);
    const ImageMetrics m = rgbMetrics(evaluate(b, depth, camera, light, medium), truth);
    MESSAGE("regionsPerSplit " << P);
    report("(b)", m);
    // Measured 9.0e-3 (P = 1) and 6.0e-3 (P = 3): shorter regions restore each part of the ray with its
    // own transmittance, so the reference ray's weights matter less (Sec. 3.3 regions help accuracy too).
    CHECK(m.relativeRmse < (P == 1 ? 0.014 : 0.009));
  }
}

TEST_CASE("prefilter: bad input gets a named InvalidArgument") {
  const Camera camera = test::groundCamera(16, 9);
  const DirectionalLight light = test::sideLight();
  const Medium medium = test::colouredMedium();
  const auto layout = test::projectiveLayout(camera, light);
  Image bad(64, 8, 1, 0.5f);
  bad.at(3, 2) = std::nanf("");
  CHECK(invalidParameter([&] { makeRectifiedMap(layout, bad); }) == "RectifiedMap.depth");
  CHECK(invalidParameter([&] { makeRectifiedMap(layout, Image(66, 8, 1)); }) == "RectifiedMap.depth");
  CHECK(invalidParameter([&] { makeRectifiedMap(nullptr, Image(64, 8, 1)); }) == "RectifiedMap.layout");
  const RectifiedMap map = makeRectifiedMap(layout, Image(64, 8, 1, 1.0f));
  PrefilterOptions o;
  o.bases = 33;
  CHECK(invalidParameter([&] { prefilter(map, medium, o); }) == "PrefilterOptions.bases");
  o = {};
  o.regionsPerSplit = 3; // 64 is not a multiple of 12
  CHECK(invalidParameter([&] { prefilter(map, medium, o); }) == "RectifiedMap.depth");
  o = {};
  o.depthMargin = 0.3;
  CHECK(invalidParameter([&] { prefilter(map, medium, o); }) == "PrefilterOptions.depthMargin");
  o = {};
  o.threads = -1;
  CHECK(invalidParameter([&] { prefilter(map, medium, o); }) == "PrefilterOptions.threads");
  CHECK(invalidParameter([&] { prefilter(map, -1.0); }) == "extinction");
  const FilteredBasis basis = prefilter(map, medium);
  Image depth(16, 9, 1, 0.5f);
  depth.at(1, 1) = 1.5f;
  CHECK(invalidParameter([&] { evaluate(basis, depth, camera, light, medium); }) == "cameraDepth");
  CHECK(invalidParameter([&] { evaluate(basis, Image(), camera, light, medium); }) == "cameraDepth");
  FilteredBasis broken = basis;
  broken.texels.pop_back();
  CHECK(invalidParameter([&] { evaluate(broken, Image(16, 9, 1, 1.0f), camera, light, medium); }) ==
        "FilteredBasis");
  // The contract needs the splits side by side.
  RectifyOptions layers;
  layers.layout = SplitLayout::Layers;
  CHECK(invalidParameter([&] { ProjectiveLayout(rectify(camera, light, layers)); }) ==
        "Rectification.layout");
}

TEST_CASE("prefilter: the region visibility table keeps the analytic ground truth within 0.1%") {
  // EvaluateOptions::visibilityTableSamples: the regions a ray crosses whole read their visibility from a
  // table over (row, depth) instead of the basis. Against the closed forms of (a) and (b), with the library's
  // splits (8 x 2 prefilter regions) and the former 4 x 1: the table may not cost more than 0.1% relative
  // RMSE (the price of the table's speed). The table itself is tested against its definition.
  const Camera camera = test::groundCamera();
  const DirectionalLight light = test::sideLight();
  const Medium medium = test::colouredMedium();
  const Image depth = groundDepth(camera, 160, 90);
  const HalfSpace plane;
  for (const int splits : {4, 8}) {
    CAPTURE(splits);
    const auto layout = test::projectiveLayout(camera, light, splits);
    PrefilterOptions po;
    po.regionsPerSplit = splits == 8 ? 2 : 1;
    for (const bool shadow : {false, true}) {
      CAPTURE(shadow);
      const RectifiedMap map =
          shadow ? halfSpaceMap(layout, plane, 512, 256)
                 : castRectifiedMap(layout, 512, 256, [](const LightRay&) { return std::nullopt; });
      const Image truth = shadow ? halfSpaceTruth(depth, camera, light, medium, plane)
                                 : unshadowedScattering(depth, camera, light, medium);
      const FilteredBasis basis = prefilter(map, medium, po);
      EvaluateOptions direct, tabled, prefixed;
      direct.visibilityTableSamples = 0;
      tabled.scatteringPrefix = false;
      REQUIRE(usesVisibilityTable(tabled));
      REQUIRE(!usesScatteringPrefix(tabled));
      REQUIRE(usesScatteringPrefix(prefixed));
      const ImageMetrics md = rgbMetrics(evaluate(basis, depth, camera, light, medium, direct), truth);
      const ImageMetrics mt = rgbMetrics(evaluate(basis, depth, camera, light, medium, tabled), truth);
      const ImageMetrics mp = rgbMetrics(evaluate(basis, depth, camera, light, medium, prefixed), truth);
      MESSAGE((shadow ? "(b)" : "(a)")
              << " " << splits << " splits x " << po.regionsPerSplit << ": relative RMSE direct "
              << md.relativeRmse << ", with the table " << mt.relativeRmse << ", with the scattering prefix "
              << mp.relativeRmse);
      CHECK(std::abs(mt.relativeRmse - md.relativeRmse) < 0.001);
      CHECK(std::abs(mp.relativeRmse - md.relativeRmse) < 0.001);
    }
    // The table's definition at a few entries: clamp(0.5 + a(z_s) . F_r(last texel of r), 0, 1).
    const RectifiedMap map = halfSpaceMap(layout, plane, 512, 256);
    const FilteredBasis basis = prefilter(map, medium, po);
    const int Z = 16;
    const std::vector<double> table = visibilityTable(basis, Z, RingingFilter::None);
    REQUIRE(table.size() == std::size_t(basis.height) * basis.regions * Z);
    std::vector<double> a(static_cast<std::size_t>(basis.bases));
    for (const int j : {0, 100, 255})
      for (const int r : {0, basis.regions - 1})
        for (const int s : {0, 7, Z - 1}) {
          fourierCoefficients(rayBasisDepth(double(s) / (Z - 1), basis.depthMargin), a);
          double dot = 0.0;
          for (int k = 0; k < basis.bases; ++k)
            dot += a[std::size_t(k)] * basis.filtered((r + 1) * basis.regionWidth() - 1, j, k);
          CHECK(table[(std::size_t(j) * basis.regions + r) * Z + s] ==
                doctest::Approx(std::clamp(0.5 + dot, 0.0, 1.0)).epsilon(1e-12));
        }
  }
  // Bad sample counts are named.
  EvaluateOptions bad;
  bad.visibilityTableSamples = 1;
  CHECK_THROWS_AS(validate(bad), InvalidArgument);
}

TEST_CASE("prefilter: the scattering prefix table telescopes to the closed form where nothing is shadowed") {
  // EvaluateOptions::scatteringPrefix. With V = 1 in every region the prefix of regions 0 .. r - 1 is the
  // transmittance integral from the camera to the boundary t_r: (1 - exp(-sigma t_r)) / sigma per channel
  // (Eq. 3), whatever the cuts in between; t_r from the layout's rayDistance, never below t_{r-1}.
  const Camera camera = test::groundCamera();
  const DirectionalLight light = test::sideLight();
  const Medium medium = test::colouredMedium();
  const glm::dvec3 sigma = medium.extinction();
  const auto layout = test::projectiveLayout(camera, light, 8);
  const RectifiedMap map = castRectifiedMap(layout, 512, 64, [](const LightRay&) { return std::nullopt; });
  PrefilterOptions po;
  po.regionsPerSplit = 2;
  const FilteredBasis basis = prefilter(map, medium, po);
  const int Z = 9, R = basis.regions;
  const std::vector<double> ones(std::size_t(basis.height) * R * Z, 1.0);
  const std::vector<double> S = scatteringPrefixTable(basis, ones, Z, sigma);
  REQUIRE(S.size() == ones.size() * kScatteringPrefixChannels);
  double worst = 0.0;
  for (const int j : {0, 31, 63})
    for (int s = 0; s < Z; ++s) {
      const double row = (j + 0.5) / basis.height, d = double(s) / (Z - 1);
      double t = 0.0;
      for (int r = 0; r < R; ++r) {
        if (r > 0) t = std::max(t, layout->rayDistance(row, d, double(r) / R));
        for (int c = 0; c < 3; ++c) {
          const double expected = t == 0.0 ? 0.0 : -std::expm1(-sigma[c] * t) / sigma[c];
          const double got = S[((std::size_t(j) * R + r) * Z + s) * 3 + c];
          worst = std::max(worst, std::abs(got - expected) / std::max(expected, 1e-300));
          if (r == 0) CHECK(got == 0.0);
        }
      }
    }
  MESSAGE("scattering prefix vs closed form: max relative error " << worst);
  CHECK(worst < 1e-12);
  // With a shadowed region the prefixes after it stop growing by exactly that region's integral.
  std::vector<double> gap = ones;
  const int j = 10, s = 4, dark = 5;
  gap[(std::size_t(j) * R + dark) * Z + s] = 0.0;
  const std::vector<double> G = scatteringPrefixTable(basis, gap, Z, sigma);
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < 3; ++c) {
      const std::size_t i = ((std::size_t(j) * R + r) * Z + s) * 3 + c;
      const std::size_t cut = ((std::size_t(j) * R + dark + 1) * Z + s) * 3 + c;
      const std::size_t before = ((std::size_t(j) * R + dark) * Z + s) * 3 + c;
      const double lost = r > dark ? S[cut] - S[before] : 0.0;
      CHECK(G[i] == doctest::Approx(S[i] - lost).epsilon(1e-12));
    }
  CHECK_THROWS_AS(scatteringPrefixTable(basis, std::vector<double>(3), Z, sigma), InvalidArgument);
}
