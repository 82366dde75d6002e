#include "frame_json.h"

#include <crep/core/error.h>
#include <crep/core/image.h>

#include <nlohmann/json.hpp>

#include <glm/gtc/quaternion.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <initializer_list>
#include <sstream>

namespace crep::tool {

namespace {

using Json = nlohmann::json;

const char* typeName(const Json& j) {
  return j.type_name();
}

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

std::string formatVec(const glm::dvec3& v) {
  return "[" + Reader::format(v.x) + ", " + Reader::format(v.y) + ", " + Reader::format(v.z) + "]";
}
std::string formatMat(const glm::dmat4& m) {
  std::string s = "[";
  for (int k = 0; k < 16; ++k)
    s += (k ? ", " : "") + Reader::format(m[k / 4][k % 4]);
  return s + "]";
}

} // namespace

FrameDescription parseFrameDescription(const std::string& text, const std::string& source) {
  const Reader r(source);
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::parse_error& e) {
    throw FormatError(source + ": not valid JSON: " + e.what());
  }
  r.requireObject(root, "", {"version", "camera", "light", "shadowMap", "medium"});
  if (const Json* v = r.find(root, "version"); v && r.number(*v, "version") != 1.0)
    r.fail("version", "unsupported version " + v->dump() + " (this crep reads version 1)");

  FrameDescription f;
  const Json& camera = r.get(root, "", "camera");
  r.requireObject(camera, "camera", {"viewFromWorld", "clipFromView", "size"});
  f.viewFromWorld = r.mat4(r.get(camera, "camera", "viewFromWorld"), "camera.viewFromWorld");
  f.clipFromView = r.mat4(r.get(camera, "camera", "clipFromView"), "camera.clipFromView");
  if (const Json* s = r.find(camera, "size")) f.cameraSize = r.size(*s, "camera.size");

  const Json& light = r.get(root, "", "light");
  r.requireObject(light, "light", {"direction", "color", "intensity"});
  f.lightDirection =
      r.vec3(r.get(light, "light", "direction"), "light.direction", "x, y, z: the direction light travels");
  f.lightColor = r.vec3(r.get(light, "light", "color"), "light.color", "linear r, g, b");
  f.lightIntensity = r.number(r.get(light, "light", "intensity"), "light.intensity");
  if (glm::length(f.lightDirection) == 0.0) r.fail("light.direction", "must not be zero");
  for (int c = 0; c < 3; ++c)
    if (f.lightColor[c] < 0.0) r.fail("light.color", "components must be >= 0");
  if (f.lightIntensity < 0.0) r.fail("light.intensity", "must be >= 0");

  const Json& shadow = r.get(root, "", "shadowMap");
  r.requireObject(shadow, "shadowMap", {"lightClipFromWorld", "size", "bias"});
  f.lightClipFromWorld =
      r.mat4(r.get(shadow, "shadowMap", "lightClipFromWorld"), "shadowMap.lightClipFromWorld");
  if (const Json* s = r.find(shadow, "size")) f.shadowSize = r.size(*s, "shadowMap.size");
  if (const Json* b = r.find(shadow, "bias")) f.shadowBias = r.number(*b, "shadowMap.bias");

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
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot open frame description '" + path.string() + "'");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw IoError("cannot read frame description '" + path.string() + "'");
  return parseFrameDescription(text.str(), path.string());
}

std::string toJson(const FrameDescription& f) {
  std::string s = "{\n  \"version\": 1,\n  \"camera\": {\n";
  s += "    \"viewFromWorld\": " + formatMat(f.viewFromWorld) + ",\n";
  s += "    \"clipFromView\": " + formatMat(f.clipFromView);
  if (f.cameraSize)
    s +=
        ",\n    \"size\": [" + std::to_string(f.cameraSize->x) + ", " + std::to_string(f.cameraSize->y) + "]";
  s += "\n  },\n  \"light\": {\n";
  s += "    \"direction\": " + formatVec(f.lightDirection) + ",\n";
  s += "    \"color\": " + formatVec(f.lightColor) + ",\n";
  s += "    \"intensity\": " + Reader::format(f.lightIntensity) + "\n  },\n  \"shadowMap\": {\n";
  s += "    \"lightClipFromWorld\": " + formatMat(f.lightClipFromWorld);
  if (f.shadowSize)
    s +=
        ",\n    \"size\": [" + std::to_string(f.shadowSize->x) + ", " + std::to_string(f.shadowSize->y) + "]";
  s += ",\n    \"bias\": " + Reader::format(f.shadowBias) + "\n  },\n  \"medium\": {\n";
  s += "    \"mieScattering\": " + formatVec(f.mieScattering) + ",\n";
  s += "    \"hgG\": " + Reader::format(f.hgG) + ",\n";
  s += "    \"rayleighScattering\": " + formatVec(f.rayleighScattering) + ",\n";
  s += "    \"absorption\": " + formatVec(f.absorption) + "\n  }\n}\n";
  return s;
}

