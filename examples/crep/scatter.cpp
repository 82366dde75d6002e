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

/// The command line of `crep scatter`, checked: every option's value, then the files.
struct ScatterArgs {
  std::string depthPath, shadowPath, framePath;
  std::string method;
  MethodSettings settings;
  std::string out;
  std::optional<std::string> png; ///< --png
  double exposure = 0.0;
  bool debugGl = false;
  std::vector<PathOption> inputs, outputs;
};

/// Parses the command line (usage errors first), then checks the files: inputs that are directories,
/// outputs that cannot be written or would overwrite an input fail here, before anything is read or
/// written. Every output is added to `files`, written at the end, all or nothing (paths.h "The output rule").
ScatterArgs parseScatterArgs(const std::vector<std::string>& argv, OutputFiles& files) {
  std::set<std::string> valued = {"depth", "shadow", "frame", "out", "png", "exposure"};
  valued.insert(kMethodOptions.begin(), kMethodOptions.end());
  const Args args(argv, valued, {"debug-gl"});
  for (const char* required : {"depth", "shadow", "frame"})
    if (!args.has(required))
      throw UsageError(std::string("option --") + required + " is required (see crep help)");
  ScatterArgs o;
  o.depthPath = args.string("depth", "");
  o.shadowPath = args.string("shadow", "");
  o.framePath = args.string("frame", "");
  o.method = args.string("method", "prefilter");
  findMethod(o.method);
  o.settings = methodSettings(args);
  o.out = args.string("out", "scattering.exr");
  o.exposure = exposureOption(args);
  o.debugGl = args.has("debug-gl");
  if (args.has("png")) o.png = args.string("png", "");
  o.inputs = {{"--depth", o.depthPath}, {"--shadow", o.shadowPath}, {"--frame", o.framePath}};
  o.outputs = {{"--out", o.out}};
  if (o.png) o.outputs.push_back({"--png", *o.png});
  for (const PathOption& p : o.inputs)
    requireNonEmpty(p);
  for (const PathOption& p : o.outputs)
    requireNonEmpty(p);
  requireDistinctFiles(o.outputs, o.inputs); // usage errors above, file system below
  for (const PathOption& p : o.outputs)
    files.addFile(p);
  for (const PathOption& p : o.inputs)
    requireInputFile(p, p.option != "--frame"); // EXRs: regular files; the JSON may come from a pipe
  return o;
}

/// The requirement of a library InvalidArgument about a light matrix, without its prefix.
std::string matrixRequirement(const InvalidArgument& e) {
  std::string what = e.what(); // "crep: invalid lightClipFromWorld = <value> (<requirement>)"
  const std::string prefix = "crep: invalid lightClipFromWorld = ";
  if (what.starts_with(prefix)) what = what.substr(prefix.size());
  return what;
}

/// The JSON frame description and what it describes, checked (format errors name the file and the field).
struct ScatterFrame {
  FrameDescription desc;
  Camera camera;
  bool directional;
  /// A night frame (the main light a spot or point light) has no directional light: `light` is unused.
  DirectionalLight light;
  Medium medium;
  std::vector<FrameLocalLight> localLights;
};

/// Reads the frame description and checks every light matrix with the library's own checks (crep::Scattering
/// applies them to the maps it is given), after the JSON's.
ScatterFrame readScatterFrame(const std::string& framePath, StageTimings& timings) {
  FrameDescription desc = timings.time("read frame json", [&] {
    try {
      return readFrameDescription(framePath);
    } catch (const IoError& e) {
      throw IoError(std::string("--frame: ") + e.what()); // format errors name the file and the field
    }
  });
  const Camera camera = cameraOf(desc, framePath);
  const bool directional = desc.lightType == LightType::Directional;
  const DirectionalLight light =
      directional ? lightOf(desc, framePath) : DirectionalLight(glm::dvec3(0.0, -1.0, 0.0), glm::dvec3(0.0));
  const Medium medium = mediumOf(desc, framePath);
  std::vector<FrameLocalLight> localLights = localLightsOf(desc, framePath);
  if (directional) {
    try {
      validateLightMatrix(desc.lightClipFromWorld, light.direction());
    } catch (const InvalidArgument& e) {
      throw FormatError(framePath + ": shadowMap.lightClipFromWorld: " + matrixRequirement(e));
    }
  }
  for (const FrameLocalLight& l : localLights)
    for (std::size_t k = 0; k < l.lightClipFromWorld.size(); ++k) {
      try {
        validateLocalLightMatrix(l.lightClipFromWorld[k], l.spot ? l.spot->position() : l.point->position());
      } catch (const InvalidArgument& e) {
        const std::string field = l.spot ? l.shadowPath + ".lightClipFromWorld"
                                         : l.shadowPath + ".faceClipFromWorld[" + std::to_string(k) + "]" +
                                               (desc.lightType == LightType::Point && l.path == "light" &&
                                                        !desc.localLight.faceClipFromWorld
                                                    ? " (default)"
                                                    : "");
        throw FormatError(framePath + ": " + field + ": " + matrixRequirement(e));
      }
    }
  return {std::move(desc), camera, directional, light, medium, std::move(localLights)};
}

