// `crep scatter` failure paths: every check of the inputs happens before any GL work, so these run
// without a context. Each bad input must exit 1 (2 for command-line misuse) with a message naming the
// field or the file, never crash.
#include "common/image_check.h"
#include "common/tool_runner.h"
#include "tool/frame_json_util.h"

#include <crep/core/image.h>
#include <crep/support/exr.h>

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace crep::test::frame_json;

/// A directory with valid inputs for the example frame: depth.exr (160x90, a constant 0.9),
/// shadow.exr (256x256, empty: 1) and frame.json (the example).
struct Inputs : ScatterFolder {
  Inputs() : ScatterFolder("crep-scatter") { writeExampleFrame(); }
  /// The arguments of a scatter run on these inputs (plus `extra`).
  std::string args(const std::string& extra = "") const {
    return "scatter --depth '" + path("depth.exr") + "' --shadow '" + path("shadow.exr") + "' --frame '" +
           path("frame.json") + "' --out '" + path("out.exr") + "' " + extra;
  }
  /// Rewrites frame.json with `edit` applied to the example.
  void editJson(const std::function<void(Json&)>& edit) const {
    writeFrame(Json::parse(readText(kExample)), edit);
  }
};

/// Rewrites an uncompressed single-part scanline EXR so that every chunk holds only the first `keep`
/// bytes of its line, with its size field and the offset table to match: a structurally consistent
/// file whose chunks are too short for its rows.
void shortenChunks(const std::filesystem::path& path, std::uint32_t keep) {
  const std::string in = readText(path.string());
  const auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 3; i >= 0; --i)
      v = (v << 8) | static_cast<unsigned char>(in.at(at + static_cast<std::size_t>(i)));
    return v;
  };
  const auto put = [](std::string& out, std::uint64_t v, int bytes) {
    for (int i = 0; i < bytes; ++i)
      out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  };
  std::size_t at = 8; // after magic and version: attributes name\0 type\0 size value, then \0
  while (in.at(at) != 0) {
    at = in.find('\0', in.find('\0', at) + 1) + 1;
    at += 4 + u32(at);
  }
  const std::size_t tableStart = at + 1;
  const std::size_t chunks = (u32(tableStart) - tableStart) / 8; // chunks follow the table
  std::string out = in.substr(0, tableStart);
  for (std::size_t i = 0; i < chunks; ++i)
    put(out, tableStart + chunks * 8 + i * (8 + keep), 8);
  for (std::size_t i = 0; i < chunks; ++i) {
    const std::size_t chunk = u32(tableStart + i * 8); // files here are far below 4 GiB
    out += in.substr(chunk, 4);                        // y
    put(out, keep, 4);
    out += in.substr(chunk + 8, keep);
  }
  writeText(path, out);
}

} // namespace

TEST_CASE("crep scatter: the example frame file parses (JSON is valid, every field known)") {
  const Json j = Json::parse(readText(kExample));
  for (const char* key : {"camera", "light", "shadowMap", "medium"})
    CHECK(j.contains(key));
  CHECK(j["camera"]["viewFromWorld"].size() == 16);
  CHECK(j["shadowMap"]["lightClipFromWorld"].size() == 16);
}

TEST_CASE("crep scatter: docs/FORMATS.md shows the complete example frame file") {
  const std::string formats = readText(std::string(CREP_SOURCE_DIR) + "/docs/FORMATS.md");
  std::string example = readText(kExample);
  while (!example.empty() && example.back() == '\n')
    example.pop_back();
  CHECK(formats.find(example) != std::string::npos);
}

TEST_CASE("crep scatter: missing options and unknown methods are usage errors naming the option") {
  const Inputs in;
  expectFailure(crep::test::runCrep("scatter --depth '" + in.path("depth.exr") + "' --shadow '" +
                                    in.path("shadow.exr") + "'"),
                2, {"--frame"});
  expectFailure(crep::test::runCrep(in.args("--method bogus")), 2, {"--method", "bogus", "prefilter"});
  expectFailure(crep::test::runCrep(in.args("--map-size 100 --splits 3")), 2, {"--map-size"});
}

