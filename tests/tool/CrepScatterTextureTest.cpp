// `crep scatter` with light textures (frame_json.h "Light textures"): every check of the optional fields
// light.texture / light.textureClipFromWorld (and a spot entry's) fails before any GL work with exit status
// 1 and a message naming the JSON path, never a crash. The valid frames run in CrepScatterTextureGLTest.
#include "common/image_check.h"
#include "common/tool_runner.h"
#include "tool/frame_json_util.h"

#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/support/exr.h>

#include <doctest/doctest.h>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string>

namespace {

using namespace crep::test::frame_json;

/// The example frame (a directional light) with light.texture "window.exr" (8x8 RGB), plus the inputs:
/// depth.exr (160x90, 0.9), shadow.exr (256x256, empty), and bad textures: grey.exr (1 channel),
/// nan.exr / negative.exr (one bad texel), corrupt.exr (not an EXR), spot.exr (a spot's map, 64x64).
struct TextureInputs : ScatterFolder {
  Json frame;
  TextureInputs() : ScatterFolder("crep-scatter-texture") {
    crep::writeExr(dir / "spot.exr", crep::Image(64, 64, 1, 1.0f), crep::ExrPixelType::Float);
    crep::writeExr(dir / "window.exr", crep::Image(8, 8, 3, 0.5f), crep::ExrPixelType::Float);
    crep::writeExr(dir / "grey.exr", crep::Image(8, 8, 1, 0.5f), crep::ExrPixelType::Float);
    crep::Image bad(8, 8, 3, 0.5f);
    bad.at(2, 5, 1) = std::numeric_limits<float>::quiet_NaN(); // (2, 2) from the top-left
    crep::writeExr(dir / "nan.exr", bad, crep::ExrPixelType::Float);
    bad.at(2, 5, 1) = -0.25f;
    crep::writeExr(dir / "negative.exr", bad, crep::ExrPixelType::Float);
    std::ofstream(dir / "corrupt.exr", std::ios::binary) << "this is not an EXR file";
    frame = Json::parse(readText(kExample));
    frame["light"]["texture"] = "window.exr";
  }
  std::string args(const char* out = "out.exr") const {
    return "scatter --method reference --depth '" + path("depth.exr") + "' --shadow '" + path("shadow.exr") +
           "' --frame '" + path("frame.json") + "' --out '" + path(out) + "'";
  }
  void write(const std::function<void(Json&)>& edit) const { writeFrame(frame, edit); }
};

/// A spot entry of "lights" (its map spot.exr) with a texture.
Json spotEntry() {
  Json e = exampleSpotJson();
  e["texture"] = "window.exr";
  e["shadowMap"] = {{"file", "spot.exr"},
                    {"lightClipFromWorld", matrixJson(exampleSpot().lightClipFromWorld())}};
  return e;
}

} // namespace

