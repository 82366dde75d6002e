#include "frame_json.h"

#include <crep/core/error.h>
#include <crep/core/image.h>

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

} // namespace

FrameDescription parseFrameDescription(const std::string& text, const std::string& source) {
  const Reader r(source);
  Json root;
  PathChecker checker(text, source);
  Json::sax_parse(text, &checker); // throws FormatError with the path; otherwise the text is valid JSON
  try {
    root = Json::parse(text);
  } catch (const Json::exception& e) {
    throw FormatError(source + ": not valid JSON: " + e.what());
  }
  r.requireObject(root, "", {"version", "camera", "light", "shadowMap", "medium"});
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
  r.requireObject(light, "light", {"direction", "color", "intensity"});
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
      r.fail("light.intensity", "color * intensity = " + Reader::format(f.lightColor[c] * f.lightIntensity) +
                                    " is beyond " + Reader::format(kMaxMagnitude));

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
  // crep::Camera::fromMatrices reads the engine's conventions: clip depth (camera.clipDepth), reversed-Z and
  // an infinite far plane (detected; then camera.maxDistance is required), off-centre projections.
  {
    // A near plane the depth buffer cannot resolve: its projection rounds to an infinite far plane (element
    // 10 = -1 in GL's convention), so name it before fromMatrices asks for a maxDistance.
    const glm::dmat4& p = f.clipFromView;
    const bool no = f.clipDepth == ClipDepth::NegativeOneToOne;
    const double a = no ? 0.5 * (1.0 - p[2][2]) : -p[2][2], b = no ? 0.5 * p[3][2] : p[3][2];
    const double near = b < 0.0 ? (a != 0.0 ? -b / a : 0.0) : (a != 1.0 ? b / (1.0 - a) : 0.0);
    if (near > 0.0 && near < 1e-12 * std::max(1.0, f.maxDistance))
      r.fail("camera.clipFromView", "near / far below 1e-12 (near = " + Reader::format(near) +
                                        "): a near plane too small for the depth buffer");
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
    r.fail("camera.clipFromView", "near / far = " + Reader::format(camera.near() / camera.far()) +
                                      " below 1e-12: a near plane too small for the depth buffer");
  return camera;
}

DirectionalLight lightOf(const FrameDescription& f, const std::string& source) {
  try {
    return DirectionalLight(f.lightDirection, f.lightColor * f.lightIntensity);
  } catch (const InvalidArgument& e) {
    Reader(source).fail(e.parameter() == "DirectionalLight.direction" ? "light.direction" : "light",
                        e.what());
  }
}

namespace {

/// Upper bound of the in-scattered radiance of any pixel (Klehm et al. 2014, Eq. 1 with V = 1 and the
/// largest phase value): E_c (sigma_mie,c HG_max + sigma_rayleigh,c 3 / (8 pi)) min(s_max, 1 / sigma_t,c).
double radianceBound(const FrameDescription& f, const Medium& m) {
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
  for (int c = 0; c < 3; ++c) {
    const double C = f.lightColor[c] * f.lightIntensity *
                     (f.mieScattering[c] * hgMax + f.rayleighScattering[c] * rayleighMax);
    const double length = sigma[c] > 0.0 ? std::min(sMax, 1.0 / sigma[c]) : sMax;
    if (C > 0.0) bound = std::max(bound, C * length);
  }
  return bound;
}

} // namespace

Medium mediumOf(const FrameDescription& f, const std::string& source) {
  try {
    Medium m({.mieScattering = f.mieScattering,
              .hgG = f.hgG,
              .rayleighScattering = f.rayleighScattering,
              .absorption = f.absorption});
    const double bound = radianceBound(f, m);
    if (!(bound <= kMaxRadiance))
      Reader(source).fail("light.intensity",
                          "with this medium the in-scattered radiance can reach " + Reader::format(bound) +
                              " (irradiance x scattering x phase x path length), beyond " +
                              Reader::format(kMaxRadiance) +
                              ": lower light.intensity / light.color or medium.mieScattering / hgG");
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
