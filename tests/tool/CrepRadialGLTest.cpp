// crep render --method radial (Mitchell 2007's radial blur, the tool's registry entry): the sun in view
// (sunset) gives finite, non-negative, non-zero in-scattering with the transmittance of the other methods;
// a frame without a sun (colonnade-night) runs with a warning and adds nothing.
#include "support/gl_fixture.h"
#include "support/image_check.h"
#include "support/tool_runner.h"

#include <crep/support/exr.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

using RunResult = crep::test::ToolResult;
using crep::test::runCrep;

namespace {

crep::Image scatteringLayer(const std::string& path) {
  crep::ExrReadOptions o;
  o.layer = "scattering";
  return crep::readExr(path, o);
}

} // namespace

TEST_CASE("crep render --method radial: the sun in view adds in-scattering and no sun adds nothing") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir;
  {
    const std::string prefix = (dir.path() / "sunset").string();
    const RunResult r =
        runCrep("render --scene sunset --size 96x54 --map-size 128 --method radial --out '" + prefix + "'");
    INFO(r.output);
    REQUIRE(r.status == 0);
    CHECK(r.output.find("radial blur") != std::string::npos); // its stage timing
    CHECK(r.output.find("occlusion fraction") != std::string::npos);
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
  {
    const std::string prefix = (dir.path() / "night").string();
    const RunResult r = runCrep(
        "render --scene colonnade-night --size 64x36 --map-size 128 --method radial --out '" + prefix + "'");
    INFO(r.output);
    REQUIRE(r.status == 0);
    CHECK(r.output.find("no directional light") != std::string::npos);
    const crep::Image s = scatteringLayer(prefix + ".exr");
    for (int y = 0; y < s.height(); ++y)
      for (int x = 0; x < s.width(); ++x)
        for (int c = 0; c < 3; ++c)
          REQUIRE(s.at(x, y, c) == 0.0f);
  }
}