Camera cameraOf(const FrameDescription& f, const std::string& source) {
  const Reader r(source);
  // viewFromWorld: rotation + translation only.
  const glm::dmat4& v = f.viewFromWorld;
  if (v[0][3] != 0.0 || v[1][3] != 0.0 || v[2][3] != 0.0 || v[3][3] != 1.0)
    r.fail("camera.viewFromWorld", "last row must be 0 0 0 1 (a rigid transform)");
  const glm::dmat3 rot(v);
  const glm::dmat3 rtr = glm::transpose(rot) * rot;
  double err = 0.0;
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k)
      err = std::max(err, std::abs(rtr[c][k] - (c == k ? 1.0 : 0.0)));
  if (err > 1e-4 || glm::determinant(rot) <= 0.0)
    r.fail("camera.viewFromWorld",
           "not a rigid transform (its 3x3 part must be a rotation: orthonormal, determinant "
           "1; no scale or mirror)");
  const glm::dmat4 worldFromView = glm::inverse(v);
  const glm::dvec3 position(worldFromView[3]);

  // clipFromView: symmetric OpenGL perspective.
  const glm::dmat4& p = f.clipFromView;
  const double a = p[2][2], b = p[3][2];
  const double scale = std::max(std::abs(p[0][0]), std::abs(p[1][1]));
  struct Zero {
    int c, k;
  };
  for (const Zero z : {Zero{1, 0}, Zero{2, 0}, Zero{3, 0}, Zero{0, 1}, Zero{2, 1}, Zero{3, 1}, Zero{0, 2},
                       Zero{1, 2}, Zero{0, 3}, Zero{1, 3}, Zero{3, 3}})
    if (std::abs(p[z.c][z.k]) > 1e-9 * std::max(1.0, scale))
      r.fail("camera.clipFromView", "not a symmetric OpenGL perspective projection: element " +
                                        std::to_string(4 * z.c + z.k) + " (column " + std::to_string(z.c) +
                                        ", row " + std::to_string(z.k) + ") is " +
                                        Reader::format(p[z.c][z.k]) +
                                        ", expected 0 (off-centre and orthographic "
                                        "projections are not supported)");
  if (std::abs(p[2][3] + 1.0) > 1e-9)
    r.fail("camera.clipFromView",
           "element 11 (column 2, row 3) must be -1 (OpenGL perspective), got " + Reader::format(p[2][3]));
  if (!(p[0][0] > 0.0) || !(p[1][1] > 0.0))
    r.fail("camera.clipFromView", "elements 0 and 5 (focal lengths) must be > 0");
  if (std::abs(a + 1.0) < 1e-12)
    r.fail("camera.clipFromView",
           "infinite far plane (element 10 = -1) is not supported: the map covers the frustum up "
           "to a finite far plane");
  const double near = b / (a - 1.0), far = b / (a + 1.0);
  if (!(near > 0.0) || !(far > near) || !std::isfinite(far))
    r.fail("camera.clipFromView",
           "near " + Reader::format(near) + " and far " + Reader::format(far) +
               " (from elements 10 and 14) must satisfy 0 < near < far: OpenGL depth conventions "
               "(NDC z in [-1, 1]; reversed Z is not supported)");
  const double fovY = 2.0 * std::atan(1.0 / p[1][1]);
  const double aspect = p[1][1] / p[0][0];
  try {
    return Camera(position, glm::quat_cast(glm::transpose(rot)), fovY, aspect, near, far);
  } catch (const InvalidArgument& e) {
    r.fail("camera", e.what());
  }
}

DirectionalLight lightOf(const FrameDescription& f, const std::string& source) {
  try {
    return DirectionalLight(f.lightDirection, f.lightColor * f.lightIntensity);
  } catch (const InvalidArgument& e) {
    Reader(source).fail(e.parameter() == "DirectionalLight.direction" ? "light.direction" : "light",
                        e.what());
  }
}

Medium mediumOf(const FrameDescription& f, const std::string& source) {
  try {
    return Medium(f.mieScattering, f.absorption, f.hgG, f.rayleighScattering);
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
