#include "frame_json.h"

#include <crep/core/error.h>
#include <crep/core/image.h>
#include <crep/scatter/light_texture.h>
#include <crep/support/exr.h>

#include <nlohmann/json.hpp>

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <set>
#include <sstream>
#include <vector>

namespace crep::tool {

namespace {

using Json = nlohmann::json;

const char* typeName(const Json& j) {
  return j.type_name();
}

/// Largest magnitude of any number of a frame description (frame_json.h).
constexpr double kMaxMagnitude = 1e30;
/// Largest in-scattered radiance the inputs may produce (frame_json.h "Ranges").
constexpr double kMaxRadiance = 1e30;
/// Deepest nesting of arrays and objects accepted (the schema needs 3).
constexpr int kMaxDepth = 32;

/// Field access with messages "<source>: <path>: <problem>".
class Reader {
public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& path, const std::string& problem) const {
    throw FormatError(source_ + ": " + path + ": " + problem);
  }

  /// Checks that `object` (at `path`) is an object with only the `allowed` keys (and "comment").
  void requireObject(const Json& object, const std::string& path,
                     std::initializer_list<const char*> allowed) const {
    if (!object.is_object())
      fail(path.empty() ? "(top level)" : path, std::string("expected an object, got ") + typeName(object));
    for (const auto& [key, value] : object.items()) {
      if (key == "comment") continue;
      bool known = false;
      std::string list;
      for (const char* a : allowed) {
        known = known || key == a;
        list += (list.empty() ? "" : ", ") + std::string(a);
      }
      if (!known) fail(join(path, key), "unknown field (expected " + list + ")");
    }
  }

  const Json* find(const Json& object, const std::string& key) const {
    const auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
  }
  const Json& get(const Json& object, const std::string& path, const std::string& key) const {
    const Json* j = find(object, key);
    if (!j) fail(join(path, key), "missing");
    return *j;
  }

  double number(const Json& j, const std::string& path) const {
    if (!j.is_number()) fail(path, std::string("expected a number, got ") + typeName(j));
    const double v = j.get<double>();
    if (!std::isfinite(v)) fail(path, "not a finite number");
    if (std::abs(v) > kMaxMagnitude)
      fail(path, format(v) + " is beyond +-" + format(kMaxMagnitude) +
                     " (the GPU passes compute in float: results must stay far below 3.4e38)");
    return v;
  }

  std::vector<double> numbers(const Json& j, const std::string& path, std::size_t count,
                              const char* what) const {
    if (!j.is_array() || j.size() != count)
      fail(path, "expected an array of " + std::to_string(count) + " numbers (" + what + "), got " +
                     (j.is_array() ? std::to_string(j.size()) + " elements" : std::string(typeName(j))));
    std::vector<double> v;
    for (std::size_t i = 0; i < count; ++i)
      v.push_back(number(j[i], path + "[" + std::to_string(i) + "]"));
    return v;
  }

  glm::dvec3 vec3(const Json& j, const std::string& path, const char* what) const {
    const auto v = numbers(j, path, 3, what);
    return {v[0], v[1], v[2]};
  }

  glm::dmat4 mat4(const Json& j, const std::string& path) const {
    const auto v = numbers(j, path, 16, "column-major 4x4 matrix");
    glm::dmat4 m;
    for (int k = 0; k < 16; ++k)
      m[k / 4][k % 4] = v[static_cast<std::size_t>(k)];
    return m;
  }

  glm::ivec2 size(const Json& j, const std::string& path) const {
    const auto v = numbers(j, path, 2, "[width, height] in pixels");
    glm::ivec2 s;
    for (int i = 0; i < 2; ++i) {
      const double x = v[static_cast<std::size_t>(i)];
      if (x != std::floor(x) || x < 1 || x > Image::kMaxDimension)
        fail(path,
             "expected whole numbers in [1, " + std::to_string(Image::kMaxDimension) + "], got " + format(x));
      s[i] = static_cast<int>(x);
    }
    return s;
  }

  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }
  static std::string format(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
  }
  const std::string& source() const { return source_; }

private:
  std::string source_;
};

