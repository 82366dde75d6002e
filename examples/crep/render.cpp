// `crep render`: the main job. Renders a built-in scene (standard shadow pass and lit camera pass),
// computes single scattering with the chosen method (lib/frame.h registry) and writes the scattering
// and composited images to EXR plus a tone-mapped PNG, with a table of per-stage timings.
// --export-frame DIR also writes the frame as users' data for `crep scatter`: DIR/depth.exr,
// DIR/shadow.exr (float depth-buffer values) and DIR/frame.json (and DIR/light-texture.exr for a scene whose
// sun has a light texture).
#include "args.h"
#include "atmosphere_frame.h"
#include "backend_method.h"
#include "commands.h"
#include "contact_sheet.h"
#include "frame_json.h"
#include "gl_session.h"
#include "methods.h"
#include "options.h"
#include "paths.h"
#include "scene_frame.h"
#include "timings.h"

#include <crep/atmosphere/atmosphere.h>
#include <crep/core/error.h>
#include <crep/postfx/gpu_tone_mapping.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>
#include <crep/support/exr.h>
#include <crep/support/output_file.h>
#include <crep/support/png.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>
#include <unistd.h>
#include <utility>
#include <vector>

namespace crep::tool {

namespace {

/// The sun's light texture as --export-frame writes it (light.texture; RGB float, the top row first).
constexpr const char* kLightTextureFile = "light-texture.exr";

/// The files --export-frame writes besides depth.exr, shadow.exr and frame.json: the sun's light texture
/// first when the scene has one, then one shadow EXR per local light after the first when there is no sun
/// (the first is then shadow.exr), per local light otherwise.
std::vector<std::string> localLightFiles(const scenes::Scene& scene) {
  std::vector<std::string> files;
  if (scene.sunTexture) files.push_back(kLightTextureFile);
  const std::size_t count = scene.spotLights.size() + scene.pointLights.size();
  for (std::size_t i = scene.hasSun ? 0 : 1; i < count; ++i)
    files.push_back("light" + std::to_string(i) + ".exr");
  return files;
}

/// A local light of the scene as the frame description holds it (frame_json.h), with its shadow map read
/// back: a spot's map, or a point light's six faces stacked top to bottom (+X first; face k in image rows
/// (5 - k) S .. (6 - k) S - 1 from the bottom, the EXR writer's flip puts +X at the top of the file).
LocalLightDescription describeLocal(const FrameInputs& f, std::size_t index, Image& shadow) {
  LocalLightDescription d;
  const auto split = [&](const glm::dvec3& colorTimesIntensity) {
    const double peak = std::max({colorTimesIntensity.x, colorTimesIntensity.y, colorTimesIntensity.z});
    d.color = colorTimesIntensity / peak;
    d.intensity = peak;
  };
  if (index < f.spotLights.size()) {
    const SpotLight& spot = f.spotLights[index];
    const LocalShadowMap& map = f.spotShadows[index];
    d.type = LightType::Spot;
    d.position = spot.position();
    d.direction = spot.direction();
    d.innerConeDeg = spot.innerConeAngle() * 180.0 / std::numbers::pi;
    d.outerConeDeg = spot.outerConeAngle() * 180.0 / std::numbers::pi;
    split(spot.intensity());
    d.nearPlane = spot.nearPlane();
    d.range = spot.range();
    d.lightClipFromWorld = map.lightClipFromWorld;
    d.shadowSize = glm::ivec2(map.width, map.height);
    d.shadowBias = map.bias;
    shadow = scenes::readDepthTexture(map.texture.get(), map.width, map.height);
    return d;
  }
  const std::size_t i = index - f.spotLights.size();
  const PointLight& point = f.pointLights[i];
  d.type = LightType::Point;
  d.position = point.position();
  split(point.intensity());
  d.nearPlane = point.nearPlane();
  d.range = point.range();
  std::array<glm::dmat4, 6> faces;
  const int S = f.pointShadows[6 * i].width;
  shadow = Image(S, 6 * S, 1);
  for (int k = 0; k < 6; ++k) {
    const LocalShadowMap& map = f.pointShadows[6 * i + static_cast<std::size_t>(k)];
    faces[static_cast<std::size_t>(k)] = map.lightClipFromWorld;
    const Image face = scenes::readDepthTexture(map.texture.get(), S, S);
    for (int y = 0; y < S; ++y)
      for (int x = 0; x < S; ++x)
        shadow.at(x, (5 - k) * S + y) = face.at(x, y);
  }
  d.faceClipFromWorld = faces;
  d.shadowSize = glm::ivec2(S, 6 * S);
  d.shadowBias = f.pointShadows[6 * i].bias;
  return d;
}

/// The --export-frame files into their temporaries of `outputs` (registered by renderCommand: the folder was
/// created then, and the files are renamed with the command's other outputs).
void exportFrame(const std::string& directory, const SceneFrame& s, StageTimings& timings,
                 OutputFiles& outputs) {
  const FrameInputs& f = *s.frame;
  const std::filesystem::path dir(directory);
  // Read back first, then write (the temporaries exist only while the files are written).
  std::vector<std::pair<std::string, Image>> images;
  const auto exr = [&](const std::string& name, Image image) { images.emplace_back(name, std::move(image)); };
  timings.time("export frame", [&] {
    const Image depth = scenes::readDepthTexture(f.cameraDepth.get(), f.width, f.height);
    exr("depth.exr", depth);
    FrameDescription d;
    const std::size_t localCount = f.spotLights.size() + f.pointLights.size();
    std::vector<std::string> files = localLightFiles(*s.scene);
    if (f.lightTexture.present()) {
      exr(kLightTextureFile, f.lightTexture.image);
      d.lightTexture = kLightTextureFile;
      d.lightTextureClipFromWorld = f.lightTexture.textureClipFromWorld;
      files.erase(files.begin());
    }
    for (std::size_t i = 0; i < localCount; ++i) {
      Image shadow;
      LocalLightDescription light = describeLocal(f, i, shadow);
      if (i == 0 && !f.directional) {
        d.lightType = light.type; // the main light: its map is shadow.exr (--shadow)
        d.localLight = light;
        exr("shadow.exr", shadow);
        continue;
      }
      light.shadowFile = files[d.lights.size()];
      exr(light.shadowFile, shadow);
      d.lights.push_back(light);
    }
    if (f.directional)
      exr("shadow.exr", scenes::readDepthTexture(f.shadowMap.get(), f.shadowWidth, f.shadowHeight));
    d.viewFromWorld = f.camera.viewFromWorld();
    d.clipFromView = f.camera.clipFromView();
    d.cameraSize = glm::ivec2(f.width, f.height);
    d.lightDirection = f.light.direction();
    d.lightColor = f.light.irradiance();
    d.lightIntensity = 1.0;
    d.lightClipFromWorld = f.lightClipFromWorld;
    d.shadowSize = glm::ivec2(f.shadowWidth, f.shadowHeight);
    d.shadowBias = f.shadowBias;
    d.mieScattering = f.medium.mieScattering();
    d.hgG = f.medium.hgG();
    d.rayleighScattering = f.medium.rayleighScattering();
    d.absorption = f.medium.absorption();
    const std::string json = toJson(d);
    for (const auto& [name, image] : images)
      // Float: half precision would move depth-buffer values by up to 2^-11.
      outputs.write((dir / name).string(),
                    [&](const std::filesystem::path& file) { writeExr(file, image, ExrPixelType::Float); });
    outputs.write((dir / "frame.json").string(),
                  [&](const std::filesystem::path& file) { writeTextFile(file, json); });
  });
}

/// --tonemap: the composite (GL_RGBA32F) through ToneMapPass (crep/postfx/gpu_tone_mapping.h): one
/// operator's linear display image, or with --tonemap all a sheet of every operator plus the default
/// clamp(v * exposure), labelled with their names. Auto exposure from this single frame's log-average.
Image toneMappedPng(const ToneMapSettings& settings, std::uint32_t composite, const Image& compositeImg,
                    double exposure) {
  const int width = compositeImg.width(), height = compositeImg.height();
  const gl::Handle output = gl::createTexture2D(GL_RGBA32F, width, height, "--size");
  // One pass for every operator (setOptions); each run resets the adaptation: a single frame.
  ToneMapPass pass({settings.options, false});
  const auto run = [&](const ToneMapOptions& options) {
    pass.setOptions(options);
    pass.run({composite, output.get(), 0.0, true});
    return readRgba(output.get(), width, height);
  };
  if (!settings.all) return run(settings.options);
  std::vector<SheetTile> tiles;
  for (const ToneMapOperator op : kToneMapOperators) {
    ToneMapOptions options = settings.options;
    options.op = op;
    tiles.push_back({toneMapOperatorName(op), run(options)});
  }
  Image clamped(width, height, 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c)
        clamped.at(x, y, c) = static_cast<float>(std::clamp(compositeImg.at(x, y, c) * exposure, 0.0, 1.0));
  tiles.push_back({"clamp (no --tonemap)", clamped});
  char exposureText[64];
  std::snprintf(exposureText, sizeof exposureText, "exposure %g", exposure);
  char header[256];
  std::snprintf(header, sizeof header,
                "crep render --tonemap all: %s, middle grey %g, white point %g, saturation %g",
                settings.options.autoExposure ? "auto exposure" : exposureText, settings.options.middleGrey,
                settings.options.whitePoint, settings.options.saturation);
  return composeGridSheet(header, tiles, std::min(width, 480), 4);
}

/// `crep render --method atmosphere`: the scene on the Earth (atmosphere_frame.h), lit by the sun after the
/// atmosphere's extinction plus the ambient sky light (Yusov 2013, "Terrain shaders"), composited with the
/// atmosphere's transmittance and in-scattering, tone mapped (default: uncharted2 with auto exposure).
int renderAtmosphere(const Args& args, const std::string& sceneName, glm::ivec2 size, double exposure) {
  ToneMapSettings toneMap = toneMapSettings(args, exposure);
  if (!args.has("tonemap")) {
    toneMap.enabled = true;
    toneMap.options.op = ToneMapOperator::Uncharted2;
    toneMap.options.autoExposure = true;
  }
  const MethodSettings settings = methodSettings(args);
  const AtmosphereSettings atmosphere = atmosphereSettings(args);
  const std::string out = args.string("out", "crep-" + sceneName);
  requireOutputPrefix({"--out", out});
  if (args.has("export-frame"))
    throw UsageError("option --export-frame: not available with --method atmosphere");
  const std::vector<PathOption> paths = {{"--out", out + ".exr"}, {"--out", out + ".png"}};
  requireDistinctFiles(paths);
  OutputFiles outputs; // checked now, written at the end, all or nothing (paths.h "The output rule")
  for (const PathOption& p : paths)
    outputs.addFile(p);
  const scenes::Scene base = scenes::makeScene(sceneName, double(size.x) / size.y);

  StageTimings timings;
  if (isatty(2)) timings.setProgress("crep render");
  ensureGlContext("render", args.has("debug-gl"), timings);
  AtmosphereTableSet tables = atmosphereTables(atmosphere, timings);
  SceneOverrides overrides;
  overrides.sun = atmosphereSun(atmosphere, base.sun);
  overrides.camera = atmosphereCamera(atmosphere, base.camera);
  // The surfaces: the sun's transmittance and the ambient sky light at the camera (one value for the
  // scene, which spans a few kilometres; Yusov evaluates them per vertex).
  const glm::dvec3 toSun = -overrides.sun->direction();
  const glm::dvec3 at =
      atmospherePosition(atmosphere.placement, atmosphere.parameters, overrides.camera->position());
  overrides.shadeIrradiance = overrides.sun->irradiance() * sunTransmittance(tables.cpu, at, toSun);
  overrides.shadeAmbient =
      overrides.sun->irradiance() * lookUpAmbientSkyLight(tables.cpu, glm::dot(glm::normalize(at), toSun));
  SceneFrame s = makeSceneFrame(sceneName, size.x, size.y, settings.mapSize, timings, overrides);
  FrameInputs& frame = *s.frame;
  const AtmosphereOutput result = runAtmosphere(frame, settings, atmosphere, *tables.pass, timings);
  gl::Handle composite =
      timings.time("composite", [&] { return compositeAtmosphere(frame, s.color.get(), result); });
  Image inscattering, transmittance, compositeImg;
  timings.time("readback", [&] {
    inscattering = readRgba(result.inscattering.get(), size.x, size.y);
    transmittance = readRgba(result.transmittance.get(), size.x, size.y);
    compositeImg = readRgba(composite.get(), size.x, size.y);
  });
  checkGlErrors("rendering");
  requireFinite(compositeImg, "the composited image");
  requireFinite(inscattering, "the atmosphere's in-scattering");
  const std::string exrPath = out + ".exr", pngPath = out + ".png";
  // The GL work first, then the files (the temporaries exist only while the files are written).
  Image png;
  timings.time("tone map", [&] { png = toneMappedPng(toneMap, composite.get(), compositeImg, exposure); });
  timings.time("write exr", [&] {
    const ExrLayer layers[] = {
        {"composite", &compositeImg}, {"scattering", &inscattering}, {"transmittance", &transmittance}};
    outputs.write(exrPath, [&](const std::filesystem::path& file) {
      writeExrLayers(file, layers, ExrPixelType::Float); // linear radiance for measurements
    });
  });
  timings.time("write png", [&] {
    outputs.write(pngPath, [&](const std::filesystem::path& file) { writePng(file, png, ToneMap{1.0f}); });
    outputs.commit();
  });
  const glm::dvec3 sunDir = toSun;
  std::printf("crep render: scene %s, %dx%d, method atmosphere (%s; sun elevation %g deg, azimuth %g deg; "
              "tables %dx%dx%dx%d, %s, %s)\n",
              s.scene->name.c_str(), size.x, size.y, result.detail.c_str(), atmosphere.sunElevation,
              std::atan2(sunDir.x, -sunDir.z) * 180.0 / std::numbers::pi, atmosphere.tables.size.height,
              atmosphere.tables.size.viewZenith, atmosphere.tables.size.sunZenith,
              atmosphere.tables.size.sunView,
              atmosphere.tables.orders == 1 ? "single scattering only"
              : usesMultipleScatteringLut(atmosphere.tables)
                  ? "multiple scattering LUT"
                  : (std::to_string(atmosphere.tables.orders) + " orders").c_str(),
              tables.loaded ? "loaded from the cache" : "computed");
  timings.print(stdout);
  std::printf("wrote %s (layers composite.RGBA, scattering.RGBA, transmittance.RGBA) and %s\n",
              exrPath.c_str(), pngPath.c_str());
  std::printf("tone mapping: %s%s\n", toneMap.all ? "all" : toneMapOperatorName(toneMap.options.op),
              toneMap.options.autoExposure ? ", auto exposure" : "");
  return 0;
}

} // namespace

int renderCommand(const std::vector<std::string>& argv) {
  std::set<std::string> valued = {"scene", "size", "out", "exposure", "export-frame", "backend"};
  valued.insert(kMethodOptions.begin(), kMethodOptions.end());
  valued.insert(kAtmosphereOptions.begin(), kAtmosphereOptions.end());
  valued.insert(kToneMapValuedOptions.begin(), kToneMapValuedOptions.end());
  const Args args(argv, valued, {"debug-gl", kAutoExposureFlag});
  const std::string sceneName = args.string("scene", "colonnade");
  requireSceneName(sceneName); // before the default --out (crep-<scene>) is derived from it
  const glm::ivec2 size = args.size("size", {1280, 720}, Image::kMaxDimension, Image::kMaxPixels);
  const double exposure = exposureOption(args);
  const ToneMapSettings toneMap = toneMapSettings(args, exposure);
  const std::string method = args.string("method", "prefilter");
  if (method == "atmosphere") return renderAtmosphere(args, sceneName, size, exposure);
  for (const std::string& name : kAtmosphereOptions)
    if (args.has(name)) throw UsageError("option --" + name + " needs --method atmosphere");
  findMethod(method); // usage error before any GL work
  const MethodSettings settings = methodSettings(args);
  requireMethodImageSize(settings, {method}, size,
                         "--size " + std::to_string(size.x) + "x" + std::to_string(size.y), true);
  const std::string backend = args.string("backend", "opengl");
  requireBackend(backend, method);
  const std::string out = args.string("out", "crep-" + sceneName);
  requireOutputPrefix({"--out", out});
  const std::string exportDir = args.string("export-frame", "");
  // Every file this command writes, checked before any work: usage errors first, then the file system.
  std::vector<PathOption> outputs = {{"--out", out + ".exr"}, {"--out", out + ".png"}};
  if (args.has("export-frame")) {
    requireNonEmpty({"--export-frame", exportDir});
    std::vector<std::string> names = {"depth.exr", "shadow.exr", "frame.json"};
    for (const std::string& name : localLightFiles(scenes::makeScene(sceneName, double(size.x) / size.y)))
      names.push_back(name);
    for (const std::string& name : names)
      outputs.push_back({"--export-frame", (std::filesystem::path(exportDir) / name).string()});
  }
  requireDistinctFiles(outputs);
  // Every output checked now (the export folder created), written at the end, all or nothing (paths.h
  // "The output rule"): a folder or file that cannot be written fails before any GL work.
  OutputFiles files;
  files.addFile(outputs[0]);
  files.addFile(outputs[1]);
  if (args.has("export-frame")) {
    files.addDirectory({"--export-frame", exportDir});
    for (std::size_t i = 2; i < outputs.size(); ++i)
      files.addFile(outputs[i]);
  }

  StageTimings timings;
  if (isatty(2)) timings.setProgress("crep render");
  ensureGlContext("render", args.has("debug-gl"), timings);
  SceneFrame s = makeSceneFrame(sceneName, size.x, size.y, settings.mapSize, timings);
  FrameInputs& frame = *s.frame;

  MethodOutput result =
      backend == "vulkan" ? runOnVulkan(s, method, settings) : runMethod(method, frame, settings);
  timings.append(result.timings.rows());
  gl::Handle composite = timings.time(
      "composite", [&] { return compositeImage(frame, s.color.get(), result.scattering.get()); });

  Image scatteringImage, compositeImg;
  timings.time("readback", [&] {
    scatteringImage = readRgba(result.scattering.get(), size.x, size.y);
    compositeImg = readRgba(composite.get(), size.x, size.y);
  });
  checkGlErrors("rendering");
  requireFinite(compositeImg, "the composited image");
  requireFinite(scatteringImage, "the scattering image");

  const std::string exrPath = out + ".exr", pngPath = out + ".png";
  // The GL work first, then the files (the temporaries exist only while the files are written).
  Image png;
  if (toneMap.enabled)
    timings.time("tone map", [&] { png = toneMappedPng(toneMap, composite.get(), compositeImg, exposure); });
  timings.time("write exr", [&] {
    const ExrLayer layers[] = {{"composite", &compositeImg}, {"scattering", &scatteringImage}};
    files.write(exrPath, [&](const std::filesystem::path& file) {
      writeExrLayers(file, layers, ExrPixelType::Half); // the tool's picture file, as it always was
    });
  });
  // Tone-mapped images are display-referred linear in [0, 1]: writePng's sRGB encoding at exposure 1.
  timings.time("write png", [&] {
    files.write(pngPath, [&](const std::filesystem::path& file) {
      writePng(file, toneMap.enabled ? png : compositeImg,
               ToneMap{toneMap.enabled ? 1.0f : static_cast<float>(exposure)});
    });
  });
  if (args.has("export-frame")) exportFrame(exportDir, s, timings, files);
  files.commit();

  std::printf("crep render: scene %s, %dx%d, method %s (%s)\n", s.scene->name.c_str(), size.x, size.y,
              result.used.c_str(), result.detail.c_str());
  timings.print(stdout);
  std::printf("wrote %s (layers composite.RGBA, scattering.RGBA) and %s\n", exrPath.c_str(), pngPath.c_str());
  if (toneMap.enabled)
    std::printf("tone mapping: %s%s\n",
                toneMap.all ? ("all: " + toneMapOperatorNames() + ", clamp").c_str()
                            : toneMapOperatorName(toneMap.options.op),
                toneMap.options.autoExposure ? ", auto exposure" : "");
  if (args.has("export-frame")) {
    std::string extra;
    for (const std::string& name : localLightFiles(*s.scene))
      extra += ", " + name;
    std::printf("exported the frame for crep scatter: %s/{depth.exr, shadow.exr%s, frame.json}\n",
                exportDir.c_str(), extra.c_str());
  }
  return 0;
}

} // namespace crep::tool
