// crep::Scattering, the frame-level front door (crep/pipeline/scattering.h): the same image as the passes
// run by hand on projective frames, the prefiltered method on fallback frames (sun in view, sun behind the
// camera) close to the world-space reference, with either shadow input; bad input named; GL state kept.
// 160 x 90 screens, 256^2 maps.
#include "common/error_checks.h"
#include "common/gl_fixture.h"
#include "common/image_check.h"
#include "pipeline/scattering_frame.h"

#include <crep/core/error.h>
#include <crep/epipolar/march.h>
#include <crep/gpu/gl.h>
#include <crep/pipeline/scattering.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/scatter/gpu_world_march.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cmath>
#include <string>

using namespace crep;
using namespace crep::test;

TEST_CASE("Scattering: a projective frame gives the image of the passes run by hand") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  Scattering scattering(smallInfo());
  const Scattering::FrameResult r = scattering.run(f.attribs(true, true));
  CHECK(r.layout == Scattering::Layout::Projective);
  CHECK(r.epipoleBlockRadius == 0.0);
  checkStages(r);
  CHECK(r.stages.front().name == "shadow pass (rectified)");
  const Image ours = f.read();

  // By hand: the rectified map rasterized with the split matrices, the prefilter and evaluation passes.
  const Rectification rect = rectify(f.scene.camera, f.scene.sun, smallInfo().rectify);
  REQUIRE(rect.projective());
  const gl::Handle map = scenes::createDepthTexture(kMap, kMap);
  f.renderer.renderRectified(rect, map.get(), kMap, kMap);
  const ProjectiveLayout layout(rect);
  PrefilterPass prefilter({kMap, kMap, smallInfo().prefilter}); // Scattering's: 2 regions per split
  prefilter.run({map.get(), &layout, &f.scene.medium});
  EvaluatePass::CreateInfo evaluateInfo;
  evaluateInfo.reconstruction = smallInfo().prefilter.reconstruction; // the front door's
  EvaluatePass evaluate(evaluateInfo);
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
  evaluate.run({f.cameraDepth.get(), out.get(), &f.scene.camera, &f.scene.sun, &f.scene.medium, &layout,
                prefilter.filteredBasis()});
  const Image byHand = gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba);
  CHECK(maxRelativeDifference(ours, byHand, 1e-6) == 0.0);

  // Without the caster callback the map is resampled from the standard one: close, not equal.
  const Scattering::FrameResult resampled = scattering.run(f.attribs(false, true));
  CHECK(resampled.layout == Scattering::Layout::Projective);
  CHECK(resampled.stages.front().name == "resample (projective)");
  const ImageMetrics m = rgbMetrics(f.read(), f.reference());
  report("projective, resampled standard map vs world-space reference", m);
  CHECK(m.relativeRmse < 0.05);
}

TEST_CASE("Scattering: fallback frames are prefiltered on the epipolar layout, close to the reference") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("forest");
  Scattering scattering(smallInfo());
  struct Case {
    const char* name;
    double forward, right, up;
  };
  for (const Case& c :
       {Case{"sun in view", 1.0, 0.25, 0.2}, Case{"sun behind the camera", -1.0, -0.3, 0.4}}) {
    CAPTURE(c.name);
    f.lightToward(c.forward, c.right, c.up);
    for (const bool casters : {false, true}) {
      CAPTURE(casters);
      // With casters only, Scattering renders its own standard shadow map (fitted to the frustum).
      const Scattering::FrameResult r = scattering.run(f.attribs(casters, !casters));
      INFO(r.rectification.message);
      CHECK(r.layout == Scattering::Layout::Epipolar);
      CHECK_FALSE(r.rectification.projective());
      checkStages(r);
      if (std::string(c.name) == "sun in view") {
        CHECK(r.epipoleBlockRadius > 0.0);
        // The block's pixels are tree-marched over the frame's epipolar map (the bounded path).
        CHECK(r.stages[r.stages.size() - 2].name == "min/max trees (epipole block)");
        CHECK(r.stages.back().name == "epipole block (tree march)");
      }
      // The reference marches the standard map the frame used: the engine's, or Scattering's own (fitted to
      // the frustum, so its texels differ from the engine's: rays toward the sun fall into one texel each).
      REQUIRE(r.shadowMap.texture != 0);
      if (casters)
        CHECK(r.shadowMap.texture != f.shadowTexture.get());
      else
        CHECK(r.shadowMap.texture == f.shadowTexture.get());
      const ImageMetrics m = rgbMetrics(f.read(), f.reference(r.shadowMap));
      report(std::string(c.name) + (casters ? ", own shadow map" : ", engine's shadow map") +
                 ": prefiltered (epipolar) vs world-space reference",
             m);
      CHECK(m.nanCount == 0);
      CHECK(m.relativeRmse < 0.05);
    }
  }
}

