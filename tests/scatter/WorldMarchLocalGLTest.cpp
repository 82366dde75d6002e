// WorldMarchPass with a local light (FrameAttribs::localLight: crep_localSegment of
// glsl/crep/local_light.glsl in float) against the CPU world march with the same LocalLight (double,
// RayScattering::segment) on the analytic scene of WorldMarchLocalTest.cpp: a ground camera, the
// half-space occluder x > 2 and a spot light or two faces of a point light on its lit side.
//
// What differs is float rounding: of the quadrature (the unoccluded case isolates it) and of the ray
// positions where the visibility is sampled. A sample within float rounding of the shadow edge can take
// the other side, and the bisection then lands in a neighbouring interval (at most one section of s / N):
// those pixels are counted and left out of a masked metric; the rest must agree to float precision.
#include "common/analytic_reference.h"
#include "common/analytic_scene.h"
#include "common/gl_fixture.h"
#include "common/prefilter_gpu.h"

#include <crep/core/error.h>
#include <crep/gpu/gl.h>
#include <crep/scatter/gpu_world_march.h>
#include <crep/scatter/ray_scattering.h>
#include <crep/scatter/world_march.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kW = 96, kH = 54, kShadow = 512;
constexpr int kSteps = 64, kRefinements = 12;
constexpr double kBias = 1e-5;

/// The occluder: x > 2 is shadowed (the lights are at x < 2).
HalfSpace wall() {
  return HalfSpace{.normal = {1.0, 0.0, 0.0}, .point = {2.0, 0.0, -10.0}};
}

SpotLight spotLight() {
  return SpotLight({.position = {-1.0, 6.0, -10.0},
                    .direction = {3.0, -6.0, -2.0},
                    .innerConeAngle = 0.45,
                    .outerConeAngle = 0.7,
                    .color = {1.0, 0.85, 0.7},
                    .intensity = 30.0,
                    .range = 60.0});
}

PointLight pointLight() {
  return PointLight(
      {.position = {-1.0, 3.0, -9.0}, .color = {1.0, 0.9, 0.8}, .intensity = 20.0, .range = 60.0});
}

struct Scene {
  Camera camera = groundCamera(kW, kH);
  Image depth = groundDepth(camera, kW, kH);
  Medium medium = colouredMedium();
  gl::Handle depthTexture = uploadR32F(depth);
};

/// The GPU pass for one local light and its shadow map (RGBA output read back).
Image gpuMarch(const Scene& s, const LocalLight& light, const glm::dmat4& M, const Image& shadow) {
  const gl::Handle shadowTexture = uploadR32F(shadow);
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kW, kH);
  WorldMarchPass pass({.options = {.steps = kSteps, .refinements = kRefinements}});
  WorldMarchPass::FrameAttribs f;
  f.camera = &s.camera;
  f.localLight = &light;
  f.medium = &s.medium;
  f.cameraDepth = s.depthTexture.get();
  f.shadowMap = shadowTexture.get();
  f.lightClipFromWorld = M;
  f.bias = kBias;
  f.output = out.get();
  pass.run(f);
  return gl::readTexture(out.get(), kW, kH, gl::TexelData::Rgba);
}

MarchResult cpuMarch(const Scene& s, const LocalLight& light, const glm::dmat4& M, const Image& shadow) {
  return worldSpaceMarch(shadow, M, s.depth, s.camera, light, s.medium,
                         {.steps = kSteps, .refinements = kRefinements, .bias = kBias});
}

// Tolerances. Float quadrature and ray positions (float epsilon 6e-8, amplified by the exponentials and
// the 1 / d^2 of some 20 world units of ray) put each pixel within a few 1e-5 of the CPU: measured
// relative RMSE 2e-6 (unoccluded spot) to 4.5e-6 (masked), largest pixel 2e-5 unoccluded and 5e-4 with
// the shadow (dim pixels near the edge). Checked: 1e-4 relative RMSE over the pixels within 1e-3.
// A visibility sample on the other side of the shadow edge (its float position differs from the
// double one by ~1e-6 of the ray) moves the change point by up to a section (1 / 64 of the ray): such
// a pixel is off by up to a few percent (measured: 5 pixels of face +z, at most 0.6%) and counted as an
// edge pixel (over 1e-3); at most 2% of the pixels may be, each must be one where the CPU ray changes
// visibility (it bisected), and the unmasked relative RMSE must stay below 2e-3 (measured 1e-5).
constexpr double kEdge = 1e-3, kMaskedRmse = 1e-4, kRmse = 2e-3, kMaxEdgeFraction = 0.02;

