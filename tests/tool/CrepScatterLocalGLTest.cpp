// `crep scatter` with spot and point lights end to end (frame_json.h "Local lights"): a spot-light frame
// exported by `crep render --export-frame` from the night colonnade, and a point-light frame written here
// (six faces stacked as the README documents), each run with the reference and the prefiltered method and
// compared with each other and with the library's CPU world-space reference (crep::worldSpaceMarch with a
// LocalLight, double precision) on the same files.
#include "common/gl_fixture.h"
#include "common/image_check.h"
#include "common/tool_runner.h"
#include "tool/frame_json_util.h"

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/scatter/ray_scattering.h>
#include <crep/scatter/world_march.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>
#include <crep/support/exr.h>
#include <crep/support/image_compare.h>

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace crep::test::frame_json;

constexpr int kWidth = 160, kHeight = 90;
// Reference march sections (the tool's --steps and the CPU reference's). With 64 the pillars' shadows change
// visibility more than once per section and the reference itself is 3.3% off the 256-step one.
constexpr int kSteps = 256;

glm::dmat4 matrix(const Json& j) {
  glm::dmat4 m;
  for (int k = 0; k < 16; ++k)
    m[k / 4][k % 4] = j[static_cast<std::size_t>(k)].get<double>();
  return m;
}
glm::dvec3 vec3(const Json& j) {
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}
Json readJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return Json::parse(s.str());
}

crep::ImageMetrics compareRgb(const crep::Image& actual, const crep::Image& reference) {
  crep::CompareOptions options;
  options.channels = 3;
  return crep::compareImages(actual, reference, options);
}

crep::Medium mediumOf(const Json& m) {
  return crep::Medium({.mieScattering = vec3(m["mieScattering"]),
                       .hgG = m["hgG"].get<double>(),
                       .rayleighScattering = vec3(m["rayleighScattering"]),
                       .absorption = vec3(m["absorption"])});
}

/// A spot light from its JSON fields (frame_json.h), read here independently of the tool.
crep::SpotLight spotOf(const Json& l) {
  const double toRad = std::numbers::pi / 180.0;
  return crep::SpotLight({.position = vec3(l["position"]),
                          .direction = vec3(l["direction"]),
                          .innerConeAngle = l["innerConeDeg"].get<double>() * toRad,
                          .outerConeAngle = l["outerConeDeg"].get<double>() * toRad,
                          .color = vec3(l["color"]),
                          .intensity = l["intensity"].get<double>(),
                          .range = l["range"].get<double>(),
                          .nearPlane = l["nearPlane"].get<double>()});
}

/// Adds the RGB of `add` to `sum` (the lights' contributions add; A is the same transmittance).
void addInto(crep::Image& sum, const crep::Image& add) {
  for (int y = 0; y < sum.height(); ++y)
    for (int x = 0; x < sum.width(); ++x)
      for (int c = 0; c < 3; ++c)
        sum.at(x, y, c) += add.at(x, y, c);
}

/// Runs `crep scatter` on the frame in `dir` with `method`; returns its image.
crep::Image scatter(const std::filesystem::path& dir, const std::string& method, const std::string& out) {
  const auto r = crep::test::runCrep(
      "scatter --depth '" + (dir / "depth.exr").string() + "' --shadow '" + (dir / "shadow.exr").string() +
      "' --frame '" + (dir / "frame.json").string() + "' --map-size 256 --steps " + std::to_string(kSteps) +
      " --method " + method + " --out '" + (dir / out).string() + "'");
  INFO(method << "\n" << r.output);
  REQUIRE(r.status == 0);
  MESSAGE(r.output.substr(0, r.output.find('\n', r.output.find("method "))));
  return crep::readExr((dir / out).string());
}

} // namespace