TEST_CASE("Scattering: bad input is named, GL state is restored") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("boxes");
  Scattering::CreateInfo bad = smallInfo();
  bad.mapSize = 250; // not a multiple of 4 splits
  CHECK(invalidParameter([&] { Scattering s(bad); }) == "Scattering::CreateInfo.mapSize");
  bad = smallInfo();
  bad.rectify.layout = SplitLayout::Layers;
  CHECK(invalidParameter([&] { Scattering s(bad); }) == "Scattering::CreateInfo.rectify.layout");
  bad = smallInfo();
  bad.prefilter.bases = 3;
  CHECK(invalidParameter([&] { Scattering s(bad); }) == "Scattering::CreateInfo.prefilter.bases");
  bad = smallInfo();
  bad.epipoleBlockMaxPixels = -1;
  CHECK(invalidParameter([&] { Scattering s(bad); }) == "Scattering::CreateInfo.epipoleBlockMaxPixels");
  bad = smallInfo();
  bad.epipoleBlockMethod = static_cast<Scattering::EpipoleBlockMethod>(7);
  CHECK(invalidParameter([&] { Scattering s(bad); }) == "Scattering::CreateInfo.epipoleBlockMethod");

  Scattering scattering(smallInfo());
  Scattering::FrameAttribs a = f.attribs(true, false);
  a.camera = nullptr;
  CHECK(invalidParameter([&] { scattering.run(a); }) == "Scattering::FrameAttribs.camera");
  a = f.attribs(false, false);
  CHECK(invalidParameter([&] { scattering.run(a); }) == "Scattering::FrameAttribs.drawCasters/shadowMap");
  const gl::Handle rgba8 = gl::createTexture2D(GL_RGBA8, kWidth, kHeight);
  a = f.attribs(true, false);
  a.output = rgba8.get();
  CHECK(invalidParameter([&] { scattering.run(a); }) == "Scattering::FrameAttribs.output");
  const gl::Handle small = scenes::createDepthTexture(kWidth / 2, kHeight);
  a = f.attribs(true, false);
  a.cameraDepth = small.get();
  CHECK(invalidParameter([&] { scattering.run(a); }) == "Scattering::FrameAttribs.cameraDepth");

  // The raster state the shadow pass changes is the caller's again afterwards.
  const gl::Handle fb = gl::createFramebuffer();
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fb.get());
  glViewport(3, 4, 50, 60);
  glEnable(GL_CULL_FACE);
  glDisable(GL_DEPTH_TEST);
  glDepthFunc(GL_GEQUAL);
  scattering.run(f.attribs(true, false));
  GLint binding = 0, viewport[4] = {}, func = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &binding);
  glGetIntegerv(GL_VIEWPORT, viewport);
  glGetIntegerv(GL_DEPTH_FUNC, &func);
  CHECK(static_cast<GLuint>(binding) == fb.get());
  CHECK(viewport[0] == 3);
  CHECK(viewport[3] == 60);
  CHECK(glIsEnabled(GL_CULL_FACE) == GL_TRUE);
  CHECK(glIsEnabled(GL_DEPTH_TEST) == GL_FALSE);
  CHECK(glIsEnabled(GL_DEPTH_CLAMP) == GL_FALSE);
  CHECK(func == GL_GEQUAL);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
}