TEST_CASE("crep scatter: unreadable, corrupt and truncated files exit 1 naming the file") {
  const Inputs in;
  std::filesystem::remove(in.dir / "depth.exr");
  expectFailure(crep::test::runCrep(in.args()), 1, {"--depth", "depth.exr"});

  writeText(in.dir / "depth.exr", "this is not an EXR file, just text that is long enough to have a header");
  expectFailure(crep::test::runCrep(in.args()), 1, {"--depth", "depth.exr"});

  crep::writeExr(in.dir / "depth.exr", crep::Image(160, 90, 1, 0.9f), crep::ExrPixelType::Float);
  const std::string whole = readText(in.path("shadow.exr"));
  writeText(in.dir / "shadow.exr", whole.substr(0, whole.size() / 2));
  expectFailure(crep::test::runCrep(in.args()), 1, {"--shadow", "shadow.exr"});

  crep::writeExr(in.dir / "shadow.exr", crep::Image(256, 256, 1, 1.0f), crep::ExrPixelType::Float);
  std::filesystem::remove(in.dir / "frame.json");
  expectFailure(crep::test::runCrep(in.args()), 1, {"frame.json"});
}

TEST_CASE("crep scatter: a depth EXR whose chunks are shorter than its rows exits 1 naming the file") {
  // 160-pixel float rows (640 bytes) in 12-byte chunks: OpenEXR would fill the rest of every row from
  // memory nobody wrote, and the depth values 0 (or ASan's fill bytes) would pass the range check.
  const Inputs in;
  crep::writeExr(in.dir / "depth.exr", crep::Image(160, 90, 1, 0.9f),
                 crep::ExrWriteOptions(crep::ExrPixelType::Float, crep::ExrCompression::None));
  shortenChunks(in.dir / "depth.exr", 12);
  expectFailure(crep::test::runCrep(in.args()), 1,
                {"--depth", "depth.exr", "chunk 0 (scanline 0): data size 12 bytes, expected exactly 640"});
  CHECK_FALSE(std::filesystem::exists(in.dir / "out.exr"));
}

TEST_CASE("crep scatter: NaN or out-of-range depth exits 1 naming the file and the pixel") {
  const Inputs in;
  crep::Image depth(160, 90, 1, 0.9f);
  depth.at(3, 89) = std::numeric_limits<float>::quiet_NaN(); // top row in the file
  crep::writeExr(in.dir / "depth.exr", depth, crep::ExrPixelType::Float);
  expectFailure(crep::test::runCrep(in.args()), 1, {"depth.exr", "NaN", "(3, 0)"});

  crep::Image shadow(256, 256, 1, 1.0f);
  shadow.at(10, 10) = 2.0f;
  crep::writeExr(in.dir / "depth.exr", crep::Image(160, 90, 1, 0.9f), crep::ExrPixelType::Float);
  crep::writeExr(in.dir / "shadow.exr", shadow, crep::ExrPixelType::Float);
  expectFailure(crep::test::runCrep(in.args()), 1, {"shadow.exr", "[0, 1]"});
}

TEST_CASE("crep scatter: image sizes that do not match the frame exit 1 naming both") {
  const Inputs in;
  crep::writeExr(in.dir / "depth.exr", crep::Image(320, 180, 1, 0.9f), crep::ExrPixelType::Float);
  expectFailure(crep::test::runCrep(in.args()), 1, {"camera.size", "160x90", "320x180", "depth.exr"});

  crep::writeExr(in.dir / "depth.exr", crep::Image(160, 90, 1, 0.9f), crep::ExrPixelType::Float);
  crep::writeExr(in.dir / "shadow.exr", crep::Image(128, 128, 1, 1.0f), crep::ExrPixelType::Float);
  expectFailure(crep::test::runCrep(in.args()), 1, {"shadowMap.size", "256x256", "128x128"});

  // Without the optional sizes, a depth image whose aspect ratio differs from the projection's.
  crep::writeExr(in.dir / "shadow.exr", crep::Image(256, 256, 1, 1.0f), crep::ExrPixelType::Float);
  crep::writeExr(in.dir / "depth.exr", crep::Image(90, 90, 1, 0.9f), crep::ExrPixelType::Float);
  in.editJson([](Json& j) { j["camera"].erase("size"); });
  expectFailure(crep::test::runCrep(in.args()), 1, {"camera.clipFromView", "aspect", "90x90"});
}

