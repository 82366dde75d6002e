// The JSON frame description of `crep scatter` (users' own data) and `crep render --export-frame`.
// Schema (docs/FORMATS.md, "The frame description"; example: examples/data/frame.json):
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
//                                                    else the far plane by default, and a larger value is
//                                                    clamped to the far plane
//       "size": [width, height]                      optional: must equal the depth EXR's size
//     },
//     "light": {                                     the main light (its shadow map: --shadow)
//       "type": "directional",                       optional: "directional" (default), "spot", "point"
//       "direction": [x, y, z],                      the direction light travels (sun -> scene), non-zero
//       "color": [r, g, b],                          linear RGB, >= 0
//       "intensity": s,                              >= 0; irradiance = color * intensity
//       "texture": "window.exr",                     optional light texture (below)
//       "textureClipFromWorld": [16 numbers]         optional (below)
//     },
//     "shadowMap": {                                 the standard shadow map EXR
//       "lightClipFromWorld": [16 numbers],          orthographic, looking along light.direction
//       "size": [width, height],                     optional: must equal the shadow EXR's size
//       "bias": b                                    optional (default 0): depth-buffer units, reference
//       march
//     },
//     "lights": [ {local light}, ... ],              optional: ADDITIONAL spot / point lights (below),
//                                                    each with its own shadow EXR; summed with the main
//                                                    light's result
//     "medium": {                                    homogeneous, per RGB channel, 1 / world unit
//       "mieScattering": [r, g, b],                  Henyey-Greenstein part
//       "hgG": g,                                    optional (default 0), in (-1, 1)
//       "rayleighScattering": [r, g, b],             optional (default 0)
//       "absorption": [r, g, b]                      optional (default 0); extinction must be > 0
//     }
//   }
//
// Local lights (Klehm et al. 2014, Sec. 3.2 "Local Lights"; crep::SpotLight, crep::PointLight). The main
// light with "type": "spot" or "point", or an entry of "lights" (where "type" is required and "directional"
// is an error):
//   spot:  "position": [x, y, z], "direction": [x, y, z] (the cone's axis, non-zero),
//          "innerConeDeg", "outerConeDeg": half angles in degrees, 0 < inner < outer < 90 (full intensity
//          inside inner, the falloff s(t) = t^2 (3 - 2t) between them, nothing beyond outer),
//          "color": [r, g, b] >= 0 (one channel > 0), "intensity": > 0, the radiant intensity on the axis per
//          unit colour (W / sr): the radiance of a view ray is the integral of exp(-sigma t) sigma_s p(theta)
//          color * intensity * s(angle) exp(-sigma d) / d^2 dt over its lit parts (d: distance to the light,
//          clamped below at nearPlane; crep/scatter/ray_scattering.h),
//          "nearPlane", "range": optional, 0 < nearPlane < range; default: the distances from the light to
//          the near (depth 0) and far (depth 1) planes of the shadow matrix (range is required if its far
//          plane is infinite).
//          Shadow map: "lightClipFromWorld" is a perspective matrix (GL conventions: NDC z in [-1, 1],
//          depth-buffer value = z / w * 0.5 + 0.5, 0 at its near plane) whose centre of projection is
//          "position" (within 1e-4 max(1, |position|)) and that has the axis in front; any field of view
//          or aspect (it must cover the outer cone). The EXR holds its depth-buffer values, any size.
//   point: "position", "color", "intensity" as above, "nearPlane" and "range" optional (default: the
//          nearest near plane and the farthest far plane of the six face matrices; without
//          faceClipFromWorld, range is required and nearPlane defaults to range * 1e-3).
//          Shadow map: six faces k = 0..5 = +X, -X, +Y, -Y, +Z, -Z stacked top to bottom in one EXR of
//          width S and height 6 S: EXR rows [k S, (k + 1) S) (row 0 = the top of the file) are face k, each
//          in the usual image orientation (its top row first: EXR row k S + r is the face's texel row
//          S - 1 - r counted from the bottom, v = (S - 1 - r + 0.5) / S). "faceClipFromWorld": optional
//          array of six matrices (each perspective, centred at "position", GL conventions as above);
//          default crep::PointLight::faceClipFromWorld(k) = perspectiveRH_NO(90 degrees, aspect 1,
//          nearPlane, range) * lookAtRH(position, position + axis_k, up_k) with axis_k the face's axis and
//          up_k = +Z for the X faces, +X for the Y faces, +Y for the Z faces (glm's functions).
//   The main light's shadow matrices are in the top-level "shadowMap" (spot: "lightClipFromWorld"; point:
//   "faceClipFromWorld"; both: "size", "bias"); an entry of "lights" has its own:
//     "shadowMap": {"file": "path.exr" (relative to the JSON file's directory), "lightClipFromWorld" (spot)
//     or
//                   "faceClipFromWorld" (point, optional), "size" (optional), "bias" (optional, default 0)}.
//   A shadow map whose every texel is 0 (the light inside an occluder) is an error naming its file.
//
// Light textures (optional; crep/scatter/light_texture.h; Klehm et al. 2014, Sec. 3.2): an RGB texture
// projected from the light multiplies its colour per light ray (a stained-glass window over the sun, a gobo
// on a spot). In "light" (directional or spot) and in a spot entry of "lights":
//   "texture": "file.exr"        an EXR path relative to the JSON file's directory: linear RGB (channels R,
//                                G, B, optionally A, which is ignored), every value finite and >= 0 (values
//                                above 1 brighten). Row convention as the tool's other EXRs: the file's
//                                first (top) row is the texture's top, texture coordinate v = 1 (OpenGL
//                                texel row H - 1), its last row v = 0; column 0 is u = 0.
//   "textureClipFromWorld": [16] optional, column-major: world -> the texture's clip space (NDC x, y in
//                                [-1, 1] cover the texture; behind a projector, clip w <= 0, no light;
//                                outside [-1, 1] the edge texels continue). It must project along the
//                                light's rays (crep::validateLightProjection): orthographic along
//                                light.direction for the directional light, perspective centred at
//                                "position" for a spot. Default: the light's shadow matrix
//                                (shadowMap.lightClipFromWorld, or the entry's), which does.
//   A point light with "texture" or "textureClipFromWorld" is an error naming the field (not supported).
//
// Ranges: every number is finite and at most 1e30 in magnitude, and so is light.color * light.intensity;
// the inputs must keep the in-scattered radiance below 1e30 (irradiance x scattering x the largest phase
// value x the longest path, 1 / extinction or the far-plane corner distance): the GPU passes compute in
// float. A frame description file is at most 1 MiB; a key may appear once per object; nesting is at most
// 32 levels. Errors name the JSON path (e.g. "light.intensity", "camera.viewFromWorld[12]",
// "lights[2].outerConeDeg"). For local lights the radiance bound is color * intensity x scattering x the
// largest phase value x pi / nearPlane (the integral of 1 / d^2 along any line), summed over the lights.
//
// Matrices are 16 numbers in column-major order (as GLSL and glm store them, and as `crep rectify`
// prints them): element k is column k / 4, row k % 4. Unknown fields are errors (a typo must not be
// silently ignored); a field named "comment" is allowed in every object.
#pragma once

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace crep::tool {

/// Largest frame description file readFrameDescription() accepts.
inline constexpr std::uintmax_t kMaxFrameBytes = 1u << 20;

/// light.type / lights[i].type.
enum class LightType { Directional, Spot, Point };
/// "directional", "spot", "point".
const char* lightTypeToken(LightType type);

/// A spot or point light of a frame description: the main light (light.type "spot" / "point", its shadow map
/// in the top-level shadowMap object and the --shadow EXR) or an entry of "lights" (its own shadowMap object
/// and file). Angles in degrees as in the file.
struct LocalLightDescription {
  LightType type = LightType::Spot;
  glm::dvec3 position{0.0};
  glm::dvec3 direction{0.0, 0.0, -1.0};            ///< spot: the cone's axis
  double innerConeDeg = 20.0, outerConeDeg = 30.0; ///< spot
  glm::dvec3 color{1.0};
  double intensity = 1.0;
  std::optional<double> nearPlane, range; ///< absent: from the shadow matrices (frame_json.h top)
  std::string shadowFile;                 ///< lights[i].shadowMap.file as written; empty for the main light
  glm::dmat4 lightClipFromWorld{1.0};     ///< spot: shadowMap.lightClipFromWorld
  std::optional<std::array<glm::dmat4, 6>> faceClipFromWorld; ///< point: shadowMap.faceClipFromWorld
  std::optional<glm::ivec2> shadowSize;                       ///< shadowMap.size
  double shadowBias = 0.0;                                    ///< shadowMap.bias
  std::string texture; ///< spot: "texture" as written (relative to the JSON file), empty = none
  /// spot: "textureClipFromWorld" (absent: the shadow matrix)
  std::optional<glm::dmat4> textureClipFromWorld;
};

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
  /// light.texture (directional main light) as written, empty = none; a spot main light's is in localLight.
  std::string lightTexture;
  std::optional<glm::dmat4> lightTextureClipFromWorld; ///< light.textureClipFromWorld (directional)
  /// light.type. For Spot / Point the main light is `localLight` (and the directional fields above, with
  /// lightClipFromWorld, shadowSize and shadowBias, are unused: its shadow fields are in localLight).
  LightType lightType = LightType::Directional;
  LocalLightDescription localLight;
  std::vector<LocalLightDescription> lights; ///< "lights" (optional): additional spot / point lights
};

