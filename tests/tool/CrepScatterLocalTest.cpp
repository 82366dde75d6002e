// `crep scatter` with spot and point lights (frame_json.h "Local lights"): every domain check of the new
// optional fields fails before any GL work with exit status 1 and a message naming the JSON path or the
// file, never a crash. The valid frames themselves run in CrepScatterLocalGLTest.
#include "common/image_check.h"
#include "common/tool_runner.h"
#include "tool/frame_json_util.h"

#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/support/exr.h>

#include <doctest/doctest.h>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

namespace {

using namespace crep::test::frame_json;

/// A directory with a spot-light frame (the example's camera and medium, light.type "spot") plus one
/// additional point light in "lights": depth.exr (160x90, 0.9), shadow.exr (the spot's, 128x128, empty),
/// point.exr (the point light's six 32x32 faces stacked: 32x192, empty).
struct SpotInputs : ScatterFolder {
  Json frame;
  SpotInputs() : ScatterFolder("crep-scatter-local", 128) {
    crep::writeExr(dir / "point.exr", crep::Image(32, 192, 1, 1.0f), crep::ExrPixelType::Float);
    frame = Json::parse(readText(kExample));
    const crep::SpotLight s = exampleSpot();
    frame["light"] = exampleSpotJson();
    frame["shadowMap"] = {{"lightClipFromWorld", matrixJson(s.lightClipFromWorld())}, {"bias", 1e-4}};
    frame["lights"] = Json::array({Json{{"type", "point"},
                                        {"position", Json::array({4.0, 3.0, -2.0})},
                                        {"color", Json::array({1.0, 1.0, 1.0})},
                                        {"intensity", 10},
                                        {"range", 50},
                                        {"shadowMap", {{"file", "point.exr"}}}}});
  }
  std::string args() const {
    return "scatter --depth '" + path("depth.exr") + "' --shadow '" + path("shadow.exr") + "' --frame '" +
           path("frame.json") + "' --out '" + path("out.exr") + "'";
  }
  /// Writes frame.json as the frame with `edit` applied.
  void write(const std::function<void(Json&)>& edit) const { writeFrame(frame, edit); }
};

} // namespace

