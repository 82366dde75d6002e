// `crep compare` and `crep bench` end to end at test sizes.
#include "common/gl_fixture.h"
#include "common/image_check.h"
#include "common/png_read.h"
#include "common/tool_runner.h"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  bool quoted = false;
  for (char c : line) {
    if (c == '"')
      quoted = !quoted;
    else if (c == ',' && !quoted) {
      fields.push_back(field);
      field.clear();
    } else
      field += c;
  }
  fields.push_back(field);
  return fields;
}

/// The CSV as one map column -> value per data row.
std::vector<std::map<std::string, std::string>> readCsv(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = splitCsv(line);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    const std::vector<std::string> f = splitCsv(line);
    REQUIRE(f.size() == header.size());
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < f.size(); ++i)
      row[header[i]] = f[i];
    rows.push_back(row);
  }
  return rows;
}

/// Width and height from a PNG's IHDR chunk (0, 0 if it is not a PNG).
std::pair<int, int> pngSize(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char b[24] = {};
  in.read(reinterpret_cast<char*>(b), 24);
  if (!in || b[1] != 'P' || b[2] != 'N' || b[3] != 'G') return {0, 0};
  auto be = [&](int o) { return (b[o] << 24) | (b[o + 1] << 16) | (b[o + 2] << 8) | b[o + 3]; };
  return {be(16), be(20)};
}

} // namespace

TEST_CASE("crep compare: contact sheet and CSV with every method against the reference") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir("crep-compare");
  const std::string prefix = (dir / "cmp").string();
  const auto r = crep::test::runCrep(
      "compare --scene boxes --size 160x90 --map-size 256 --steps 256 --out '" + prefix + "'");
  INFO(r.output);
  REQUIRE(r.status == 0);
  const auto rows = readCsv(prefix + ".csv");
  REQUIRE(rows.size() >= 2); // the reference and at least the prefiltered method
  std::map<std::string, std::map<std::string, std::string>> byMethod;
  for (const auto& row : rows)
    byMethod[row.at("method")] = row;
  REQUIRE(byMethod.count("reference") == 1);
  REQUIRE(byMethod.count("prefilter") == 1);
  for (const auto& row : rows) {
    for (const char* column :
         {"scene", "relative_rmse", "psnr_db", "max_abs_error", "mean_abs_error", "ms total"})
      CHECK(!row.at(column).empty());
    CHECK(row.at("scene") == "boxes");
    CHECK(std::strtod(row.at("ms total").c_str(), nullptr) > 0.0);
  }
  CHECK(byMethod["reference"]["relative_rmse"] == "0");
  CHECK(byMethod["reference"]["psnr_db"] == "inf");
  CHECK(!byMethod["reference"]["ms reference march"].empty());
  const double rel = std::strtod(byMethod["prefilter"]["relative_rmse"].c_str(), nullptr);
  CHECK(rel > 0.0);
  CHECK(rel < 0.04); // prefiltered vs world-space march (CrepToolGLTest: 0.89% on boxes at 512^2)
  CHECK(std::isfinite(std::strtod(byMethod["prefilter"]["psnr_db"].c_str(), nullptr)));
  CHECK(!byMethod["prefilter"]["ms prefilter"].empty());
  CHECK(!byMethod["prefilter"]["ms evaluate"].empty());
  CHECK(byMethod["prefilter"]["ms reference march"].empty());

  // Sheet: one column per method, each 160 wide (margins 8), images and heat maps stacked.
  const auto [w, h] = pngSize(prefix + ".png");
  CHECK(w == 8 + static_cast<int>(rows.size()) * (160 + 8));
  CHECK(h > 2 * 90);
  // The printed table names every method and the files.
  CHECK(r.output.find("prefilter") != std::string::npos);
  CHECK(r.output.find("cmp.csv") != std::string::npos);
}

