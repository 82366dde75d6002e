// `crep rectify`: prints the projective rectification (or the fallback decision) for a camera and a
// directional light as one JSON object (rectify/include/crep/rectify/json.h). Status "projective",
// "fallback" or "empty" (the lit part of the camera frustum is empty or flat; rectify.h).
#include "args.h"
#include "commands.h"

#include <crep/core/error.h>
#include <crep/rectify/json.h>
#include <crep/rectify/rectify.h>
#include <crep/scenes/scene.h>

#include <cstdio>
#include <map>
#include <numbers>
#include <string>
#include <vector>

namespace crep::tool {

namespace {
constexpr double kMinFovyDeg = 1e-3;

// Library parameter names -> the command-line options that set them.
const std::map<std::string, std::string> kOptionOf = {
    {"Camera.position", "--camera-pos"},
    {"Camera.target", "--camera-target"},
    {"Camera.up", "--camera-up"},
    {"Camera.fovY", "--fovy-deg"},
    {"Camera.aspect", "--aspect"},
    {"Camera.near", "--near"},
    {"Camera.far", "--far"},
    {"DirectionalLight.direction", "--light-dir"},
    {"RectifyOptions.splits", "--splits"},
    {"RectifyOptions.blend", "--blend"},
};
} // namespace

int rectifyCommand(const std::vector<std::string>& argv) {
  const Args args(argv,
                  {"camera-pos", "camera-target", "camera-up", "fovy-deg", "aspect", "near", "far",
                   "light-dir", "splits", "scheme", "blend"},
                  {});
  // Defaults: the default scene's camera and sun.
  const scenes::Scene scene = scenes::makeScene("colonnade");
  const glm::dvec3 defaultTarget = scene.camera.position() + scene.camera.forward();
  // Below a thousandth of a degree the frustum is numerically a line (at 1e-12 degrees the lit region
  // collapses and the status is "empty"): such a camera is a typo, not a request.
  const double fovyDeg = args.number("fovy-deg", 60.0);
  if (!(fovyDeg >= kMinFovyDeg && fovyDeg < 180.0))
    throw UsageError("option --fovy-deg: " + args.string("fovy-deg", "") +
                     " is outside [0.001, 180) degrees");
  // near >= far: the option the user set is the one to change (both named when both were given).
  const double near = args.number("near", 0.1), far = args.number("far", 120.0);
  if (!(near < far)) {
    const std::string values = "near " + args.string("near", "0.1") + " must be below far " +
                               args.string("far", "120") + (args.has("far") ? "" : " (the default)");
    if (args.has("near") && args.has("far")) throw UsageError("options --near/--far: " + values);
    throw UsageError(std::string("option ") + (args.has("far") ? "--far" : "--near") + ": " + values +
                     (args.has("near") && !args.has("far") ? "; raise --far too" : ""));
  }
  try {
    const Camera camera =
        Camera::lookAt(args.vec3("camera-pos", scene.camera.position()),
                       args.vec3("camera-target", defaultTarget), args.vec3("camera-up", {0, 1, 0}),
                       fovyDeg * std::numbers::pi / 180.0, args.number("aspect", 16.0 / 9.0), near, far);
    const DirectionalLight light(args.vec3("light-dir", scene.sun.direction()));
    RectifyOptions options;
    options.splits = args.integer("splits", options.splits, 1, RectifyOptions::kMaxSplits);
    const std::string scheme = args.string("scheme", "logarithmic");
    if (scheme == "uniform")
      options.scheme = SplitScheme::Uniform;
    else if (scheme == "logarithmic")
      options.scheme = SplitScheme::Logarithmic;
    else if (scheme == "blend")
      options.scheme = SplitScheme::Blend;
    else
      throw UsageError("option --scheme: '" + scheme + "' is not uniform, logarithmic or blend");
    options.blend = args.number("blend", options.blend);
    const Rectification r = rectify(camera, light, options);
    std::printf("%s\n", toJson(r).c_str());
    return 0;
  } catch (const InvalidArgument& e) {
    // Parameters that depend on several options name the ones the user set (all of them if none was).
    const std::map<std::string, std::vector<std::string>> kGroups = {
        {"Camera.target", {"camera-pos", "camera-target"}},
        {"Camera.orientation", {"camera-pos", "camera-target", "camera-up"}}};
    if (const auto group = kGroups.find(e.parameter()); group != kGroups.end()) {
      std::vector<std::string> set;
      for (const std::string& name : group->second)
        if (args.has(name)) set.push_back(name);
      if (set.empty()) set = group->second;
      std::string names;
      for (const std::string& name : set)
        names += (names.empty() ? "--" : "/--") + name;
      throw UsageError((set.size() == 1 ? "option " : "options ") + names + ": " + e.what());
    }
    const auto it = kOptionOf.find(e.parameter());
    if (it == kOptionOf.end()) throw;
    throw UsageError("option " + it->second + ": " + e.what());
  }
}

} // namespace crep::tool
