// crep::Scattering with local lights (FrameAttribs::spotLights / pointLights; Klehm et al. 2014, Sec. 3.2
// "Local Lights"): on a built-in scene, a spot light off screen (projective: prefiltered), a spot light in
// view (not projective: prefiltered on its epipolar layout) and a point light (six faces), each against the
// world-space reference march of the same light (WorldMarchPass with the light's own perspective shadow maps,
// 1024^2, 256 steps). The directional light has zero irradiance, so the output is the local lights' alone.
#include "common/gl_fixture.h"
#include "common/prefilter_gpu.h"
#include "pipeline/scattering_frame.h"

#include <crep/core/error.h>

#include <crep/scatter/ray_scattering.h>

using namespace crep;
using namespace crep::test;

namespace {

Scattering::CreateInfo localInfo() {
  Scattering::CreateInfo info = smallInfo();
  info.mapSize = 512;
  return info;
}

} // namespace

TEST_CASE(
    "Scattering with local lights: spot lights off screen and in view against the world-space reference") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  f.setLight(DirectionalLight(f.scene.sun.direction(), glm::dvec3(0.0))); // night: the local lights alone
  const Camera& c = f.scene.camera;
  struct Case {
    const char* name;
    glm::dvec3 position;
    RectifyStatus expected;
  };
  Scattering scattering(localInfo());
  for (const Case& k : {Case{"off screen, behind and above the camera",
                             c.position() - 4.0 * c.forward() + 7.0 * c.up(), RectifyStatus::Projective},
                        Case{"in view", c.position() + 9.0 * c.forward() + 1.5 * c.up() - 1.0 * c.right(),
                             RectifyStatus::Fallback}}) {
    CAPTURE(std::string(k.name));
    const SpotLight spot = spotToward(c, k.position);
    Scattering::FrameAttribs a = f.attribs(true, false);
    a.spotLights = std::span<const SpotLight>(&spot, 1);
    const Scattering::FrameResult r = scattering.run(a);
    REQUIRE(r.localLights.size() == 1);
    MESSAGE(std::string(k.name) << ": " << r.localLights[0].message);
    CHECK(r.localLights[0].status == k.expected);
    CHECK(r.localLights[0].epipolar == (k.expected == RectifyStatus::Fallback));
    CHECK(r.localLights[0].wallMilliseconds > 0.0);
    const Image ours = f.read();
    const Image ref = localReference(f, LocalLight::spot(spot), spot.lightClipFromWorld());
    const ImageMetrics m = rgbMetrics(ours, ref);
    report(std::string("spot light ") + k.name + ": Scattering vs world-space reference", m);
    CHECK(m.nanCount == 0);
    CHECK(m.peak > 0.0);
    // The local lights' accuracy goal for both: within 2% of the world-space reference. Measured 0.52% off
    // screen, 0.76% in view (on its epipolar layout, depth warp 0.03, the epipole block of 1% of the
    // diagonal; 1.35% without the block, 3.2% with the sun's depth warp 0.1).
    bool block = false;
    for (const Scattering::Stage& stage : r.stages)
      block = block || stage.name == "local light: epipole block (world march)";
    CHECK(block == (k.expected == RectifyStatus::Fallback));
    CHECK(m.relativeRmse < 0.02);
    if (k.expected != RectifyStatus::Fallback) continue;
    // The world-space march kept as an option (CreateInfo::localLightFallback): the reference's method.
    Scattering::CreateInfo marchInfo = localInfo();
    marchInfo.localLightFallback = Scattering::LocalLightFallback::WorldMarch;
    Scattering march(marchInfo);
    const Scattering::FrameResult rm = march.run(a);
    REQUIRE(rm.localLights.size() == 1);
    CHECK(rm.localLights[0].status == RectifyStatus::Fallback);
    CHECK(!rm.localLights[0].epipolar);
    bool marched = false;
    for (const Scattering::Stage& stage : rm.stages)
      marched = marched || stage.name == "local light: world-space march";
    CHECK(marched);
    const ImageMetrics mm = rgbMetrics(f.read(), ref);
    report("spot light in view, localLightFallback = WorldMarch: Scattering vs world-space reference", mm);
    CHECK(mm.relativeRmse < 0.01);
  }
}

TEST_CASE("Scattering with local lights: a point light's six faces and a spot added to the sun") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  const Camera& c = f.scene.camera;
  const PointLight point({.position = c.position() - 8.0 * c.right() + 4.0 * c.up() - 6.0 * c.forward(),
                          .color = {1.0, 0.8, 0.6},
                          .intensity = 60.0,
                          .range = 80.0});
  Scattering scattering(localInfo());
  // The sun alone first (the reference of the sum).
  const Scattering::FrameResult sunOnly = scattering.run(f.attribs(true, false));
  CHECK(sunOnly.localLights.empty());
  const Image sun = f.read();
  Scattering::FrameAttribs a = f.attribs(true, false);
  a.pointLights = std::span<const PointLight>(&point, 1);
  const Scattering::FrameResult r = scattering.run(a);
  REQUIRE(r.localLights.size() == 6);
  Image expected(kWidth, kHeight, 4); // the point light's faces, each's world-space reference
  int projective = 0;
  for (const Scattering::LightResult& face : r.localLights) {
    MESSAGE("face " << face.face << ": " << face.message);
    CHECK(face.kind == Scattering::LightResult::Kind::PointFace);
    projective += face.status == RectifyStatus::Projective ? 1 : 0;
    if (face.status != RectifyStatus::Empty)
      addInto(expected,
              localReference(f, LocalLight::pointFace(point, face.face), point.faceClipFromWorld(face.face)));
  }
  CHECK(projective >= 1);
  // The sun's part is the same pass on the same frame, so (sun + point) - sun is the point light's part.
  Image local = f.read();
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      for (int ch = 0; ch < 3; ++ch)
        local.at(x, y, ch) -= sun.at(x, y, ch);
  const ImageMetrics m = rgbMetrics(local, expected);
  report("point light (six faces) added to the sun: Scattering - sun vs world-space references", m);
  CHECK(m.peak > 0.0);
  CHECK(m.nanCount == 0);
  // The built-in scenes' goal for local lights: within 2% of the world-space reference. Measured 1.17% with
  // Scattering::CreateInfo::localLightBases = 64 and localLightTableSamples = 64 (the defaults; 1.08% with
  // 128 samples); 2.67% with M = 32, where the Fourier depth resolution smoothed the pillars' shadow steps of
  // the faces seen from close by.
  CHECK(m.relativeRmse < 0.02);
  // Local lights need drawCasters.
  Scattering::FrameAttribs noCasters = f.attribs(false, true);
  noCasters.pointLights = std::span<const PointLight>(&point, 1);
  CHECK_THROWS_WITH_AS(scattering.run(noCasters), doctest::Contains("Scattering::FrameAttribs.drawCasters"),
                       crep::InvalidArgument);
}
