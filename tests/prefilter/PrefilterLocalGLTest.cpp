// The GPU prefilter pass for local lights (PrefilterPass::FrameAttribs::localLight, CREP_LOCAL_LIGHT)
// against the CPU reference crep::prefilter(map, medium, LocalLight) on the analytic spot light's map
// (common/local_light_scene.h): the stored basis, RGBA32F, value by value.
#include "common/analytic_reference.h"
#include "common/gl_fixture.h"
#include "common/local_light_scene.h"
#include "common/prefilter_gpu.h"

#include <crep/core/error.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>

#include <epoxy/gl.h>

#include <doctest/doctest.h>

#include <memory>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

/// A local light of the analytic scene with its rectification for the camera.
struct Case {
  const char* name;
  Rectification rect;
  LocalLight light;
};

/// The analytic spot and the analytic point light's face +X.
std::vector<Case> spotAndFace(const Camera& camera, const RectifyOptions& ro) {
  const SpotLight spot = analyticSpot();
  const PointLight point = analyticPoint();
  return {
      Case{"spot light", rectify(camera, spot, ro), LocalLight::spot(spot)},
      Case{"point light face +X", rectifyPointLight(camera, point, ro)[0], LocalLight::pointFace(point, 0)}};
}

} // namespace

TEST_CASE("prefilter GL, local lights: the GPU basis equals the CPU reference (spot light, point face)") {
  CREP_REQUIRE_GL();
  constexpr int W = 256, H = 128;
  const auto [camera, depth, medium, ro] = localLightView(160, 90);
  PrefilterOptions o;
  o.regionsPerSplit = 2;
  o.format = StorageFormat::RGBA32F;
  PrefilterPass pass({.mapWidth = W, .mapHeight = H, .options = o});
  const SpotLight spot = analyticSpot();
  for (const Case& k : spotAndFace(camera, ro)) {
    CAPTURE(std::string(k.name));
    REQUIRE(k.rect.projective());
    const auto layout = std::make_shared<const ProjectiveLayout>(k.rect);
    const RectifiedMap map = castRectifiedMap(layout, W, H, wallHitFromLight);
    const FilteredBasis cpu = prefilter(map, medium, k.light, o);
    const gl::Handle texture = uploadR32F(map.depth);
    pass.run(
        {.rectifiedDepth = texture.get(), .layout = layout.get(), .medium = &medium, .localLight = &k.light});
    CHECK(pass.filteredBasis().localLight);
    const std::vector<float> gpu = readTextureArray(pass.filteredBasisTexture(), W, H, pass.layers());
    // Float weights (light factor, exponentials) against double: measured max 1.1e-6 (spot) and 8.3e-7
    // (face) with the local variant's 32 bases per invocation (5.4e-7 and 4.2e-7 with 16: a longer harmonic
    // recurrence per invocation); the RGBA32F tolerance of the directional prefilter (4e-6) holds.
    const BasisDifference d = compareBasis(gpu, cpu, FormatTolerance{StorageFormat::RGBA32F});
    MESSAGE(std::string(k.name) << ": " << describe(d));
    CHECK(d.over == 0);
  }
  // Local lights need the exact weights and a medium.
  PrefilterOptions constant = o;
  constant.weights = WeightMode::ConstantStep;
  PrefilterPass other({.mapWidth = W, .mapHeight = H, .options = constant});
  const LocalLight light = LocalLight::spot(spot);
  const auto layout = std::make_shared<const ProjectiveLayout>(rectify(camera, spot, ro));
  const gl::Handle texture = createTexture2D(GL_R32F, W, H);
  CHECK_THROWS_WITH_AS(
      other.run(
          {.rectifiedDepth = texture.get(), .layout = layout.get(), .medium = &medium, .localLight = &light}),
      doctest::Contains("PrefilterPass::CreateInfo.options.weights"), crep::InvalidArgument);
  CHECK_THROWS_WITH_AS(
      pass.run({.rectifiedDepth = texture.get(), .layout = layout.get(), .localLight = &light}),
      doctest::Contains("PrefilterPass::FrameAttribs.medium"), crep::InvalidArgument);
}

TEST_CASE("evaluate GL, local lights: the GPU image equals the CPU evaluation and the closed form") {
  CREP_REQUIRE_GL();
  constexpr int W = 512, H = 256, w = 160, h = 90;
  const auto [camera, depth, medium, ro] = localLightView(w, h);
  PrefilterOptions o;
  o.regionsPerSplit = 2;
  PrefilterPass prefilterPass({.mapWidth = W, .mapHeight = H, .options = o});
  const gl::Handle depthTexture = uploadR32F(depth);
  for (const int variant : {0, 1, 2}) {
    // Prefix table or per-region loop; the sections by the quadrature or in closed form (airlight table).
    const bool prefixTable = variant != 1, closedForm = variant == 2;
    EvaluateOptions eo;
    eo.scatteringPrefix = prefixTable;
    EvaluatePass evaluatePass({.options = eo, .localClosedForm = closedForm});
    for (const Case& k : spotAndFace(camera, ro)) {
      const std::string name = std::string(k.name) + (prefixTable ? ", prefix table" : ", per-region table") +
                               (closedForm ? ", closed form" : "");
      CAPTURE(name);
      REQUIRE(k.rect.projective());
      const auto layout = std::make_shared<const ProjectiveLayout>(k.rect);
      const RectifiedMap map = castRectifiedMap(layout, W, H, wallHitFromLight);
      const Image gpu = prefilterEvaluateLocal(prefilterPass, evaluatePass, map, layout.get(), camera,
                                               depthTexture.get(), w, h, medium, k.light);
      const Image cpu = evaluate(prefilter(map, medium, k.light, o), depth, camera, k.light, medium, eo);
      const ImageMetrics vsCpu = rgbMetrics(gpu, cpu);
      if (prefixTable) {
        // The last region from the local section table times the ray's share (EvaluateOptions::
        // localSectionTable, the default) against its own quadrature, on the CPU.
        EvaluateOptions quadrature = eo;
        quadrature.localSectionTable = false;
        const Image exact =
            evaluate(prefilter(map, medium, k.light, o), depth, camera, k.light, medium, quadrature);
        const ImageMetrics rule = rgbMetrics(cpu, exact);
        report(name + ": CPU, section table and share vs the last region's quadrature", rule);
        CHECK(rule.relativeRmse < 2e-4);
      }
      const ImageMetrics vsTruth = rgbMetrics(gpu, closedFormLocal(depth, camera, {k.light}, medium, true));
      report(name + ": GPU vs CPU evaluation", vsCpu);
      report(name + ": GPU vs closed form", vsTruth);
      CHECK(vsCpu.nanCount == 0);
      CHECK(vsCpu.relativeRmse < 1e-3); // RGBA8 basis read through GL_LINEAR with 8-bit weights
      CHECK(vsTruth.relativeRmse < 0.01);
    }
  }
}
