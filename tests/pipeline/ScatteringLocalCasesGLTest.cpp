// crep::Scattering with a local light in the placements that break naive implementations: the camera inside
// and outside a spot's cone, the light inside the view frustum, the light behind the camera, and the camera
// at the light's position (spot and point light). Each result must be finite and non-negative, and where the
// light reaches the view it is compared with the world-space reference of the same light (WorldMarchPass
// against the light's own perspective shadow maps, 1024^2, 256 steps): relative RMSE within the built-in
// scenes' 2% goal. A light whose cones miss the camera frustum must cost nothing and add exactly zero.
// Colonnade at night (zero sun).
#include "common/gl_fixture.h"
#include "common/prefilter_gpu.h"
#include "pipeline/scattering_frame.h"

#include <crep/core/error.h>
#include <crep/scatter/ray_scattering.h>

#include <cmath>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

/// World-space reference of the lights `faces` (a spot: one), each with its own perspective shadow map.
Image reference(ScatteringFixture& f, const std::vector<std::pair<LocalLight, glm::dmat4>>& faces) {
  Image sum(kWidth, kHeight, 4);
  for (const auto& [light, clipFromWorld] : faces)
    addInto(sum, localReference(f, light, clipFromWorld));
  return sum;
}

/// Every RGB value finite and >= 0; returns the largest.
float checkFiniteNonNegative(const Image& image) {
  int bad = 0;
  float peak = 0.0f;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < 3; ++c) {
        const float v = image.at(x, y, c);
        if (!(std::isfinite(v) && v >= 0.0f))
          ++bad;
        else
          peak = std::max(peak, v);
      }
  CHECK(bad == 0);
  return peak;
}

Scattering::CreateInfo caseInfo() {
  Scattering::CreateInfo info = smallInfo();
  info.mapSize = 512;
  return info;
}

} // namespace

TEST_CASE("Scattering, spot light placements: camera in and out of the cone, light in view, behind, at the "
          "camera") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  f.setLight(DirectionalLight(f.scene.sun.direction(), glm::dvec3(0.0))); // night: the spot alone
  const Camera c = f.scene.camera;
  struct Case {
    const char* name;
    glm::dvec3 position, direction;
    bool lit; ///< the cone reaches the camera frustum
  };
  const Case cases[] = {
      {"camera inside the cone (light behind the camera, pointing forward)",
       c.position() - 3.0 * c.forward() + 0.5 * c.up(), c.forward(), true},
      {"camera outside the cone (light off screen above and to the side, pointing ahead of the camera)",
       c.position() - 2.0 * c.forward() - 8.0 * c.right() + 6.0 * c.up(),
       17.0 * c.forward() + 11.0 * c.right() - 6.0 * c.up(), true},
      {"light inside the view frustum", c.position() + 9.0 * c.forward() + 1.0 * c.up(),
       c.forward() - 0.3 * c.up(), true},
      {"light behind the camera pointing away", c.position() - 3.0 * c.forward(), -c.forward(), false},
      {"camera at the light's position", c.position(), c.forward() - 0.1 * c.up(), true},
  };
  Scattering scattering(caseInfo());
  for (const Case& k : cases) {
    CAPTURE(std::string(k.name));
    const SpotLight spot({.position = k.position,
                          .direction = k.direction,
                          .innerConeAngle = 0.3,
                          .outerConeAngle = 0.5,
                          .color = {1.0, 0.9, 0.7},
                          .intensity = 100.0,
                          .range = 80.0});
    Scattering::FrameAttribs a = f.attribs(true, false);
    a.spotLights = std::span<const SpotLight>(&spot, 1);
    const Scattering::FrameResult r = scattering.run(a);
    REQUIRE(r.localLights.size() == 1);
    MESSAGE(std::string(std::string(k.name) + ": " + statusToken(r.localLights[0].status) + ", " +
                        r.localLights[0].message));
    const Image ours = f.read();
    const float peak = checkFiniteNonNegative(ours);
    const Image ref = reference(f, {{LocalLight::spot(spot), spot.lightClipFromWorld()}});
    const float refPeak = checkFiniteNonNegative(ref);
    if (!k.lit) {
      // Outside the frustum: nothing done, nothing added (the reference agrees that nothing is lit).
      CHECK(r.localLights[0].status == RectifyStatus::Empty);
      CHECK(peak == 0.0f);
      CHECK(refPeak == 0.0f);
      continue;
    }
    CHECK(r.localLights[0].status != RectifyStatus::Empty);
    const ImageMetrics m = rgbMetrics(ours, ref);
    report(std::string(k.name) + ": Scattering vs world-space reference", m);
    CHECK(m.peak > 0.0);
    CHECK(m.relativeRmse < 0.02);
  }
}

