// `crep render`: the main job. Renders a built-in scene (standard shadow pass and lit camera pass),
// computes single scattering with the chosen method (lib/frame.h registry) and writes the scattering
// and composited images to EXR plus a tone-mapped PNG, with a table of per-stage timings.
// --export-frame DIR also writes the frame as users' data for `crep scatter`: DIR/depth.exr,
// DIR/shadow.exr (float depth-buffer values) and DIR/frame.json.
#include "args.h"
#include "commands.h"
#include "frame_json.h"
#include "gl_session.h"
#include "methods.h"
#include "options.h"
#include "paths.h"
#include "scene_frame.h"
#include "timings.h"

#include <crep/core/error.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>
#include <crep/support/exr.h>
#include <crep/support/png.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace crep::tool {

namespace {

void exportFrame(const std::filesystem::path& dir, const SceneFrame& s, StageTimings& timings) {
  const FrameInputs& f = *s.frame;
  timings.time("export frame", [&] {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw IoError("--export-frame: cannot create directory '" + dir.string() + "': " + ec.message());
    const Image depth = scenes::readDepthTexture(f.cameraDepth.get(), f.width, f.height);
    const Image shadow = scenes::readDepthTexture(f.shadowMap.get(), f.shadowWidth, f.shadowHeight);
    // Float: half precision would move depth-buffer values by up to 2^-11.
    writeExr(dir / "depth.exr", depth, ExrPixelType::Float);
    writeExr(dir / "shadow.exr", shadow, ExrPixelType::Float);
    FrameDescription d;
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
    const std::filesystem::path json = dir / "frame.json";
    std::ofstream out(json, std::ios::binary);
    out << toJson(d);
    out.close();
    if (!out) throw IoError("--export-frame: cannot write '" + json.string() + "'");
  });
}

} // namespace

int renderCommand(const std::vector<std::string>& argv) {
  std::set<std::string> valued = {"scene", "size", "out", "exposure", "export-frame"};
  valued.insert(kMethodOptions.begin(), kMethodOptions.end());
  const Args args(argv, valued, {"debug-gl"});
  const std::string sceneName = args.string("scene", "colonnade");
  const glm::ivec2 size = args.size("size", {1280, 720}, Image::kMaxDimension, Image::kMaxPixels);
  const double exposure = exposureOption(args);
  const std::string method = args.string("method", "prefilter");
  findMethod(method); // usage error before any GL work
  const MethodSettings settings = methodSettings(args);
  const std::string out = args.string("out", "crep-" + sceneName);
  requireOutputPrefix({"--out", out});
  const std::string exportDir = args.string("export-frame", "");
  // Every file this command writes, checked before any work: usage errors first, then the file system.
  std::vector<PathOption> outputs = {{"--out", out + ".exr"}, {"--out", out + ".png"}};
  if (args.has("export-frame")) {
    requireNonEmpty({"--export-frame", exportDir});
    for (const char* name : {"depth.exr", "shadow.exr", "frame.json"})
      outputs.push_back({"--export-frame", (std::filesystem::path(exportDir) / name).string()});
  }
  requireDistinctFiles(outputs);
  requireOutputFile(outputs[0]);
  requireOutputFile(outputs[1]);
  if (args.has("export-frame")) requireOutputDirectory({"--export-frame", exportDir});

  StageTimings timings;
  if (isatty(2)) timings.setProgress("crep render");
  ensureGlContext("render", args.has("debug-gl"), timings);
  SceneFrame s = makeSceneFrame(sceneName, size.x, size.y, settings.mapSize, timings);
  FrameInputs& frame = *s.frame;

  MethodOutput result = runMethod(method, frame, settings);
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
  timings.time("write exr", [&] {
    const ExrLayer layers[] = {{"composite", &compositeImg}, {"scattering", &scatteringImage}};
    writeExrLayers(exrPath, layers, ExrPixelType::Half); // the tool's picture file, as it always was
  });
  timings.time("write png", [&] { writePng(pngPath, compositeImg, ToneMap{static_cast<float>(exposure)}); });
  if (args.has("export-frame")) exportFrame(exportDir, s, timings);

  std::printf("crep render: scene %s, %dx%d, method %s (%s)\n", s.scene->name.c_str(), size.x, size.y,
              result.used.c_str(), result.detail.c_str());
  timings.print(stdout);
  std::printf("wrote %s (layers composite.RGBA, scattering.RGBA) and %s\n", exrPath.c_str(), pngPath.c_str());
  if (args.has("export-frame"))
    std::printf("exported the frame for crep scatter: %s/{depth.exr, shadow.exr, frame.json}\n",
                exportDir.c_str());
  return 0;
}

} // namespace crep::tool
