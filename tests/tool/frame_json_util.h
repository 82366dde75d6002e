// Helpers of the crep scatter tests that write frame descriptions (examples/crep/lib/frame_json.h): the
// example frame, text and JSON conversions, and the spot light of the local-light and texture frames.
#pragma once

#include <crep/core/light.h>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <fstream>
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

} // namespace crep::test::frame_json