TEST_CASE("crep scatter local lights: every domain check names the JSON path") {
  const SpotInputs in;
  struct Case {
    const char* name;
    std::function<void(Json&)> edit;
    const char* mentions;
  };
  const crep::PointLight point({.position = {4.0, 3.0, -2.0}, .range = 50.0});
  const Case cases[] = {
      {"unknown type", [](Json& j) { j["light"]["type"] = "area"; }, "light.type"},
      {"type not a string", [](Json& j) { j["light"]["type"] = 3; }, "light.type"},
      {"directional in lights", [](Json& j) { j["lights"][0]["type"] = "directional"; }, "lights[0].type"},
      {"type missing in lights", [](Json& j) { j["lights"][0].erase("type"); }, "lights[0].type: missing"},
      {"lights not an array", [](Json& j) { j["lights"] = Json::object(); }, "lights: expected an array"},
      {"lights entry not an object", [](Json& j) { j["lights"][0] = 3; }, "lights[0]: expected an object"},
      {"missing position", [](Json& j) { j["light"].erase("position"); }, "light.position: missing"},
      {"missing cone", [](Json& j) { j["light"].erase("outerConeDeg"); }, "light.outerConeDeg: missing"},
      {"inner cone 0", [](Json& j) { j["light"]["innerConeDeg"] = 0; }, "light.innerConeDeg"},
      {"inner cone negative", [](Json& j) { j["light"]["innerConeDeg"] = -5; }, "light.innerConeDeg"},
      {"outer cone 90", [](Json& j) { j["light"]["outerConeDeg"] = 90; }, "light.outerConeDeg"},
      {"cones out of order", [](Json& j) { j["light"]["innerConeDeg"] = 35; },
       "light.outerConeDeg: 30 must be greater than innerConeDeg (35)"},
      {"equal cones", [](Json& j) { j["light"]["innerConeDeg"] = 30; }, "light.outerConeDeg"},
      {"zero intensity", [](Json& j) { j["light"]["intensity"] = 0; }, "light.intensity: must be > 0"},
      {"negative intensity in lights", [](Json& j) { j["lights"][0]["intensity"] = -1; },
       "lights[0].intensity: must be > 0"},
      {"negative colour", [](Json& j) { j["light"]["color"][2] = -0.5; }, "light.color"},
      {"black colour",
       [](Json& j) {
         j["lights"][0]["color"] = Json::array({0, 0, 0});
       },
       "lights[0].color"},
      {"zero axis",
       [](Json& j) {
         j["light"]["direction"] = Json::array({0, 0, 0});
       },
       "light.direction"},
      {"zero near plane", [](Json& j) { j["light"]["nearPlane"] = 0; }, "light.nearPlane: must be > 0"},
      {"negative range", [](Json& j) { j["lights"][0]["range"] = -3; }, "lights[0].range: must be > 0"},
      {"near beyond range", [](Json& j) { j["lights"][0]["nearPlane"] = 60; }, "lights[0].nearPlane"},
      {"point without range or matrices", [](Json& j) { j["lights"][0].erase("range"); },
       "lights[0].range: missing"},
      {"spot matrix not centred at the light", [](Json& j) { j["light"]["position"][0] = -5.0; },
       "shadowMap.lightClipFromWorld: its centre of projection"},
      {"orthographic matrix for a spot",
       [](Json& j) {
         j["shadowMap"]["lightClipFromWorld"] =
             Json::parse(readText(kExample))["shadowMap"]["lightClipFromWorld"];
       },
       "shadowMap.lightClipFromWorld: not a perspective projection"},
      {"axis behind the matrix",
       [](Json& j) {
         for (int k = 0; k < 3; ++k)
           j["light"]["direction"][k] = -j["light"]["direction"][k].get<double>();
       },
       "shadowMap.lightClipFromWorld: the light's direction is behind"},
      {"spot matrix narrower than the outer cone", [](Json& j) { j["light"]["outerConeDeg"] = 40; },
       "shadowMap.lightClipFromWorld: does not cover the outer cone (light.outerConeDeg)"},
      {"face matrix narrower than its sector",
       [&](Json& j) {
         const crep::PointLight narrow({.position = {4.0, 3.0, -2.0}, .range = 50.0});
         Json faces = Json::array();
         for (int k = 0; k < 6; ++k)
           faces.push_back(
               matrixJson(k == 4 ? glm::perspectiveRH_NO(1.2, 1.0, 0.05, 50.0) * narrow.faceViewFromWorld(4)
                                 : narrow.faceClipFromWorld(k)));
         j["lights"][0]["shadowMap"]["faceClipFromWorld"] = faces;
       },
       "lights[0].shadowMap.faceClipFromWorld[4]: does not cover face 4's sector"},
      {"spot with face matrices", [&](Json& j) { j["shadowMap"]["faceClipFromWorld"] = Json::array(); },
       "shadowMap.faceClipFromWorld: unknown field"},
      {"five face matrices",
       [&](Json& j) {
         Json faces = Json::array();
         for (int k = 0; k < 5; ++k)
           faces.push_back(matrixJson(point.faceClipFromWorld(k)));
         j["lights"][0]["shadowMap"]["faceClipFromWorld"] = faces;
       },
       "lights[0].shadowMap.faceClipFromWorld: expected an array of 6 matrices"},
      {"face matrix of another light",
       [&](Json& j) {
         const crep::PointLight other({.position = {4.0, 3.5, -2.0}, .range = 50.0});
         Json faces = Json::array();
         for (int k = 0; k < 6; ++k)
           faces.push_back(matrixJson((k == 3 ? other : point).faceClipFromWorld(k)));
         j["lights"][0]["shadowMap"]["faceClipFromWorld"] = faces;
       },
       "lights[0].shadowMap.faceClipFromWorld[3]: its centre of projection"},
      {"face matrices out of order",
       [&](Json& j) {
         Json faces = Json::array();
         for (int k = 0; k < 6; ++k)
           faces.push_back(matrixJson(point.faceClipFromWorld(k ^ 1)));
         j["lights"][0]["shadowMap"]["faceClipFromWorld"] = faces;
       },
       "lights[0].shadowMap.faceClipFromWorld[0]: the light's direction is behind"},
      {"point shadow size not S x 6S",
       [](Json& j) {
         j["lights"][0]["shadowMap"]["size"] = Json::array({32, 32});
       },
       "lights[0].shadowMap.size"},
      {"zero shadow size",
       [](Json& j) {
         j["shadowMap"]["size"] = Json::array({0, 128});
       },
       "shadowMap.size"},
      {"negative shadow size",
       [](Json& j) {
         j["lights"][0]["shadowMap"]["size"] = Json::array({-32, 192});
       },
       "lights[0].shadowMap.size"},
      {"spot shadow size mismatch",
       [](Json& j) {
         j["shadowMap"]["size"] = Json::array({64, 64});
       },
       "shadowMap.size 64x64 does not match"},
      {"missing shadow file field", [](Json& j) { j["lights"][0]["shadowMap"].erase("file"); },
       "lights[0].shadowMap.file: missing"},
      {"empty shadow file", [](Json& j) { j["lights"][0]["shadowMap"]["file"] = ""; },
       "lights[0].shadowMap.file"},
      {"missing shadow file", [](Json& j) { j["lights"][0]["shadowMap"]["file"] = "nowhere.exr"; },
       "lights[0].shadowMap.file: '"},
      {"missing shadowMap in lights", [](Json& j) { j["lights"][0].erase("shadowMap"); },
       "lights[0].shadowMap: missing"},
      {"lightClipFromWorld on a point light",
       [](Json& j) {
         j["lights"][0]["shadowMap"]["lightClipFromWorld"] = j["shadowMap"]["lightClipFromWorld"];
       },
       "lights[0].shadowMap.lightClipFromWorld: unknown field"},
      {"cone on a point light", [](Json& j) { j["lights"][0]["innerConeDeg"] = 10; },
       "lights[0].innerConeDeg: unknown field"},
      {"second entry",
       [](Json& j) {
         j["lights"].push_back(j["lights"][0]);
         j["lights"][1]["range"] = 0;
       },
       "lights[1].range"},
      {"radiance bound",
       [](Json& j) {
         j["light"]["intensity"] = 1e29;
         j["light"]["nearPlane"] = 1e-3;
       },
       "with this medium the in-scattered radiance can reach"},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    in.write(c.edit);
    const crep::test::ToolResult r = crep::test::runCrep(in.args());
    expectFailure(r, 1, {"frame.json", c.mentions});
    CHECK_FALSE(std::filesystem::exists(in.dir / "out.exr"));
  }
}

