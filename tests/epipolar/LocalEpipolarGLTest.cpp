// A local light in the view prefiltered on its epipolar layout (EpipolarLayout for the light's position;
// Klehm et al. 2014, Sec. 3.2 on the Sec. 4.1 layout): the GPU prefilter and evaluation against the CPU
// references (crep::prefilter and crep::evaluate with the LocalLight on the same map) and against the
// closed form of the analytic wall scene (common/local_light_scene.h), for a spot and a point-light face.
#include "common/analytic_reference.h"
#include "common/gl_fixture.h"
#include "common/local_light_scene.h"
#include "common/prefilter_gpu.h"

#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/resample.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/gpu_light_texture.h>
#include <crep/scatter/light_texture.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>

#include <memory>

using namespace crep;
using namespace crep::test;

TEST_CASE(
    "evaluate GL, a local light in view on its epipolar layout: GPU equals CPU, CPU near the closed form") {
  CREP_REQUIRE_GL();
  constexpr int W = 256, H = 256, w = 160, h = 90;
  const auto [camera, depth, medium, ro] = localLightView(w, h);
  PrefilterOptions o;
  o.regionsPerSplit = 4;
  PrefilterPass prefilterPass({.mapWidth = W, .mapHeight = H, .options = o});
  EvaluatePass evaluatePass({});
  const gl::Handle depthTexture = uploadR32F(depth);
  const SpotLight spot = analyticViewSpot();
  const PointLight point = analyticViewPoint();
  struct Case {
    const char* name;
    LocalLight light;
  };
  for (const Case& k : {Case{"spot light", LocalLight::spot(spot)},
                        Case{"point light face -Z", LocalLight::pointFace(point, 5)}}) {
    CAPTURE(std::string(k.name));
    EpipolarOptions eo;
    eo.slices = H;
    eo.depthWarp = 0.03; // Scattering::CreateInfo::localLightDepthWarp
    const auto layout = std::make_shared<const EpipolarLayout>(camera, k.light.position, w, h, eo);
    REQUIRE(layout->epipoleOnScreen());
    const RectifiedMap map = castRectifiedMap(layout, W, H, wallHitFromLight);
    const Image gpu = prefilterEvaluateLocal(prefilterPass, evaluatePass, map, layout.get(), camera,
                                             depthTexture.get(), w, h, medium, k.light);
    const Image cpu = evaluate(prefilter(map, medium, k.light, o), depth, camera, k.light, medium, {});
    const ImageMetrics vsCpu = rgbMetrics(gpu, cpu);
    const ImageMetrics cpuVsTruth = rgbMetrics(cpu, closedFormLocal(depth, camera, {k.light}, medium, true));
    report(std::string(k.name) + ": GPU vs CPU evaluation", vsCpu);
    report(std::string(k.name) + ": CPU vs closed form", cpuVsTruth);
    CHECK(vsCpu.nanCount == 0);
    CHECK(vsCpu.peak > 0.0);
    // Float distances and angles against double: measured 2.2e-4 (spot) and 1.8e-3 (face: its rays next to
    // the light cross many columns within a short distance, where float t = D sin(theta) / sin(psi + theta)
    // rounds most).
    CHECK(vsCpu.relativeRmse < 3e-3);
    // Measured 0.65% (spot) and 1.5% (face) with depth warp 0.03 (2.7% and 1.4% with the sun's 0.1).
    CHECK(cpuVsTruth.relativeRmse < 0.02);
  }
}

TEST_CASE("resample GL, a spot in view on its epipolar layout: the GL pass equals the CPU reference") {
  CREP_REQUIRE_GL();
  constexpr int w = 160, h = 90, kMap = 256, kShadow = 1024;
  const scenes::Scene scene = scenes::makeScene("colonnade", double(w) / h);
  scenes::SceneRenderer renderer(scene.mesh);
  const Camera& c = scene.camera;
  const glm::dvec3 position = c.position() + 9.0 * c.forward() + 1.5 * c.up() - 1.0 * c.right();
  const SpotLight spot({.position = position,
                        .direction = c.position() + 14.0 * c.forward() - position,
                        .innerConeAngle = 0.35,
                        .outerConeAngle = 0.55,
                        .range = 80.0});
  EpipolarOptions eo;
  eo.slices = kMap;
  const auto layout = std::make_shared<const EpipolarLayout>(c, spot.position(), w, h, eo);
  REQUIRE(layout->epipoleOnScreen());
  const gl::Handle shadow = scenes::createDepthTexture(kShadow, kShadow);
  renderer.renderDepth(spot.lightClipFromWorld(), shadow.get(), 0, 0, 0, kShadow, kShadow,
                       {.depthClamp = true});
  const RectifiedMap cpu =
      resampleShadowMap(layout, kMap, kMap, scenes::readDepthTexture(shadow.get(), kShadow, kShadow),
                        spot.lightClipFromWorld());
  const gl::Handle gpuMap = gl::createTexture2D(GL_R32F, kMap, kMap);
  ShadowResamplePass resample({kMap, kMap});
  resample.run({layout.get(), shadow.get(), spot.lightClipFromWorld(), gpuMap.get()});
  const Image gpu = gl::readTexture(gpuMap.get(), kMap, kMap, gl::TexelData::Red);
  int differ = 0, covered = 0;
  double mean = 0.0;
  for (int j = 0; j < kMap; ++j)
    for (int i = 0; i < kMap; ++i) {
      const double d = std::abs(gpu.at(i, j) - cpu.depth.at(i, j));
      differ += d > 1e-3 ? 1 : 0;
      covered += cpu.depth.at(i, j) < 1.0f ? 1 : 0;
      mean += d / (kMap * kMap);
    }
  MESSAGE("GL pass vs CPU: " << covered << " texels with an occluder, " << differ
                             << " differ by more than 1e-3, mean |difference| " << mean);
  CHECK(covered > kMap * kMap / 20); // the casters are in the map
  // Float light rays now and then pick the neighbouring perspective texel (as on the projective layout).
  CHECK(double(differ) / (kMap * kMap) < 0.005);
  CHECK(mean < 1e-4);
}