TEST_CASE(
    "Scattering: the epipole exactly on a screen corner or edge gives a finite image near the reference") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("forest");
  Scattering scattering(smallInfo());
  struct Case {
    const char* name;
    double ndcX, ndcY;
  };
  for (const Case& c : {Case{"corner (1, 1)", 1.0, 1.0}, Case{"corner (-1, -1)", -1.0, -1.0},
                        Case{"edge (1, 0)", 1.0, 0.0}, Case{"edge (0, -1)", 0.0, -1.0}}) {
    CAPTURE(c.name);
    // The light comes from the direction of the view ray through that NDC point: the epipole is there.
    const glm::dvec3 towardLight = f.scene.camera.rayDirection(c.ndcX, c.ndcY);
    f.setLight(DirectionalLight(-towardLight, f.scene.sun.irradiance()));
    const Scattering::FrameResult r = scattering.run(f.attribs(false, true));
    CHECK(r.layout == Scattering::Layout::Epipolar);
    const Image ours = f.read();
    const ImageMetrics m = rgbMetrics(ours, f.reference(r.shadowMap));
    report(std::string("epipole on the ") + c.name + ": prefiltered (epipolar) vs world-space reference", m);
    CHECK(m.nanCount == 0);
    CHECK(m.infCount == 0);
    CHECK(ours.width() == kWidth);
    // Measured with this 256^2 map: 1.3% (corner (1, 1)), 4.3% (edge (1, 0); 3.1% with a 1024^2 map, where
    // the brute-force march over the same map, the map's own error, is 2.2%: a sun 4 degrees above the
    // horizon casts grazing shadows that the resampled slices blur), 44-55% with the light from below the
    // ground (edge (0, -1), corner (-1, -1): the ground shadows the whole view, the reference is nearly
    // black, peak 0.11; the brute-force march over the same map is within 4-5%, so the prefilter's smooth
    // step leaks where the ground is both the receiver and, at grazing depth differences, the only occluder
    // of the ray; an open item). Reported, not asserted: the 2% goal is asserted on the sun-in-view cases of
    // SunInViewGLTest.
    WARN(m.relativeRmse < 0.02);
  }
}

TEST_CASE("Scattering: memoryBytes() counts the GPU memory it owns") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("forest");
  const Scattering::CreateInfo info = smallInfo();
  Scattering scattering(info);
  const std::size_t map = std::size_t(kMap) * kMap * 4; // D32F rasterized + R32F resampled
  const std::size_t basis = info.prefilter.reconstruction == VisibilityReconstruction::Exact
                                ? exactBasisBytes(kMap, kMap)
                                : filteredBasisBytes(kMap, kMap, info.prefilter.bases, info.prefilter.format);
  const auto tables = [&](int regions) {
    const int Z = info.evaluate.visibilityTableSamples;
    return info.evaluate.scatteringPrefix ? scatteringPrefixBytes(kMap, regions, Z)
                                          : visibilityTableBytes(kMap, regions, Z);
  };
  const std::size_t table = tables(info.rectify.splits * info.prefilter.regionsPerSplit);
  // Buffers: the region weights (16 bytes per row and region), the table's ray coefficients (a vec4 per
  // sample and layer) and a few uniform blocks.
  const std::size_t coefficients =
      std::size_t(info.evaluate.visibilityTableSamples) * layerCount(info.prefilter.bases) * 16;
  const auto within = [&](std::size_t bytes, std::size_t textures) {
    return bytes >= textures && bytes <= textures + std::size_t(kMap) * 16 * 16 + coefficients + 4096;
  };
  // The epipole block's min/max trees (made with the object: MinMaxTreePass::memoryBytes(), rowStride
  // nodes of 8 bytes per row).
  const std::size_t trees = std::size_t(MinMaxTrees::rowStrideFor(kMap)) * kMap * 8;
  scattering.run(f.attribs(true, false)); // projective frame
  CHECK(within(scattering.memoryBytes(), basis + table + 2 * map + trees));
  f.lightToward(1.0, 0.25, 0.2); // a fallback frame with the casters only: its own standard shadow map
  const Scattering::FrameResult r = scattering.run(f.attribs(true, false));
  REQUIRE(r.layout == Scattering::Layout::Epipolar);
  const std::size_t own = std::size_t(info.ownShadowMapSize) * info.ownShadowMapSize * 4;
  const std::size_t epipolarTable = tables(info.epipolarRegions * info.prefilter.regionsPerSplit);
  CHECK(within(scattering.memoryBytes(), basis + epipolarTable + 2 * map + own + trees));
  MESSAGE("Scattering at " << kMap << "^2 after a fallback frame: " << scattering.memoryBytes() << " bytes");
}