/// A SAX pass over the text before the DOM parse: it knows the JSON path of every token, so a number
/// that overflows a double, a duplicate key, nesting beyond kMaxDepth and syntax errors are reported with
/// the path (and line and column) instead of the parser's internal message.
class PathChecker final : public nlohmann::json_sax<Json> {
public:
  PathChecker(const std::string& text, const std::string& source) : text_(text), source_(source) {}

  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(number_integer_t) override { return value(); }
  bool number_unsigned(number_unsigned_t) override { return value(); }
  bool number_float(number_float_t, const string_t&) override { return value(); }
  bool string(string_t&) override { return value(); }
  bool binary(binary_t&) override { return value(); }
  bool start_object(std::size_t) override { return open(false); }
  bool start_array(std::size_t) override { return open(true); }
  bool end_object() override { return close(); }
  bool end_array() override { return close(); }
  bool key(string_t& k) override {
    Level& l = stack_.back();
    if (!l.keys.insert(k).second)
      throw FormatError(source_ + ": " + join(path(stack_.size() - 1), k) +
                        ": duplicate key (each field may appear once)");
    l.key = k;
    return true;
  }
  bool parse_error(std::size_t position, const std::string& token,
                   const nlohmann::detail::exception& e) override {
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i + 1 < position && i < text_.size(); ++i) {
      if (text_[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    const std::string where = path().empty() ? "(top level)" : path();
    const std::string at = " (line " + std::to_string(line) + ", column " + std::to_string(column) + ")";
    if (e.id == 406) // number overflow
      throw FormatError(source_ + ": " + where + ": number '" + token + "' is beyond the range of a double" +
                        at);
    throw FormatError(source_ + ": not valid JSON at " + where + at + ": " + e.what());
  }

private:
  struct Level {
    bool array = false;
    std::size_t index = 0;
    std::string key;
    std::set<std::string> keys;
  };

  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }
  /// The path of the current position through the outermost `levels` levels (all by default).
  std::string path(std::size_t levels = std::numeric_limits<std::size_t>::max()) const {
    std::string p;
    for (std::size_t i = 0; i < stack_.size() && i < levels; ++i)
      p = stack_[i].array ? p + "[" + std::to_string(stack_[i].index) + "]" : join(p, stack_[i].key);
    return p;
  }
  bool value() {
    if (!stack_.empty() && stack_.back().array) ++stack_.back().index;
    return true;
  }
  bool open(bool array) {
    if (static_cast<int>(stack_.size()) >= kMaxDepth)
      throw FormatError(source_ + ": " + (path().empty() ? "(top level)" : path()) + ": nested deeper than " +
                        std::to_string(kMaxDepth) + " levels");
    stack_.push_back({array, 0, {}, {}});
    return true;
  }
  bool close() {
    stack_.pop_back();
    return value();
  }

  const std::string& text_;
  const std::string& source_;
  std::vector<Level> stack_;
};

std::string formatVec(const glm::dvec3& v) {
  return "[" + Reader::format(v.x) + ", " + Reader::format(v.y) + ", " + Reader::format(v.z) + "]";
}
std::string formatMat(const glm::dmat4& m) {
  std::string s = "[";
  for (int k = 0; k < 16; ++k)
    s += (k ? ", " : "") + Reader::format(m[k / 4][k % 4]);
  return s + "]";
}

std::string formatSize(const glm::ivec2& v) {
  return "[" + std::to_string(v.x) + ", " + std::to_string(v.y) + "]";
}

std::string indexPath(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

/// light.type / lights[i].type: "directional" (default where absent and allowed), "spot" or "point".
LightType parseLightType(const Reader& r, const Json& light, const std::string& path, bool inLights) {
  const Json* t = r.find(light, "type");
  if (!t) {
    if (inLights) r.fail(Reader::join(path, "type"), "missing (\"spot\" or \"point\")");
    return LightType::Directional;
  }
  if (t->is_string()) {
    if (*t == "directional" && !inLights) return LightType::Directional;
    if (*t == "spot") return LightType::Spot;
    if (*t == "point") return LightType::Point;
  }
  if (inLights && t->is_string() && *t == "directional")
    r.fail(Reader::join(path, "type"),
           "\"directional\" is not allowed here: \"lights\" holds spot and point lights (the directional "
           "light is the main \"light\")");
  r.fail(Reader::join(path, "type"),
         std::string("must be ") +
             (inLights ? "\"spot\" or \"point\"" : "\"directional\", \"spot\" or \"point\"") + ", got " +
             t->dump());
}

/// "texture" and "textureClipFromWorld" of a light object at `path` (frame_json.h "Light textures").
void parseTexture(const Reader& r, const Json& j, const std::string& path, std::string& file,
                  std::optional<glm::dmat4>& matrix) {
  if (const Json* t = r.find(j, "texture")) {
    if (!t->is_string() || t->get<std::string>().empty())
      r.fail(Reader::join(path, "texture"),
             "expected a non-empty EXR file name (relative to the JSON file), got " + t->dump());
    file = t->get<std::string>();
  }
  if (const Json* m = r.find(j, "textureClipFromWorld")) {
    matrix = r.mat4(*m, Reader::join(path, "textureClipFromWorld"));
    if (file.empty())
      r.fail(Reader::join(path, "textureClipFromWorld"),
             "given without " + Reader::join(path, "texture") + " (the texture it projects)");
  }
}

/// The fields of a spot or point light (frame_json.h "Local lights"), without its shadow map.
LocalLightDescription parseLocalLight(const Reader& r, const Json& j, const std::string& path, LightType type,
                                      bool inLights) {
  if (type == LightType::Point && j.is_object())
    for (const char* key : {"texture", "textureClipFromWorld"})
      if (r.find(j, key))
        r.fail(Reader::join(path, key), "light textures are not supported for point lights (only for the "
                                        "directional light and spot lights)");
  if (type == LightType::Spot) {
    if (inLights)
      r.requireObject(j, path,
                      {"type", "position", "direction", "innerConeDeg", "outerConeDeg", "color", "intensity",
                       "nearPlane", "range", "shadowMap", "texture", "textureClipFromWorld"});
    else
      r.requireObject(j, path,
                      {"type", "position", "direction", "innerConeDeg", "outerConeDeg", "color", "intensity",
                       "nearPlane", "range", "texture", "textureClipFromWorld"});
  } else if (inLights) {
    r.requireObject(j, path, {"type", "position", "color", "intensity", "nearPlane", "range", "shadowMap"});
  } else {
    r.requireObject(j, path, {"type", "position", "color", "intensity", "nearPlane", "range"});
  }
  const auto field = [&](const char* key) { return Reader::join(path, key); };
  LocalLightDescription d;
  d.type = type;
  d.position = r.vec3(r.get(j, path, "position"), field("position"), "x, y, z: the light's position");
  if (type == LightType::Spot) {
    d.direction = r.vec3(r.get(j, path, "direction"), field("direction"), "x, y, z: the cone's axis");
    d.innerConeDeg = r.number(r.get(j, path, "innerConeDeg"), field("innerConeDeg"));
    d.outerConeDeg = r.number(r.get(j, path, "outerConeDeg"), field("outerConeDeg"));
  }
  d.color = r.vec3(r.get(j, path, "color"), field("color"), "linear r, g, b");
  d.intensity = r.number(r.get(j, path, "intensity"), field("intensity"));
  if (const Json* n = r.find(j, "nearPlane")) d.nearPlane = r.number(*n, field("nearPlane"));
  if (const Json* n = r.find(j, "range")) d.range = r.number(*n, field("range"));
  if (type == LightType::Spot) parseTexture(r, j, path, d.texture, d.textureClipFromWorld);
  return d;
}

/// The shadowMap object of a local light: the top-level one of the main light (no "file") or lights[i]'s.
void parseLocalShadow(const Reader& r, const Json& j, const std::string& path, LocalLightDescription& d,
                      bool inLights) {
  const bool spot = d.type == LightType::Spot;
  if (inLights)
    r.requireObject(j, path, {"file", spot ? "lightClipFromWorld" : "faceClipFromWorld", "size", "bias"});
  else
    r.requireObject(j, path, {spot ? "lightClipFromWorld" : "faceClipFromWorld", "size", "bias"});
  const auto field = [&](const char* key) { return Reader::join(path, key); };
  if (inLights) {
    const Json& file = r.get(j, path, "file");
    if (!file.is_string() || file.get<std::string>().empty())
      r.fail(field("file"), "expected a non-empty file name (relative to the JSON file), got " + file.dump());
    d.shadowFile = file.get<std::string>();
  }
  if (spot) {
    d.lightClipFromWorld = r.mat4(r.get(j, path, "lightClipFromWorld"), field("lightClipFromWorld"));
  } else if (const Json* faces = r.find(j, "faceClipFromWorld")) {
    if (!faces->is_array() || faces->size() != 6)
      r.fail(field("faceClipFromWorld"),
             "expected an array of 6 matrices (faces +X, -X, +Y, -Y, +Z, -Z), got " +
                 (faces->is_array() ? std::to_string(faces->size()) + " elements"
                                    : std::string(typeName(*faces))));
    std::array<glm::dmat4, 6> m;
    for (std::size_t k = 0; k < 6; ++k)
      m[k] = r.mat4((*faces)[k], indexPath(field("faceClipFromWorld"), k));
    d.faceClipFromWorld = m;
  }
  if (const Json* s = r.find(j, "size")) d.shadowSize = r.size(*s, field("size"));
  if (const Json* b = r.find(j, "bias")) d.shadowBias = r.number(*b, field("bias"));
}

/// Row i of m (m[column][row]).
glm::dvec4 row(const glm::dmat4& m, int i) {
  return {m[0][i], m[1][i], m[2][i], m[3][i]};
}

/// The centre of projection of a perspective matrix: the point c with clip x = y = w = 0, i.e. rows 0, 1 and
/// 3 of m applied to (c, 1) vanish (the light's position for a perspective shadow matrix); none for an
/// orthographic or singular matrix.
std::optional<glm::dvec3> centreOfProjection(const glm::dmat4& m) {
  glm::dmat3 a; // a[column][row]: rows 0, 1, 3 of m without the translation
  glm::dvec3 b;
  const int rows[3] = {0, 1, 3};
  double scale = 0.0;
  for (int i = 0; i < 3; ++i) {
    const glm::dvec4 rw = row(m, rows[i]);
    for (int c = 0; c < 3; ++c)
      a[c][i] = rw[c];
    b[i] = -rw.w;
    scale = std::max(scale, glm::length(glm::dvec3(rw)));
  }
  const double det = glm::determinant(a);
  if (!(std::abs(det) > 1e-12 * scale * scale * scale)) return std::nullopt;
  const glm::dvec3 c = glm::inverse(a) * b;
  if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) return std::nullopt;
  return c;
}

/// Distance from p to the plane where the depth-buffer value of m is `depth` (0: near, 1: far; GL clip z in
/// [-w, w]); infinity when the plane is at infinity.
double depthPlaneDistance(const glm::dmat4& m, const glm::dvec3& p, double depth) {
  // NDC z = 2 depth - 1: clip z - (2 depth - 1) w = 0.
  const glm::dvec4 plane = row(m, 2) - (2.0 * depth - 1.0) * row(m, 3);
  const double n = glm::length(glm::dvec3(plane));
  if (!(n > 1e-12 * glm::length(glm::dvec3(row(m, 3))))) return std::numeric_limits<double>::infinity();
  return std::abs(glm::dot(plane, glm::dvec4(p, 1.0))) / n;
}

/// Checks a local light's perspective shadow matrix at `path`: a perspective projection centred at `position`
/// with `towards` (a direction the light shines in) in front; returns its near and far plane distances.
glm::dvec2 checkLocalMatrix(const Reader& r, const glm::dmat4& m, const std::string& path,
                            const glm::dvec3& position, const glm::dvec3& towards,
                            const std::string& positionPath) {
  const std::optional<glm::dvec3> c = centreOfProjection(m);
  if (!c)
    r.fail(path,
           "not a perspective projection (no centre of projection: an orthographic or singular matrix); "
           "a local light's shadow matrix is a perspective one centred at the light");
  const double tolerance = 1e-4 * std::max(1.0, glm::length(position));
  if (!(glm::length(*c - position) <= tolerance))
    r.fail(path, "its centre of projection (" + Reader::format(c->x) + ", " + Reader::format(c->y) + ", " +
                     Reader::format(c->z) + ") is not " + positionPath + " (" + Reader::format(position.x) +
                     ", " + Reader::format(position.y) + ", " + Reader::format(position.z) + ")");
  if (!(glm::dot(row(m, 3), glm::dvec4(position + glm::normalize(towards), 1.0)) > 0.0))
    r.fail(path, "the light's direction is behind its centre of projection (clip w <= 0 along it)");
  const double near = depthPlaneDistance(m, position, 0.0), far = depthPlaneDistance(m, position, 1.0);
  if (!(near > 0.0 && near < far))
    r.fail(path, "near plane " + Reader::format(near) + ", far plane " + Reader::format(far) +
                     ": expected OpenGL depth conventions (depth-buffer value 0 at the near plane, 1 at the "
                     "far plane, 0 < near < far)");
  return {near, far};
}

/// The map of `m` covers `directions` from `position` (in front, NDC x and y within [-1, 1] up to 1e-3, as
/// crep::Scattering requires of the maps it is given): FormatError at `path` naming `what` otherwise.
void checkCoverage(const Reader& r, const glm::dmat4& m, const std::string& path, const glm::dvec3& position,
                   const std::vector<glm::dvec3>& directions, const std::string& what) {
  const double t = std::max(1.0, glm::length(position));
  for (const glm::dvec3& d : directions) {
    const glm::dvec4 q = m * glm::dvec4(position + t * glm::normalize(d), 1.0);
    if (!(q.w > 0.0) || !(std::abs(q.x / q.w) <= 1.001 && std::abs(q.y / q.w) <= 1.001))
      r.fail(path, "does not cover " + what + ": direction " + formatVec(glm::normalize(d)) +
                       " from the light is outside the map");
  }
}

/// Directions a local light's map must cover: a spot's outer cone (its axis and 32 directions on the cone),
/// point-light face k's sector (its axis and the four corners, |w_j| <= |w_axis|).
std::vector<glm::dvec3> coverageDirections(const LocalLightDescription& d, int face) {
  std::vector<glm::dvec3> dirs;
  if (d.type == LightType::Spot) {
    const glm::dvec3 axis = glm::normalize(d.direction), u = anyOrthogonal(axis), v = glm::cross(axis, u);
    const double a = d.outerConeDeg * std::numbers::pi / 180.0;
    dirs.push_back(axis);
    for (int j = 0; j < 32; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / 32.0;
      dirs.push_back(std::cos(a) * axis + std::sin(a) * (std::cos(phi) * u + std::sin(phi) * v));
    }
    return dirs;
  }
  const glm::dvec3 axis = PointLight::faceAxis(face);
  glm::dvec3 e1(0.0), e2(0.0);
  e1[(face / 2 + 1) % 3] = 1.0;
  e2[(face / 2 + 2) % 3] = 1.0;
  dirs.push_back(axis);
  for (const double s1 : {-1.0, 1.0})
    for (const double s2 : {-1.0, 1.0})
      dirs.push_back(axis + s1 * e1 + s2 * e2);
  return dirs;
}

/// Every domain check of a local light description at `path` (its shadow map at `shadowPath`).
void checkLocalLight(const Reader& r, const LocalLightDescription& d, const std::string& path,
                     const std::string& shadowPath) {
  const auto field = [&](const char* key) { return Reader::join(path, key); };
  for (int c = 0; c < 3; ++c)
    if (d.color[c] < 0.0) r.fail(field("color"), "components must be >= 0");
  if (!(std::max({d.color.x, d.color.y, d.color.z}) > 0.0))
    r.fail(field("color"), "at least one component must be > 0 for a local light");
  if (!(d.intensity > 0.0)) r.fail(field("intensity"), "must be > 0 for a local light");
  for (int c = 0; c < 3; ++c)
    if (d.color[c] * d.intensity > kMaxMagnitude)
      r.fail(field("intensity"), "color * intensity = " + Reader::format(d.color[c] * d.intensity) +
                                     " is beyond " + Reader::format(kMaxMagnitude));
  if (d.type == LightType::Spot) {
    if (d.direction == glm::dvec3(0.0)) r.fail(field("direction"), "must not be zero");
    if (!(d.innerConeDeg > 0.0 && d.innerConeDeg < 90.0))
      r.fail(field("innerConeDeg"), Reader::format(d.innerConeDeg) + " is not in (0, 90) degrees");
    if (!(d.outerConeDeg > 0.0 && d.outerConeDeg < 90.0))
      r.fail(field("outerConeDeg"), Reader::format(d.outerConeDeg) + " is not in (0, 90) degrees");
    if (!(d.innerConeDeg < d.outerConeDeg))
      r.fail(field("outerConeDeg"), Reader::format(d.outerConeDeg) + " must be greater than innerConeDeg (" +
                                        Reader::format(d.innerConeDeg) + ")");
  }
  if (d.nearPlane && !(*d.nearPlane > 0.0)) r.fail(field("nearPlane"), "must be > 0");
  if (d.range && !(*d.range > 0.0)) r.fail(field("range"), "must be > 0");
  if (d.nearPlane && d.range && !(*d.nearPlane < *d.range))
    r.fail(field("nearPlane"),
           Reader::format(*d.nearPlane) + " must be below range (" + Reader::format(*d.range) + ")");
  if (d.type == LightType::Spot) {
    const std::string matrix = Reader::join(shadowPath, "lightClipFromWorld");
    checkLocalMatrix(r, d.lightClipFromWorld, matrix, d.position, d.direction, field("position"));
    checkCoverage(r, d.lightClipFromWorld, matrix, d.position, coverageDirections(d, -1),
                  "the outer cone (" + field("outerConeDeg") + ")");
  } else if (d.faceClipFromWorld) {
    for (std::size_t k = 0; k < 6; ++k) {
      const std::string matrix = indexPath(Reader::join(shadowPath, "faceClipFromWorld"), k);
      checkLocalMatrix(r, (*d.faceClipFromWorld)[k], matrix, d.position,
                       PointLight::faceAxis(static_cast<int>(k)), field("position"));
      checkCoverage(r, (*d.faceClipFromWorld)[k], matrix, d.position,
                    coverageDirections(d, static_cast<int>(k)),
                    "face " + std::to_string(k) + "'s sector (+X, -X, +Y, -Y, +Z, -Z)");
    }
  } else if (!d.range) {
    r.fail(field("range"), "missing: required for a point light without shadowMap.faceClipFromWorld (the "
                           "default face matrices are built from it)");
  }
  if (d.type == LightType::Point && d.shadowSize && d.shadowSize->y != 6 * d.shadowSize->x)
    r.fail(Reader::join(shadowPath, "size"),
           formatSize(*d.shadowSize) +
               ": a point light's shadow EXR is S wide and 6 S high (six faces stacked)");
}

} // namespace