TEST_CASE("crep scatter: malformed frame descriptions exit 1 naming the field") {
  const Inputs in;
  writeText(in.dir / "frame.json", "{\"camera\": {\"viewFromWorld\": [1, 2,, 3]}}");
  expectFailure(crep::test::runCrep(in.args()), 1, {"frame.json", "not valid JSON", "line 1"});

  struct Case {
    const char* name;
    std::function<void(Json&)> edit;
    const char* mentions;
  };
  const Case cases[] = {
      {"missing light", [](Json& j) { j.erase("light"); }, "light: missing"},
      {"missing intensity", [](Json& j) { j["light"].erase("intensity"); }, "light.intensity: missing"},
      {"missing viewFromWorld", [](Json& j) { j["camera"].erase("viewFromWorld"); },
       "camera.viewFromWorld: missing"},
      {"12 numbers", [](Json& j) { j["camera"]["clipFromView"].erase(0); }, "camera.clipFromView"},
      {"string number", [](Json& j) { j["medium"]["hgG"] = "0.6"; }, "medium.hgG"},
      {"hg out of range", [](Json& j) { j["medium"]["hgG"] = 1.5; }, "medium.hgG"},
      {"negative scattering", [](Json& j) { j["medium"]["mieScattering"][1] = -1; }, "medium.mieScattering"},
      {"no extinction",
       [](Json& j) {
         j["medium"]["mieScattering"] = Json::array({0, 0, 0});
         j["medium"]["rayleighScattering"] = Json::array({0, 0, 0});
         j["medium"]["absorption"] = Json::array({0, 0, 0});
       },
       "extinction"},
      {"unknown field", [](Json& j) { j["camera"]["fovy"] = 60; }, "camera.fovy: unknown field"},
      {"zero direction",
       [](Json& j) {
         j["light"]["direction"] = Json::array({0, 0, 0});
       },
       "light.direction"},
      {"negative colour", [](Json& j) { j["light"]["color"][0] = -1; }, "light.color"},
      {"array of strings",
       [](Json& j) {
         j["light"]["direction"] = Json::array({"1", "0", "0"});
       },
       "light.direction[0]"},
      {"scaled view", [](Json& j) { j["camera"]["viewFromWorld"][0] = 2.0; }, "camera.viewFromWorld"},
      {"infinite far plane without maxDistance",
       [](Json& j) {
         Json& p = j["camera"]["clipFromView"];
         p[14] = p[14].get<double>() / (1.0 - p[10].get<double>()) * 2.0; // -2 near
         p[10] = -1.0;
       },
       "camera.maxDistance"},
      {"unknown clip depth", [](Json& j) { j["camera"]["clipDepth"] = "minusOneToOne"; }, "camera.clipDepth"},
      {"orthographic projection",
       [](Json& j) {
         j["camera"]["clipFromView"][11] = 0.0;
         j["camera"]["clipFromView"][15] = 1.0;
       },
       "camera.clipFromView"},
      {"reversed depth",
       [](Json& j) {
         j["camera"]["clipFromView"][10] = 0.001;
         j["camera"]["clipFromView"][14] = 0.1;
       },
       "camera.clipFromView"},
      {"shadow matrix not along the light",
       [](Json& j) {
         Json& m = j["shadowMap"]["lightClipFromWorld"];
         for (int k = 0; k < 3; ++k)
           std::swap(m[k], m[4 + k]);
       },
       "shadowMap.lightClipFromWorld"},
      {"perspective shadow matrix", [](Json& j) { j["shadowMap"]["lightClipFromWorld"][3] = 0.5; },
       "shadowMap.lightClipFromWorld"},
      {"bad size",
       [](Json& j) {
         j["camera"]["size"] = Json::array({160.5, 90});
       },
       "camera.size"},
      {"bad version", [](Json& j) { j["version"] = 7; }, "version"},
      {"not an object",
       [](Json& j) {
         j["medium"] = Json::array({1, 2});
       },
       "medium"},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    in.editJson(c.edit);
    expectFailure(crep::test::runCrep(in.args()), 1, {"frame.json", c.mentions});
  }
}