/// The frame's images, read and checked before any GL work.
struct ScatterImages {
  Image depth, shadow;
  /// The directional light's texture and the local lights' (localTextures[i] is localLights[i]'s, or empty).
  std::optional<FrameLightTexture> sunTexture;
  Image sunTextureImage;
  std::vector<std::optional<FrameLightTexture>> localTextures;
  std::vector<Image> localTextureImages;
  std::vector<Image> localShadows; ///< each local light's map: the main light's is --shadow
};

/// The additional lights' shadow EXRs, relative to the JSON file: they must exist and must not be outputs.
std::vector<PathOption> localShadowFiles(const ScatterArgs& o, const ScatterFrame& f) {
  std::vector<PathOption> lightFiles;
  for (const FrameLocalLight& l : f.localLights)
    if (!l.shadowFile.empty()) {
      const std::filesystem::path file = std::filesystem::path(o.framePath).parent_path() / l.shadowFile;
      lightFiles.push_back({l.shadowPath + ".file", file.string()});
      std::error_code ec;
      if (!std::filesystem::exists(file, ec))
        throw IoError(o.framePath + ": " + l.shadowPath + ".file: '" + file.string() + "' does not exist");
      requireInputFile(lightFiles.back(), true);
    }
  requireDistinctFiles(o.outputs, lightFiles);
  return lightFiles;
}

/// Light textures (frame_json.h "Light textures"): the directional light's and the spots', their
/// projections checked along the light's rays, the EXRs relative to the JSON file read and checked.
void readLightTextures(const ScatterArgs& o, const ScatterFrame& f, ScatterImages& images,
                       StageTimings& timings) {
  const std::filesystem::path jsonDir = std::filesystem::path(o.framePath).parent_path();
  std::vector<PathOption> textureFiles;
  const auto readTexture = [&](const FrameLightTexture& t) {
    const std::string field = t.path + ".texture";
    const std::filesystem::path file = jsonDir / t.file;
    textureFiles.push_back({field, file.string()});
    requireDistinctFiles(o.outputs, {textureFiles.back()});
    requireInputFile({o.framePath + ": " + field, file.string()}, true);
    return timings.time("read light texture", [&] { return readLightTexture(file, field, o.framePath); });
  };
  images.sunTexture = lightTextureOf(f.desc, o.framePath);
  if (images.sunTexture) images.sunTextureImage = readTexture(*images.sunTexture);
  for (const FrameLocalLight& l : f.localLights) {
    images.localTextures.push_back(lightTextureOf(l, o.framePath));
    images.localTextureImages.push_back(
        images.localTextures.back() ? readTexture(*images.localTextures.back()) : Image());
  }
}

