// crep render --method froxel-esm / froxel-prefilter (the tool's registry entries of the froxel fog): a
// sunlit scene gives finite, non-negative, non-zero in-scattering and a transmittance in [0, 1]; a frame
// without a sun (colonnade-night) runs with a warning on stderr and adds nothing.
#include "support/gl_fixture.h"
#include "support/image_check.h"
#include "support/tool_runner.h"

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

} // namespace

TEST_CASE("crep render --method froxel-esm and froxel-prefilter: sunlit fog, and no sun adds nothing") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir;
  for (const std::string method : {"froxel-esm", "froxel-prefilter"}) {
    CAPTURE(method);
    {
      const std::string prefix = (dir.path() / (method + "-colonnade")).string();
      const crep::test::ToolResult r =
          runCrep("render --scene colonnade --size 96x54 --map-size 128 --method " + method + " --out '" +
                  prefix + "'");
      INFO(r.output);
      REQUIRE(r.status == 0);
      CHECK(r.output.find("160x90x64") != std::string::npos); // the grid in the method's detail
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
      const std::string prefix = (dir.path() / (method + "-night")).string();
      const crep::test::ToolResult r =
          runCrep("render --scene colonnade-night --size 64x36 --map-size 128 --method " + method +
                  " --out '" + prefix + "'");
      INFO(r.output);
      REQUIRE(r.status == 0);
      CHECK(r.output.find("no directional light") != std::string::npos);
      const crep::Image s = scatteringLayer(prefix + ".exr");
      for (int y = 0; y < s.height(); ++y)
        for (int x = 0; x < s.width(); ++x) {
          for (int c = 0; c < 3; ++c)
            REQUIRE(s.at(x, y, c) == 0.0f);
          CHECK(s.at(x, y, 3) > 0.0f); // the medium's transmittance
          CHECK(s.at(x, y, 3) <= 1.0f);
        }
    }
  }
}
