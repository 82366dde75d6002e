// crep render --method radial / froxel-esm / froxel-prefilter (the tool's registry entries of postfx/): a
// sunlit scene gives finite, non-negative, non-zero in-scattering and a transmittance in [0, 1] with the
// method's stage in the report; a frame without a sun (colonnade-night) runs with a warning on stderr and
// adds no in-scattering (the medium's transmittance stays).
#include "common/gl_fixture.h"
#include "common/image_check.h"
#include "common/tool_runner.h"

#include <crep/support/exr.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

using crep::test::runCrep;

namespace {

crep::Image scatteringLayer(const std::string& path) {
  crep::ExrReadOptions o;
  o.layer = "scattering";
  return crep::readExr(path, o);
}

/// `crep render --method M` on a sunlit scene: finite non-negative in-scattering with a positive peak,
/// transmittance in [0, 1], and `expected` (the method's stage or detail) in the report.
void checkSunlit(const crep::test::TempDir& dir, const std::string& method, const std::string& scene,
                 const std::string& expected) {
  CAPTURE(method);
  const std::string prefix = (dir.path() / (method + "-" + scene)).string();
  const crep::test::ToolResult r =
      runCrep("render --scene " + scene + " --size 96x54 --map-size 128 --method " + method + " --out '" +
              prefix + "'");
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find(expected) != std::string::npos);
  const crep::Image s = scatteringLayer(prefix + ".exr");
  REQUIRE(s.width() == 96);
  double peak = 0.0;
  for (int y = 0; y < s.height(); ++y)
    for (int x = 0; x < s.width(); ++x) {
      for (int c = 0; c < 3; ++c) {
        REQUIRE(std::isfinite(s.at(x, y, c)));
        CHECK(s.at(x, y, c) >= 0.0f);
        peak = std::max(peak, double(s.at(x, y, c)));
      }
      CHECK(s.at(x, y, 3) >= 0.0f);
      CHECK(s.at(x, y, 3) <= 1.0f);
    }
  CHECK(peak > 0.0);
}

/// The same on colonnade-night (no sun): a warning, RGB exactly 0, the transmittance in (0, 1].
void checkNoSun(const crep::test::TempDir& dir, const std::string& method) {
  CAPTURE(method);
  const std::string prefix = (dir.path() / (method + "-night")).string();
  const crep::test::ToolResult r =
      runCrep("render --scene colonnade-night --size 64x36 --map-size 128 --method " + method + " --out '" +
              prefix + "'");
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("no directional light") != std::string::npos);
  const crep::Image s = scatteringLayer(prefix + ".exr");
  for (int y = 0; y < s.height(); ++y)
    for (int x = 0; x < s.width(); ++x) {
      for (int c = 0; c < 3; ++c)
        REQUIRE(s.at(x, y, c) == 0.0f);
      CHECK(s.at(x, y, 3) > 0.0f);
      CHECK(s.at(x, y, 3) <= 1.0f);
    }
}

} // namespace

TEST_CASE("crep render --method radial: the sun in view adds in-scattering and no sun adds nothing") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir;
  checkSunlit(dir, "radial", "sunset", "occlusion fraction"); // the mode in the method's detail
  checkNoSun(dir, "radial");
}

TEST_CASE("crep render --method froxel-esm and froxel-prefilter: sunlit fog, and no sun adds nothing") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir;
  for (const std::string method : {"froxel-esm", "froxel-prefilter"}) {
    checkSunlit(dir, method, "colonnade", "160x90x64"); // the grid in the method's detail
    checkNoSun(dir, method);
  }
}
