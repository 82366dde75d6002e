// `crep scatter`: single scattering for users' own data. Inputs: a camera depth EXR (GL depth-buffer
// values in [0, 1]), a standard shadow map EXR (depth-buffer values of an orthographic light matrix)
// and a JSON frame description (lib/frame_json.h; docs/FORMATS.md). Output: a scattering EXR,
// RGB in-scattered radiance and A transmittance.
//
// Methods (lib/methods.h registry): `reference` marches every view ray against the user's standard
// shadow map; `prefilter` builds the projective rectification of the JSON camera and light, point-
// resamples the standard map into it on the CPU (crep::resampleShadowMap; Klehm et al. 2014, Sec. 4.1's
// rule on the projective layout) and runs the GPU prefilter and evaluation passes on it.
// Spot and point lights (light.type, "lights"; Klehm et al. 2014, Sec. 3.2) come with their perspective
// maps (a point light's six faces stacked in one EXR): every method adds them (lib/methods.cpp).
#include "args.h"
#include "commands.h"
#include "gl_session.h"
#include "methods.h"

#include "frame_json.h"
#include "options.h"
#include "paths.h"
#include "timings.h"
#include <crep/epipolar/resample.h>

#include <crep/core/error.h>
#include <crep/support/exr.h>
#include <crep/support/output_file.h>
#include <crep/support/png.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <unistd.h>