TEST_CASE("Scattering, point light at the camera's position: finite and equal to the reference") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  f.setLight(DirectionalLight(f.scene.sun.direction(), glm::dvec3(0.0)));
  const Camera c = f.scene.camera;
  const PointLight point(
      {.position = c.position(), .color = {1.0, 0.8, 0.6}, .intensity = 40.0, .range = 80.0});
  Scattering scattering(caseInfo());
  Scattering::FrameAttribs a = f.attribs(true, false);
  a.pointLights = std::span<const PointLight>(&point, 1);
  const Scattering::FrameResult r = scattering.run(a);
  REQUIRE(r.localLights.size() == 6);
  std::vector<std::pair<LocalLight, glm::dmat4>> faces;
  for (const Scattering::LightResult& face : r.localLights) {
    MESSAGE(std::string(std::string("face ") + std::to_string(face.face) + ": " + statusToken(face.status) +
                        ", " + face.message));
    // Every view ray starts at the light: no face's rectification is projective (the epipole is
    // everywhere), each is marched in world space or empty.
    CHECK(face.status != RectifyStatus::Projective);
    faces.push_back({LocalLight::pointFace(point, face.face), point.faceClipFromWorld(face.face)});
  }
  const Image ours = f.read();
  checkFiniteNonNegative(ours);
  const ImageMetrics m = rgbMetrics(ours, reference(f, faces));
  report("point light at the camera: Scattering vs world-space reference", m);
  CHECK(m.peak > 0.0);
  CHECK(m.relativeRmse < 0.02);
}

TEST_CASE("Scattering, point light in view: its faces on their epipolar layouts, near the reference") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  f.setLight(DirectionalLight(f.scene.sun.direction(), glm::dvec3(0.0)));
  const Camera c = f.scene.camera;
  const PointLight point({.position = c.position() + 8.0 * c.forward() + 1.5 * c.up() + 0.5 * c.right(),
                          .color = {1.0, 0.8, 0.6},
                          .intensity = 40.0,
                          .range = 80.0});
  Scattering scattering(caseInfo());
  Scattering::FrameAttribs a = f.attribs(true, false);
  a.pointLights = std::span<const PointLight>(&point, 1);
  const Scattering::FrameResult r = scattering.run(a);
  REQUIRE(r.localLights.size() == 6);
  std::vector<std::pair<LocalLight, glm::dmat4>> faces;
  int epipolar = 0;
  for (const Scattering::LightResult& face : r.localLights) {
    MESSAGE(std::string(std::string("face ") + std::to_string(face.face) + ": " + statusToken(face.status) +
                        (face.epipolar ? " (epipolar layout)" : "") + ", " + face.message));
    CHECK(face.epipolar == (face.status == RectifyStatus::Fallback));
    epipolar += face.epipolar ? 1 : 0;
    faces.push_back({LocalLight::pointFace(point, face.face), point.faceClipFromWorld(face.face)});
  }
  CHECK(epipolar >= 4); // the light is on screen: every face it lights next to itself falls back
  const Image ours = f.read();
  checkFiniteNonNegative(ours);
  const ImageMetrics m = rgbMetrics(ours, reference(f, faces));
  report("point light in view: Scattering vs world-space reference", m);
  CHECK(m.peak > 0.0);
  CHECK(m.relativeRmse < 0.02); // the local lights' accuracy goal: 2% of the world-space reference
}