TEST_CASE(
    "light colour map GL, a spot in view on its epipolar layout: the GL pass equals the CPU reference") {
  CREP_REQUIRE_GL();
  constexpr int w = 160, h = 90, kMap = 256;
  const Camera camera = groundCamera(w, h);
  const SpotLight spot = analyticViewSpot();
  const LocalLight light = LocalLight::spot(spot);
  EpipolarOptions eo;
  eo.slices = kMap;
  const EpipolarLayout layout(camera, light.position, w, h, eo);
  // A two-colour slide: red left half, blue right half (RGBA32F, A = 1).
  Image rgba(8, 8, 4, 1.0f);
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) {
      rgba.at(i, j, 0) = i < 4 ? 1.0f : 0.1f;
      rgba.at(i, j, 1) = 0.5f;
      rgba.at(i, j, 2) = i < 4 ? 0.1f : 1.0f;
    }
  const gl::Handle texture = gl::createTexture2D(GL_RGBA32F, 8, 8);
  glTextureSubImage2D(texture.get(), 0, 0, 0, 8, 8, GL_RGBA, GL_FLOAT, rgba.data().data());
  LightColorMapPass pass({kMap, kMap});
  pass.run(
      {.layout = &layout, .lightTexture = {texture.get(), spot.lightClipFromWorld()}, .localLight = &light});
  const Image gpu = gl::readTexture(pass.colorMapTexture(), kMap, kMap, gl::TexelData::Rgba);
  const Image cpu = lightColorMap({&rgba, spot.lightClipFromWorld()}, layout, kMap, kMap);
  double worst = 0.0;
  for (int j = 0; j < kMap; ++j)
    for (int i = 0; i < kMap; ++i)
      for (int c = 0; c < 3; ++c)
        worst = std::max(worst, double(std::abs(gpu.at(i, j, c) - cpu.at(i, j, c))));
  MESSAGE("colour map GL vs CPU: max |difference| " << worst);
  CHECK(worst < 1e-3); // float light rays and bilinear weights at the slide's texel edges: measured 2.2e-4

  // The textured prefilter and evaluation on the layout: GPU against the CPU reference, on the wall map.
  const Image depth = groundDepth(camera, w, h);
  const Medium medium = colouredMedium();
  const auto shared = std::make_shared<const EpipolarLayout>(layout);
  const RectifiedMap map = castRectifiedMap(shared, kMap, kMap, wallHitFromLight);
  const gl::Handle mapTexture = uploadR32F(map.depth);
  PrefilterOptions o;
  o.regionsPerSplit = 4;
  PrefilterPass prefilterPass({.mapWidth = kMap, .mapHeight = kMap, .options = o});
  prefilterPass.run({.rectifiedDepth = mapTexture.get(),
                     .layout = &layout,
                     .medium = &medium,
                     .localLight = &light,
                     .lightColors = pass.colorMapTexture()});
  EvaluatePass evaluatePass({});
  const gl::Handle depthTexture = uploadR32F(depth);
  const gl::Handle out = createTexture2D(GL_RGBA32F, w, h);
  evaluatePass.run({.cameraDepth = depthTexture.get(),
                    .output = out.get(),
                    .camera = &camera,
                    .medium = &medium,
                    .layout = &layout,
                    .basis = prefilterPass.filteredBasis(),
                    .localLight = &light});
  const Image gpuImage = readRgbaTexture(out.get(), w, h);
  const Image cpuImage = evaluate(prefilter(map, medium, light, cpu, o), depth, camera, light, medium, {});
  const ImageMetrics m = rgbMetrics(gpuImage, cpuImage);
  report("textured spot in view: GPU vs CPU evaluation", m);
  CHECK(m.peak > 0.0);
  CHECK(m.relativeRmse < 3e-3);
}
