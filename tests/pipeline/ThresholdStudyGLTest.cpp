// The projective path next to its fallback thresholds (where the prefiltered frame switches layout): frames
// whose angular span is just below / above rectify()'s 150 degrees and whose epipole angle is just above /
// below its 5 degrees, found among random sun directions above the horizon for the forest's camera (60
// degree, 16:9). Each runs through crep::Scattering with the default thresholds (projective below them, the
// epipolar layout above) and with the thresholds relaxed (projective wherever the matrix exists), against the
// world-space reference; the brute-force march over the defaults' map gives the map's own error. The figures
// decide where the thresholds stay (README "Sun in view"): beyond them the epipolar layout is the more
// accurate one, so no split placement should keep those frames projective.
#include "common/gl_fixture.h"
#include "pipeline/scattering_frame.h"

#include <crep/pipeline/scattering.h>
#include <crep/rectify/rectify.h>

#include <doctest/doctest.h>

#include <random>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

TEST_CASE("threshold study: the projective path next to the span and epipole-angle thresholds") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("forest");
  Scattering::CreateInfo defaults = smallInfo();
  defaults.mapSize = 1024;
  Scattering::CreateInfo relaxed = defaults;
  relaxed.rectify.maxSpanDegrees = 180.0;
  relaxed.rectify.minEpipoleAngleDegrees = 0.0;
  Scattering withDefaults(defaults), projectiveOnly(relaxed);
  struct Bin {
    const char* name;
    bool (*contains)(const Rectification&);
    bool fallback;
    int found = 0;
  };
  std::vector<Bin> bins = {
      {"span 140-150 (projective)", [](const Rectification& r) { return r.projective() && r.span >= 140.0; },
       false},
      {"span 150-165 (fallback: non-linearity)",
       [](const Rectification& r) { return r.reason == FallbackReason::NonLinearity && r.span < 165.0; },
       true},
      {"epipole angle 5-9 (projective)",
       [](const Rectification& r) { return r.projective() && r.epipoleAngle < 9.0; }, false},
      {"epipole angle 2.5-5 (fallback: too close)",
       [](const Rectification& r) {
         return r.reason == FallbackReason::EpipoleTooClose && r.epipoleAngle >= 2.5;
       },
       true},
  };
  const int perBin = 3;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  const glm::dvec3 irradiance = f.scene.sun.irradiance();
  for (int i = 0; i < 20000; ++i) {
    bool done = true;
    for (const Bin& b : bins)
      done = done && b.found >= perBin;
    if (done) break;
    glm::dvec3 d(normal(rng), normal(rng), normal(rng));
    if (!(glm::length(d) > 1e-9) || d.y > -0.05 * glm::length(d)) continue; // the sun above the horizon
    const DirectionalLight light(d, irradiance);
    const Rectification r = rectify(f.scene.camera, light, defaults.rectify);
    for (Bin& b : bins) {
      if (b.found >= perBin || !b.contains(r)) continue;
      ++b.found;
      CAPTURE(b.name);
      f.setLight(light);
      const Scattering::FrameResult a = withDefaults.run(f.attribs(false, true));
      const Image ours = f.read(), ref = f.reference(a.shadowMap.texture ? a.shadowMap : f.shadow);
      const ImageMetrics m = rgbMetrics(ours, ref);
      const double floor = rgbMetrics(marchSameMap(f, a), ref).relativeRmse;
      const Scattering::FrameResult p = projectiveOnly.run(f.attribs(false, true));
      REQUIRE(p.layout == Scattering::Layout::Projective);
      const ImageMetrics mp = rgbMetrics(f.read(), f.reference()); // projective: the engine's map throughout
      MESSAGE(std::string(b.name) << ": span " << r.span << ", epipole angle " << r.epipoleAngle
                                  << "; defaults (" << std::string(layoutToken(a.layout)) << ") "
                                  << m.relativeRmse << " (the map's own error " << floor
                                  << "), projective with the thresholds relaxed " << mp.relativeRmse);
      CHECK(m.nanCount == 0);
      if (b.fallback) {
        // Beyond the thresholds the fallback is the more accurate layout, and within the 2% goal.
        CHECK(a.layout == Scattering::Layout::Epipolar);
        CHECK(m.relativeRmse < 0.02);
        CHECK(m.relativeRmse < mp.relativeRmse);
      } else {
        // Inside them: no accuracy goal; measured 0.9-3.0% (the map itself 0.5-1.9%). 4 splits without
        // regions per split gave up to 12% (README "Sun in view").
        CHECK(a.layout == Scattering::Layout::Projective);
        CHECK(m.relativeRmse < 0.035);
      }
      break;
    }
  }
  for (const Bin& b : bins) {
    CAPTURE(b.name);
    CHECK(b.found == perBin);
  }
}