TEST_CASE("crep compare: --methods selects methods and always adds the reference") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir("crep-compare");
  const std::string prefix = (dir / "one").string();
  const auto r = crep::test::runCrep(
      "compare --size 160x90 --map-size 128 --steps 64 --methods prefilter --tile-width 80 --out '" + prefix +
      "'");
  INFO(r.output);
  REQUIRE(r.status == 0);
  const auto rows = readCsv(prefix + ".csv");
  REQUIRE(rows.size() == 2);
  CHECK(rows[0].at("method") == "reference");
  CHECK(rows[1].at("method") == "prefilter");
  CHECK(pngSize(prefix + ".png").first == 8 + 2 * (80 + 8));
}

TEST_CASE("crep compare: every title and text line stays within its tile") {
  // Three methods and the reference in 80-pixel tiles on the sunset, where the marches fall back to the
  // epipolar layout: their titles ("minmax (ran minmax (epipolar))") and the error legend are wider than
  // a tile at their font sizes. Between two tiles runs an 8-pixel gap of background: no text may be drawn
  // there from the first row of images down (the header above spans the sheet).
  CREP_REQUIRE_GL();
  crep::test::TempDir dir("crep-compare");
  const std::string prefix = (dir / "labels").string();
  const auto r =
      crep::test::runCrep("compare --scene sunset --size 160x90 --map-size 128 --steps 32 --methods "
                          "prefilter,minmax,brute --tile-width 80 --out '" +
                          prefix + "'");
  INFO(r.output);
  REQUIRE(r.status == 0);
  REQUIRE(r.output.find("(epipolar)") != std::string::npos); // the long titles
  const crep::test::Png sheet = crep::test::readPng(prefix + ".png");
  const int columns = 4, tile = 80, margin = 8;
  REQUIRE(sheet.width == margin + columns * (tile + margin));
  const auto isBackground = [&](int x, int y) {
    for (int c = 0; c < 3; ++c)
      if (sheet.at(x, y, c) != sheet.at(0, sheet.height - 1, c)) return false;
    return true;
  };
  // The first row of images: the first run of 20 rows that are not background at the first tile's centre
  // (a line of text is at most 10 rows tall).
  int imagesTop = -1;
  for (int y = 0, run = 0; y < sheet.height && imagesTop < 0; ++y) {
    run = isBackground(margin + tile / 2, y) ? 0 : run + 1;
    if (run == 20) imagesTop = y - 19;
  }
  REQUIRE(imagesTop > 0);
  int drawn = 0;
  for (int y = imagesTop; y < sheet.height; ++y)
    for (int c = 0; c + 1 < columns; ++c)
      for (int x = margin + c * (tile + margin) + tile; x < margin + (c + 1) * (tile + margin); ++x)
        drawn += isBackground(x, y) ? 0 : 1;
  CHECK(drawn == 0);
}

TEST_CASE("crep compare: images 1 pixel wide (--size 1x1, 1x2, 1x90) make a sheet of 16-pixel tiles") {
  // These used to crash: the default tile width min(width, 400) = 1 skipped the [16, 4096] check and
  // the legend's ramp divided 0 by 0 and indexed out of bounds (UBSan).
  CREP_REQUIRE_GL();
  crep::test::TempDir dir("crep-compare");
  for (const char* size : {"1x1", "1x2", "1x90", "7x1"}) {
    const std::string prefix = (dir / (std::string("s") + size)).string();
    const auto r =
        crep::test::runCrep(std::string("compare --size ") + size +
                            " --map-size 64 --steps 16 --methods prefilter --out '" + prefix + "'");
    INFO(size << " -> " << r.output);
    REQUIRE(r.status == 0);
    const auto [w, h] = pngSize(prefix + ".png");
    CHECK(w == 8 + 2 * (16 + 8)); // reference + prefilter, each 16 wide
    CHECK(h > 0);
    CHECK(readCsv(prefix + ".csv").size() == 2);
  }
}