namespace crep::tool {

namespace {

/// The shortest text that reads back as exactly `v` (std::to_chars): 1.0000001f is "1.0000001", not the
/// "1.000000" of std::to_string.
template <class T>
std::string shortest(T v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

/// The channels a depth EXR is read from (docs/FORMATS.md): the first present of these, unprefixed.
constexpr const char* kDepthChannels[] = {"Y", "Z", "depth", "R"};

/// Reads a depth EXR (channel 0 of crep::readExr: Y, Z, depth or R) and checks every value is a depth-buffer
/// value in [0, 1]. A file without any of those channels (only G, B, A, a lowercase "y", ...) is refused
/// naming the channels found: readExr would read a lone channel of any name.
Image readDepthExr(const std::string& option, const std::string& path, const char* what) {
  Image image;
  try {
    const ExrFileInfo info = readExrInfo(path);
    bool found = false;
    std::string list;
    for (const ExrChannelInfo& c : info.channels) {
      list += (list.empty() ? "" : ", ") + c.name;
      for (const char* name : kDepthChannels)
        found = found || c.name == name;
    }
    if (!found)
      throw FormatError("'" + path + "' has no depth channel (channels: " + (list.empty() ? "none" : list) +
                        "); a depth EXR holds its values in a channel named Y, Z, depth or R");
    image = readExr(path);
  } catch (const IoError& e) {
    throw IoError(option + " (" + what + "): " + e.what());
  } catch (const FormatError& e) {
    throw FormatError(option + " (" + what + "): " + e.what());
  }
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const float d = image.at(x, y, 0);
      if (!(d >= 0.0f && d <= 1.0f))
        // Report the pixel as a viewer shows it: row 0 at the top.
        throw FormatError(option + " (" + what + "): '" + path + "': pixel (" + std::to_string(x) + ", " +
                          std::to_string(image.height() - 1 - y) + ") from the top-left is " + shortest(d) +
                          (std::isnan(d) ? " (NaN)" : "") +
                          "; expected OpenGL depth-buffer values in [0, 1] (1 = nothing / sky)");
    }
  return image;
}

std::string sizeText(int w, int h) {
  return std::to_string(w) + "x" + std::to_string(h);
}

/// "A light inside an occluder": every texel of its shadow map at the near plane (depth 0), so it lights
/// nothing; refused, naming the file, rather than producing a black image.
void requireNotEnclosed(const Image& shadow, const std::string& what) {
  for (float d : shadow.data())
    if (!(d < 1e-6f)) return;
  throw FormatError(what +
                    ": every texel is at the light's near plane (depth 0): the light is inside an "
                    "occluder and lights nothing; move it out of the geometry (or lower its nearPlane)");
}

/// Face k (+X, -X, +Y, -Y, +Z, -Z) of a point light's shadow EXR: faces stacked top to bottom, each in the
/// usual orientation (frame_json.h), i.e. image rows (5 - k) S .. (6 - k) S - 1 counted from the bottom.
Image pointFace(const Image& stacked, int face) {
  const int S = stacked.width();
  Image out(S, S, 1);
  for (int y = 0; y < S; ++y)
    for (int x = 0; x < S; ++x)
      out.at(x, y) = stacked.at(x, (5 - face) * S + y, 0);
  return out;
}

/// A directional frame whose shadow matrix maps none of the points the camera sees into the map (clip x and
/// y within [-w, w]) is unshadowed whatever the map holds: most likely the matrix is not the one the map was
/// rendered with. Warned on stderr (the image is still computed). The points: each pixel's surface from the
/// depth image, the sky at the integration distance (crep::Camera::surfaceViewDepth), on a grid of at most
/// about 4M pixels.
void warnIfShadowMapMissesView(const Camera& camera, const Image& depth, const glm::dmat4& lightClipFromWorld,
                               const std::string& framePath, const std::string& depthPath) {
  const int W = depth.width(), H = depth.height();
  const int step = std::max(1, static_cast<int>(std::ceil(std::sqrt(double(W) * H / 4194304.0))));
  const glm::dvec3 forward = camera.forward();
  long long points = 0;
  for (int y = 0; y < H; y += step)
    for (int x = 0; x < W; x += step) {
      const glm::dvec3 dir = camera.rayDirection((x + 0.5) / W * 2.0 - 1.0, (y + 0.5) / H * 2.0 - 1.0);
      const double viewDepth = camera.surfaceViewDepth(depth.at(x, y, 0));
      const glm::dvec3 p = camera.position() + dir * (viewDepth / glm::dot(dir, forward));
      const glm::dvec4 c = lightClipFromWorld * glm::dvec4(p, 1.0);
      ++points;
      if (c.w > 0.0 && std::abs(c.x) <= c.w && std::abs(c.y) <= c.w) return;
    }
  std::fprintf(
      stderr,
      "crep scatter: warning: %s: shadowMap.lightClipFromWorld maps none of the %lld points the camera "
      "sees (the surfaces of --depth '%s', the sky at %s) inside the shadow map: the image is "
      "unshadowed; is it the matrix the map was rendered with?\n",
      framePath.c_str(), points, depthPath.c_str(), shortest(camera.far()).c_str());
}

} // namespace

int scatterCommand(const std::vector<std::string>& argv) {
  std::set<std::string> valued = {"depth", "shadow", "frame", "out", "png", "exposure"};
  valued.insert(kMethodOptions.begin(), kMethodOptions.end());
  const Args args(argv, valued, {"debug-gl"});
  for (const char* required : {"depth", "shadow", "frame"})
    if (!args.has(required))
      throw UsageError(std::string("option --") + required + " is required (see crep help)");
  const std::string depthPath = args.string("depth", ""), shadowPath = args.string("shadow", "");
  const std::string framePath = args.string("frame", "");
  const std::string method = args.string("method", "prefilter");
  findMethod(method);
  const MethodSettings settings = methodSettings(args);
  const std::string out = args.string("out", "scattering.exr");
  const double exposure = exposureOption(args);
  // Files: inputs that are directories, outputs that cannot be written or would overwrite an input fail
  // here, before anything is read or written.
  const std::vector<PathOption> inputs = {
      {"--depth", depthPath}, {"--shadow", shadowPath}, {"--frame", framePath}};
  std::vector<PathOption> outputs = {{"--out", out}};
  if (args.has("png")) outputs.push_back({"--png", args.string("png", "")});
  for (const PathOption& p : inputs)
    requireNonEmpty(p);
  for (const PathOption& p : outputs)
    requireNonEmpty(p);
  requireDistinctFiles(outputs, inputs); // usage errors above, file system below
  // Every output checked now, written at the end, all or nothing (paths.h "The output rule").
  OutputFiles files;
  for (const PathOption& p : outputs)
    files.addFile(p);
  for (const PathOption& p : inputs)
    requireInputFile(p, p.option != "--frame"); // EXRs: regular files; the JSON may come from a pipe

  StageTimings timings;
  if (isatty(2)) timings.setProgress("crep scatter");
  // Everything about the inputs is checked before any GL work.
  const FrameDescription desc = timings.time("read frame json", [&] {
    try {
      return readFrameDescription(framePath);
    } catch (const IoError& e) {
      throw IoError(std::string("--frame: ") + e.what()); // format errors name the file and the field
    }
  });
  const Camera camera = cameraOf(desc, framePath);
  const bool directional = desc.lightType == LightType::Directional;
  // A night frame (the main light a spot or point light): no directional light; `light` is unused.
  const DirectionalLight light =
      directional ? lightOf(desc, framePath) : DirectionalLight(glm::dvec3(0.0, -1.0, 0.0), glm::dvec3(0.0));
  const Medium medium = mediumOf(desc, framePath);
  const std::vector<FrameLocalLight> localLights = localLightsOf(desc, framePath);
  const auto strip = [](const InvalidArgument& e) {
    std::string what = e.what(); // "crep: invalid lightClipFromWorld = <value> (<requirement>)"
    const std::string prefix = "crep: invalid lightClipFromWorld = ";
    if (what.starts_with(prefix)) what = what.substr(prefix.size());
    return what;
  };
  if (directional) {
    try {
      validateLightMatrix(desc.lightClipFromWorld, light.direction());
    } catch (const InvalidArgument& e) {
      throw FormatError(framePath + ": shadowMap.lightClipFromWorld: " + strip(e));
    }
  }
  for (const FrameLocalLight& l : localLights)
    for (std::size_t k = 0; k < l.lightClipFromWorld.size(); ++k) {
      // The library's own check (crep::Scattering applies it to the maps it is given), after the JSON's.
      try {
        validateLocalLightMatrix(l.lightClipFromWorld[k], l.spot ? l.spot->position() : l.point->position());
      } catch (const InvalidArgument& e) {
        const std::string field = l.spot ? l.shadowPath + ".lightClipFromWorld"
                                         : l.shadowPath + ".faceClipFromWorld[" + std::to_string(k) + "]" +
                                               (desc.lightType == LightType::Point && l.path == "light" &&
                                                        !desc.localLight.faceClipFromWorld
                                                    ? " (default)"
                                                    : "");
        throw FormatError(framePath + ": " + field + ": " + strip(e));
      }
    }
  // The additional lights' shadow EXRs, relative to the JSON file; they must not be outputs either.
  std::vector<PathOption> lightFiles;
  for (const FrameLocalLight& l : localLights)
    if (!l.shadowFile.empty()) {
      const std::filesystem::path file = std::filesystem::path(framePath).parent_path() / l.shadowFile;
      lightFiles.push_back({l.shadowPath + ".file", file.string()});
      std::error_code ec;
      if (!std::filesystem::exists(file, ec))
        throw IoError(framePath + ": " + l.shadowPath + ".file: '" + file.string() + "' does not exist");
      requireInputFile(lightFiles.back(), true);
    }
  requireDistinctFiles(outputs, lightFiles);
  // Light textures (frame_json.h "Light textures"): the directional light's and the spots', their
  // projections checked along the light's rays, the EXRs relative to the JSON file read and checked here,
  // before any GL work. textures[i] is localLights[i]'s (or empty).
  const std::filesystem::path jsonDir = std::filesystem::path(framePath).parent_path();
  std::vector<PathOption> textureFiles;
  const auto readTexture = [&](const FrameLightTexture& t) {
    const std::string field = t.path + ".texture";
    const std::filesystem::path file = jsonDir / t.file;
    textureFiles.push_back({field, file.string()});
    requireDistinctFiles(outputs, {textureFiles.back()});
    requireInputFile({framePath + ": " + field, file.string()}, true);
    return timings.time("read light texture", [&] { return readLightTexture(file, field, framePath); });
  };
  std::optional<FrameLightTexture> sunTexture = lightTextureOf(desc, framePath);
  Image sunTextureImage;
  if (sunTexture) sunTextureImage = readTexture(*sunTexture);
  std::vector<std::optional<FrameLightTexture>> localTextures;
  std::vector<Image> localTextureImages;
  for (const FrameLocalLight& l : localLights) {
    localTextures.push_back(lightTextureOf(l, framePath));
    localTextureImages.push_back(localTextures.back() ? readTexture(*localTextures.back()) : Image());
  }
  const Image depth =
      timings.time("read depth exr", [&] { return readDepthExr("--depth", depthPath, "camera depth"); });
  const Image shadow =
      timings.time("read shadow exr", [&] { return readDepthExr("--shadow", shadowPath, "shadow map"); });
  if (desc.cameraSize && (desc.cameraSize->x != depth.width() || desc.cameraSize->y != depth.height()))
    throw FormatError(framePath + ": camera.size " + sizeText(desc.cameraSize->x, desc.cameraSize->y) +
                      " does not match the depth image '" + depthPath + "' (" +
                      sizeText(depth.width(), depth.height()) + ")");
  if (directional && desc.shadowSize &&
      (desc.shadowSize->x != shadow.width() || desc.shadowSize->y != shadow.height()))
    throw FormatError(framePath + ": shadowMap.size " + sizeText(desc.shadowSize->x, desc.shadowSize->y) +
                      " does not match the shadow map '" + shadowPath + "' (" +
                      sizeText(shadow.width(), shadow.height()) + ")");
  // Each local light's map: the main light's is --shadow, the others' their files.
  std::vector<Image> localShadows;
  for (std::size_t i = 0, file = 0; i < localLights.size(); ++i) {
    const FrameLocalLight& l = localLights[i];
    const bool main = l.shadowFile.empty();
    const std::string option = main ? "--shadow" : framePath + ": " + l.shadowPath + ".file";
    const std::string path = main ? shadowPath : lightFiles[file++].path;
    Image image = main ? shadow : timings.time("read shadow exr (local lights)", [&] {
      return readDepthExr(option, path, "local light shadow map");
    });
    if (l.shadowSize && (l.shadowSize->x != image.width() || l.shadowSize->y != image.height()))
      throw FormatError(framePath + ": " + l.shadowPath + ".size " +
                        sizeText(l.shadowSize->x, l.shadowSize->y) + " does not match the shadow map '" +
                        path + "' (" + sizeText(image.width(), image.height()) + ")");
    if (l.point && image.height() != 6 * image.width())
      throw FormatError(option + ": '" + path + "' is " + sizeText(image.width(), image.height()) +
                        "; the point light " + l.path +
                        " needs its six faces stacked top to bottom (+X, -X, +Y, -Y, +Z, -Z): S x 6 S");
    requireNotEnclosed(image, option + ": '" + path + "' (shadow map of " + l.path + ")");
    localShadows.push_back(std::move(image));
  }
  requireMethodImageSize(
      settings, {method}, {depth.width(), depth.height()},
      "the depth image '" + depthPath + "' (" + sizeText(depth.width(), depth.height()) + ")", true);
  const double imageAspect = double(depth.width()) / double(depth.height());
  const glm::dvec4& tangents = camera.tangents(); // the frustum's own extent (off-centre ones too)
  const double frustumAspect = (tangents.y - tangents.x) / (tangents.w - tangents.z);
  if (std::abs(frustumAspect / imageAspect - 1.0) > 0.01)
    throw FormatError(framePath + ": camera.clipFromView has aspect ratio " + shortest(frustumAspect) +
                      ", which does not match the depth image '" + depthPath + "' (" +
                      sizeText(depth.width(), depth.height()) + ", aspect " + shortest(imageAspect) + ")");

  if (directional) warnIfShadowMapMissesView(camera, depth, desc.lightClipFromWorld, framePath, depthPath);

  ensureGlContext("scatter", args.has("debug-gl"), timings);
  FrameInputs frame(camera, light, medium);
  frame.width = depth.width();
  frame.height = depth.height();
  timings.time("upload", [&] {
    frame.cameraDepth = uploadR32F(depth, "--depth");
    frame.shadowMap = uploadR32F(shadow, "--shadow");
  });
  frame.shadowWidth = shadow.width();
  frame.shadowHeight = shadow.height();
  frame.lightClipFromWorld = desc.lightClipFromWorld;
  frame.shadowBias = desc.shadowBias;
  frame.directional = directional;
  if (directional) frame.shadowImage = shadow;
  if (sunTexture)
    frame.lightTexture =
        makeLightTextureMap(std::move(sunTextureImage), sunTexture->textureClipFromWorld, "light.texture");
  timings.time("upload (local lights)", [&] {
    for (std::size_t i = 0; i < localLights.size(); ++i) {
      const FrameLocalLight& l = localLights[i];
      const auto add = [&](std::vector<LocalShadowMap>& maps, Image image, const glm::dmat4& matrix) {
        LocalShadowMap m;
        m.texture = uploadR32F(image, "--shadow");
        m.width = image.width();
        m.height = image.height();
        m.lightClipFromWorld = matrix;
        m.bias = l.shadowBias;
        m.image = std::move(image);
        maps.push_back(std::move(m));
      };
      if (l.spot) {
        if (localTextures[i]) {
          frame.spotTextures.resize(frame.spotLights.size() + 1);
          frame.spotTextures.back() =
              makeLightTextureMap(std::move(localTextureImages[i]), localTextures[i]->textureClipFromWorld,
                                  "texture of a spot light");
        }
        frame.spotLights.push_back(*l.spot);
        add(frame.spotShadows, localShadows[i], l.lightClipFromWorld[0]);
      } else {
        frame.pointLights.push_back(*l.point);
        for (int k = 0; k < 6; ++k)
          add(frame.pointShadows, pointFace(localShadows[i], k),
              l.lightClipFromWorld[static_cast<std::size_t>(k)]);
      }
    }
  });

  if (!frame.spotTextures.empty()) frame.spotTextures.resize(frame.spotLights.size());
  MethodOutput result = runMethod(method, frame, settings);
  timings.append(result.timings.rows());
  const Image scattering =
      timings.time("readback", [&] { return readRgba(result.scattering.get(), frame.width, frame.height); });
  checkGlErrors("scattering");
  requireFinite(scattering, "the scattering image");
  timings.time("write exr", [&] {
    files.write(out,
                [&](const std::filesystem::path& file) { writeExr(file, scattering, ExrPixelType::Float); });
  });
  if (args.has("png"))
    timings.time("write png", [&] {
      files.write(args.string("png", ""), [&](const std::filesystem::path& file) {
        writePng(file, scattering, ToneMap{static_cast<float>(exposure)});
      });
    });
  files.commit();

  std::printf("crep scatter: %s, %dx%d, method %s (%s)\n", framePath.c_str(), frame.width, frame.height,
              result.used.c_str(), result.detail.c_str());
  timings.print(stdout);
  std::printf("wrote %s (RGB in-scattered radiance, A transmittance)%s%s\n", out.c_str(),
              args.has("png") ? " and " : "", args.has("png") ? args.string("png", "").c_str() : "");
  return 0;
}

} // namespace crep::tool