TEST_CASE("crep scatter: numbers out of range are refused where they come in, naming the JSON path") {
  const Inputs in;
  struct Case {
    const char* name;
    std::function<void(Json&)> edit;
    const char* mentions;
  };
  const Case cases[] = {
      {"intensity 1e38", [](Json& j) { j["light"]["intensity"] = 1e38; }, "light.intensity"},
      {"intensity 1e300", [](Json& j) { j["light"]["intensity"] = 1e300; }, "light.intensity"},
      {"colour 1e308", [](Json& j) { j["light"]["color"][0] = 1e308; }, "light.color[0]"},
      {"absorption 1e300",
       [](Json& j) {
         j["medium"]["absorption"] = Json::array({1e300, 0, 0});
       },
       "medium.absorption[0]"},
      {"mie + rayleigh 1e308",
       [](Json& j) {
         j["medium"]["mieScattering"] = Json::array({1e308, 1e308, 1e308});
         j["medium"]["rayleighScattering"] = Json::array({1e308, 1e308, 1e308});
       },
       "medium.mieScattering[0]"},
      // Each factor in range, the product not: 1e20 x 1e20.
      {"colour x intensity",
       [](Json& j) {
         j["light"]["color"] = Json::array({1e20, 1e20, 1e20});
         j["light"]["intensity"] = 1e20;
       },
       "light.intensity: color * intensity"},
      // In range, but the radiance bound (irradiance x scattering x phase x path) is not.
      {"radiance bound",
       [](Json& j) {
         j["light"]["intensity"] = 1e28;
         j["medium"]["hgG"] = 0.999;
       },
       "light.intensity: with this medium the in-scattered radiance can reach"},
      {"camera translated by 1e30", [](Json& j) { j["camera"]["viewFromWorld"][12] = 1e30; },
       "camera.viewFromWorld: camera position at distance"},
      {"camera translated by 1e20", [](Json& j) { j["camera"]["viewFromWorld"][12] = 1e20; },
       "camera.viewFromWorld: camera position at distance"},
      {"near plane 1e-300",
       [](Json& j) {
         const double n = 1e-300, f = 120.0;
         j["camera"]["clipFromView"][10] = -(f + n) / (f - n);
         j["camera"]["clipFromView"][14] = -2.0 * f * n / (f - n);
       },
       "camera.clipFromView: near / far below 1e-12"},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    in.editJson(c.edit);
    const crep::test::ToolResult r = crep::test::runCrep(in.args());
    expectFailure(r, 1, {"frame.json", c.mentions});
    CHECK(r.output.find("non-finite") == std::string::npos); // refused up front, not after the work
    CHECK_FALSE(std::filesystem::exists(in.dir / "out.exr"));
  }
}

