// The tool's methods, each built from the library: the world-space reference march (WorldMarchPass),
// Klehm et al. 2014's prefiltered scattering on every frame (crep::Scattering), and the
// min/max tree and brute-force marches over the rectified rows (MinMaxTreePass, RectifiedMarchPass), with
// the epipolar resampling fallback (EpipolarLayout + ShadowResamplePass) for frames whose rectification is
// not projective.
#include "methods.h"

#include "args.h"
#include "gl_session.h"

#include <crep/core/error.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/resample.h>
#include <crep/pipeline/scattering.h>
#include <crep/postfx/gpu_froxel_fog.h>
#include <crep/postfx/gpu_radial_blur.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/gpu_light_texture.h>
#include <crep/scatter/gpu_world_march.h>
#include <crep/scatter/ray_scattering.h>
#include <crep/scenes/scene_renderer.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

namespace crep::tool {

namespace {

gl::Handle newScatteringTexture(const FrameInputs& frame) {
  return gl::createTexture2D(GL_RGBA32F, frame.width, frame.height, "--size");
}

/// WorldMarchPass on every pixel of the frame (the reference).
void runWorldMarch(const FrameInputs& frame, const MethodSettings& settings, std::uint32_t scattering) {
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
  a.lightTexture = frame.lightTexture.gpu(); // texture 0: untextured
  pass.run(a);
  glFinish();
}

/// One local light as the marches see it: a spot, or one face of a point light, with its perspective map.
struct LocalLightView {
  LocalLight light;
  const LocalShadowMap* shadow = nullptr;
  int spot = -1;             ///< index into spotLights, or -1
  int point = -1, face = -1; ///< index into pointLights and its face, or -1
  std::string name() const {
    return spot >= 0 ? "spot " + std::to_string(spot)
                     : "point " + std::to_string(point) + " face " + std::to_string(face);
  }
};

/// Every spot and every point-light face of the frame (Klehm et al. 2014, Sec. 3.2: six spot faces per
/// point).
std::vector<LocalLightView> localLightViews(const FrameInputs& frame) {
  std::vector<LocalLightView> views;
  for (std::size_t i = 0; i < frame.spotLights.size(); ++i)
    views.push_back(
        {LocalLight::spot(frame.spotLights[i]), &frame.spotShadows.at(i), static_cast<int>(i), -1, -1});
  for (std::size_t i = 0; i < frame.pointLights.size(); ++i)
    for (int k = 0; k < 6; ++k)
      views.push_back({LocalLight::pointFace(frame.pointLights[i], k),
                       &frame.pointShadows.at(6 * i + static_cast<std::size_t>(k)), -1, static_cast<int>(i),
                       k});
  return views;
}

/// The world-space march of one local light against its perspective shadow map (WorldMarchPass with
/// localLight; crep/scatter/world_march.h) into `output`.
void marchLocalLight(const FrameInputs& frame, WorldMarchPass& pass, const LocalLightView& view,
                     std::uint32_t output) {
  WorldMarchPass::FrameAttribs a;
  a.camera = &frame.camera;
  a.localLight = &view.light;
  a.medium = &frame.medium;
  a.cameraDepth = frame.cameraDepth.get();
  a.shadowMap = view.shadow->texture.get();
  a.lightClipFromWorld = view.shadow->lightClipFromWorld;
  a.bias = view.shadow->bias;
  a.output = output;
  if (const LightTextureMap* t =
          view.spot >= 0 ? frame.spotTexture(static_cast<std::size_t>(view.spot)) : nullptr)
    a.lightTexture = t->gpu();
  pass.run(a);
  glFinish();
}

/// Adds `light`'s result to the method's output: computed by `compute` into the output itself when it holds
/// nothing yet (`empty`), else into a scratch texture and added (the lights' contributions add).
void addLight(const FrameInputs& frame, MethodOutput& out, bool& empty, gl::Handle& scratch,
              const std::function<void(std::uint32_t)>& compute) {
  if (empty) {
    compute(out.scattering.get());
    empty = false;
    return;
  }
  if (!scratch) scratch = newScatteringTexture(frame);
  compute(scratch.get());
  addScattering(frame, out.scattering.get(), scratch.get());
  glFinish();
}

/// The world-space reference: every pixel's view ray marched against the standard shadow map
/// (crep/scatter/world_march.h), independent of any rectification; each local light against its own
/// perspective map (each point-light face against its face's map), the results summed.
MethodOutput runReference(FrameInputs& frame, const MethodSettings& settings) {
  MethodOutput out;
  out.used = "reference";
  out.detail = std::to_string(settings.steps) + " march steps";
  if (frame.directional)
    out.detail +=
        ", standard map " + std::to_string(frame.shadowWidth) + "x" + std::to_string(frame.shadowHeight);
  out.scattering = newScatteringTexture(frame);
  bool empty = true;
  if (frame.directional) {
    out.timings.time("reference march", [&] { runWorldMarch(frame, settings, out.scattering.get()); });
    empty = false;
  }
  const std::vector<LocalLightView> views = localLightViews(frame);
  if (!views.empty()) {
    out.detail += (frame.directional ? " + " : ", ") + std::to_string(frame.spotLights.size()) + " spot, " +
                  std::to_string(frame.pointLights.size()) + " point lights (perspective maps)";
    WorldMarchPass::CreateInfo info;
    info.options.steps = settings.steps;
    WorldMarchPass pass(info);
    gl::Handle scratch;
    for (const LocalLightView& v : views)
      out.timings.time("reference march (local lights)", [&] {
        addLight(frame, out, empty, scratch,
                 [&](std::uint32_t target) { marchLocalLight(frame, pass, v, target); });
      });
  }
  return out;
}

} // namespace

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

namespace {

/// The min/max tree (tree = true) or brute-force march of every pixel's view ray along its row of the
/// rectified map (projective), or of the epipolar fallback map. No epipole block: both marches take every
/// texel's visibility exactly, next to the epipole as anywhere (the block is the prefiltered method's).
void addLocalLightsRectified(FrameInputs& frame, const MethodSettings& settings, bool tree, MethodOutput& out,
                             bool empty);

MethodOutput runRectifiedMarch(FrameInputs& frame, const MethodSettings& settings, bool tree) {
  MethodOutput out;
  out.used = tree ? "minmax" : "brute";
  if (!frame.directional) {
    out.scattering = newScatteringTexture(frame);
    addLocalLightsRectified(frame, settings, tree, out, true);
    return out;
  }
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
  // A light texture: the colour of every texel's light ray (LightColorMapPass), which the march multiplies
  // each lit section by (RectifiedMarchPass::FrameAttribs::lightColors).
  std::unique_ptr<LightColorMapPass> colors;
  if (frame.lightTexture.present())
    colors = out.timings.time("light colour map", [&] {
      auto colorMap = std::make_unique<LightColorMapPass>(LightColorMapPass::CreateInfo{width, height});
      colorMap->run({.layout = layout, .lightTexture = frame.lightTexture.gpu(), .light = &frame.light});
      glFinish();
      return colorMap;
    });
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
    a.lightColors = colors ? colors->colorMapTexture() : 0;
    pass->run(a);
    glFinish();
  });
  addLocalLightsRectified(frame, settings, tree, out, false);
  return out;
}