/// Each local light's map (the main light's is --shadow, the others' their files), its size checked.
void readLocalShadows(const ScatterArgs& o, const ScatterFrame& f, const std::vector<PathOption>& lightFiles,
                      ScatterImages& images, StageTimings& timings) {
  for (std::size_t i = 0, file = 0; i < f.localLights.size(); ++i) {
    const FrameLocalLight& l = f.localLights[i];
    const bool main = l.shadowFile.empty();
    const std::string option = main ? "--shadow" : o.framePath + ": " + l.shadowPath + ".file";
    const std::string path = main ? o.shadowPath : lightFiles[file++].path;
    Image image = main ? images.shadow : timings.time("read shadow exr (local lights)", [&] {
      return readDepthExr(option, path, "local light shadow map");
    });
    if (l.shadowSize && (l.shadowSize->x != image.width() || l.shadowSize->y != image.height()))
      throw FormatError(o.framePath + ": " + l.shadowPath + ".size " +
                        sizeText(l.shadowSize->x, l.shadowSize->y) + " does not match the shadow map '" +
                        path + "' (" + sizeText(image.width(), image.height()) + ")");
    if (l.point && image.height() != 6 * image.width())
      throw FormatError(option + ": '" + path + "' is " + sizeText(image.width(), image.height()) +
                        "; the point light " + l.path +
                        " needs its six faces stacked top to bottom (+X, -X, +Y, -Y, +Z, -Z): S x 6 S");
    requireNotEnclosed(image, option + ": '" + path + "' (shadow map of " + l.path + ")");
    images.localShadows.push_back(std::move(image));
  }
}

/// The JSON's camera.size and shadowMap.size against the images.
void checkImageSizes(const ScatterArgs& o, const ScatterFrame& f, const ScatterImages& images) {
  const Image &depth = images.depth, &shadow = images.shadow;
  const FrameDescription& desc = f.desc;
  if (desc.cameraSize && (desc.cameraSize->x != depth.width() || desc.cameraSize->y != depth.height()))
    throw FormatError(o.framePath + ": camera.size " + sizeText(desc.cameraSize->x, desc.cameraSize->y) +
                      " does not match the depth image '" + o.depthPath + "' (" +
                      sizeText(depth.width(), depth.height()) + ")");
  if (f.directional && desc.shadowSize &&
      (desc.shadowSize->x != shadow.width() || desc.shadowSize->y != shadow.height()))
    throw FormatError(o.framePath + ": shadowMap.size " + sizeText(desc.shadowSize->x, desc.shadowSize->y) +
                      " does not match the shadow map '" + o.shadowPath + "' (" +
                      sizeText(shadow.width(), shadow.height()) + ")");
}

/// The method's image size limits and the camera's aspect ratio against the depth image.
void checkCameraImage(const ScatterArgs& o, const ScatterFrame& f, const Image& depth) {
  requireMethodImageSize(
      o.settings, {o.method}, {depth.width(), depth.height()},
      "the depth image '" + o.depthPath + "' (" + sizeText(depth.width(), depth.height()) + ")", true);
  const double imageAspect = double(depth.width()) / double(depth.height());
  const glm::dvec4& tangents = f.camera.tangents(); // the frustum's own extent (off-centre ones too)
  const double frustumAspect = (tangents.y - tangents.x) / (tangents.w - tangents.z);
  if (std::abs(frustumAspect / imageAspect - 1.0) > 0.01)
    throw FormatError(o.framePath + ": camera.clipFromView has aspect ratio " + shortest(frustumAspect) +
                      ", which does not match the depth image '" + o.depthPath + "' (" +
                      sizeText(depth.width(), depth.height()) + ", aspect " + shortest(imageAspect) + ")");
}

/// Reads and checks every image of the frame (the light files, the textures, the depth and shadow EXRs,
/// the local lights' maps), before any GL work.
ScatterImages readScatterImages(const ScatterArgs& o, const ScatterFrame& f, StageTimings& timings) {
  const std::vector<PathOption> lightFiles = localShadowFiles(o, f);
  ScatterImages images;
  readLightTextures(o, f, images, timings);
  images.depth =
      timings.time("read depth exr", [&] { return readDepthExr("--depth", o.depthPath, "camera depth"); });
  images.shadow =
      timings.time("read shadow exr", [&] { return readDepthExr("--shadow", o.shadowPath, "shadow map"); });
  checkImageSizes(o, f, images);
  readLocalShadows(o, f, lightFiles, images, timings);
  checkCameraImage(o, f, images.depth);
  return images;
}