TEST_CASE("crep scatter: JSON text problems name the path: overflow, duplicate keys, nesting, size") {
  const Inputs in;
  const std::string example = readText(kExample);
  const auto runWith = [&](const std::string& text) {
    writeText(in.dir / "frame.json", text);
    return crep::test::runCrep(in.args());
  };
  // 1e309 is valid JSON grammar but overflows a double: named with its field, line and column.
  {
    Json j = Json::parse(example);
    j["light"]["intensity"] = 12345.0;
    std::string text = j.dump(2);
    text.replace(text.find("12345.0"), 7, "1e309");
    const crep::test::ToolResult r = runWith(text);
    expectFailure(r, 1,
                  {"frame.json", "light.intensity: number '1e309' is beyond the range of a double", "line"});
    CHECK(r.output.find("json.exception") == std::string::npos);
  }
  // A key given twice in one object.
  {
    std::string text = example;
    const auto at = text.find("\"light\"");
    REQUIRE(at != std::string::npos);
    text.insert(text.find('{', at) + 1, "\"intensity\": 2, ");
    expectFailure(runWith(text), 1, {"frame.json", "light.intensity: duplicate key"});
  }
  // Deep nesting (destroying a deeply nested document recurses): refused while parsing.
  expectFailure(runWith(std::string(100000, '[') + std::string(100000, ']')), 1,
                {"frame.json", "nested deeper than 32 levels"});
  // Over the documented size limit (1 MiB): refused before it is parsed.
  {
    std::string text = example;
    text.insert(text.rfind('}'), ", \"comment\": \"" + std::string(1 << 20, 'x') + "\"");
    expectFailure(runWith(text), 1, {"frame.json", "at most 1048576 bytes"});
  }
  // A directory instead of a file.
  {
    std::filesystem::create_directory(in.dir / "frame.dir");
    const std::string args = "scatter --depth '" + in.path("depth.exr") + "' --shadow '" +
                             in.path("shadow.exr") + "' --frame '" + in.path("frame.dir") + "' --out '" +
                             in.path("out.exr") + "'";
    expectFailure(crep::test::runCrep(args), 1, {"frame.dir", "is a directory"});
  }
  CHECK_FALSE(std::filesystem::exists(in.dir / "out.exr"));
}

TEST_CASE("crep scatter: a light direction of tiny or huge length is normalised, not called zero") {
  // [1e-300, 0, 0] and [1e300, 0, 0] are the direction +x: not "zero", and the checks that follow see +x
  // (here the example's shadow matrix, which does not look along +x, is what is refused).
  const Inputs in;
  for (const double scale : {1e-300, 1e-30, 1e30}) {
    INFO(scale);
    in.editJson([&](Json& j) { j["light"]["direction"] = Json::array({scale, 0.0, 0.0}); });
    const crep::test::ToolResult r = crep::test::runCrep(in.args());
    INFO(r.output);
    CHECK(r.output.find("zero") == std::string::npos);
    CHECK(r.output.find("shadowMap.lightClipFromWorld") != std::string::npos);
  }
}

TEST_CASE("crep scatter: a directory as --frame, --depth or --shadow is an I/O error naming the option") {
  // A directory given as --frame used to be read as an empty JSON text ("unexpected end of input").
  for (const char* option : {"frame", "depth", "shadow"}) {
    const Inputs in;
    const std::string file = std::string(option) + (std::string(option) == "frame" ? ".json" : ".exr");
    std::filesystem::remove(in.dir / file);
    std::filesystem::create_directory(in.dir / file);
    const auto r = crep::test::runCrep(in.args());
    INFO(option);
    expectFailure(r, 1, {("--" + std::string(option)).c_str(), file.c_str(), "is a directory"});
    CHECK(r.output.find("unexpected end of input") == std::string::npos);
    CHECK(!std::filesystem::exists(in.dir / "out.exr"));
  }
}