FrameDescription parseFrameDescription(const std::string& text, const std::string& source) {
  const Reader r(source);
  // A NUL byte is no JSON text (the parser would stop reading at it and accept what came before).
  if (const std::size_t nul = text.find('\0'); nul != std::string::npos) {
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < nul; ++i) {
      if (text[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    throw FormatError(source + ": not valid JSON at (top level) (line " + std::to_string(line) + ", column " +
                      std::to_string(column) + ", byte " + std::to_string(nul) +
                      "): a NUL byte; a frame description is UTF-8 JSON text");
  }
  Json root;
  PathChecker checker(text, source);
  Json::sax_parse(text, &checker); // throws FormatError with the path; otherwise the text is valid JSON
  try {
    root = Json::parse(text);
  } catch (const Json::exception& e) {
    throw FormatError(source + ": not valid JSON: " + e.what());
  }
  r.requireObject(root, "", {"version", "camera", "light", "shadowMap", "medium", "lights"});
  if (const Json* v = r.find(root, "version"); v && r.number(*v, "version") != 1.0)
    r.fail("version", "unsupported version " + v->dump() + " (this crep reads version 1)");

  FrameDescription f;
  const Json& camera = r.get(root, "", "camera");
  r.requireObject(camera, "camera", {"viewFromWorld", "clipFromView", "size", "clipDepth", "maxDistance"});
  f.viewFromWorld = r.mat4(r.get(camera, "camera", "viewFromWorld"), "camera.viewFromWorld");
  f.clipFromView = r.mat4(r.get(camera, "camera", "clipFromView"), "camera.clipFromView");
  if (const Json* s = r.find(camera, "size")) f.cameraSize = r.size(*s, "camera.size");
  if (const Json* c = r.find(camera, "clipDepth")) {
    if (!c->is_string() || (*c != "negativeOneToOne" && *c != "zeroToOne"))
      r.fail("camera.clipDepth", "must be \"negativeOneToOne\" (OpenGL's default) or \"zeroToOne\" "
                                 "(glClipControl GL_ZERO_TO_ONE, Vulkan, Metal)");
    f.clipDepth = *c == "zeroToOne" ? ClipDepth::ZeroToOne : ClipDepth::NegativeOneToOne;
  }
  if (const Json* m = r.find(camera, "maxDistance")) f.maxDistance = r.number(*m, "camera.maxDistance");

  const Json& light = r.get(root, "", "light");
  f.lightType = parseLightType(r, light, "light", false);
  if (f.lightType != LightType::Directional) {
    f.localLight = parseLocalLight(r, light, "light", f.lightType, false);
    parseLocalShadow(r, r.get(root, "", "shadowMap"), "shadowMap", f.localLight, false);
    checkLocalLight(r, f.localLight, "light", "shadowMap");
  } else {
    r.requireObject(light, "light",
                    {"type", "direction", "color", "intensity", "texture", "textureClipFromWorld"});
    parseTexture(r, light, "light", f.lightTexture, f.lightTextureClipFromWorld);
    f.lightDirection =
        r.vec3(r.get(light, "light", "direction"), "light.direction", "x, y, z: the direction light travels");
    f.lightColor = r.vec3(r.get(light, "light", "color"), "light.color", "linear r, g, b");
    f.lightIntensity = r.number(r.get(light, "light", "intensity"), "light.intensity");
    if (f.lightDirection == glm::dvec3(0.0)) r.fail("light.direction", "must not be zero");
    for (int c = 0; c < 3; ++c)
      if (f.lightColor[c] < 0.0) r.fail("light.color", "components must be >= 0");
    if (f.lightIntensity < 0.0) r.fail("light.intensity", "must be >= 0");
    for (int c = 0; c < 3; ++c)
      if (f.lightColor[c] * f.lightIntensity > kMaxMagnitude)
        r.fail("light.intensity",
               "color * intensity = " + Reader::format(f.lightColor[c] * f.lightIntensity) + " is beyond " +
                   Reader::format(kMaxMagnitude));

    const Json& shadow = r.get(root, "", "shadowMap");
    r.requireObject(shadow, "shadowMap", {"lightClipFromWorld", "size", "bias"});
    f.lightClipFromWorld =
        r.mat4(r.get(shadow, "shadowMap", "lightClipFromWorld"), "shadowMap.lightClipFromWorld");
    if (const Json* s = r.find(shadow, "size")) f.shadowSize = r.size(*s, "shadowMap.size");
    if (const Json* b = r.find(shadow, "bias")) f.shadowBias = r.number(*b, "shadowMap.bias");
  }
  if (const Json* lights = r.find(root, "lights")) {
    if (!lights->is_array())
      r.fail("lights", std::string("expected an array of spot / point lights, got ") + typeName(*lights));
    for (std::size_t i = 0; i < lights->size(); ++i) {
      const std::string path = indexPath("lights", i);
      const Json& entry = (*lights)[i];
      if (!entry.is_object()) r.fail(path, std::string("expected an object, got ") + typeName(entry));
      LocalLightDescription d = parseLocalLight(r, entry, path, parseLightType(r, entry, path, true), true);
      parseLocalShadow(r, r.get(entry, path, "shadowMap"), Reader::join(path, "shadowMap"), d, true);
      checkLocalLight(r, d, path, Reader::join(path, "shadowMap"));
      f.lights.push_back(std::move(d));
    }
  }

  const Json& medium = r.get(root, "", "medium");
  r.requireObject(medium, "medium", {"mieScattering", "hgG", "rayleighScattering", "absorption"});
  f.mieScattering =
      r.vec3(r.get(medium, "medium", "mieScattering"), "medium.mieScattering", "r, g, b per world unit");
  if (const Json* g = r.find(medium, "hgG")) f.hgG = r.number(*g, "medium.hgG");
  if (const Json* v = r.find(medium, "rayleighScattering"))
    f.rayleighScattering = r.vec3(*v, "medium.rayleighScattering", "r, g, b per world unit");
  if (const Json* v = r.find(medium, "absorption"))
    f.absorption = r.vec3(*v, "medium.absorption", "r, g, b per world unit");
  return f;
}

FrameDescription readFrameDescription(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw IoError("cannot read frame description '" + path.string() + "': it is a directory");
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (!ec && bytes > kMaxFrameBytes)
    throw FormatError(path.string() + ": " + std::to_string(bytes) +
                      " bytes; a frame description is at most " + std::to_string(kMaxFrameBytes) +
                      " bytes (1 MiB)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot open frame description '" + path.string() + "'");
  // Bounded read: also for files whose size the file system does not report (pipes).
  std::string text(kMaxFrameBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw IoError("cannot read frame description '" + path.string() + "'");
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > kMaxFrameBytes)
    throw FormatError(path.string() + ": a frame description is at most " + std::to_string(kMaxFrameBytes) +
                      " bytes (1 MiB)");
  return parseFrameDescription(text, path.string());
}

const char* lightTypeToken(LightType type) {
  switch (type) {
  case LightType::Directional:
    return "directional";
  case LightType::Spot:
    return "spot";
  case LightType::Point:
    return "point";
  }
  return "?";
}

namespace {

/// ",\n" + the "texture" and "textureClipFromWorld" fields of a light, when it has a texture.
std::string textureFields(const std::string& file, const std::optional<glm::dmat4>& matrix,
                          const std::string& pad) {
  if (file.empty()) return "";
  std::string s = ",\n" + pad + "\"texture\": " + Json(file).dump();
  if (matrix) s += ",\n" + pad + "\"textureClipFromWorld\": " + formatMat(*matrix);
  return s;
}

/// The fields of a local light (frame_json.h), each line indented by `pad`, without a final newline.
std::string localLightFields(const LocalLightDescription& d, const std::string& pad) {
  std::string s = pad + "\"type\": \"" + lightTypeToken(d.type) + "\",\n";
  s += pad + "\"position\": " + formatVec(d.position) + ",\n";
  if (d.type == LightType::Spot) {
    s += pad + "\"direction\": " + formatVec(d.direction) + ",\n";
    s += pad + "\"innerConeDeg\": " + Reader::format(d.innerConeDeg) + ",\n";
    s += pad + "\"outerConeDeg\": " + Reader::format(d.outerConeDeg) + ",\n";
  }
  s += pad + "\"color\": " + formatVec(d.color) + ",\n";
  s += pad + "\"intensity\": " + Reader::format(d.intensity);
  if (d.nearPlane) s += ",\n" + pad + "\"nearPlane\": " + Reader::format(*d.nearPlane);
  if (d.range) s += ",\n" + pad + "\"range\": " + Reader::format(*d.range);
  return s + textureFields(d.texture, d.textureClipFromWorld, pad);
}

/// The shadowMap fields of a local light (with "file" when it has one), each line indented by `pad`.
std::string localShadowFields(const LocalLightDescription& d, const std::string& pad) {
  std::string s;
  if (!d.shadowFile.empty()) s += pad + "\"file\": " + Json(d.shadowFile).dump() + ",\n";
  if (d.type == LightType::Spot) {
    s += pad + "\"lightClipFromWorld\": " + formatMat(d.lightClipFromWorld) + ",\n";
  } else if (d.faceClipFromWorld) {
    s += pad + "\"faceClipFromWorld\": [\n";
    for (std::size_t k = 0; k < 6; ++k)
      s += pad + "  " + formatMat((*d.faceClipFromWorld)[k]) + (k < 5 ? ",\n" : "\n");
    s += pad + "],\n";
  }
  if (d.shadowSize) s += pad + "\"size\": " + formatSize(*d.shadowSize) + ",\n";
  s += pad + "\"bias\": " + Reader::format(d.shadowBias);
  return s;
}

} // namespace

std::string toJson(const FrameDescription& f) {
  std::string s = "{\n  \"version\": 1,\n  \"camera\": {\n";
  s += "    \"viewFromWorld\": " + formatMat(f.viewFromWorld) + ",\n";
  s += "    \"clipFromView\": " + formatMat(f.clipFromView);
  if (f.cameraSize)
    s +=
        ",\n    \"size\": [" + std::to_string(f.cameraSize->x) + ", " + std::to_string(f.cameraSize->y) + "]";
  if (f.clipDepth == ClipDepth::ZeroToOne) s += ",\n    \"clipDepth\": \"zeroToOne\"";
  if (f.maxDistance != 0.0) s += ",\n    \"maxDistance\": " + Reader::format(f.maxDistance);
  s += "\n  },\n  \"light\": {\n";
  if (f.lightType == LightType::Directional) {
    s += "    \"direction\": " + formatVec(f.lightDirection) + ",\n";
    s += "    \"color\": " + formatVec(f.lightColor) + ",\n";
    s += "    \"intensity\": " + Reader::format(f.lightIntensity);
    s += textureFields(f.lightTexture, f.lightTextureClipFromWorld, "    ");
    s += "\n  },\n  \"shadowMap\": {\n";
    s += "    \"lightClipFromWorld\": " + formatMat(f.lightClipFromWorld);
    if (f.shadowSize)
      s += ",\n    \"size\": [" + std::to_string(f.shadowSize->x) + ", " + std::to_string(f.shadowSize->y) +
           "]";
    s += ",\n    \"bias\": " + Reader::format(f.shadowBias) + "\n  },\n";
  } else {
    LocalLightDescription main = f.localLight;
    main.shadowFile.clear(); // the main light's map is --shadow
    s += localLightFields(main, "    ") + "\n  },\n  \"shadowMap\": {\n";
    s += localShadowFields(main, "    ") + "\n  },\n";
  }
  if (!f.lights.empty()) {
    s += "  \"lights\": [\n";
    for (std::size_t i = 0; i < f.lights.size(); ++i) {
      s += "    {\n" + localLightFields(f.lights[i], "      ") + ",\n      \"shadowMap\": {\n";
      s += localShadowFields(f.lights[i], "        ") + "\n      }\n    }" +
           (i + 1 < f.lights.size() ? ",\n" : "\n");
    }
    s += "  ],\n";
  }
  s += "  \"medium\": {\n";
  s += "    \"mieScattering\": " + formatVec(f.mieScattering) + ",\n";
  s += "    \"hgG\": " + Reader::format(f.hgG) + ",\n";
  s += "    \"rayleighScattering\": " + formatVec(f.rayleighScattering) + ",\n";
  s += "    \"absorption\": " + formatVec(f.absorption) + "\n  }\n}\n";
  return s;
}

Camera cameraOf(const FrameDescription& f, const std::string& source) {
  const Reader r(source);
  // crep::Camera::fromMatrices reads the engine's conventions: clip depth (camera.clipDepth), reversed-Z and
  // an infinite far plane (detected; then camera.maxDistance is required), off-centre projections.
  {
    // A near plane the depth buffer cannot resolve: its projection rounds to an infinite far plane (element
    // 10 = -1 in GL's convention), so name it before fromMatrices asks for a maxDistance.
    const glm::dmat4& p = f.clipFromView;
    const bool no = f.clipDepth == ClipDepth::NegativeOneToOne;
    const double a = no ? 0.5 * (1.0 - p[2][2]) : -p[2][2], b = no ? 0.5 * p[3][2] : p[3][2];
    const double near = b < 0.0 ? (a != 0.0 ? -b / a : 0.0) : (a != 1.0 ? b / (1.0 - a) : 0.0);
    // The far plane (depth 1, or 0 reversed; infinite when the depth row says so, as Camera detects it) and
    // the distance the frame integrates to: maxDistance clamped to a finite far plane (camera.h), else
    // maxDistance itself.
    const double denominator = b < 0.0 ? 1.0 - a : -a;
    const double far =
        std::abs(denominator) <= 1e-12 ? std::numeric_limits<double>::infinity() : b / denominator;
    const bool finiteFar = std::isfinite(far) && far > 0.0;
    const double reach =
        finiteFar ? (f.maxDistance > 0.0 ? std::min(f.maxDistance, far) : far) : f.maxDistance;
    if (near > 0.0 && near < 1e-12 * std::max(1.0, reach)) {
      if (!finiteFar && f.maxDistance > 0.0)
        r.fail("camera.maxDistance",
               Reader::format(f.maxDistance) + " is more than 1e12 times the near plane " +
                   Reader::format(near) +
                   " (near / maxDistance below 1e-12: the depth buffer cannot resolve it)");
      r.fail("camera.clipFromView", "near / far below 1e-12 (near = " + Reader::format(near) +
                                        "): a near plane too small for the depth buffer");
    }
  }
  Camera camera = [&] {
    try {
      return Camera::fromMatrices(f.viewFromWorld, f.clipFromView, f.clipDepth, f.maxDistance);
    } catch (const InvalidArgument& e) {
      const std::string field = e.parameter() == "Camera.viewFromWorld" ? "camera.viewFromWorld"
                                : e.parameter() == "Camera.maxDistance" ? "camera.maxDistance"
                                                                        : "camera.clipFromView";
      std::string what = e.what();
      if (const std::size_t at = what.find(" = "); at != std::string::npos) what = what.substr(at + 3);
      r.fail(field, what);
    }
  }();
  // World coordinates must resolve the near plane: beyond |position| = 1e12 near, double precision no
  // longer separates the frustum corners from the camera (and float GPU math failed long before).
  if (!(glm::length(camera.position()) < 1e12 * camera.near()))
    r.fail("camera.viewFromWorld",
           "camera position at distance " + Reader::format(glm::length(camera.position())) +
               " from the origin is not representable against the near plane " +
               Reader::format(camera.near()) +
               " (|position| must be < 1e12 near): use camera-relative world coordinates");
  if (camera.near() / camera.far() < 1e-12)
    r.fail(camera.far() < camera.projectionFar() ? "camera.maxDistance" : "camera.clipFromView",
           "near / far = " + Reader::format(camera.near() / camera.far()) +
               " below 1e-12: a near plane too small for the depth buffer");
  return camera;
}

DirectionalLight lightOf(const FrameDescription& f, const std::string& source) {
  if (f.lightType != LightType::Directional)
    Reader(source).fail("light.type", std::string("\"") + lightTypeToken(f.lightType) +
                                          "\": not a directional light (see localLightsOf)");
  try {
    return DirectionalLight(f.lightDirection, f.lightColor * f.lightIntensity);
  } catch (const InvalidArgument& e) {
    Reader(source).fail(e.parameter() == "DirectionalLight.direction" ? "light.direction" : "light",
                        e.what());
  }
}

namespace {

/// A local light's nearPlane and range: the description's, else its shadow matrices' (frame_json.h top).
glm::dvec2 nearAndRange(const Reader& r, const LocalLightDescription& d, const std::string& path,
                        const std::string& shadowPath) {
  double near = std::numeric_limits<double>::infinity(), far = 0.0;
  if (d.type == LightType::Spot) {
    const glm::dvec2 p =
        checkLocalMatrix(r, d.lightClipFromWorld, Reader::join(shadowPath, "lightClipFromWorld"), d.position,
                         d.direction, Reader::join(path, "position"));
    near = p.x;
    far = p.y;
  } else if (d.faceClipFromWorld) {
    for (std::size_t k = 0; k < 6; ++k) {
      const glm::dvec2 p = checkLocalMatrix(
          r, (*d.faceClipFromWorld)[k], indexPath(Reader::join(shadowPath, "faceClipFromWorld"), k),
          d.position, PointLight::faceAxis(static_cast<int>(k)), Reader::join(path, "position"));
      near = std::min(near, p.x);
      far = std::max(far, p.y);
    }
  }
  const double range = d.range ? *d.range : far;
  if (!std::isfinite(range))
    r.fail(Reader::join(path, "range"),
           "missing: required when the shadow matrix has an infinite far plane (the light's reach)");
  double nearPlane = d.nearPlane ? *d.nearPlane : std::isfinite(near) ? near : range * 1e-3;
  if (!d.nearPlane && !(nearPlane < range)) nearPlane = range * 1e-3;
  if (!(nearPlane < range))
    r.fail(Reader::join(path, d.nearPlane ? "nearPlane" : "range"),
           "nearPlane " + Reader::format(nearPlane) + " must be below range " + Reader::format(range));
  return {nearPlane, range};
}

/// One local light of the frame as the library's light (localLightsOf).
FrameLocalLight resolveLocalLight(const Reader& r, const LocalLightDescription& d, const std::string& path,
                                  const std::string& shadowPath) {
  FrameLocalLight out;
  out.path = path;
  out.shadowPath = shadowPath;
  out.shadowBias = d.shadowBias;
  out.shadowSize = d.shadowSize;
  out.shadowFile = d.shadowFile;
  out.texture = d.texture;
  out.textureClipFromWorld = d.textureClipFromWorld ? *d.textureClipFromWorld : d.lightClipFromWorld;
  out.textureDefaultProjection = !d.textureClipFromWorld;
  const glm::dvec2 nr = nearAndRange(r, d, path, shadowPath);
  try {
    if (d.type == LightType::Spot) {
      const double toRad = std::numbers::pi / 180.0;
      out.spot.emplace(SpotLightParams{.position = d.position,
                                       .direction = d.direction,
                                       .innerConeAngle = d.innerConeDeg * toRad,
                                       .outerConeAngle = d.outerConeDeg * toRad,
                                       .color = d.color,
                                       .intensity = d.intensity,
                                       .range = nr.y,
                                       .nearPlane = nr.x});
      out.lightClipFromWorld = {d.lightClipFromWorld};
    } else {
      out.point.emplace(PointLightParams{.position = d.position,
                                         .color = d.color,
                                         .intensity = d.intensity,
                                         .range = nr.y,
                                         .nearPlane = nr.x});
      for (int k = 0; k < 6; ++k)
        out.lightClipFromWorld.push_back(d.faceClipFromWorld
                                             ? (*d.faceClipFromWorld)[static_cast<std::size_t>(k)]
                                             : out.point->faceClipFromWorld(k));
    }
  } catch (const InvalidArgument& e) {
    // "SpotLight.innerConeAngle" -> "<path>.innerConeDeg", ...
    std::string key = e.parameter().substr(e.parameter().find('.') + 1);
    if (key == "innerConeAngle") key = "innerConeDeg";
    if (key == "outerConeAngle") key = "outerConeDeg";
    r.fail(Reader::join(path, key), e.what());
  }
  return out;
}

} // namespace

namespace {

/// Runs `check` (crep::validateLightProjection at the field) and turns its InvalidArgument into FormatError
/// naming <path>.textureClipFromWorld (and, when it was absent, the shadow matrix it defaulted to).
template <class Check>
void checkProjection(const Reader& r, const FrameLightTexture& t, const Check& check) {
  const std::string field = Reader::join(t.path, "textureClipFromWorld");
  try {
    check(field);
  } catch (const InvalidArgument& e) {
    std::string what = e.what();
    if (const std::size_t at = what.find(" = "); at != std::string::npos) what = what.substr(at + 3);
    r.fail(field + (t.defaultProjection ? " (default: the light's shadow matrix)" : ""),
           "not along the light's rays: " + what);
  }
}

} // namespace

std::vector<FrameLocalLight> localLightsOf(const FrameDescription& f, const std::string& source) {
  const Reader r(source);
  std::vector<FrameLocalLight> lights;
  if (f.lightType != LightType::Directional)
    lights.push_back(resolveLocalLight(r, f.localLight, "light", "shadowMap"));
  for (std::size_t i = 0; i < f.lights.size(); ++i)
    lights.push_back(
        resolveLocalLight(r, f.lights[i], indexPath("lights", i), indexPath("lights", i) + ".shadowMap"));
  return lights;
}

std::optional<FrameLightTexture> lightTextureOf(const FrameDescription& f, const std::string& source) {
  if (f.lightType != LightType::Directional || f.lightTexture.empty()) return std::nullopt;
  FrameLightTexture t{"light", f.lightTexture,
                      f.lightTextureClipFromWorld ? *f.lightTextureClipFromWorld : f.lightClipFromWorld,
                      !f.lightTextureClipFromWorld};
  const DirectionalLight light = lightOf(f, source);
  checkProjection(Reader(source), t, [&](const std::string& field) {
    validateLightProjection(t.textureClipFromWorld, light, field);
  });
  return t;
}

std::optional<FrameLightTexture> lightTextureOf(const FrameLocalLight& l, const std::string& source) {
  if (l.texture.empty()) return std::nullopt;
  if (!l.spot)
    Reader(source).fail(Reader::join(l.path, "texture"), "light textures are not supported for point lights");
  FrameLightTexture t{l.path, l.texture, l.textureClipFromWorld, false};
  t.defaultProjection = l.textureDefaultProjection;
  const LocalLight light = LocalLight::spot(*l.spot);
  checkProjection(Reader(source), t, [&](const std::string& field) {
    validateLightProjection(t.textureClipFromWorld, light, field);
  });
  return t;
}

Image readLightTexture(const std::filesystem::path& file, const std::string& field,
                       const std::string& source) {
  const std::string where = source + ": " + field + ": '" + file.string() + "'";
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw IoError(where + " does not exist");
  if (std::filesystem::is_directory(file, ec)) throw IoError(where + " is a directory");
  Image image;
  try {
    image = readExr(file);
  } catch (const IoError& e) {
    throw IoError(where + ": " + e.what());
  } catch (const FormatError& e) {
    throw FormatError(where + ": " + e.what());
  }
  if (image.channels() != 3 && image.channels() != 4)
    throw FormatError(where + ": has " + std::to_string(image.channels()) +
                      " channel(s); a light texture is linear RGB (channels R, G, B, optionally A)");
  Image rgb(image.width(), image.height(), 3);
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < 3; ++c) {
        const float v = image.at(x, y, c);
        if (!(v >= 0.0f && std::isfinite(v)))
          throw FormatError(where + ": texel (" + std::to_string(x) + ", " +
                            std::to_string(image.height() - 1 - y) + ") from the top-left, channel " +
                            "RGB"[c] + ", is " + Reader::format(v) + (std::isnan(v) ? " (NaN)" : "") +
                            "; expected finite values >= 0 (linear RGB)");
        rgb.at(x, y, c) = v;
      }
  return rgb;
}

namespace {

/// One term of the radiance bound: a light's share of the in-scattered radiance of a channel.
struct RadianceTerm {
  double value = 0.0;
  int light = -1; ///< -1: the directional light, else the index into localLightsOf()
};

/// Upper bound of the in-scattered radiance of any pixel (Klehm et al. 2014, Eq. 1 with V = 1 and the
/// largest phase value): E_c (sigma_mie,c HG_max + sigma_rayleigh,c 3 / (8 pi)) min(s_max, 1 / sigma_t,c) for
/// the directional light, plus per local light I_c (the same scattering) pi / nearPlane. Returns the worst
/// channel's sum and fills `terms` with that channel's per-light shares.
double radianceBound(const FrameDescription& f, const Medium& m, const std::vector<FrameLocalLight>& local,
                     std::vector<RadianceTerm>& terms) {
  const double g = std::abs(f.hgG);
  const double hgMax = (1.0 + g) / (4.0 * std::numbers::pi * (1.0 - g) * (1.0 - g));
  const double rayleighMax = 3.0 / (8.0 * std::numbers::pi);
  // Longest view ray: the far plane at the frustum corner (from clipFromView; infinite if not finite).
  const glm::dmat4& p = f.clipFromView;
  const double far = p[3][2] / (p[2][2] + 1.0);
  const double corner = std::sqrt(1.0 + 1.0 / (p[0][0] * p[0][0]) + 1.0 / (p[1][1] * p[1][1]));
  const double sMax =
      std::isfinite(far) && far > 0.0 ? far * corner : std::numeric_limits<double>::infinity();
  const glm::dvec3 sigma = m.extinction();
  double bound = 0.0;
  const bool directional = f.lightType == LightType::Directional;
  for (int c = 0; c < 3; ++c) {
    std::vector<RadianceTerm> channelTerms;
    const double scattering = f.mieScattering[c] * hgMax + f.rayleighScattering[c] * rayleighMax;
    const double C = directional ? f.lightColor[c] * f.lightIntensity * scattering : 0.0;
    const double length = sigma[c] > 0.0 ? std::min(sMax, 1.0 / sigma[c]) : sMax;
    double channel = C > 0.0 ? C * length : 0.0;
    if (directional) channelTerms.push_back({channel, -1});
    // Local lights: I exp(-sigma d) / d^2 <= I / d^2, and the integral of 1 / d^2 along a line at distance h
    // >= nearPlane from the light is at most pi / nearPlane.
    for (std::size_t i = 0; i < local.size(); ++i) {
      const FrameLocalLight& light = local[i];
      const glm::dvec3 I = light.spot ? light.spot->intensity() : light.point->intensity();
      const double near = light.spot ? light.spot->nearPlane() : light.point->nearPlane();
      const double term = I[c] * scattering * std::numbers::pi / near;
      channel += term;
      channelTerms.push_back({term, static_cast<int>(i)});
    }
    if (!(channel <= bound)) {
      bound = channel;
      terms = channelTerms;
    }
  }
  return bound;
}

/// The description of local light `index` of localLightsOf() (the main light first when it is local).
const LocalLightDescription& localDescription(const FrameDescription& f, std::size_t index) {
  if (f.lightType != LightType::Directional) {
    if (index == 0) return f.localLight;
    --index;
  }
  return f.lights[index];
}

} // namespace

Medium mediumOf(const FrameDescription& f, const std::string& source) {
  try {
    Medium m({.mieScattering = f.mieScattering,
              .hgG = f.hgG,
              .rayleighScattering = f.rayleighScattering,
              .absorption = f.absorption});
    const std::vector<FrameLocalLight> local = localLightsOf(f, source);
    std::vector<RadianceTerm> terms;
    const double bound = radianceBound(f, m, local, terms);
    if (!(bound <= kMaxRadiance)) {
      // Name the light with the largest share, and the field to change: a local light's nearPlane when
      // raising it to range x 1e-3 (the tool's default for a point light without face matrices) would bring
      // its share within the bound, else its intensity.
      RadianceTerm worst = terms.front();
      for (const RadianceTerm& t : terms)
        if (t.value > worst.value) worst = t;
      const std::string what =
          "with this medium the in-scattered radiance can reach " + Reader::format(bound);
      if (worst.light < 0)
        Reader(source).fail("light.intensity",
                            what + " (irradiance x scattering x phase x path length), beyond " +
                                Reader::format(kMaxRadiance) +
                                ": lower light.intensity / light.color or medium.mieScattering / hgG");
      const FrameLocalLight& light = local[static_cast<std::size_t>(worst.light)];
      const double near = light.spot ? light.spot->nearPlane() : light.point->nearPlane();
      const double range = light.spot ? light.spot->range() : light.point->range();
      const double floor = range * 1e-3;
      const bool blameNear = near < floor && worst.value * near / floor <= kMaxRadiance;
      const bool given = localDescription(f, static_cast<std::size_t>(worst.light)).nearPlane.has_value();
      const std::string nearText = Reader::join(light.path, "nearPlane") + " (" + Reader::format(near) +
                                   (given ? "" : ", from its shadow matrix") + ")";
      Reader(source).fail(
          Reader::join(light.path, blameNear ? "nearPlane" : "intensity"),
          what + " (color * intensity x scattering x phase x pi / nearPlane), beyond " +
              Reader::format(kMaxRadiance) + ": " +
              (blameNear
                   ? "raise " + nearText + ", or lower " + Reader::join(light.path, "intensity")
                   : "lower " + Reader::join(light.path, "intensity") + " / color or raise " + nearText) +
              " or lower medium.mieScattering / hgG");
    }
    return m;
  } catch (const InvalidArgument& e) {
    std::string field = "medium (extinction = mieScattering + rayleighScattering + absorption)";
    const std::string& p = e.parameter();
    if (p.find("hgG") != std::string::npos)
      field = "medium.hgG";
    else if (p.find("mie") != std::string::npos)
      field = "medium.mieScattering";
    else if (p.find("rayleigh") != std::string::npos)
      field = "medium.rayleighScattering";
    else if (p.find("absorption") != std::string::npos)
      field = "medium.absorption";
    Reader(source).fail(field, e.what());
  }
}

} // namespace crep::tool
