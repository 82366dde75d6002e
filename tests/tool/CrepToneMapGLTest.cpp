// `crep render --tonemap`: the PNG through ToneMapPass with a chosen operator, `--tonemap all` as a sheet
// of every operator, usage errors for unknown names (listing them) and for knobs without --tonemap.
#include "common/gl_fixture.h"
#include "common/image_check.h"
#include "common/png_read.h"
#include "common/tool_runner.h"

#include <crep/postfx/tone_mapping.h>

#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace {

using crep::test::Png;
using crep::test::readPng;
using crep::test::runCrep;

/// Mean absolute difference of two same-size PNGs in 8-bit codes.
double meanDifference(const Png& a, const Png& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    sum += std::abs(int(a.pixels[i]) - int(b.pixels[i]));
  return sum / double(a.pixels.size());
}

const std::string kCommon = "render --size 160x90 --map-size 128 --steps 32 ";

} // namespace

TEST_CASE("crep render --tonemap: two operators write different PNGs of the frame's size") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir;
  const std::string a = (dir.path() / "reinhard").string(), b = (dir.path() / "uncharted").string();
  const std::string plain = (dir.path() / "plain").string();
  const auto ra = runCrep(kCommon + "--tonemap reinhard --auto-exposure --out '" + a + "'");
  const auto rb = runCrep(kCommon + "--tonemap uncharted2 --auto-exposure --out '" + b + "'");
  const auto rp = runCrep(kCommon + "--out '" + plain + "'");
  INFO(ra.output);
  INFO(rb.output);
  REQUIRE(ra.status == 0);
  REQUIRE(rb.status == 0);
  REQUIRE(rp.status == 0);
  CHECK(ra.output.find("tone mapping: reinhard, auto exposure") != std::string::npos);
  CHECK(rb.output.find("tone mapping: uncharted2, auto exposure") != std::string::npos);
  CHECK(rp.output.find("tone mapping") == std::string::npos); // absent: the default PNG
  const Png pa = readPng(a + ".png"), pb = readPng(b + ".png"), pp = readPng(plain + ".png");
  REQUIRE(pa.width == 160);
  REQUIRE(pa.height == 90);
  REQUIRE(pb.width == 160);
  REQUIRE(pp.width == 160);
  // Different curves on the same frame: Reinhard's L / (1 + L) vs Hable's filmic curve differ by far more
  // than a code on average (a mean difference of 0 would mean the option is ignored).
  const double ab = meanDifference(pa, pb), ap = meanDifference(pa, pp);
  MESSAGE((std::string("mean |reinhard - uncharted2| = ") + std::to_string(ab) +
           " codes, |reinhard - default| = " + std::to_string(ap)));
  CHECK(ab > 1.0);
  CHECK(ap > 1.0);
  // Not black: the auto exposure brings the frame's log-average to middle grey.
  double sum = 0.0;
  for (unsigned char v : pa.pixels)
    sum += v;
  CHECK(sum / double(pa.pixels.size()) > 20.0);
}

TEST_CASE("crep render --tonemap all: a sheet with one tile per operator") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir;
  const std::string prefix = (dir.path() / "sheet").string();
  const auto r = runCrep(kCommon + "--tonemap all --auto-exposure --white-point 4 --out '" + prefix + "'");
  INFO(r.output);
  REQUIRE(r.status == 0);
  for (const crep::ToneMapOperator op : crep::kToneMapOperators)
    CHECK(r.output.find(crep::toneMapOperatorName(op)) != std::string::npos);
  const Png sheet = readPng(prefix + ".png");
  // 8 tiles (7 operators and the default clamp) of 160 x 90 in 4 columns, 2 rows, margins of 8.
  CHECK(sheet.width == 8 + 4 * (160 + 8));
  CHECK(sheet.height > 2 * 90);
}

TEST_CASE("crep render --tonemap: unknown names and knobs without --tonemap are usage errors") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir;
  const std::string prefix = (dir.path() / "bad").string();
  const auto r = runCrep(kCommon + "--tonemap aces --out '" + prefix + "'");
  INFO(r.output);
  CHECK(r.status == 2);
  CHECK(r.output.find("--tonemap") != std::string::npos);
  CHECK(r.output.find("aces") != std::string::npos);
  for (const crep::ToneMapOperator op : crep::kToneMapOperators)
    CHECK(r.output.find(crep::toneMapOperatorName(op)) != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(prefix + ".png"));
  const auto knob = runCrep(kCommon + "--white-point 2 --out '" + prefix + "'");
  CHECK(knob.status == 2);
  CHECK(knob.output.find("--white-point needs --tonemap") != std::string::npos);
  const auto range = runCrep(kCommon + "--tonemap log --saturation 9 --out '" + prefix + "'");
  CHECK(range.status == 2);
  CHECK(range.output.find("--saturation") != std::string::npos);
}