TEST_CASE("crep scatter local lights: shadow EXRs of the wrong shape, or all at the near plane, name the "
          "file") {
  const SpotInputs in;
  in.write([](Json&) {});
  // A point light's map must be S x 6 S.
  crep::writeExr(in.dir / "point.exr", crep::Image(32, 32, 1, 1.0f), crep::ExrPixelType::Float);
  expectFailure(crep::test::runCrep(in.args()), 1, {"point.exr", "32x32", "lights[0]", "S x 6 S"});
  crep::writeExr(in.dir / "point.exr", crep::Image(32, 192, 1, 1.0f), crep::ExrPixelType::Float);
  // The light inside an occluder: every texel at the near plane.
  crep::writeExr(in.dir / "shadow.exr", crep::Image(128, 128, 1, 0.0f), crep::ExrPixelType::Float);
  expectFailure(crep::test::runCrep(in.args()), 1, {"shadow.exr", "inside an occluder", "light)"});
  crep::writeExr(in.dir / "shadow.exr", crep::Image(128, 128, 1, 1.0f), crep::ExrPixelType::Float);
  crep::writeExr(in.dir / "point.exr", crep::Image(32, 192, 1, 0.0f), crep::ExrPixelType::Float);
  expectFailure(crep::test::runCrep(in.args()), 1, {"point.exr", "inside an occluder", "lights[0]"});
  // Out-of-range values in an additional light's map.
  crep::Image bad(32, 192, 1, 1.0f);
  bad.at(1, 1) = 1.5f;
  crep::writeExr(in.dir / "point.exr", bad, crep::ExrPixelType::Float);
  expectFailure(crep::test::runCrep(in.args()), 1, {"lights[0].shadowMap.file", "point.exr", "[0, 1]"});
  // A light's map as the output: refused before anything is written.
  crep::writeExr(in.dir / "point.exr", crep::Image(32, 192, 1, 1.0f), crep::ExrPixelType::Float);
  const std::string point = readText(in.path("point.exr"));
  const auto r = crep::test::runCrep("scatter --depth '" + in.path("depth.exr") + "' --shadow '" +
                                     in.path("shadow.exr") + "' --frame '" + in.path("frame.json") +
                                     "' --out '" + in.path("point.exr") + "'");
  expectFailure(r, 2, {"--out", "lights[0].shadowMap.file"});
  CHECK(readText(in.path("point.exr")) == point);
}