/// The min/max tree or brute-force march of one local light (Klehm et al. 2014, Sec. 3.2) into `target`,
/// as crep::Scattering decides: its rectification for the camera; projective (the light off screen) -> its
/// rectified map, rasterized with the scene's casters or point-resampled from its perspective map
/// (ShadowResamplePass, Sec. 4.1's rule on the light's layout), marched along the rows with `localLight`; in
/// or near the view -> the world-space march against its perspective map; outside the view -> nothing
/// (returns false, `target` untouched).
bool marchLocalRectified(FrameInputs& frame, const MethodSettings& settings, const LocalLightView& v,
                         bool tree, WorldMarchPass& world, std::uint32_t target, StageTimings& timings,
                         std::string& summary) {
  const Rectification rect = timings.time("rectify (local lights)", [&] {
    return v.spot >= 0
               ? rectify(frame.camera, frame.spotLights[static_cast<std::size_t>(v.spot)], settings.rectify)
               : rectifyPointLight(frame.camera, frame.pointLights[static_cast<std::size_t>(v.point)],
                                   settings.rectify)[static_cast<std::size_t>(v.face)];
  });
  if (rect.status == RectifyStatus::Empty) return false;
  if (!rect.projective()) {
    summary += " " + v.name() + ": world march;";
    timings.time("world-space march (local lights)", [&] { marchLocalLight(frame, world, v, target); });
    return true;
  }
  summary += " " + v.name() + ": rectified;";
  const auto layout = std::make_shared<const ProjectiveLayout>(rect);
  const int size = settings.mapSize;
  gl::Handle map;
  if (frame.renderer) {
    map = scenes::createDepthTexture(size, size, "--map-size");
    timings.time("shadow pass (local lights, rectified)", [&] {
      frame.renderer->renderRectified(rect, map.get(), size, size);
      glFinish();
    });
  } else {
    map = gl::createTexture2D(GL_R32F, size, size, "--map-size");
    timings.time("resample (local lights)", [&] {
      ShadowResamplePass pass({size, size});
      ShadowResamplePass::FrameAttribs a;
      a.layout = layout.get();
      a.shadowMap = v.shadow->texture.get();
      a.lightClipFromWorld = v.shadow->lightClipFromWorld;
      a.output = map.get();
      pass.run(a);
      glFinish();
    });
  }
  const RectifiedMarchPass::Mode mode =
      tree ? RectifiedMarchPass::Mode::MinMaxTree : RectifiedMarchPass::Mode::BruteForce;
  RectifiedMarchPass pass({size, size, mode});
  std::unique_ptr<MinMaxTreePass> trees;
  if (tree) {
    trees = std::make_unique<MinMaxTreePass>(MinMaxTreePass::CreateInfo{size, size});
    timings.time("min/max trees (local lights)", [&] {
      trees->run(map.get());
      glFinish();
    });
  }
  std::unique_ptr<LightColorMapPass> colors;
  if (const LightTextureMap* t = v.spot >= 0 ? frame.spotTexture(static_cast<std::size_t>(v.spot)) : nullptr)
    colors = timings.time("light colour map (local lights)", [&] {
      auto colorMap = std::make_unique<LightColorMapPass>(LightColorMapPass::CreateInfo{size, size});
      colorMap->run({.layout = layout.get(), .lightTexture = t->gpu(), .localLight = &v.light});
      glFinish();
      return colorMap;
    });
  timings.time(tree ? "min/max march (local lights)" : "brute-force march (local lights)", [&] {
    RectifiedMarchPass::FrameAttribs a;
    a.layout = layout.get();
    a.camera = &frame.camera;
    a.localLight = &v.light;
    a.medium = &frame.medium;
    a.cameraDepth = frame.cameraDepth.get();
    a.rectifiedDepth = map.get();
    a.minMaxBuffer = trees ? trees->treeBuffer() : 0;
    a.output = target;
    a.lightColors = colors ? colors->colorMapTexture() : 0;
    pass.run(a);
    glFinish();
  });
  return true;
}