/// A local light of the frame built as the library's light, with the JSON paths of its fields (for messages)
/// and its shadow matrices (one for a spot, six for a point light: face k at k).
struct FrameLocalLight {
  std::string path;       ///< "light" or "lights[i]"
  std::string shadowPath; ///< "shadowMap" or "lights[i].shadowMap"
  std::optional<SpotLight> spot;
  std::optional<PointLight> point;
  std::vector<glm::dmat4> lightClipFromWorld; ///< 1 (spot) or 6 (point) matrices
  double shadowBias = 0.0;
  std::optional<glm::ivec2> shadowSize;
  std::string shadowFile;                ///< as written in the JSON (empty for the main light: --shadow)
  std::string texture;                   ///< spot: its light texture as written in the JSON (empty = none)
  glm::dmat4 textureClipFromWorld{1.0};  ///< spot: the texture's projection (given, or the shadow matrix)
  bool textureDefaultProjection = false; ///< textureClipFromWorld was absent (the shadow matrix)
};

/// A light texture of the frame (frame_json.h "Light textures"): the directional light's or a spot's.
struct FrameLightTexture {
  std::string path;                     ///< JSON path of the light: "light" or "lights[i]"
  std::string file;                     ///< "texture" as written (relative to the JSON file)
  glm::dmat4 textureClipFromWorld{1.0}; ///< given, or the light's shadow matrix
  bool defaultProjection = false;       ///< textureClipFromWorld was absent (the shadow matrix)
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
/// light.direction, color * intensity; FormatError naming the field. Only for a directional main light
/// (light.type absent or "directional"): FormatError naming light.type otherwise.
DirectionalLight lightOf(const FrameDescription& frame, const std::string& source);
/// The spot and point lights of the frame, the main light first when it is one, then "lights" in order;
/// nearPlane and range defaulted from the shadow matrices (frame_json.h top). FormatError naming the field.
std::vector<FrameLocalLight> localLightsOf(const FrameDescription& frame, const std::string& source);
/// The directional main light's texture (frame_json.h "Light textures"), if any; FormatError naming
/// light.textureClipFromWorld when its projection is not along light.direction.
std::optional<FrameLightTexture> lightTextureOf(const FrameDescription& frame, const std::string& source);
/// A spot's texture (localLightsOf's `light`), if any; FormatError naming <path>.textureClipFromWorld when
/// its projection is not centred at the spot.
std::optional<FrameLightTexture> lightTextureOf(const FrameLocalLight& light, const std::string& source);
/// Reads a light texture EXR (frame_json.h "Light textures"): an RGB image (3 channels, the alpha of an RGBA
/// file dropped), row 0 at the bottom (Image convention). IoError / FormatError naming `field` (the JSON
/// path, e.g. "light.texture") and the file: missing, unreadable, not an EXR, not R, G, B channels, a texel
/// NaN, infinite or negative (its position from the top-left, as a viewer shows it).
Image readLightTexture(const std::filesystem::path& file, const std::string& field,
                       const std::string& source);

/// The medium; FormatError naming the field (e.g. medium.hgG outside (-1, 1), zero extinction).
Medium mediumOf(const FrameDescription& frame, const std::string& source);

} // namespace crep::tool
