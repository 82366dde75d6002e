// The tool's methods, each built from the library: the world-space reference march (WorldMarchPass),
// Klehm et al. 2014's prefiltered scattering on every frame (crep::Scattering), and the
// min/max tree and brute-force marches over the rectified rows (MinMaxTreePass, RectifiedMarchPass), with
// the epipolar resampling fallback (EpipolarLayout + ShadowResamplePass + the epipole block) for frames
// whose rectification is not projective.
#include "methods.h"

#include "args.h"

#include <crep/core/error.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/resample.h>
#include <crep/pipeline/scattering.h>
#include <crep/scatter/gpu_world_march.h>
#include <crep/scenes/scene_renderer.h>

#include <epoxy/gl.h>

#include <cstdio>
#include <memory>
#include <optional>

namespace crep::tool {

namespace {

gl::Handle newScatteringTexture(const FrameInputs& frame) {
  return gl::createTexture2D(GL_RGBA32F, frame.width, frame.height, "--size");
}

/// WorldMarchPass on `pixels` of the frame (all, or the block around `blockCenter`).
void runWorldMarch(const FrameInputs& frame, const MethodSettings& settings, std::uint32_t scattering,
                   const glm::dvec2& blockCenter = glm::dvec2(0.0), double blockRadius = -1.0) {
  WorldMarchPass::CreateInfo info;
  info.options.steps = settings.steps;
  WorldMarchPass pass(info);
  WorldMarchPass::FrameAttribs a;
  a.camera = &frame.camera;
  a.light = &frame.light;
  a.medium = &frame.medium;
  a.cameraDepth = frame.cameraDepth.get();
  a.shadowMap = frame.shadowMap.get();
  a.lightClipFromWorld = frame.lightClipFromWorld;
  a.bias = frame.shadowBias;
  a.output = scattering;
  a.blockCenter = blockCenter;
  a.blockRadius = blockRadius;
  pass.run(a);
  glFinish();
}

/// The world-space reference: every pixel's view ray marched against the standard shadow map
/// (crep/scatter/world_march.h), independent of any rectification.
MethodOutput runReference(FrameInputs& frame, const MethodSettings& settings) {
  MethodOutput out;
  out.used = "reference";
  out.detail = std::to_string(settings.steps) + " march steps, standard map " +
               std::to_string(frame.shadowWidth) + "x" + std::to_string(frame.shadowHeight);
  out.scattering = newScatteringTexture(frame);
  out.timings.time("reference march", [&] { runWorldMarch(frame, settings, out.scattering.get()); });
  return out;
}

/// The epipolar fallback map of a frame: the layout of Klehm et al. 2014, Sec. 4.1 for the frame's
/// camera, light and screen, and the standard shadow map resampled into it on the GPU.
struct EpipolarMap {
  std::shared_ptr<EpipolarLayout> layout;
  gl::Handle texture; ///< R32F, width x sliceCount
  int width = 0, height = 0;
};

EpipolarMap makeEpipolarMap(const FrameInputs& frame, const MethodSettings& settings, StageTimings& timings) {
  EpipolarMap m;
  EpipolarOptions options;
  options.regions = settings.rectify.splits;
  m.layout = timings.time("epipolar layout", [&] {
    return std::make_shared<EpipolarLayout>(frame.camera, frame.light, frame.width, frame.height, options);
  });
  m.width = settings.mapSize;
  m.height = m.layout->sliceCount();
  m.texture = gl::createTexture2D(GL_R32F, m.width, m.height, "--map-size");
  timings.time("resample (epipolar)", [&] {
    ShadowResamplePass pass({m.width, m.height});
    ShadowResamplePass::FrameAttribs a;
    a.layout = m.layout.get();
    a.shadowMap = frame.shadowMap.get();
    a.lightClipFromWorld = frame.lightClipFromWorld;
    a.output = m.texture.get();
    pass.run(a);
    glFinish();
  });
  return m;
}

/// The world-space march of the pixels around the epipole (Klehm et al. 2014, Fig. 8), over `scattering`.
void marchEpipoleBlock(const FrameInputs& frame, const MethodSettings& settings, const EpipolarLayout& layout,
                       std::uint32_t scattering, StageTimings& timings) {
  const auto centre = layout.epipolePixel();
  if (!centre || layout.epipoleBlockRadiusPixels() <= 0.0) return;
  timings.time("epipole block march", [&] {
    runWorldMarch(frame, settings, scattering, *centre, layout.epipoleBlockRadiusPixels());
  });
}

/// The min/max tree (tree = true) or brute-force march of every pixel's view ray along its row of the
/// rectified map (projective), or of the epipolar fallback map (plus the epipole block).
MethodOutput runRectifiedMarch(FrameInputs& frame, const MethodSettings& settings, bool tree) {
  MethodOutput out;
  out.used = tree ? "minmax" : "brute";
  Rectification rect;
  const RectifiedGpuMap* map = frame.rectified(settings, out.timings, &rect);
  std::optional<EpipolarMap> epipolar;
  const RectifiedLayout* layout = nullptr;
  std::uint32_t texture = 0;
  int width = 0, height = 0;
  if (map) {
    layout = map->layout.get();
    texture = map->texture.get();
    width = height = map->size;
    out.detail = std::to_string(map->rect.splitCount()) + " splits, map " + std::to_string(map->size) +
                 "^2 " + map->source;
  } else {
    std::fprintf(
        stderr, "crep: %s: rectification is %s (%s); using the epipolar resampling fallback (%s march)\n",
        out.used.c_str(), statusToken(rect.status), rect.message.c_str(), tree ? "min/max" : "brute-force");
    epipolar = makeEpipolarMap(frame, settings, out.timings);
    layout = epipolar->layout.get();
    texture = epipolar->texture.get();
    width = epipolar->width;
    height = epipolar->height;
    out.used += " (epipolar)";
    out.detail = "epipolar fallback, map " + std::to_string(width) + "x" + std::to_string(height);
  }
  const RectifiedMarchPass::Mode mode =
      tree ? RectifiedMarchPass::Mode::MinMaxTree : RectifiedMarchPass::Mode::BruteForce;
  auto pass = out.timings.time("march setup", [&] {
    return std::make_unique<RectifiedMarchPass>(RectifiedMarchPass::CreateInfo{width, height, mode});
  });
  std::unique_ptr<MinMaxTreePass> trees;
  if (tree) {
    trees = out.timings.time("min/max setup", [&] {
      return std::make_unique<MinMaxTreePass>(MinMaxTreePass::CreateInfo{width, height});
    });
    out.timings.time("min/max trees", [&] {
      trees->run(texture);
      glFinish();
    });
  }
  out.scattering = newScatteringTexture(frame);
  out.timings.time(tree ? "min/max march" : "brute-force march", [&] {
    RectifiedMarchPass::FrameAttribs a;
    a.layout = layout;
    a.camera = &frame.camera;
    a.light = &frame.light;
    a.medium = &frame.medium;
    a.cameraDepth = frame.cameraDepth.get();
    a.rectifiedDepth = texture;
    a.minMaxBuffer = trees ? trees->treeBuffer() : 0;
    a.output = out.scattering.get();
    pass->run(a);
    glFinish();
  });
  if (epipolar) marchEpipoleBlock(frame, settings, *epipolar->layout, out.scattering.get(), out.timings);
  return out;
}

MethodOutput runMinMax(FrameInputs& frame, const MethodSettings& settings) {
  return runRectifiedMarch(frame, settings, true);
}
MethodOutput runBrute(FrameInputs& frame, const MethodSettings& settings) {
  return runRectifiedMarch(frame, settings, false);
}

/// Klehm et al. 2014 on every frame through the library's front door (crep::Scattering): the rectified map
/// rasterized with the scene's casters (built-in scenes) or resampled from the standard shadow map (users'
/// data) when the rectification is projective, else the epipolar fallback with the epipole block. The
/// stages are Scattering's wall-clock stage times (like every other method's).
MethodOutput runPrefilter(FrameInputs& frame, const MethodSettings& settings) {
  MethodOutput out;
  out.used = "prefilter";
  Scattering::CreateInfo info;
  info.width = frame.width;
  info.height = frame.height;
  info.mapSize = settings.mapSize;
  info.rectify = settings.rectify;
  info.prefilter = settings.prefilter;
  info.epipoleBlock.steps = settings.steps;
  info.evaluationScale = settings.scale;
  auto scattering = out.timings.time("setup", [&] { return std::make_unique<Scattering>(info); });
  const Scattering::ShadowMap shadow{frame.shadowMap.get(), frame.lightClipFromWorld, frame.shadowBias};
  Scattering::FrameAttribs a;
  a.camera = &frame.camera;
  a.light = &frame.light;
  a.medium = &frame.medium;
  a.cameraDepth = frame.cameraDepth.get();
  out.scattering = newScatteringTexture(frame);
  a.output = out.scattering.get();
  if (frame.renderer)
    a.drawCasters = [&](const glm::dmat4& clipFromWorld) { frame.renderer->drawDepth(clipFromWorld); };
  a.shadowMap = &shadow;
  const Scattering::FrameResult r = scattering->run(a);
  for (const Scattering::Stage& stage : r.stages)
    out.timings.append({{stage.name, stage.wallMilliseconds}}); // comparable with the other methods' stages
  const PrefilterOptions& options = settings.prefilter;
  const std::string basis =
      "M = " + std::to_string(options.bases) + ", " + storageFormatToken(options.format);
  if (r.layout == Scattering::Layout::Projective) {
    out.detail = "projective layout, " + basis + ", " + std::to_string(r.rectification.splitCount()) +
                 " splits, map " + std::to_string(settings.mapSize) + "^2 " +
                 (frame.renderer ? "rasterized" : "resampled from the standard map");
  } else {
    std::fprintf(stderr,
                 "crep: prefilter: rectification is %s (%s); using the epipolar resampling fallback\n",
                 statusToken(r.rectification.status), r.rectification.message.c_str());
    char blockText[32];
    std::snprintf(blockText, sizeof blockText, "%.1f", r.epipoleBlockRadius);
    out.detail = std::string("epipolar layout (") + reasonToken(r.rectification.reason) +
                 "), epipole block radius " + blockText + " px, " + basis + ", " +
                 std::to_string(settings.mapSize) + " slices x " + std::to_string(settings.mapSize);
  }
  return out;
}

} // namespace

const std::vector<Method>& methodRegistry() {
  static const std::vector<Method> registry = {
      {"reference", "world-space march of every view ray against the standard shadow map", true,
       runReference},
      {"prefilter", "Klehm et al. 2014: prefiltered Fourier basis on the rectified map (GPU)", false,
       runPrefilter},
      {"minmax", "1D min/max tree march over the rectified rows (Chen et al. 2011, Yusov 2012)", false,
       runMinMax},
      {"brute", "brute-force march over the rectified rows, texel by texel", false, runBrute},
  };
  return registry;
}

std::string methodNames() {
  std::string names;
  for (const Method& m : methodRegistry())
    names += (names.empty() ? "" : " | ") + m.name;
  return names;
}

const Method& findMethod(const std::string& name, const std::string& option) {
  for (const Method& m : methodRegistry())
    if (m.name == name) return m;
  throw UsageError("option " + option + ": '" + name + "' is not a method (" + methodNames() + ")");
}

MethodOutput runMethod(const std::string& name, FrameInputs& frame, const MethodSettings& settings) {
  return findMethod(name).run(frame, settings);
}

} // namespace crep::tool