/// The local lights of the frame marched by marchLocalRectified and added to `out` (`empty`: out holds
/// nothing yet).
void addLocalLightsRectified(FrameInputs& frame, const MethodSettings& settings, bool tree, MethodOutput& out,
                             bool empty) {
  const std::vector<LocalLightView> views = localLightViews(frame);
  if (views.empty()) return;
  WorldMarchPass::CreateInfo info;
  info.options.steps = settings.steps;
  WorldMarchPass world(info);
  gl::Handle scratch;
  std::string summary;
  for (const LocalLightView& v : views) {
    if (empty) {
      if (marchLocalRectified(frame, settings, v, tree, world, out.scattering.get(), out.timings, summary))
        empty = false;
      continue;
    }
    if (!scratch) scratch = newScatteringTexture(frame);
    if (marchLocalRectified(frame, settings, v, tree, world, scratch.get(), out.timings, summary)) {
      addScattering(frame, out.scattering.get(), scratch.get());
      glFinish();
    }
  }
  if (empty) {
    // No light reaches the view: zero radiance, and the transmittance from an unlit world march.
    const LocalLightView& v = views.front();
    LocalLightView dark = v;
    dark.light.intensity = glm::dvec3(0.0);
    marchLocalLight(frame, world, dark, out.scattering.get());
  }
  out.detail += (out.detail.empty() ? "" : "; ") + std::string("local lights:") + summary;
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
/// With `sampling` Epipolar (Yusov 2012, Sec. 5-6): the method evaluates the epipolar samples and the
/// corrections only (epipolar-prefilter), or, with `method` MinMaxMarch, marches them along the map's
/// min/max trees (epipolar-sampling: Yusov's method); the stages are the sampling's.
MethodOutput runFrontDoor(FrameInputs& frame, const MethodSettings& settings, Scattering::Method method,
                          Scattering::Sampling sampling, const char* name) {
  MethodOutput out;
  out.used = name;
  const Scattering::CreateInfo info = frontDoorCreateInfo(frame, settings, method, sampling);
  auto scattering = out.timings.time("setup", [&] { return std::make_unique<Scattering>(info); });
  const Scattering::ShadowMap shadow{frame.shadowMap.get(), frame.lightClipFromWorld, frame.shadowBias};
  Scattering::FrameAttribs a;
  a.camera = &frame.camera;
  a.light = frame.directional ? &frame.light : nullptr; // a night frame: the local lights alone
  a.medium = &frame.medium;
  // Local lights (Klehm et al. 2014, Sec. 3.2): drawn with the scene's casters, or users' perspective maps
  // (resampled into each projective light's rectified map, marched directly by a light in view).
  a.spotLights = frame.spotLights;
  a.pointLights = frame.pointLights;
  std::vector<Scattering::ShadowMap> spotMaps, pointMaps;
  if (!frame.renderer) {
    for (const LocalShadowMap& m : frame.spotShadows)
      spotMaps.push_back({m.texture.get(), m.lightClipFromWorld, m.bias});
    for (const LocalShadowMap& m : frame.pointShadows)
      pointMaps.push_back({m.texture.get(), m.lightClipFromWorld, m.bias});
    a.spotShadowMaps = spotMaps;
    a.pointShadowMaps = pointMaps;
  }
  // Light textures (Klehm et al. 2014, Sec. 3.2): the sun's and the spots' (an untextured spot: texture 0).
  const GpuLightTexture sunTexture = frame.lightTexture.gpu();
  if (frame.directional && frame.lightTexture.present()) a.lightTexture = &sunTexture;
  std::vector<GpuLightTexture> spotTextures;
  if (!frame.spotTextures.empty()) {
    for (std::size_t i = 0; i < frame.spotLights.size(); ++i)
      spotTextures.push_back(frame.spotTexture(i) ? frame.spotTexture(i)->gpu() : GpuLightTexture{});
    a.spotLightTextures = spotTextures;
  }
  a.cameraDepth = frame.cameraDepth.get();
  out.scattering = newScatteringTexture(frame);
  a.output = out.scattering.get();
  if (frame.renderer)
    a.drawCasters = [&](const glm::dmat4& clipFromWorld) { frame.renderer->drawDepth(clipFromWorld); };
  if (frame.directional) a.shadowMap = &shadow;
  const Scattering::FrameResult r = scattering->run(a);
  for (const Scattering::Stage& stage : r.stages)
    out.timings.append({{stage.name, stage.wallMilliseconds}}); // comparable with the other methods' stages
  const PrefilterOptions& options = settings.prefilter;
  const std::string basis =
      method == Scattering::Method::MinMaxMarch ? std::string("min/max tree march")
      : options.reconstruction == VisibilityReconstruction::Exact
          ? std::string("exact visibility")
          : "Fourier, M = " + std::to_string(options.bases) + ", " + storageFormatToken(options.format);
  std::string local;
  if (!r.localLights.empty()) {
    // prefiltered (projective layout), prefiltered on the epipolar layout (in or near the view), marched,
    // outside the view
    int counts[4] = {0, 0, 0, 0};
    for (const Scattering::LightResult& l : r.localLights)
      ++counts[l.status == RectifyStatus::Projective ? 0
               : l.status == RectifyStatus::Fallback ? (l.epipolar ? 1 : 2)
                                                     : 3];
    local = "; local lights: " + std::to_string(counts[0] + counts[1]) + " prefiltered (" +
            std::to_string(counts[1]) + " on the epipolar layout), " + std::to_string(counts[2]) +
            " marched in world space, " + std::to_string(counts[3]) + " outside the view";
  }
  if (!frame.directional) {
    out.detail =
        "no directional light, " + basis + ", map " + std::to_string(settings.mapSize) + "^2" + local;
    return out;
  }
  if (r.layout == Scattering::Layout::Projective) {
    out.detail = "projective layout, " + basis + ", " + std::to_string(r.rectification.splitCount()) +
                 " splits, map " + std::to_string(settings.mapSize) + "^2 " +
                 (frame.renderer ? "rasterized" : "resampled from the standard map");
  } else {
    std::fprintf(stderr, "crep: %s: rectification is %s (%s); using the epipolar resampling fallback\n", name,
                 statusToken(r.rectification.status), r.rectification.message.c_str());
    char blockText[32];
    std::snprintf(blockText, sizeof blockText, "%.1f", r.epipoleBlockRadius);
    out.detail = std::string("epipolar layout (") + reasonToken(r.rectification.reason) +
                 "), epipole block radius " + blockText + " px, " + basis + ", " +
                 std::to_string(settings.mapSize) + " slices x " + std::to_string(settings.mapSize);
  }
  out.detail += local;
  if (sampling == Scattering::Sampling::Epipolar) {
    const EpipolarSamplingOptions& o = settings.sampling;
    const Scattering::FrameResult::SamplingStatistics& st = r.sampling;
    char text[256];
    std::snprintf(text, sizeof text,
                  "; epipolar sampling %d x %d, step %d, downscale %d: %d samples on screen, %d evaluated "
                  "(%.1f%%), %d + %d pixels corrected (%.2f%%)",
                  o.slices, o.samples, o.initialStep, o.downscale, st.validSamples, st.marchedSamples,
                  st.validSamples > 0 ? 100.0 * st.marchedSamples / st.validSamples : 0.0, st.correctedPixels,
                  st.correctedFullPixels,
                  100.0 * (st.correctedPixels * o.downscale * o.downscale + st.correctedFullPixels) /
                      (double(frame.width) * frame.height));
    out.detail += text;
  }
  return out;
}

MethodOutput runPrefilter(FrameInputs& frame, const MethodSettings& settings) {
  return runFrontDoor(frame, settings, Scattering::Method::Prefiltered, Scattering::Sampling::PerPixel,
                      "prefilter");
}
/// Yusov 2012: epipolar sampling with the min/max tree march at the selected samples.
MethodOutput runEpipolarSampling(FrameInputs& frame, const MethodSettings& settings) {
  return runFrontDoor(frame, settings, Scattering::Method::MinMaxMarch, Scattering::Sampling::Epipolar,
                      "epipolar-sampling");
}
/// The hybrid: epipolar sampling with the prefiltered evaluation at the selected samples.
MethodOutput runEpipolarPrefilter(FrameInputs& frame, const MethodSettings& settings) {
  return runFrontDoor(frame, settings, Scattering::Method::Prefiltered, Scattering::Sampling::Epipolar,
                      "epipolar-prefilter");
}

/// Mitchell 2007's screen-space radial blur (crep/postfx/gpu_radial_blur.h) with its default, physically
/// anchored knobs in mode OcclusionFraction (Eq. 2: the radial sky fraction times the pixel's own
/// unshadowed in-scattering; on sunset 320x180 26% relative RMSE against the reference, the default
/// SourceRadiance 77%): the sun only. Local lights and light textures are ignored with a warning on stderr
/// (the blur models neither); a frame without a directional light gets no in-scattering (RGB 0, A the
/// transmittance), also with a warning, so that compare and bench, which run every method, still run.
MethodOutput runRadial(FrameInputs& frame, const MethodSettings&) {
  if (!frame.directional)
    std::fprintf(stderr, "crep: radial: the frame has no directional light; the radial blur (the sun only) "
                         "adds no in-scattering\n");
  if (frame.hasLocalLights())
    std::fprintf(stderr,
                 "crep: radial: the radial blur models the sun only; the frame's %zu spot and %zu "
                 "point lights are ignored\n",
                 frame.spotLights.size(), frame.pointLights.size());
  if (frame.textured()) std::fprintf(stderr, "crep: radial: light textures are ignored by the radial blur\n");
  // Without a sun: one behind the camera, whose fade is 0 (the pass writes RGB 0 and the transmittance).
  const DirectionalLight sun = frame.directional ? frame.light : DirectionalLight(frame.camera.forward());
  MethodOutput out;
  out.used = "radial";
  RadialBlurPass::CreateInfo info;
  info.options.mode = RadialBlurMode::OcclusionFraction;
  auto pass = out.timings.time("setup", [&] { return std::make_unique<RadialBlurPass>(info); });
  out.scattering = newScatteringTexture(frame);
  RadialBlurPass::FrameAttribs a;
  a.camera = &frame.camera;
  a.light = &sun;
  a.medium = &frame.medium;
  a.cameraDepth = frame.cameraDepth.get();
  a.output = out.scattering.get();
  out.timings.time("radial blur", [&] {
    pass->run(a);
    glFinish();
  });
  char fade[32];
  std::snprintf(fade, sizeof fade, "%.3f", pass->lastLight().fade);
  out.detail = "occlusion fraction (Eq. 2), " + std::to_string(info.options.samples) +
               " samples, source scale " + std::to_string(info.options.sourceScale) + ", sun fade " + fade +
               " (screen space, Mitchell 2007)";
  return out;
}

/// The froxel grid of the tool's froxel methods: Wronski 2014's 160 x 90 x 64 from the camera's near plane,
/// the far face placed so that the last slice's sample lies on the camera's far plane (the sky's distance):
/// the apply clamps beyond the last sample, so the sky reads its own distance.
FroxelGrid toolFroxelGrid(const Camera& camera) {
  FroxelGrid grid;
  grid.nearDepth = camera.near();
  grid.farDepth = camera.near() * std::pow(camera.far() / camera.near(), grid.depth / (grid.depth - 0.5));
  return grid;
}

/// Wronski 2014's froxel fog (crep/postfx/gpu_froxel_fog.h) on one frame: ESM of the standard shadow map
/// (at 512^2, see below), per-cell lighting, front-to-back accumulation, one lookup per pixel. A single
/// frame: temporal reprojection off (no jitter). The sun only: local lights and light textures are ignored
/// with a warning on stderr; a frame without a directional light gets no in-scattering (RGB 0, A the
/// transmittance), also with a warning, so that compare and bench, which run every method, still run.
/// `name`: the method the user asked for, named in the warnings (froxel-prefilter runs this path without a
/// sun).
MethodOutput runFroxelEsmAs(FrameInputs& frame, const MethodSettings& settings, const char* name) {
  if (!frame.directional)
    std::fprintf(stderr,
                 "crep: %s: the frame has no directional light; the froxel fog (the sun only) "
                 "adds no in-scattering\n",
                 name);
  if (frame.hasLocalLights())
    std::fprintf(stderr,
                 "crep: %s: the froxel fog lights the volume with the sun only; the frame's %zu spot and "
                 "%zu point lights are ignored\n",
                 name, frame.spotLights.size(), frame.pointLights.size());
  if (frame.textured())
    std::fprintf(stderr, "crep: %s: light textures are ignored by the froxel fog\n", name);
  const DirectionalLight sun =
      frame.directional ? frame.light : DirectionalLight(frame.camera.forward(), glm::dvec3(0.0));
  MethodOutput out;
  out.used = "froxel-esm";
  FroxelFog::CreateInfo info;
  info.grid = toolFroxelGrid(frame.camera);
  info.esm.bias = frame.shadowBias;
  // The ESM at 512^2 whatever the map size, blurred only when downsampled: filtering exp(c z) is dominated
  // by the deepest texel of the window, so any filter wider than the casters (the colonnade's beams are 1-2
  // texels of a 512^2 map) erases their shadows (colonnade at --map-size 512 vs the reference: 7.4%
  // unfiltered, 21% at 1/2, 33% at 1/4 with a radius 2 blur, Wronski 2014's setting for 1536^2 cascades).
  info.esm.downsample = std::max(1, settings.mapSize / 512);
  info.esm.blurRadius = info.esm.downsample > 1 ? 1 : 0;
  info.temporal.historyWeight = 0.0;
  auto fog = out.timings.time("setup", [&] { return std::make_unique<FroxelFog>(info); });
  out.scattering = newScatteringTexture(frame);
  FroxelFog::FrameAttribs a;
  a.camera = &frame.camera;
  a.light = &sun;
  a.medium = &frame.medium;
  a.cameraDepth = frame.cameraDepth.get();
  a.shadowMap = frame.directional ? frame.shadowMap.get() : 0;
  a.lightClipFromWorld = frame.lightClipFromWorld;
  a.output = out.scattering.get();
  out.timings.time("froxel fog", [&] {
    fog->run(a);
    glFinish();
  });
  char text[160];
  std::snprintf(text, sizeof text,
                "%dx%dx%d RGBA16F (%.1f MB), ESM c = %g, 1/%d, blur radius %d, single frame", info.grid.width,
                info.grid.height, info.grid.depth, fog->memoryBytes() / 1e6, info.esm.exponent,
                info.esm.downsample, info.esm.blurRadius);
  out.detail = text;
  return out;
}

MethodOutput runFroxelEsm(FrameInputs& frame, const MethodSettings& settings) {
  return runFroxelEsmAs(frame, settings, "froxel-esm");
}

/// Klehm et al. 2014's prefiltered scattering evaluated at the froxel volume's cells by crep::Scattering
/// (FrameAttribs::froxels: the same frame's basis, no ESM and no accumulation), then FroxelFog's per-pixel
/// lookup (Mode::Prefiltered) on the same grid as froxel-esm: the difference between the two froxel methods
/// is the volume's fill. The sun only (with its light texture): local lights are ignored with a warning on
/// stderr (the fill does not add them); a frame without a directional light runs froxel-esm's unlit path.
MethodOutput runFroxelPrefilter(FrameInputs& frame, const MethodSettings& settings) {
  if (!frame.directional) {
    std::fprintf(stderr, "crep: froxel-prefilter: no directional light to prefilter; running froxel-esm's "
                         "unlit volume\n");
    MethodOutput out = runFroxelEsmAs(frame, settings, "froxel-prefilter");
    out.used = "froxel-prefilter (froxel-esm, no sun)";
    return out;
  }
  if (frame.hasLocalLights())
    std::fprintf(
        stderr,
        "crep: froxel-prefilter: the froxel fill is the sun's only; the frame's %zu spot and %zu point "
        "lights are ignored\n",
        frame.spotLights.size(), frame.pointLights.size());
  MethodOutput out;
  out.used = "froxel-prefilter";
  FroxelFog::CreateInfo fogInfo;
  fogInfo.grid = toolFroxelGrid(frame.camera);
  fogInfo.temporal.historyWeight = 0.0;
  auto fog = out.timings.time("setup", [&] { return std::make_unique<FroxelFog>(fogInfo); });
  Scattering::CreateInfo info;
  info.width = frame.width;
  info.height = frame.height;
  info.mapSize = settings.mapSize;
  info.rectify = settings.rectify;
  info.prefilter = settings.prefilter;
  info.epipoleBlock.steps = settings.steps;
  info.blockingTimings = true; // the tool prints each stage's time, GPU work included
  auto scattering = out.timings.time("setup", [&] { return std::make_unique<Scattering>(info); });
  const Scattering::ShadowMap shadow{frame.shadowMap.get(), frame.lightClipFromWorld, frame.shadowBias};
  const Scattering::FroxelTarget target{fog->currentVolume(), fogInfo.grid, fog->jitter(0)};
  Scattering::FrameAttribs a;
  a.camera = &frame.camera;
  a.light = &frame.light;
  a.medium = &frame.medium;
  a.cameraDepth = frame.cameraDepth.get();
  a.shadowMap = &shadow;
  a.froxels = &target;
  const GpuLightTexture sunTexture = frame.lightTexture.gpu();
  if (frame.lightTexture.present()) a.lightTexture = &sunTexture;
  if (frame.renderer)
    a.drawCasters = [&](const glm::dmat4& clipFromWorld) { frame.renderer->drawDepth(clipFromWorld); };
  const Scattering::FrameResult r = scattering->run(a);
  for (const Scattering::Stage& stage : r.stages)
    out.timings.append({{stage.name, stage.wallMilliseconds}});
  out.scattering = newScatteringTexture(frame);
  out.timings.time("froxel apply", [&] {
    FroxelFog::FrameAttribs f;
    f.mode = FroxelFog::Mode::Prefiltered;
    f.camera = &frame.camera;
    f.cameraDepth = frame.cameraDepth.get();
    f.output = out.scattering.get();
    fog->run(f);
    glFinish();
  });
  char text[160];
  std::snprintf(text, sizeof text, "%dx%dx%d RGBA16F (%.1f MB), %s layout, M = %d, map %d^2, single frame",
                fogInfo.grid.width, fogInfo.grid.height, fogInfo.grid.depth, fog->memoryBytes() / 1e6,
                r.layout == Scattering::Layout::Projective ? "projective" : "epipolar",
                settings.prefilter.bases, settings.mapSize);
  out.detail = text;
  return out;
}

} // namespace