TEST_CASE(
    "crep scatter: a spot-light frame exported from the night colonnade, reference vs prefiltered vs the "
    "library's world-space reference") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir("crep-scatter-spot");
  const std::filesystem::path frame = dir / "frame";
  const auto render = crep::test::runCrep(
      "render --scene colonnade-night --size 160x90 --map-size 256 --steps " + std::to_string(kSteps) +
      " --method prefilter --out '" + (dir / "pre").string() + "' --export-frame '" + frame.string() + "'");
  INFO(render.output);
  REQUIRE(render.status == 0);

  // The exported description: the first lamp is the main light (no sun), the others are in "lights", each
  // field exactly the scene's (17 significant digits).
  const Json j = readJson(frame / "frame.json");
  const crep::scenes::Scene scene = crep::scenes::makeScene("colonnade-night", double(kWidth) / kHeight);
  REQUIRE(scene.spotLights.size() == 3);
  CHECK(j["light"]["type"] == "spot");
  REQUIRE(j["lights"].size() == 2);
  std::vector<Json> lights = {j["light"], j["lights"][0], j["lights"][1]};
  for (std::size_t i = 0; i < 3; ++i) {
    CAPTURE(i);
    const crep::SpotLight ours = spotOf(lights[i]);
    const crep::SpotLight& theirs = scene.spotLights[i];
    CHECK(ours.position() == theirs.position());
    CHECK(glm::length(ours.direction() - theirs.direction()) < 1e-15);
    CHECK(std::abs(ours.innerConeAngle() - theirs.innerConeAngle()) < 1e-15);
    CHECK(std::abs(ours.outerConeAngle() - theirs.outerConeAngle()) < 1e-15);
    CHECK(glm::length(ours.intensity() - theirs.intensity()) < 1e-12 * glm::length(theirs.intensity()));
    if (i > 0) CHECK(lights[i]["shadowMap"]["file"] == "light" + std::to_string(i) + ".exr");
  }

  // The library's world-space reference on the exported files (CPU, double): each lamp against its map.
  const crep::Camera camera =
      crep::Camera::fromMatrices(matrix(j["camera"]["viewFromWorld"]), matrix(j["camera"]["clipFromView"]));
  const crep::Medium medium = mediumOf(j["medium"]);
  const crep::Image depth = crep::readExr((frame / "depth.exr").string());
  crep::Image cpu;
  for (std::size_t i = 0; i < 3; ++i) {
    const Json& shadow = i == 0 ? j["shadowMap"] : lights[i]["shadowMap"];
    const std::string file = i == 0 ? "shadow.exr" : shadow["file"].get<std::string>();
    crep::WorldMarchOptions options;
    options.steps = kSteps;
    options.bias = shadow["bias"].get<double>();
    const crep::MarchResult r =
        crep::worldSpaceMarch(crep::readExr((frame / file).string()), matrix(shadow["lightClipFromWorld"]),
                              depth, camera, crep::LocalLight::spot(spotOf(lights[i])), medium, options);
    if (i == 0)
      cpu = r.scattering;
    else
      addInto(cpu, r.scattering);
  }

  const crep::Image reference = scatter(frame, "reference", "sref.exr");
  const crep::Image prefilter = scatter(frame, "prefilter", "spre.exr");
  const crep::Image minmax = scatter(frame, "minmax", "smm.exr");
  crep::ExrReadOptions layer;
  layer.layer = "scattering";
  const crep::Image direct = crep::readExr((dir / "pre.exr").string(), layer);

  const crep::ImageMetrics refCpu = compareRgb(reference, cpu), directRef = compareRgb(direct, reference),
                           preRef = compareRgb(prefilter, reference), preCpu = compareRgb(prefilter, cpu);
  MESSAGE(
      "scatter reference (GPU, float) vs the library's CPU world-space march: " << crep::describe(refCpu));
  MESSAGE("render --method prefilter (rasterized rectified maps, half-float EXR layer) vs scatter reference: "
          << crep::describe(directRef));
  MESSAGE("scatter prefilter vs scatter reference: " << crep::describe(preRef));
  MESSAGE("scatter prefilter vs the CPU world-space march: " << crep::describe(preCpu));
  CHECK(refCpu.peak > 0.0);
  CHECK(refCpu.nanCount == 0);
  CHECK(preRef.nanCount == 0);
  // The same march in float on the GPU and in double on the CPU, on the same maps.
  CHECK(refCpu.relativeRmse < 2e-3);
  // The prefiltered method on rectified maps rasterized from the scene (render) and resampled from the
  // exported perspective maps (scatter): both within the goal of 2%.
  CHECK(directRef.relativeRmse < 0.02);
  CHECK(preRef.relativeRmse < 0.02);
  CHECK(preCpu.relativeRmse < 0.02);
  // The min/max march over the same resampled rectified maps: the maps' own error (measured 0.20%).
  const crep::ImageMetrics minmaxRef = compareRgb(minmax, reference);
  MESSAGE("scatter minmax (resampled rectified maps) vs scatter reference: " << crep::describe(minmaxRef));
  CHECK(minmaxRef.nanCount == 0);
  CHECK(minmaxRef.relativeRmse < 0.01);
}

