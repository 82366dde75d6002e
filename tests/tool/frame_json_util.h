// Helpers of the crep tool tests that write frame descriptions (examples/crep/lib/frame_json.h): the
// example frame, text files and JSON conversions, the spot light of the local-light and texture frames, the
// listing of a folder (what a command left behind), and a folder of `crep scatter` inputs.
#pragma once

#include "common/image_check.h"

#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/support/exr.h>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <string>

namespace crep::test::frame_json {

using Json = nlohmann::json;
inline const std::string kExample = std::string(CREP_SOURCE_DIR) + "/examples/data/frame.json";

inline std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void writeText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

/// The names in `dir` (recursively, relative), to see that a failed command left nothing behind.
inline std::set<std::string> listing(const std::filesystem::path& dir) {
  std::set<std::string> names;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    names.insert(e.path().lexically_relative(dir).string());
  return names;
}

/// 16 numbers, column-major (the schema's matrix convention).
inline Json matrixJson(const glm::dmat4& m) {
  Json j = Json::array();
  for (int k = 0; k < 16; ++k)
    j.push_back(m[k / 4][k % 4]);
  return j;
}

inline Json vecJson(const glm::dvec3& v) {
  return Json::array({v.x, v.y, v.z});
}

/// The spot light of the local-light and texture frames (in front of the example camera's ground, off
/// screen above it).
inline SpotLight exampleSpot() {
  return SpotLight({.position = {-6.0, 8.0, 4.0},
                    .direction = {6.0, -8.0, -8.0},
                    .innerConeAngle = 20.0 * 3.14159265358979 / 180.0,
                    .outerConeAngle = 30.0 * 3.14159265358979 / 180.0,
                    .color = {1.0, 0.9, 0.8},
                    .intensity = 30.0,
                    .range = 60.0,
                    .nearPlane = 0.1});
}

/// exampleSpot() as a light entry of the frame (type, position, direction, cones, colour, intensity);
/// callers add its shadow map, texture or near plane.
inline Json exampleSpotJson() {
  const SpotLight s = exampleSpot();
  return Json{{"type", "spot"},
              {"position", vecJson(s.position())},
              {"direction", vecJson(s.direction())},
              {"innerConeDeg", 20},
              {"outerConeDeg", 30},
              {"color", Json::array({1.0, 0.9, 0.8})},
              {"intensity", 30}};
}

/// A temporary folder (`prefix`) of `crep scatter` inputs: depth.exr (160x90, a constant 0.9) and shadow.exr
/// (shadowSize^2, empty: 1); callers add the frame (writeFrame) and other files.
struct ScatterFolder {
  explicit ScatterFolder(const std::string& prefix, int shadowSize = 256) : dir(prefix) {
    writeExr(dir / "depth.exr", Image(160, 90, 1, 0.9f), ExrPixelType::Float);
    writeExr(dir / "shadow.exr", Image(shadowSize, shadowSize, 1, 1.0f), ExrPixelType::Float);
  }
  TempDir dir;
  std::string path(const std::string& name) const { return (dir / name).string(); }
  /// Writes frame.json: the example frame as it is.
  void writeExampleFrame() const { writeText(dir / "frame.json", readText(kExample)); }
  /// Writes frame.json: `frame` with `edit` applied.
  void writeFrame(Json frame, const std::function<void(Json&)>& edit = {}) const {
    if (edit) edit(frame);
    writeText(dir / "frame.json", frame.dump(2));
  }
};

} // namespace crep::test::frame_json