/// The local lights' maps and textures uploaded into `frame` (a point light's six faces from its stacked
/// map).
void uploadLocalLights(const ScatterFrame& f, ScatterImages& images, FrameInputs& frame) {
  for (std::size_t i = 0; i < f.localLights.size(); ++i) {
    const FrameLocalLight& l = f.localLights[i];
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
      if (images.localTextures[i]) {
        frame.spotTextures.resize(frame.spotLights.size() + 1);
        frame.spotTextures.back() =
            makeLightTextureMap(std::move(images.localTextureImages[i]),
                                images.localTextures[i]->textureClipFromWorld, "texture of a spot light");
      }
      frame.spotLights.push_back(*l.spot);
      add(frame.spotShadows, images.localShadows[i], l.lightClipFromWorld[0]);
    } else {
      frame.pointLights.push_back(*l.point);
      for (int k = 0; k < 6; ++k)
        add(frame.pointShadows, pointFace(images.localShadows[i], k),
            l.lightClipFromWorld[static_cast<std::size_t>(k)]);
    }
  }
}

/// The GL context and the frame on the GPU: depth, shadow map, light texture, local lights.
FrameInputs uploadScatterFrame(const ScatterArgs& o, const ScatterFrame& f, ScatterImages& images,
                               StageTimings& timings) {
  ensureGlContext("scatter", o.debugGl, timings);
  FrameInputs frame(f.camera, f.light, f.medium);
  frame.width = images.depth.width();
  frame.height = images.depth.height();
  timings.time("upload", [&] {
    frame.cameraDepth = uploadR32F(images.depth, "--depth");
    frame.shadowMap = uploadR32F(images.shadow, "--shadow");
  });
  frame.shadowWidth = images.shadow.width();
  frame.shadowHeight = images.shadow.height();
  frame.lightClipFromWorld = f.desc.lightClipFromWorld;
  frame.shadowBias = f.desc.shadowBias;
  frame.directional = f.directional;
  if (f.directional) frame.shadowImage = images.shadow;
  if (images.sunTexture)
    frame.lightTexture = makeLightTextureMap(std::move(images.sunTextureImage),
                                             images.sunTexture->textureClipFromWorld, "light.texture");
  timings.time("upload (local lights)", [&] { uploadLocalLights(f, images, frame); });
  if (!frame.spotTextures.empty()) frame.spotTextures.resize(frame.spotLights.size());
  return frame;
}

/// Runs the method, writes the EXR (and the PNG), all or nothing, and prints what was done.
void runAndWrite(const ScatterArgs& o, FrameInputs& frame, OutputFiles& files, StageTimings& timings) {
  MethodOutput result = runMethod(o.method, frame, o.settings);
  timings.append(result.timings.rows());
  const Image scattering =
      timings.time("readback", [&] { return readRgba(result.scattering.get(), frame.width, frame.height); });
  checkGlErrors("scattering");
  requireFinite(scattering, "the scattering image");
  timings.time("write exr", [&] {
    files.write(o.out,
                [&](const std::filesystem::path& file) { writeExr(file, scattering, ExrPixelType::Float); });
  });
  if (o.png)
    timings.time("write png", [&] {
      files.write(*o.png, [&](const std::filesystem::path& file) {
        writePng(file, scattering, ToneMap{static_cast<float>(o.exposure)});
      });
    });
  files.commit();

  std::printf("crep scatter: %s, %dx%d, method %s (%s)\n", o.framePath.c_str(), frame.width, frame.height,
              result.used.c_str(), result.detail.c_str());
  timings.print(stdout);
  std::printf("wrote %s (RGB in-scattered radiance, A transmittance)%s%s\n", o.out.c_str(),
              o.png ? " and " : "", o.png ? o.png->c_str() : "");
}

} // namespace

int scatterCommand(const std::vector<std::string>& argv) {
  OutputFiles files;
  const ScatterArgs options = parseScatterArgs(argv, files);
  StageTimings timings;
  if (isatty(2)) timings.setProgress("crep scatter");
  // Everything about the inputs is checked before any GL work.
  const ScatterFrame frame = readScatterFrame(options.framePath, timings);
  ScatterImages images = readScatterImages(options, frame, timings);
  if (frame.directional)
    warnIfShadowMapMissesView(frame.camera, images.depth, frame.desc.lightClipFromWorld, options.framePath,
                              options.depthPath);
  FrameInputs inputs = uploadScatterFrame(options, frame, images, timings);
  runAndWrite(options, inputs, files, timings);
  return 0;
}

} // namespace crep::tool