TEST_CASE("Scattering::CreateInfo.spotLightBases and localLightBases: 0 is prefilter.bases, -1 follows "
          "localLightBases, spotLightTableSamples 0 follows localLightTableSamples, bad values named") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  f.setLight(DirectionalLight(f.scene.sun.direction(), glm::dvec3(0.0)));
  const Camera c = f.scene.camera;
  const SpotLight spot({.position = c.position() - 2.0 * c.forward() - 8.0 * c.right() + 6.0 * c.up(),
                        .direction = 17.0 * c.forward() + 11.0 * c.right() - 6.0 * c.up(),
                        .innerConeAngle = 0.3,
                        .outerConeAngle = 0.5,
                        .intensity = 100.0,
                        .range = 80.0});
  const auto image = [&](int spotBases, int localBases = 64, int spotTable = 32) {
    Scattering::CreateInfo info = caseInfo();
    info.prefilter.reconstruction = VisibilityReconstruction::Fourier; // M matters to the series only
    info.spotLightBases = spotBases;
    info.localLightBases = localBases;
    info.spotLightTableSamples = spotTable;
    Scattering scattering(info);
    Scattering::FrameAttribs a = f.attribs(true, false);
    a.spotLights = std::span<const SpotLight>(&spot, 1);
    const Scattering::FrameResult r = scattering.run(a);
    REQUIRE(r.localLights.size() == 1);
    CHECK(r.localLights[0].status == RectifyStatus::Projective);
    return std::make_pair(f.read(), scattering.memoryBytes());
  };
  const int M = caseInfo().prefilter.bases;
  const auto [same, sameBytes] = image(0);
  const auto [explicitSame, explicitBytes] = image(M);
  const auto [own, ownBytes] = image(2 * M);
  // -1: the spot takes localLightBases (the rule before spotLightBases).
  const auto [followed, followedBytes] = image(-1, 2 * M);
  CHECK(rgbMetrics(followed, own).maxAbsError == 0.0);
  CHECK(followedBytes == ownBytes);
  // 0 and prefilter.bases share the directional light's passes: the same image, the same memory.
  CHECK(rgbMetrics(same, explicitSame).maxAbsError == 0.0);
  CHECK(sameBytes == explicitBytes);
  // Another M runs its own passes (more memory) on the same map: a different image of the same light.
  CHECK(ownBytes > sameBytes);
  const ImageMetrics m = rgbMetrics(own, same);
  report("spotLightBases 2M vs M", m);
  CHECK(m.maxAbsError > 0.0);
  CHECK(m.relativeRmse < 0.02);
  // spotLightTableSamples: 0 takes localLightTableSamples (the same table as naming it), another Z its own.
  const int Z = caseInfo().localLightTableSamples;
  const auto [followTable, followTableBytes] = image(0, 64, 0);
  const auto [explicitTable, explicitTableBytes] = image(0, 64, Z);
  CHECK(rgbMetrics(followTable, explicitTable).maxAbsError == 0.0);
  CHECK(followTableBytes == explicitTableBytes);
  const ImageMetrics mz = rgbMetrics(same, explicitTable);
  report("spotLightTableSamples 32 vs localLightTableSamples", mz);
  CHECK(mz.maxAbsError > 0.0);
  CHECK(mz.relativeRmse < 0.02);
  for (const int bad : {-1, 1, 5000}) {
    Scattering::CreateInfo info = caseInfo();
    info.localLightTableSamples = bad;
    CHECK_THROWS_WITH_AS(Scattering{info}, doctest::Contains("Scattering::CreateInfo.localLightTableSamples"),
                         crep::InvalidArgument);
    info = caseInfo();
    info.spotLightTableSamples = bad;
    CHECK_THROWS_WITH_AS(Scattering{info}, doctest::Contains("Scattering::CreateInfo.spotLightTableSamples"),
                         crep::InvalidArgument);
  }
  for (const double bad : {-0.1, 0.6, std::nan("")}) {
    Scattering::CreateInfo info = caseInfo();
    info.localLightBlockRadius = bad;
    CHECK_THROWS_WITH_AS(Scattering{info}, doctest::Contains("Scattering::CreateInfo.localLightBlockRadius"),
                         crep::InvalidArgument);
  }
  for (const double bad : {-1.0, std::nan(""), HUGE_VAL}) {
    Scattering::CreateInfo info = caseInfo();
    info.localLightDepthWarp = bad;
    CHECK_THROWS_WITH_AS(Scattering{info}, doctest::Contains("Scattering::CreateInfo.localLightDepthWarp"),
                         crep::InvalidArgument);
  }
  for (const int bad : {-2, 3, 130}) {
    Scattering::CreateInfo info = caseInfo();
    info.localLightBases = bad;
    CHECK_THROWS_WITH_AS(Scattering{info}, doctest::Contains("Scattering::CreateInfo.localLightBases"),
                         crep::InvalidArgument);
    info = caseInfo();
    info.spotLightBases = bad;
    CHECK_THROWS_WITH_AS(Scattering{info}, doctest::Contains("Scattering::CreateInfo.spotLightBases"),
                         crep::InvalidArgument);
  }
}