TEST_CASE(
    "crep compare: epipolar-sampling and epipolar-prefilter on the sun-in-view scene, with their stages") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir("crep-compare-epipolar");
  const std::string prefix = (dir / "sunset").string();
  const auto r = crep::test::runCrep("compare --scene sunset --size 160x90 --map-size 256 --steps 256 "
                                     "--methods epipolar-sampling,epipolar-prefilter,minmax --out '" +
                                     prefix + "'");
  INFO(r.output);
  REQUIRE(r.status == 0);
  std::map<std::string, std::map<std::string, std::string>> byMethod;
  for (const auto& row : readCsv(prefix + ".csv"))
    byMethod[row.at("method")] = row;
  for (const char* method : {"epipolar-sampling", "epipolar-prefilter"}) {
    CAPTURE(method);
    REQUIRE(byMethod.count(method) == 1);
    const auto& row = byMethod[method];
    const double rel = std::strtod(row.at("relative_rmse").c_str(), nullptr);
    MESSAGE(method << " on sunset 160x90, map 256^2: relative RMSE " << rel * 100.0 << "%");
    CHECK(rel > 0.0);
    CHECK(rel < 0.03);
    for (const char* stage :
         {"ms epipolar samples", "ms refine samples", "ms interpolate", "ms unwarp", "ms correct"})
      CHECK(!row.at(stage).empty());
  }
  CHECK(!byMethod["epipolar-sampling"]["ms march samples"].empty());
  CHECK(!byMethod["epipolar-prefilter"]["ms evaluate samples"].empty());
  // render reports the sample counts.
  const auto one =
      crep::test::runCrep("render --scene sunset --size 96x54 --map-size 256 --method epipolar-sampling "
                          "--slices 256 --samples 64 --initial-step 8 --out '" +
                          (dir / "one").string() + "'");
  INFO(one.output);
  CHECK(one.status == 0);
  CHECK(one.output.find("epipolar sampling 256 x 64, step 8") != std::string::npos);
  CHECK(one.output.find("samples on screen") != std::string::npos);
  // A bad sampling option is a usage error naming it.
  const auto bad = crep::test::runCrep("render --scene boxes --size 64x36 --method epipolar-sampling "
                                       "--samples 48 --out '" +
                                       (dir / "bad").string() + "'");
  CHECK(bad.status != 0);
  CHECK(bad.output.find("samples") != std::string::npos);
}

#if CREP_TOOL_HAS_BENCH // bench/ built: it adds `crep bench`
TEST_CASE("crep bench --quick: every section at a reduced cost, the slow marches left out") {
  CREP_REQUIRE_GL();
  // stdout alone: the methods' warnings on stderr would land between stdout's buffered blocks.
  const auto r = crep::test::runCrep("bench --quick --size 160x90 --map 128x128 2>/dev/null; exit $?");
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("median of 1 runs") != std::string::npos); // --quick: --repeat 1 unless given
  for (const char* text : {"CPU/GPU", "prefilter", "evaluate", "bandwidth", "methods side by side",
                           "reference", "vs prefilter", "how measured"})
    CHECK(r.output.find(text) != std::string::npos);
  // One heading per section of the suite, in its order (benchSections()).
  std::size_t at = 0;
  for (const char* text : {"\nlimits (",
                           "write-only",
                           "fetch-only",
                           "\nevaluation profile",
                           "\nbandwidth over",
                           "\nGPU memory",
                           "\nlocal lights (",
                           "\nlocal lights, spot scene",
                           "\nlocal lights, scaling",
                           "\nlight textures (",
                           "\nconstant cost (",
                           "\nreduced resolution",
                           "\nmethods side by side (",
                           "\nsun in view (",
                           "\npost effects (",
                           "\nepipolar sampling (",
                           "minmax / epipolar-sampling",
                           "\nepipolar sampling scaling",
                           "\natmosphere tables from scratch",
                           "\natmosphere per frame",
                           "\nscaling (GPU pass",
                           "\nparallelization (Table 1",
                           "\nhow measured"}) {
    INFO(text);
    const std::size_t found = r.output.find(text, at);
    CHECK(found != std::string::npos);
    if (found != std::string::npos) at = found;
  }
  CHECK(r.output.find("(--quick leaves out the slow marches: reference, brute)") != std::string::npos);
  CHECK(r.output.find("4 orders on Yusov's table (the reference)") == std::string::npos);
  CHECK(r.output.find("brute-force march") == std::string::npos);
}