TEST_CASE("crep scatter: a point-light frame, six faces stacked in one EXR, reference vs prefiltered vs the "
          "library's world-space reference per face") {
  CREP_REQUIRE_GL();
  const crep::scenes::Scene scene = crep::scenes::makeScene("colonnade-night", double(kWidth) / kHeight);
  crep::scenes::SceneRenderer renderer(scene.mesh);
  // A lamp outside the left row of pillars, behind the camera (off screen).
  const crep::PointLight point({.position = {-9.0, 6.0, 20.0},
                                .color = {1.0, 0.85, 0.7},
                                .intensity = 600.0,
                                .range = 70.0,
                                .nearPlane = 0.3});
  constexpr int S = 128;
  // The README's layout, written here from its text: face k (+X, -X, +Y, -Y, +Z, -Z) in EXR rows [k S, (k +
  // 1) S) from the top of the file, each face top row first. crep::writeExr writes image row height - 1 - r
  // as file row r (images are stored bottom to top), so face k's texel row y (from the bottom) is image row
  // 6 S - 1 - (k S + S - 1 - y).
  crep::Image stacked(S, 6 * S, 1);
  std::vector<crep::Image> faces;
  for (int k = 0; k < 6; ++k) {
    faces.push_back(renderer.renderDepthImage(point.faceClipFromWorld(k), S, S, {.depthClamp = true}));
    for (int y = 0; y < S; ++y)
      for (int x = 0; x < S; ++x)
        stacked.at(x, 6 * S - 1 - (k * S + S - 1 - y)) = faces.back().at(x, y);
  }
  const crep::Image depth = renderer.renderDepthImage(scene.camera.clipFromWorld(), kWidth, kHeight);
  crep::test::TempDir dir("crep-scatter-point");
  crep::writeExr(dir / "depth.exr", depth, crep::ExrPixelType::Float);
  crep::writeExr(dir / "shadow.exr", stacked, crep::ExrPixelType::Float);
  const double bias = 1e-4;
  const crep::Medium& m = scene.medium;
  // faceClipFromWorld left out: the documented default, PointLight::faceClipFromWorld(k).
  const Json j = {{"camera",
                   {{"viewFromWorld", matrixJson(scene.camera.viewFromWorld())},
                    {"clipFromView", matrixJson(scene.camera.clipFromView())},
                    {"size", Json::array({kWidth, kHeight})}}},
                  {"light",
                   {{"type", "point"},
                    {"position", vecJson(point.position())},
                    {"color", Json::array({1.0, 0.85, 0.7})},
                    {"intensity", 600.0},
                    {"nearPlane", 0.3},
                    {"range", 70.0}}},
                  {"shadowMap", {{"size", Json::array({S, 6 * S})}, {"bias", bias}}},
                  {"medium",
                   {{"mieScattering", vecJson(m.mieScattering())},
                    {"hgG", m.hgG()},
                    {"rayleighScattering", vecJson(m.rayleighScattering())},
                    {"absorption", vecJson(m.absorption())}}}};
  std::ofstream(dir / "frame.json") << j.dump(2);

  crep::Image cpu;
  for (int k = 0; k < 6; ++k) {
    crep::WorldMarchOptions options;
    options.steps = kSteps;
    options.bias = bias;
    const crep::MarchResult r =
        crep::worldSpaceMarch(faces[static_cast<std::size_t>(k)], point.faceClipFromWorld(k), depth,
                              scene.camera, crep::LocalLight::pointFace(point, k), m, options);
    if (k == 0)
      cpu = r.scattering;
    else
      addInto(cpu, r.scattering);
  }
  const crep::Image reference = scatter(dir.path(), "reference", "sref.exr");
  const crep::Image prefilter = scatter(dir.path(), "prefilter", "spre.exr");
  const crep::ImageMetrics refCpu = compareRgb(reference, cpu), preRef = compareRgb(prefilter, reference);
  MESSAGE("point light: scatter reference vs the library's CPU world-space march per face: "
          << crep::describe(refCpu));
  MESSAGE("point light: scatter prefilter vs scatter reference: " << crep::describe(preRef));
  CHECK(refCpu.peak > 0.0);
  CHECK(refCpu.nanCount == 0);
  // A face read from the wrong rows, or upside down, would march against another face's depths.
  CHECK(refCpu.relativeRmse < 2e-3);
  CHECK(preRef.nanCount == 0);
  CHECK(preRef.relativeRmse < 0.02); // the goal (measured 0.91%)
}

