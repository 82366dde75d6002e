// `crep scatter` with light textures end to end (frame_json.h "Light textures"): the stained-glass scene
// exported by `crep render --export-frame` (light.texture + light.textureClipFromWorld written by toJson,
// the texture as an RGB EXR) read back by `crep scatter`; a constant white texture gives the untextured
// image with every method; a two-colour texture over the colonnade (default projection: the shadow
// matrix): the rectified methods against the world-space reference.
#include "common/gl_fixture.h"
#include "common/image_check.h"
#include "common/tool_runner.h"

#include <crep/support/exr.h>
#include <crep/support/image_compare.h>

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

using Json = nlohmann::json;

constexpr int kSteps = 128;

Json readJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return Json::parse(s.str());
}

void writeJson(const std::filesystem::path& path, const Json& j) {
  std::ofstream(path, std::ios::binary) << j.dump(2);
}

crep::ImageMetrics compareRgb(const crep::Image& actual, const crep::Image& reference) {
  crep::CompareOptions options;
  options.channels = 3;
  return crep::compareImages(actual, reference, options);
}

/// Exports `scene` (128x72, mapSize^2 maps) into `dir`/frame; the direct render's reference
/// march is `dir`/ref.exr.
void exportScene(const crep::test::TempDir& dir, const std::string& scene, int mapSize = 256) {
  const auto r =
      crep::test::runCrep("render --scene " + scene + " --size 128x72 --map-size " + std::to_string(mapSize) +
                          " --steps " + std::to_string(kSteps) + " --method reference --out '" +
                          (dir / "ref").string() + "' --export-frame '" + (dir / "frame").string() + "'");
  INFO(r.output);
  REQUIRE(r.status == 0);
}

/// Runs `crep scatter` on `dir`/frame with the frame description `json` (in that directory) and `method`.
crep::Image scatter(const crep::test::TempDir& dir, const std::string& json, const std::string& method,
                    const std::string& out, int mapSize = 256, int steps = kSteps) {
  const std::filesystem::path f = dir / "frame";
  const auto r = crep::test::runCrep(
      "scatter --depth '" + (f / "depth.exr").string() + "' --shadow '" + (f / "shadow.exr").string() +
      "' --frame '" + (f / json).string() + "' --map-size " + std::to_string(mapSize) + " --steps " +
      std::to_string(steps) + " --method " + method + " --out '" + (dir / out).string() + "'");
  INFO(method << " " << json << "\n" << r.output);
  REQUIRE(r.status == 0);
  return crep::readExr((dir / out).string());
}

} // namespace

TEST_CASE("crep scatter light textures: the exported stained-glass frame reads back (toJson round trip)") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir("crep-scatter-texture");
  exportScene(dir, "stained-glass");
  const Json j = readJson(dir / "frame" / "frame.json");
  REQUIRE(j["light"].contains("texture"));
  CHECK(j["light"]["texture"] == "light-texture.exr");
  REQUIRE(j["light"]["textureClipFromWorld"].size() == 16);
  // The texture file: RGB, coloured panes and dark lead (the EXR's top row is the texture's top).
  const crep::Image texture = crep::readExr((dir / "frame" / "light-texture.exr").string());
  CHECK(texture.channels() == 3);
  float darkest = 1e30f, reddest = 0.0f, bluest = 0.0f;
  for (int y = 0; y < texture.height(); ++y)
    for (int x = 0; x < texture.width(); ++x) {
      darkest = std::min(darkest, texture.at(x, y, 0) + texture.at(x, y, 1) + texture.at(x, y, 2));
      reddest = std::max(reddest, texture.at(x, y, 0) - texture.at(x, y, 2));
      bluest = std::max(bluest, texture.at(x, y, 2) - texture.at(x, y, 0));
    }
  CHECK(darkest < 0.1f);
  CHECK(reddest > 0.5f);
  CHECK(bluest > 0.5f);

  // The tool's reference on the exported files reproduces the render's (its half-float layer).
  crep::ExrReadOptions layer;
  layer.layer = "scattering";
  const crep::Image direct = crep::readExr((dir / "ref.exr").string(), layer);
  const crep::Image textured = scatter(dir, "frame.json", "reference", "tex.exr");
  const crep::ImageMetrics round = compareRgb(textured, direct);
  MESSAGE(std::string(std::string("scatter reference vs render reference, relative RMSE ") +
                      std::to_string(round.relativeRmse)));
  CHECK(round.relativeRmse < 1e-3);
  // ... and the texture matters: without it the shafts are white and brighter.
  Json plain = j;
  plain["light"].erase("texture");
  plain["light"].erase("textureClipFromWorld");
  writeJson(dir / "frame" / "plain.json", plain);
  const crep::Image untextured = scatter(dir, "plain.json", "reference", "plain.exr");
  const crep::ImageMetrics change = compareRgb(textured, untextured);
  MESSAGE(std::string(std::string("textured vs untextured, relative RMSE ") +
                      std::to_string(change.relativeRmse)));
  CHECK(change.relativeRmse > 0.1);
}