TEST_CASE("crep bench --section local-lights: the local-light sections alone and the spot scaling rows") {
  CREP_REQUIRE_GL();
  const auto r = crep::test::runCrep("bench --section local-lights --quick --size 64x36 --map 256x256 "
                                     "--repeat 1");
  INFO(r.output);
  REQUIRE(r.status == 0);
  for (const char* text : {"local lights (", "local lights, spot scene", "local lights, scaling", "sun alone",
                           "a spot in the view", "how measured"})
    CHECK(r.output.find(text) != std::string::npos);
  CHECK(r.output.find("bandwidth over") == std::string::npos); // the section alone
  // The scaling rows: N, frame ms, spots ms, per spot ms, per spot / sun, "prefiltered k of N"; every spot
  // is placed off screen, so every one is prefiltered (projective).
  const std::regex row(R"(^\s*(\d+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+prefiltered (\d+) of (\d+)\s*$)");
  std::set<int> counts;
  std::istringstream lines(r.output);
  for (std::string line; std::getline(lines, line);) {
    std::smatch m;
    if (!std::regex_match(line, m, row)) continue;
    INFO(line);
    const int n = std::stoi(m[1].str());
    counts.insert(n);
    CHECK(std::stoi(m[7].str()) == n);
    CHECK(std::stoi(m[6].str()) == n);
    for (int i = 2; i <= 5; ++i) {
      const double value = std::strtod(m[i].str().c_str(), nullptr);
      CHECK(std::isfinite(value));
      CHECK(value > 0.0);
    }
  }
  CHECK(counts == std::set<int>{1, 2, 4, 8});
  // The option's error and the help name the section.
  const auto bad = crep::test::runCrep("bench --section bogus");
  CHECK(bad.status == 2);
  CHECK(bad.output.find("local-lights") != std::string::npos);
  const auto help = crep::test::runCrep("bench --help");
  CHECK(help.output.find("--section NAME[,NAME...]") != std::string::npos);
  CHECK(help.output.find("  local-lights ") != std::string::npos);
}

TEST_CASE("crep bench --plot: the Table 1/2 rows as an SVG chart beside the paper's") {
  CREP_REQUIRE_GL();
  // testOutputDir() creates the folder: --plot's folder must exist (checked before the suite runs).
  const std::string svg = (crep::test::testOutputDir() / "bench-tables.svg").string();
  std::remove(svg.c_str());
  // The two sections whose rows it draws (the whole suite also does; its atmosphere reference table alone
  // takes minutes).
  const auto r = crep::test::runCrep("bench --section scaling,parallelization --size 160x90 --map 128x128 "
                                     "--repeat 1 --plot " +
                                     svg);
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find("Table 1") != std::string::npos);
  std::ifstream in(svg);
  REQUIRE(in.good());
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(text.starts_with("<svg"));
  CHECK(text.find("</svg>") != std::string::npos);
  for (const char* title : {"Table 2", "Table 1", "crepuscular, llvmpipe", "Klehm et al. 2014"})
    CHECK(text.find(title) != std::string::npos);
  // One bar per measured row and series: 6 scaling rows x 2 panels + 9 parallelization cells (M = 32: 4, 8,
  // 16, 32 bases per invocation x 3 region counts, minus none), ours only at a 128^2 map (the paper's rows
  // are for 1024^2) except Table 1's relative shape.
  std::size_t bars = 0;
  for (std::size_t at = text.find("<rect x="); at != std::string::npos; at = text.find("<rect x=", at + 1))
    ++bars;
  CHECK(bars >= 12 + 12);
  CHECK(r.output.find("wrote " + svg) != std::string::npos);
  CHECK(r.output.find("bandwidth over") == std::string::npos); // those sections alone
  for (const char* args : {"bench --quick --plot ", "bench --section scaling --plot "}) {
    const auto bad = crep::test::runCrep(args + svg);
    CHECK(bad.status == 2);
    CHECK(bad.output.find("--plot") != std::string::npos);
  }
}
#endif
