// The registry entries that need the epipolar module (epipolar/: min/max tree and brute-force marches
// over rectified rows, the epipolar resampling fallback). They are compiled in when its headers are
// part of the build; without them the registry holds `prefilter` and `reference` only and a frame that
// is not projective runs the reference march (frame.cpp).
#include "epipolar_methods.h"

#if __has_include(<crep/epipolar/gpu_march.h>) && __has_include(<crep/epipolar/resample.h>) && \
    __has_include(<crep/epipolar/epipolar.h>) && __has_include(<crep/epipolar/march.h>)
#define CREP_TOOL_HAS_EPIPOLAR 1
#include <crep/core/error.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/epipolar/resample.h>
#include <crep/scenes/scene_renderer.h>

#include <epoxy/gl.h>

#include <cstdio>
#include <memory>
#endif

namespace crep::tool {

#ifdef CREP_TOOL_HAS_EPIPOLAR

namespace {

/// The epipolar fallback map of a frame: the layout of Sec. 4.1 for the frame's camera, light and
/// screen, and the standard shadow map resampled into it on the GPU (ShadowResamplePass).
struct EpipolarMap {
  std::shared_ptr<EpipolarLayout> layout;
  gl::Handle texture; ///< R32F, width x sliceCount
  int width = 0, height = 0;
};

EpipolarMap makeEpipolarMap(const Frame& frame, const MethodSettings& settings, StageTimings& timings) {
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
    a.shadowWidth = frame.shadowWidth;
    a.shadowHeight = frame.shadowHeight;
    a.lightClipFromWorld = frame.lightClipFromWorld;
    a.rectifiedOut = m.texture.get();
    pass.run(a);
    glFinish();
  });
  return m;
}

/// The world-space march of the pixels around the epipole (seed 003 Fig. 8), over `scattering`.
void marchEpipoleBlock(const Frame& frame, const EpipolarLayout& layout, std::uint32_t scattering, int steps,
                       StageTimings& timings) {
  const auto centre = layout.epipolePixel();
  if (!centre || layout.epipoleBlockRadiusPixels() <= 0.0) return;
  timings.time("epipole block march", [&] {
    WorldMarchPass pass({steps, 16});
    WorldMarchPass::FrameAttribs a;
    a.camera = &frame.camera;
    a.light = &frame.light;
    a.medium = &frame.medium;
    a.cameraDepth = frame.cameraDepth.get();
    a.width = frame.width;
    a.height = frame.height;
    a.shadowMap = frame.shadowMap.get();
    a.shadowWidth = frame.shadowWidth;
    a.shadowHeight = frame.shadowHeight;
    a.lightClipFromWorld = frame.lightClipFromWorld;
    a.bias = frame.shadowBias;
    a.scatteringOut = scattering;
    a.blockCenter = *centre;
    a.blockRadius = layout.epipoleBlockRadiusPixels();
    pass.run(a);
    glFinish();
  });
}

/// The min/max tree (tree = true) or brute-force march of every pixel's view ray along its row of the
/// rectified map (projective), or of the epipolar fallback map (plus the epipole block).
MethodOutput runRectifiedMarch(Frame& frame, const MethodSettings& settings, bool tree, const char* caller) {
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
    std::fprintf(stderr,
                 "crep: %s: rectification is %s (%s); using the epipolar resampling fallback (%s march)\n",
                 caller, statusToken(rect.status), rect.message.c_str(), tree ? "min/max" : "brute-force");
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
  out.scattering = gl::createTexture2D(GL_RGBA32F, frame.width, frame.height, "--size");
  out.timings.time(tree ? "min/max march" : "brute-force march", [&] {
    RectifiedMarchPass::FrameAttribs a;
    a.layout = layout;
    a.camera = &frame.camera;
    a.light = &frame.light;
    a.medium = &frame.medium;
    a.cameraDepth = frame.cameraDepth.get();
    a.width = frame.width;
    a.height = frame.height;
    a.rectifiedDepth = texture;
    a.minMaxBuffer = trees ? trees->treeBuffer() : 0;
    a.scatteringOut = out.scattering.get();
    pass->run(a);
    glFinish();
  });
  if (epipolar)
    marchEpipoleBlock(frame, *epipolar->layout, out.scattering.get(), settings.steps, out.timings);
  return out;
}

MethodOutput runMinMax(Frame& frame, const MethodSettings& settings) {
  return runRectifiedMarch(frame, settings, true, "minmax");
}
MethodOutput runBrute(Frame& frame, const MethodSettings& settings) {
  return runRectifiedMarch(frame, settings, false, "brute");
}

} // namespace

void appendEpipolarMethods(std::vector<Method>& registry) {
  registry.push_back({"minmax",
                      "1D min/max tree march over the rectified rows (Chen et al. 2011, Yusov 2012)", false,
                      runMinMax});
  registry.push_back({"brute", "brute-force march over the rectified rows, texel by texel", false, runBrute});
}

std::optional<MethodOutput> prefilterFallback(Frame& frame, const MethodSettings& settings,
                                              const Rectification&) {
  // The prefiltered evaluation pass needs a projective layout (gpu_pass.h); on the epipolar layout the
  // min/max march over the resampled map stands in for it (it announces the fallback on stderr).
  return runRectifiedMarch(frame, settings, true, "prefilter");
}

bool epipolarAvailable() {
  return true;
}

#else

void appendEpipolarMethods(std::vector<Method>&) {}
std::optional<MethodOutput> prefilterFallback(Frame&, const MethodSettings&, const Rectification&) {
  return std::nullopt;
}
bool epipolarAvailable() {
  return false;
}

#endif

} // namespace crep::tool
