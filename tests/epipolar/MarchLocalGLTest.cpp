// The GPU rectified marches for a local light (RectifiedMarchPass::FrameAttribs::localLight, brute force
// and min/max tree) against the CPU brute-force march over the same map: the analytic spot light's map
// (common/local_light_scene.h), cast exactly; a directional light beside the local one is refused by name.
#include "common/analytic_reference.h"
#include "common/gl_fixture.h"
#include "common/local_light_scene.h"
#include "common/prefilter_gpu.h"

#include <crep/core/error.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/rectified_march.h>

#include <epoxy/gl.h>

#include <doctest/doctest.h>

#include <memory>
#include <string>

using namespace crep;
using namespace crep::test;

TEST_CASE("rectified marches GL, local lights: brute force and min/max equal the CPU brute-force march") {
  CREP_REQUIRE_GL();
  constexpr int W = 512, H = 256, w = 160, h = 90;
  const auto [camera, depth, medium, ro] = localLightView(w, h);
  const SpotLight spot = analyticSpot();
  const LocalLight light = LocalLight::spot(spot);
  const auto layout = std::make_shared<const ProjectiveLayout>(rectify(camera, spot, ro));
  const RectifiedMap map = castRectifiedMap(layout, W, H, wallHitFromLight);
  const gl::Handle mapTexture = uploadR32F(map.depth);
  const gl::Handle depthTexture = uploadR32F(depth);
  const Image cpu = bruteForceMarch(map, depth, camera, light, medium).scattering;
  MinMaxTreePass trees({W, H});
  trees.run(mapTexture.get());
  for (const auto mode : {RectifiedMarchPass::Mode::BruteForce, RectifiedMarchPass::Mode::MinMaxTree}) {
    const std::string name = mode == RectifiedMarchPass::Mode::BruteForce ? "brute force" : "min/max";
    RectifiedMarchPass pass({W, H, mode});
    const gl::Handle out = createTexture2D(GL_RGBA32F, w, h);
    RectifiedMarchPass::FrameAttribs a;
    a.layout = layout.get();
    a.camera = &camera;
    a.medium = &medium;
    a.cameraDepth = depthTexture.get();
    a.rectifiedDepth = mapTexture.get();
    a.minMaxBuffer = trees.treeBuffer();
    a.output = out.get();
    a.localLight = &light;
    pass.run(a);
    const ImageMetrics m = rgbMetrics(readRgbaTexture(out.get(), w, h), cpu);
    report("spot light, GPU " + name + " march vs CPU brute force", m);
    CHECK(m.nanCount == 0);
    CHECK(m.relativeRmse < 1e-4); // float sections and distances against double
    const DirectionalLight sun = test::sideLight();
    a.light = &sun;
    CHECK_THROWS_WITH_AS(pass.run(a), doctest::Contains("RectifiedMarchPass::FrameAttribs.light/localLight"),
                         crep::InvalidArgument);
  }
}
