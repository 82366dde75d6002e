// The front door on the analytic cases (common/analytic_frames.h: the ground and a plane occluder in the
// maps, the sun to the side, in view, oblique and behind, a spot near the view and one to the side) against
// the closed form of each ray's lit part, with the default exact reconstruction and with the Fourier series;
// and the flicker under a slow strafe and a slow rotation against the world-space reference march's. 160 x 90
// pixels, the default maps (1024^2 rectified, 2048^2 own standard map; the error budget's figures at 320 x
// 180: docs/MEASUREMENTS.md, "Error budget").
#include "common/analytic_frames.h"
#include "common/gl_fixture.h"

#include <crep/pipeline/scattering.h>

#include <doctest/doctest.h>

#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kW = 160, kH = 90;
const glm::dvec3 kPosition{0.0, 2.0, 0.0};

Scattering::CreateInfo caseInfo(VisibilityReconstruction reconstruction) {
  Scattering::CreateInfo info;
  info.width = kW;
  info.height = kH;
  info.stageTimings = false;
  info.prefilter.reconstruction = reconstruction;
  return info;
}

} // namespace

TEST_CASE(
    "analytic cases: the exact reconstruction is within 0.5% of the closed form in the sun's cases, better "
    "than the series in all") {
  CREP_REQUIRE_GL();
  Scattering exact(caseInfo(VisibilityReconstruction::Exact));
  Scattering fourier(caseInfo(VisibilityReconstruction::Fourier));
  for (const Case& c : allCases()) {
    CAPTURE(c.name);
    const Camera camera = caseCamera(kPosition, 0.0, double(kW) / kH);
    CaseFrame frame(c, camera, kW, kH);
    const Image truth = truthOf(c, camera, frame.depth(), frame.medium());
    const double e = rgbRelativeRmse(frame.run(exact, Input::Rasterized), truth);
    const double f = rgbRelativeRmse(frame.run(fourier, Input::Rasterized), truth);
    MESSAGE(c.name << ": relative RMSE exact " << e << ", Fourier M = 32 " << f);
    // Measured: the sun's cases 0.15-0.35% (the series 1.0-2.1%); the spots 0.76% (near the view, on its
    // epipolar layout) and 0.52% (to the side), bounded by other sources than the visibility (the series with
    // M = 128 gives the same: docs/MEASUREMENTS.md, "Error budget"), so the 0.5% goal is missed there.
    if (c.sun) CHECK(e <= 0.005);
    CHECK(e < f);
  }
}

TEST_CASE("analytic cases: the flicker under a strafe and a rotation against the reference march's") {
  CREP_REQUIRE_GL();
  Scattering exact(caseInfo(VisibilityReconstruction::Exact));
  const std::vector<CameraMotion> motions = slowMotions();
  for (const Case& c : allCases()) {
    if (c.name != "sun to the side" && c.name != "sun in view") continue;
    for (const CameraMotion& m : motions) {
      CAPTURE(c.name);
      CAPTURE(std::string(m.name));
      FlickerTrack reference, ours;
      for (int i = 0; i < 5; ++i) {
        const Camera camera = caseCamera(kPosition + double(i) * m.step, double(i) * m.yaw, double(kW) / kH);
        CaseFrame frame(c, camera, kW, kH);
        const Image truth = truthOf(c, camera, frame.depth(), frame.medium());
        ours.add(frame.run(exact, Input::Rasterized), truth);
        reference.add(frame.worldMarch(), truth);
      }
      const double ratio = ours.flicker() / reference.flicker();
      MESSAGE(c.name << ", " << std::string(m.name) << ": flicker " << ours.flicker() << ", reference march "
                     << reference.flicker() << ", ratio " << ratio);
      if (c.name == "sun in view" && m.yaw > 0.0) {
        // The goal (1.1x) is missed here: the epipolar layout's slices turn with the view (measured 1.37x);
        // bounded so that it does not get worse.
        CHECK(ratio <= 2.0);
      } else {
        CHECK(ratio <=
              1.1); // measured 0.16x and 0.42x to the side, 0.70x for the strafe with the sun in view
      }
    }
  }
}