TEST_CASE("crep scatter light textures: a constant white texture gives the untextured image, every method") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir("crep-scatter-texture-white");
  exportScene(dir, "stained-glass");
  const Json j = readJson(dir / "frame" / "frame.json");
  crep::writeExr((dir / "frame" / "white.exr").string(), crep::Image(5, 3, 3, 1.0f),
                 crep::ExrPixelType::Float);
  Json white = j, plain = j;
  white["light"]["texture"] = "white.exr";
  plain["light"].erase("texture");
  plain["light"].erase("textureClipFromWorld");
  writeJson(dir / "frame" / "white.json", white);
  writeJson(dir / "frame" / "plain.json", plain);
  for (const char* method : {"reference", "minmax", "brute", "prefilter"}) {
    CAPTURE(method);
    const crep::Image a = scatter(dir, "white.json", method, std::string(method) + "-white.exr");
    const crep::Image b = scatter(dir, "plain.json", method, std::string(method) + "-plain.exr");
    const crep::ImageMetrics m = compareRgb(a, b);
    MESSAGE(std::string(std::string(method) + ": white texture vs none, max |difference| " +
                        std::to_string(m.maxAbsError) + ", relative RMSE " + std::to_string(m.relativeRmse)));
    // Bit for bit, except the min/max march: its textured variant walks the lit tree nodes texel by texel
    // (each texel's section times its colour) where the untextured one adds whole lit nodes, so the float
    // sums differ in order (measured max |difference| 2.7e-7 of a peak about 0.2).
    if (std::string(method) == "minmax")
      CHECK(m.maxAbsError <= 1e-5 * m.peak);
    else
      CHECK(m.maxAbsError == 0.0);
  }
}

TEST_CASE("crep scatter light textures: a two-colour texture over the colonnade, the rectified methods vs "
          "the reference") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir("crep-scatter-texture-two");
  // The sunlit colonnade (shafts through the roof openings), a 1024^2 standard map (the users'-data path
  // resamples it), the texture over the whole map with the default projection (the shadow matrix).
  exportScene(dir, "colonnade", 1024);
  Json j = readJson(dir / "frame" / "frame.json");
  // Red (1, 0.1, 0.05) on the map's first 30% in u, blue (0.05, 0.1, 1) on the rest: the colour edge runs
  // through the hall's shafts.
  crep::Image two(64, 64, 3);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const bool red = x < 19;
      two.at(x, y, 0) = red ? 1.0f : 0.05f;
      two.at(x, y, 1) = 0.1f;
      two.at(x, y, 2) = red ? 0.05f : 1.0f;
    }
  crep::writeExr((dir / "frame" / "two.exr").string(), two, crep::ExrPixelType::Float);
  j["light"]["texture"] = "two.exr";
  writeJson(dir / "frame" / "two.json", j);
  Json plain = j;
  plain["light"].erase("texture");
  writeJson(dir / "frame" / "plain.json", plain);
  const int map = 512, steps = 256;
  const crep::Image reference = scatter(dir, "two.json", "reference", "ref2.exr", map, steps);
  const crep::Image plainReference = scatter(dir, "plain.json", "reference", "refp.exr", map, steps);
  // Textured: below 3% (prefiltered) / 2% (min/max march); the untextured frame's error stated beside it.
  for (const char* method : {"prefilter", "minmax"}) {
    CAPTURE(method);
    const crep::ImageMetrics m =
        compareRgb(scatter(dir, "two.json", method, std::string(method) + "2.exr", map, steps), reference);
    const crep::ImageMetrics p = compareRgb(
        scatter(dir, "plain.json", method, std::string(method) + "p.exr", map, steps), plainReference);
    MESSAGE(std::string(std::string(method) + " vs reference, two-colour texture: relative RMSE " +
                        std::to_string(m.relativeRmse) + " (untextured " + std::to_string(p.relativeRmse) +
                        ")"));
    CHECK(m.relativeRmse < (std::string(method) == "prefilter" ? 0.03 : 0.02));
  }
}