/// GPU vs CPU: relative RMSE over all pixels, the largest relative difference of a pixel (RGB, against
/// max(|cpu|, 1e-3 peak)), the pixels over `edge` relative difference (a visibility sample that took
/// the other side of the shadow edge) and the relative RMSE and maximum over the other pixels.
struct Agreement {
  double relativeRmse = 0.0, maxRelative = 0.0;
  int edgePixels = 0;
  int edgePixelsWithoutChange = 0; ///< of those, pixels whose CPU ray has no visibility change
  double maskedRelativeRmse = 0.0, maskedMaxRelative = 0.0;
  long long nonFinite = 0;
};

Agreement compare(const Image& gpu, const MarchResult& cpuResult, double edge) {
  const Image& cpu = cpuResult.scattering;
  Agreement a;
  const ImageMetrics m = rgbMetrics(gpu, cpu);
  a.relativeRmse = m.relativeRmse;
  a.nonFinite = m.nanCount + m.infCount;
  double peak = 0.0, sumRef2 = 0.0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      for (int c = 0; c < 3; ++c) {
        peak = std::max(peak, std::abs(static_cast<double>(cpu.at(x, y, c))));
        sumRef2 += static_cast<double>(cpu.at(x, y, c)) * cpu.at(x, y, c);
      }
  double sumErr2 = 0.0, sumMaskedRef2 = 0.0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      double worst = 0.0, err2 = 0.0, ref2 = 0.0;
      for (int c = 0; c < 3; ++c) {
        const double r = cpu.at(x, y, c), d = static_cast<double>(gpu.at(x, y, c)) - r;
        worst = std::max(worst, std::abs(d) / std::max(std::abs(r), 1e-3 * peak));
        err2 += d * d;
        ref2 += r * r;
      }
      a.maxRelative = std::max(a.maxRelative, worst);
      if (worst > edge) {
        ++a.edgePixels;
        // No bisection on the CPU (N + 1 lookups): no visibility change, so not a shadow-edge pixel.
        if (!cpuResult.steps.empty() && cpuResult.steps.at(x, y) <= kSteps + 1) ++a.edgePixelsWithoutChange;
        continue;
      }
      a.maskedMaxRelative = std::max(a.maskedMaxRelative, worst);
      sumErr2 += err2;
      sumMaskedRef2 += ref2;
    }
  a.maskedRelativeRmse = sumMaskedRef2 > 0.0 ? std::sqrt(sumErr2 / sumMaskedRef2) : 0.0;
  return a;
}

void report(const std::string& what, const Agreement& a) {
  MESSAGE(what << ": relative RMSE " << a.relativeRmse << ", max relative " << a.maxRelative << "; "
               << a.edgePixels << " of " << kW * kH << " pixels over " << kEdge << " (shadow-edge samples; "
               << a.edgePixelsWithoutChange
               << " without a visibility change on the CPU); the others: relative RMSE "
               << a.maskedRelativeRmse << ", max relative " << a.maskedMaxRelative);
}

} // namespace