TEST_CASE("crep scatter: --out or --png naming an input or each other is refused, the input untouched") {
  const Inputs in;
  const std::string depth = readText(in.path("depth.exr")), frame = readText(in.path("frame.json"));
  const std::string inputs = "scatter --depth '" + in.path("depth.exr") + "' --shadow '" +
                             in.path("shadow.exr") + "' --frame '" + in.path("frame.json") + "' ";
  // The same file spelled differently ("dir/../dir/x") is still the same file.
  const std::string viaParent = (in.dir / ".." / in.dir.path().filename() / "depth.exr").string();
  struct Case {
    std::string extra;
    std::vector<std::string> mentions;
  };
  const Case cases[] = {
      {"--out '" + in.path("depth.exr") + "'", {"--out", "--depth", "depth.exr"}},
      {"--out '" + viaParent + "'", {"--out", "--depth"}},
      {"--out '" + in.path("x.exr") + "' --png '" + in.path("frame.json") + "'", {"--png", "--frame"}},
      {"--out '" + in.path("x.exr") + "' --png '" + in.path("x.exr") + "'", {"--png", "--out", "x.exr"}},
  };
  for (const Case& c : cases) {
    const auto r = crep::test::runCrep(inputs + c.extra);
    INFO(c.extra);
    expectFailure(r, 2, {"refus"});
    for (const std::string& m : c.mentions)
      CHECK(r.output.find(m) != std::string::npos);
  }
  CHECK(readText(in.path("depth.exr")) == depth);
  CHECK(readText(in.path("frame.json")) == frame);
  CHECK(!std::filesystem::exists(in.dir / "x.exr"));
}

TEST_CASE("crep scatter: unusable output paths fail before anything is written") {
  const Inputs in;
  std::filesystem::create_directory(in.dir / "sub");
  // --png '' used to fail after the EXR was written.
  expectFailure(crep::test::runCrep(in.args("--png ''")), 2, {"--png", "must not be empty"});
  expectFailure(crep::test::runCrep(in.args("--png '" + in.path("sub") + "'")), 1,
                {"--png", "sub", "is a directory"});
  expectFailure(crep::test::runCrep(in.args("--png '" + in.path("missing/preview.png") + "'")), 1,
                {"--png", "missing", "does not exist"});
  // Inputs::args() gives --out out.exr; these give their own.
  const std::string inputs = "scatter --depth '" + in.path("depth.exr") + "' --shadow '" +
                             in.path("shadow.exr") + "' --frame '" + in.path("frame.json") + "' ";
  expectFailure(crep::test::runCrep(inputs + "--out '" + in.path("sub") + "/'"), 1,
                {"--out", "is a directory"});
  expectFailure(crep::test::runCrep(inputs + "--out '" + in.path("sub") + "'"), 1,
                {"--out", "is a directory"});
  expectFailure(crep::test::runCrep(inputs + "--out ''"), 2, {"--out", "must not be empty"});
  CHECK(!std::filesystem::exists(in.dir / "out.exr"));
  CHECK(std::filesystem::is_empty(in.dir / "sub"));
}

TEST_CASE("crep scatter: --map-size and --exposure out of range are usage errors naming the option") {
  const Inputs in;
  // --map-size 32768 used to fail inside the CPU resampling, naming Image.width*height.
  const auto big = crep::test::runCrep(in.args("--map-size 32768"));
  expectFailure(big, 2, {"--map-size", "16384"});
  CHECK(big.output.find("Image.") == std::string::npos);
  expectFailure(crep::test::runCrep(in.args("--exposure 1e39")), 2, {"--exposure", "1e30"});
  expectFailure(crep::test::runCrep(in.args("--exposure 0")), 2, {"--exposure"});
  CHECK(!std::filesystem::exists(in.dir / "out.exr"));
}

TEST_CASE("crep scatter: an out-of-range depth is printed with the digits that tell it from 1") {
  // 1.0000001f printed with %f reads "1.000000", which looks valid; the message must show the value.
  const Inputs in;
  crep::Image depth(160, 90, 1, 0.9f);
  depth.at(3, 89) = std::nextafter(1.0f, 2.0f); // 1.00000012, top-left row
  crep::writeExr(in.dir / "depth.exr", depth, crep::ExrPixelType::Float);
  const crep::test::ToolResult r = crep::test::runCrep(in.args());
  expectFailure(r, 1, {"depth.exr", "pixel (3, 0) from the top-left is 1.0000001", "[0, 1]"});
  CHECK_FALSE(std::filesystem::exists(in.dir / "out.exr"));
}