Scattering::CreateInfo frontDoorCreateInfo(const FrameInputs& frame, const MethodSettings& settings,
                                           Scattering::Method method, Scattering::Sampling sampling) {
  Scattering::CreateInfo info;
  info.method = method;
  info.sampling = sampling;
  info.epipolarSampling = settings.sampling;
  info.width = frame.width;
  info.height = frame.height;
  info.mapSize = settings.mapSize;
  info.rectify = settings.rectify;
  info.prefilter = settings.prefilter;
  info.epipoleBlock.steps = settings.steps;
  info.epipoleBlockMethod = settings.epipoleBlock;
  info.epipoleBlockRadius = settings.epipoleBlockRadius;
  info.epipoleBlockMaxPixels = settings.epipoleBlockMaxPixels;
  // --scale is the per-pixel evaluation's (compare runs the epipolar methods beside it at full size).
  info.evaluationScale = sampling == Scattering::Sampling::PerPixel ? settings.scale : 1.0;
  info.blockingTimings = true; // the tool prints each stage's time, GPU work included
  return info;
}

const std::vector<Method>& methodRegistry() {
  static const std::vector<Method> registry = {
      {"reference", "world-space march of every view ray against the standard shadow map", true,
       runReference},
      {"prefilter", "Klehm et al. 2014: prefiltered Fourier basis on the rectified map (GPU)", false,
       runPrefilter},
      {"minmax", "1D min/max tree march over the rectified rows (Chen et al. 2011, Yusov 2012)", false,
       runMinMax},
      {"brute", "brute-force march over the rectified rows, texel by texel", false, runBrute},
      {"epipolar-sampling",
       "Yusov 2012: epipolar sampling, refinement at breaks, min/max march at the samples, bilateral unwarp",
       false, runEpipolarSampling},
      {"epipolar-prefilter",
       "epipolar sampling with the prefiltered evaluation at the samples (a hybrid of the two)", false,
       runEpipolarPrefilter},
      {"froxel-esm",
       "Wronski 2014: froxel volume lit through a blurred exponential shadow map, one 3D lookup "
       "per pixel",
       false, runFroxelEsm},
      {"froxel-prefilter",
       "Klehm et al. 2014's prefiltered scattering filling the froxel volume (crep::Scattering), one 3D "
       "lookup per pixel",
       false, runFroxelPrefilter},
      {"radial", "Mitchell 2007: screen-space radial blur of the sky toward the sun (a heuristic)", false,
       runRadial},
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
  MethodOutput out = findMethod(name).run(frame, settings);
  if (frame.textured()) out.detail += "; light textures";
  return out;
}

} // namespace crep::tool