TEST_CASE("world march GL, local lights: the GPU pass agrees with the CPU march (spot, point faces)") {
  CREP_REQUIRE_GL();
  const auto start = std::chrono::steady_clock::now();
  const Scene s;

  SUBCASE("spot light, no occluder: the quadrature alone") {
    const SpotLight spot = spotLight();
    const LocalLight light = LocalLight::spot(spot);
    const glm::dmat4 M = spot.lightClipFromWorld();
    const Image open(64, 64, 1, 1.0f);
    const Image gpu = gpuMarch(s, light, M, open);
    const MarchResult cpu = cpuMarch(s, light, M, open);
    const Agreement a = compare(gpu, cpu, kEdge);
    report("spot light, unoccluded: GPU vs CPU", a);
    CHECK(a.nonFinite == 0);
    CHECK(a.edgePixels == 0);
    CHECK(a.relativeRmse < kMaskedRmse);
    CHECK(a.maxRelative < kEdge);
  }

  SUBCASE("spot light, half-space shadow") {
    const SpotLight spot = spotLight();
    const LocalLight light = LocalLight::spot(spot);
    const glm::dmat4 M = spot.lightClipFromWorld();
    const Image shadow = halfSpaceShadowMap(wall(), M, kShadow);
    const Image gpu = gpuMarch(s, light, M, shadow);
    const MarchResult cpu = cpuMarch(s, light, M, shadow);
    const Agreement a = compare(gpu, cpu, kEdge);
    report("spot light, half-space shadow: GPU vs CPU", a);
    CHECK(a.nonFinite == 0);
    CHECK(a.edgePixels <= kMaxEdgeFraction * kW * kH);
    CHECK(a.edgePixelsWithoutChange == 0);
    CHECK(a.maskedRelativeRmse < kMaskedRmse);
    CHECK(a.relativeRmse < kRmse);
  }

  SUBCASE("point light, faces +x and +z (their sector border crosses the view), half-space shadow") {
    const PointLight point = pointLight();
    Image gpuSum(kW, kH, 4), cpuSum(kW, kH, 4);
    std::vector<Image> cpuFaces;
    for (const int face : {0, 4}) {
      const LocalLight light = LocalLight::pointFace(point, face);
      const glm::dmat4 M = point.faceClipFromWorld(face);
      const Image shadow = halfSpaceShadowMap(wall(), M, kShadow);
      const Image gpu = gpuMarch(s, light, M, shadow);
      const MarchResult cpu = cpuMarch(s, light, M, shadow);
      const Agreement a = compare(gpu, cpu, kEdge);
      report("point light face " + std::to_string(face) + ", half-space shadow: GPU vs CPU", a);
      CHECK(a.nonFinite == 0);
      CHECK(a.edgePixels <= kMaxEdgeFraction * kW * kH);
      CHECK(a.edgePixelsWithoutChange == 0);
      CHECK(a.edgePixelsWithoutChange == 0);
      CHECK(a.maskedRelativeRmse < kMaskedRmse);
      CHECK(a.relativeRmse < kRmse);
      for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
          for (int c = 0; c < 3; ++c) {
            gpuSum.at(x, y, c) += gpu.at(x, y, c);
            cpuSum.at(x, y, c) += cpu.scattering.at(x, y, c);
          }
      cpuFaces.push_back(cpu.scattering);
    }
    // Rays that cross the border between the two sectors get light from both faces: every ray starts in
    // the +z sector (the camera is on the light's +z side) and about a quarter of them reach the lit part
    // of the +x sector.
    int both = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x)
        both += cpuFaces[0].at(x, y, 0) > 0.0f && cpuFaces[1].at(x, y, 0) > 0.0f ? 1 : 0;
    MESSAGE(both << " of " << kW * kH << " pixels see both faces");
    CHECK(both > kW * kH / 10);
    const Agreement sum = compare(gpuSum, MarchResult{cpuSum, Image()}, kEdge);
    report("point light faces +x and +z summed: GPU vs CPU", sum);
    CHECK(sum.maskedRelativeRmse < kMaskedRmse);
  }
  MESSAGE("time " << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() << " s");
}

TEST_CASE("world march GL, local lights: exactly one of FrameAttribs.light and .localLight") {
  CREP_REQUIRE_GL();
  const Scene s;
  const SpotLight spot = spotLight();
  const LocalLight local = LocalLight::spot(spot);
  const DirectionalLight sun(glm::dvec3(0.3, -1.0, -0.2));
  const gl::Handle shadow = uploadR32F(Image(16, 16, 1, 1.0f));
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kW, kH);
  WorldMarchPass pass({.options = {.steps = 4, .refinements = 2}});
  WorldMarchPass::FrameAttribs f;
  f.camera = &s.camera;
  f.medium = &s.medium;
  f.cameraDepth = s.depthTexture.get();
  f.shadowMap = shadow.get();
  f.lightClipFromWorld = spot.lightClipFromWorld();
  f.output = out.get();
  const auto expectLightError = [&](const char* what) {
    CAPTURE(what);
    try {
      pass.run(f);
      FAIL_CHECK("no InvalidArgument");
    } catch (const InvalidArgument& e) {
      CHECK(std::string(e.what()).find("WorldMarchPass::FrameAttribs.light/localLight") != std::string::npos);
    }
  };
  expectLightError("neither");
  f.light = &sun;
  f.localLight = &local;
  expectLightError("both");
  // Either alone runs.
  f.light = nullptr;
  CHECK_NOTHROW(pass.run(f));
  f.light = &sun;
  f.localLight = nullptr;
  CHECK_NOTHROW(pass.run(f));
}
