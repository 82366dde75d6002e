// `crep scatter` failure paths: every check of the inputs happens before any GL work, so these run
// without a context. Each bad input must exit 1 (2 for command-line misuse) with a message naming the
// field or the file, never crash.
#include "support/image_check.h"
#include "support/tool_runner.h"

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

namespace {

using Json = nlohmann::json;
const std::string kExample = std::string(CREP_SOURCE_DIR) + "/examples/data/frame.json";

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void writeText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

/// A directory with valid inputs for the example frame: depth.exr (160x90, a constant 0.9),
/// shadow.exr (256x256, empty: 1) and frame.json (the example).
struct Inputs {
  crep::test::TempDir dir{"crep-scatter"};
  Inputs() {
    crep::writeExr(dir / "depth.exr", crep::Image(160, 90, 1, 0.9f), crep::ExrPixelType::Float);
    crep::writeExr(dir / "shadow.exr", crep::Image(256, 256, 1, 1.0f), crep::ExrPixelType::Float);
    writeText(dir / "frame.json", readText(kExample));
  }
  std::string path(const char* name) const { return (dir / name).string(); }
  /// The arguments of a scatter run on these inputs (plus `extra`).
  std::string args(const std::string& extra = "") const {
    return "scatter --depth '" + path("depth.exr") + "' --shadow '" + path("shadow.exr") + "' --frame '" +
           path("frame.json") + "' --out '" + path("out.exr") + "' " + extra;
  }
  /// Rewrites frame.json with `edit` applied to the example.
  void editJson(const std::function<void(Json&)>& edit) const {
    Json j = Json::parse(readText(kExample));
    edit(j);
    writeText(dir / "frame.json", j.dump(2));
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

void expectFailure(const crep::test::ToolResult& r, int status, std::initializer_list<const char*> mentions) {
  INFO(r.output);
  CHECK(r.status == status);
  for (const char* m : mentions)
    CHECK(r.output.find(m) != std::string::npos);
  CHECK(r.output.find("unexpected error") == std::string::npos);
}

} // namespace

TEST_CASE("crep scatter: the example frame file parses (JSON is valid, every field known)") {
  const Json j = Json::parse(readText(kExample));
  for (const char* key : {"camera", "light", "shadowMap", "medium"})
    CHECK(j.contains(key));
  CHECK(j["camera"]["viewFromWorld"].size() == 16);
  CHECK(j["shadowMap"]["lightClipFromWorld"].size() == 16);
}

TEST_CASE("crep scatter: the README shows the complete example frame file") {
  const std::string readme = readText(std::string(CREP_SOURCE_DIR) + "/README.md");
  std::string example = readText(kExample);
  while (!example.empty() && example.back() == '\n')
    example.pop_back();
  CHECK(readme.find(example) != std::string::npos);
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
      {"off-centre projection", [](Json& j) { j["camera"]["clipFromView"][8] = 0.2; }, "camera.clipFromView"},
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