TEST_CASE("crep scatter light textures: every check names the JSON path") {
  const TextureInputs in;
  struct Case {
    const char* name;
    std::function<void(Json&)> edit;
    const char* mentions;
  };
  const crep::PointLight point({.position = {4.0, 3.0, -2.0}, .range = 50.0});
  const Case cases[] = {
      {"missing file", [](Json& j) { j["light"]["texture"] = "nowhere.exr"; },
       "light.texture: '"}, // ... nowhere.exr' does not exist
      {"texture is a directory", [](Json& j) { j["light"]["texture"] = "."; }, "light.texture: '"},
      {"corrupt file", [](Json& j) { j["light"]["texture"] = "corrupt.exr"; }, "light.texture: '"},
      {"one channel", [](Json& j) { j["light"]["texture"] = "grey.exr"; }, "has 1 channel(s)"},
      {"NaN texel", [](Json& j) { j["light"]["texture"] = "nan.exr"; },
       "texel (2, 2) from the top-left, channel G, is nan (NaN)"},
      {"negative texel", [](Json& j) { j["light"]["texture"] = "negative.exr"; },
       "texel (2, 2) from the top-left, channel G, is -0.25"},
      {"texture not a string", [](Json& j) { j["light"]["texture"] = 3; },
       "light.texture: expected a non-empty EXR file name"},
      {"empty texture name", [](Json& j) { j["light"]["texture"] = ""; },
       "light.texture: expected a non-empty EXR file name"},
      {"projection without texture",
       [](Json& j) {
         j["light"].erase("texture");
         j["light"]["textureClipFromWorld"] = matrixJson(glm::dmat4(1.0));
       },
       "light.textureClipFromWorld: given without light.texture"},
      {"projection of 15 numbers",
       [](Json& j) {
         Json m = matrixJson(glm::dmat4(1.0));
         m.erase(15);
         j["light"]["textureClipFromWorld"] = m;
       },
       "light.textureClipFromWorld: expected an array of 16 numbers"},
      {"sun texture projected across the light's rays",
       [](Json& j) {
         // An orthographic projection looking straight down: the sun's rays (1, -0.8, -0.4) are oblique.
         j["light"]["textureClipFromWorld"] =
             matrixJson(glm::ortho(-20.0, 20.0, -20.0, 20.0, 1.0, 100.0) *
                        glm::lookAt(glm::dvec3(0, 50, 0), glm::dvec3(0.0), glm::dvec3(0, 0, -1)));
       },
       "light.textureClipFromWorld: not along the light's rays"},
      {"sun texture with a perspective projection",
       [](Json& j) {
         j["light"]["textureClipFromWorld"] =
             matrixJson(glm::perspective(1.0, 1.0, 1.0, 100.0) *
                        glm::lookAt(glm::dvec3(-20, 16, 8), glm::dvec3(0.0), glm::dvec3(0, 1, 0)));
       },
       "light.textureClipFromWorld: not along the light's rays"},
      {"point light with a texture",
       [&](Json& j) {
         j["lights"] = Json::array({Json{{"type", "point"},
                                         {"position", vecJson(point.position())},
                                         {"color", Json::array({1, 1, 1})},
                                         {"intensity", 10},
                                         {"range", 50},
                                         {"texture", "window.exr"},
                                         {"shadowMap", {{"file", "spot.exr"}}}}});
       },
       "lights[0].texture: light textures are not supported for point lights"},
      {"point light with a projection",
       [&](Json& j) {
         j["lights"] = Json::array({Json{{"type", "point"},
                                         {"position", vecJson(point.position())},
                                         {"color", Json::array({1, 1, 1})},
                                         {"intensity", 10},
                                         {"range", 50},
                                         {"textureClipFromWorld", matrixJson(glm::dmat4(1.0))},
                                         {"shadowMap", {{"file", "spot.exr"}}}}});
       },
       "lights[0].textureClipFromWorld: light textures are not supported for point lights"},
      {"spot texture missing",
       [](Json& j) {
         Json e = spotEntry();
         e["texture"] = "gobo.exr";
         j["lights"] = Json::array({e});
       },
       "lights[0].texture: '"},
      {"spot texture of one channel",
       [](Json& j) {
         Json e = spotEntry();
         e["texture"] = "grey.exr";
         j["lights"] = Json::array({e});
       },
       "lights[0].texture: '"},
      {"spot projection not centred at the spot",
       [](Json& j) {
         Json e = spotEntry();
         const crep::SpotLight s = exampleSpot();
         e["textureClipFromWorld"] = matrixJson(
             glm::perspective(1.2, 1.0, 0.1, 60.0) *
             glm::lookAt(s.position() + glm::dvec3(0.5, 0.0, 0.0), glm::dvec3(0.0), glm::dvec3(0, 1, 0)));
         j["lights"] = Json::array({e});
       },
       "lights[0].textureClipFromWorld: not along the light's rays"},
      {"spot projection orthographic",
       [](Json& j) {
         Json e = spotEntry();
         e["textureClipFromWorld"] = Json::parse(readText(kExample))["shadowMap"]["lightClipFromWorld"];
         j["lights"] = Json::array({e});
       },
       "lights[0].textureClipFromWorld: not along the light's rays"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.name);
    in.write(c.edit);
    expectFailure(crep::test::runCrep(in.args()), 1, {c.mentions});
    CHECK(!std::filesystem::exists(in.dir / "out.exr"));
  }
}

TEST_CASE("crep scatter light textures: the texture as the output is a usage error") {
  const TextureInputs in;
  in.write([](Json&) {});
  const auto r = crep::test::runCrep(in.args("window.exr"));
  INFO(r.output);
  CHECK(r.status == 2);
  CHECK(r.output.find("light.texture") != std::string::npos);
  CHECK(crep::readExr(in.dir / "window.exr").at(0, 0, 0) == 0.5f); // untouched
}

TEST_CASE("crep scatter light textures: an unknown field next to the texture is still an error") {
  const TextureInputs in;
  in.write([](Json& j) { j["light"]["textures"] = "window.exr"; });
  expectFailure(crep::test::runCrep(in.args()), 1, {"light.textures: unknown field"});
}
