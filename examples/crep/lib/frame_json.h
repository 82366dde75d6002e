// The JSON frame description of `crep scatter` (users' own data) and `crep render --export-frame`.
// Schema (README "crep scatter: the frame description"; example: examples/data/frame.json):
//
//   {
//     "version": 1,                                  optional; 1 if given
//     "camera": {
//       "viewFromWorld": [16 numbers],               rigid transform (rotation + translation)
//       "clipFromView":  [16 numbers],               perspective projection: standard or reversed depth,
//                                                    finite or infinite far plane, centred or off-centre
//       "clipDepth": "negativeOneToOne",             optional (default, OpenGL) or "zeroToOne"
//                                                    (glClipControl GL_ZERO_TO_ONE): the matrix's clip depth
//       "maxDistance": d,                            optional: how far the scattering is integrated (the
//                                                    sky's distance); required with an infinite far plane,
//                                                    else at most the far plane (default: the far plane)
//       "size": [width, height]                      optional: must equal the depth EXR's size
//     },
//     "light": {                                     directional light
//       "direction": [x, y, z],                      the direction light travels (sun -> scene), non-zero
//       "color": [r, g, b],                          linear RGB, >= 0
//       "intensity": s                               >= 0; irradiance = color * intensity
//     },
//     "shadowMap": {                                 the standard shadow map EXR
//       "lightClipFromWorld": [16 numbers],          orthographic, looking along light.direction
//       "size": [width, height],                     optional: must equal the shadow EXR's size
//       "bias": b                                    optional (default 0): depth-buffer units, reference
//       march
//     },
//     "medium": {                                    homogeneous, per RGB channel, 1 / world unit
//       "mieScattering": [r, g, b],                  Henyey-Greenstein part
//       "hgG": g,                                    optional (default 0), in (-1, 1)
//       "rayleighScattering": [r, g, b],             optional (default 0)
//       "absorption": [r, g, b]                      optional (default 0); extinction must be > 0
//     }
//   }
//
// Ranges: every number is finite and at most 1e30 in magnitude, and so is light.color * light.intensity;
// the inputs must keep the in-scattered radiance below 1e30 (irradiance x scattering x the largest phase
// value x the longest path, 1 / extinction or the far-plane corner distance): the GPU passes compute in
// float. A frame description file is at most 1 MiB; a key may appear once per object; nesting is at most
// 32 levels. Errors name the JSON path (e.g. "light.intensity", "camera.viewFromWorld[12]").
//
// Matrices are 16 numbers in column-major order (as GLSL and glm store them, and as `crep rectify`
// prints them): element k is column k / 4, row k % 4. Unknown fields are errors (a typo must not be
// silently ignored); a field named "comment" is allowed in every object.
#pragma once

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>

#include <glm/glm.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace crep::tool {

/// Largest frame description file readFrameDescription() accepts.
inline constexpr std::uintmax_t kMaxFrameBytes = 1u << 20;

struct FrameDescription {
  glm::dmat4 viewFromWorld{1.0};
  glm::dmat4 clipFromView{1.0};
  std::optional<glm::ivec2> cameraSize;
  ClipDepth clipDepth = ClipDepth::NegativeOneToOne; ///< camera.clipDepth (optional)
  double maxDistance = 0.0;                          ///< camera.maxDistance (optional; 0 = the far plane)
  glm::dvec3 lightDirection{0.0, -1.0, 0.0};
  glm::dvec3 lightColor{1.0};
  double lightIntensity = 1.0;
  glm::dmat4 lightClipFromWorld{1.0};
  std::optional<glm::ivec2> shadowSize;
  double shadowBias = 0.0;
  glm::dvec3 mieScattering{0.0};
  double hgG = 0.0;
  glm::dvec3 rayleighScattering{0.0};
  glm::dvec3 absorption{0.0};
};

/// Parses `text`; throws crep::FormatError "<source>: <field>: <problem>" for malformed JSON (with line
/// and column), a missing or unknown field, or a value of the wrong type, count or domain.
FrameDescription parseFrameDescription(const std::string& text, const std::string& source);
/// Reads and parses a file; IoError naming it if it cannot be read.
FrameDescription readFrameDescription(const std::filesystem::path& path);
/// The description as JSON (the schema above; full double precision, so it reads back exactly).
std::string toJson(const FrameDescription& frame);

/// The camera of camera.viewFromWorld, camera.clipFromView, camera.clipDepth and camera.maxDistance
/// (Camera::fromMatrices); FormatError naming the field when the view is not a rigid transform or the
/// projection not a perspective one. `source` prefixes messages. The depth EXR holds the depth-buffer
/// values of that projection (cleared to 1, or to 0 with reversed-Z).
Camera cameraOf(const FrameDescription& frame, const std::string& source);
/// light.direction, color * intensity; FormatError naming the field.
DirectionalLight lightOf(const FrameDescription& frame, const std::string& source);
/// The medium; FormatError naming the field (e.g. medium.hgG outside (-1, 1), zero extinction).
Medium mediumOf(const FrameDescription& frame, const std::string& source);

} // namespace crep::tool