TEST_CASE(
    "crep scatter: the example frame with an explicit light.type \"directional\" gives the same image") {
  // light.type is optional and "directional" by default: existing files read exactly as before.
  CREP_REQUIRE_GL();
  crep::test::TempDir dir("crep-scatter-type");
  const std::string example = std::string(CREP_SOURCE_DIR) + "/examples/data/frame.json";
  Json j = readJson(example);
  j["light"]["type"] = "directional";
  std::ofstream(dir / "typed.json") << j.dump(2);
  crep::writeExr(dir / "depth.exr", crep::Image(kWidth, kHeight, 1, 0.995f), crep::ExrPixelType::Float);
  crep::Image shadow(256, 256, 1, 1.0f);
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 100; ++x)
      shadow.at(x, y) = 0.4f;
  crep::writeExr(dir / "shadow.exr", shadow, crep::ExrPixelType::Float);
  for (const char* method : {"reference", "prefilter"}) {
    crep::Image images[2];
    for (int typed = 0; typed < 2; ++typed) {
      const std::string out = (dir / (std::string(method) + std::to_string(typed) + ".exr")).string();
      const auto r = crep::test::runCrep("scatter --depth '" + (dir / "depth.exr").string() + "' --shadow '" +
                                         (dir / "shadow.exr").string() + "' --frame '" +
                                         (typed ? (dir / "typed.json").string() : example) +
                                         "' --map-size 256 --method " + method + " --out '" + out + "'");
      INFO(r.output);
      REQUIRE(r.status == 0);
      images[typed] = crep::readExr(out);
    }
    CAPTURE(method);
    const auto a = images[0].data(), b = images[1].data();
    CHECK(std::equal(a.begin(), a.end(), b.begin(), b.end())); // bit for bit
    CHECK(compareRgb(images[0], crep::Image(kWidth, kHeight, 4)).peak > 0.0);
  }
}

TEST_CASE(
    "crep compare on the night colonnade: prefiltered and min/max march against the world-space reference") {
  CREP_REQUIRE_GL();
  crep::test::TempDir dir("crep-compare-night");
  const auto r =
      crep::test::runCrep("compare --scene colonnade-night --size 128x72 --map-size 256 --steps 256 "
                          "--methods prefilter,minmax --tile-width 128 --out '" +
                          (dir / "night").string() + "'");
  INFO(r.output);
  REQUIRE(r.status == 0);
  REQUIRE(std::filesystem::exists(dir / "night.png"));
  std::ifstream csv(dir / "night.csv");
  std::string line;
  std::getline(csv, line); // header
  int rows = 0;
  while (std::getline(csv, line)) {
    // scene,width,height,method,ran,relative_rmse,...
    std::stringstream fields(line);
    std::string field[6];
    for (std::string& f : field)
      std::getline(fields, f, ',');
    CAPTURE(line);
    CHECK(field[0] == "colonnade-night");
    const double rmse = std::stod(field[5]);
    if (field[3] == "reference")
      CHECK(rmse == 0.0);
    else
      CHECK(rmse < 0.02); // three projective lamps: rasterized rectified maps, 256^2
    ++rows;
  }
  CHECK(rows == 3);
}
