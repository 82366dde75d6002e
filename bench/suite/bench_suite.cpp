#include "bench_suite.h"
#include "backends.h"
#include "plot.h"

#include "args.h"
#include "atmosphere_frame.h"
#include "backend_method.h"
#include "gl_session.h"
#include "methods.h"
#include "paths.h"
#include "scene_frame.h"
#include "timings.h"

#include <crep/core/error.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/gpu/gl.h>
#include <crep/pipeline/rectified_shadow_pass.h>
#include <crep/pipeline/scattering.h>
#include <crep/postfx/gpu_froxel_fog.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/ray.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>
#include <crep/scenes/shaders.h>
#include <crep/support/image_compare.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <vector>

namespace crep::bench {

namespace {

using Clock = std::chrono::steady_clock;

/// The most regions per split of the parallelization rows (Table 1).
constexpr int kMaxRegionsPerSplit = 4;

/// Median wall time in ms of `repeat` runs of f (GPU work is finished inside f with glFinish).
double medianMs(int repeat, const std::function<void()>& f) {
  std::vector<double> t;
  for (int i = 0; i < repeat; ++i) {
    const auto start = Clock::now();
    f();
    t.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

struct Setup {
  scenes::Scene scene;
  Rectification rect;
  std::shared_ptr<ProjectiveLayout> layout;
  gl::Handle rectified, cameraDepth, scattering;
  Image rectifiedImage, cameraDepthImage;
  int mapW, mapH, screenW, screenH;
};

Setup makeSetup(const std::string& sceneName, int screenW, int screenH, int mapW, int mapH) {
  Setup s{scenes::makeScene(sceneName, double(screenW) / screenH),
          {},
          {},
          {},
          {},
          {},
          {},
          {},
          mapW,
          mapH,
          screenW,
          screenH};
  s.rect = rectify(s.scene.camera, s.scene.sun, Scattering::CreateInfo{}.rectify); // the library's defaults
  if (!s.rect.projective()) throw Error("scene " + sceneName + " is not projective: " + s.rect.message);
  s.layout = std::make_shared<ProjectiveLayout>(s.rect);
  scenes::SceneRenderer renderer(s.scene.mesh);
  s.rectified = scenes::createDepthTexture(mapW, mapH, "--map");
  renderer.renderRectified(s.rect, s.rectified.get(), mapW, mapH);
  s.rectifiedImage = scenes::readDepthTexture(s.rectified.get(), mapW, mapH);
  s.cameraDepth = scenes::createDepthTexture(screenW, screenH, "--size");
  renderer.renderDepth(s.scene.camera.clipFromWorld(), s.cameraDepth.get(), 0, 0, 0, screenW, screenH);
  s.cameraDepthImage = scenes::readDepthTexture(s.cameraDepth.get(), screenW, screenH);
  s.scattering = gl::createTexture2D(GL_RGBA32F, screenW, screenH, "--size");
  glFinish();
  return s;
}

/// The evaluation's profile on the CPU (the GPU pass's rule): prefilter regions crossed per pixel (the last
/// one partly) and the filtered-basis fetches that makes (one per RGBA layer and region).
struct EvaluationProfile {
  double meanRegions = 0.0;
  int maxRegions = 0;
  std::vector<double> histogram; ///< fraction of pixels crossing 1, 2, ... regions
};

EvaluationProfile profileEvaluation(const Setup& s, int regionsPerSplit) {
  EvaluationProfile p;
  const int R = s.layout->regionCount() * regionsPerSplit;
  p.histogram.assign(static_cast<std::size_t>(R), 0.0);
  const int n = s.cameraDepthImage.width() * s.cameraDepthImage.height();
  for (int y = 0; y < s.cameraDepthImage.height(); ++y)
    for (int x = 0; x < s.cameraDepthImage.width(); ++x) {
      const PixelRay ray = pixelRay(s.scene.camera, s.cameraDepthImage, x, y);
      const RectPoint hit = s.layout->toRectified(s.scene.camera.position() + ray.surface * ray.direction);
      const int q =
          std::min(static_cast<int>(std::floor(std::clamp(hit.splitColumn, 0.0, 1.0) * regionsPerSplit)),
                   regionsPerSplit - 1);
      const int regions = std::clamp(hit.split * regionsPerSplit + q + 1, 1, R);
      p.meanRegions += regions;
      p.maxRegions = std::max(p.maxRegions, regions);
      p.histogram[static_cast<std::size_t>(regions - 1)] += 1.0 / n;
    }
  p.meanRegions /= n;
  return p;
}

struct GpuTimes {
  double prefilter, evaluate;
  double prefilterLimit = 0.0, evaluateLimit = 0.0; ///< the passes stripped to their memory traffic
  /// The fastest write-only prefilter over 4, 8, 16 and 32 bases per invocation, and that count.
  double prefilterLimitFastest = 0.0;
  int prefilterLimitFastestBases = 0;
  /// Evaluation variants (with `limits`): the per-region loop over the visibility table (scatteringPrefix
  /// false), no table at all (visibilityTableSamples 0), and the default's per-frame tables alone (the
  /// evaluation of an 8 x 8 image: what does not scale with the screen).
  double evaluatePerRegion = 0.0, evaluateDirect = 0.0, evaluateTablesOnly = 0.0;
  double evaluateVisibilityTableOnly = 0.0; ///< the same for the visibility table alone
};

/// The evaluation pass's inputs for a set-up's frame and a filtered basis.
EvaluatePass::FrameAttribs evaluateAttribs(const Setup& s, const FilteredBasisView& basis) {
  EvaluatePass::FrameAttribs ev;
  ev.cameraDepth = s.cameraDepth.get();
  ev.output = s.scattering.get();
  ev.camera = &s.scene.camera;
  ev.light = &s.scene.sun;
  ev.medium = &s.scene.medium;
  ev.layout = s.layout.get();
  ev.basis = basis;
  return ev;
}

/// PrefilterOptions::basesPerInvocation for `requested` bases per invocation at M = `bases`: at most M
/// rounded up to a multiple of 4 (the library's rule: a multiple of 4 in [4, 128]; the last group of a row
/// may be partial), so every even M of --bases (6, 10, 30, ...) runs.
int perInvocationFor(int requested, int bases) {
  return std::min(requested, (bases + 3) / 4 * 4);
}

/// What timeGpu measures: the passes at the set-up's map with these options.
struct GpuRun {
  int regionsPerSplit = Scattering::CreateInfo{}.prefilter.regionsPerSplit;
  int basesPerInvocation = PrefilterOptions{}.basesPerInvocation;
  bool evaluate = true; ///< false: the prefilter alone (GpuTimes::evaluate stays 0)
  bool limits = false;  ///< the passes stripped to their memory traffic and the evaluation variants
};

/// Median ms of `repeat` runs of a GL pass, after one warm-up run (shader specialization on first dispatch).
double timePass(int repeat, const std::function<void()>& pass) {
  pass();
  glFinish();
  return medianMs(repeat, [&] {
    pass();
    glFinish();
  });
}

/// GpuTimes' limits and evaluation variants (`info`, `evalInfo`: the measured passes' create infos).
void timeGpuLimits(PrefilterPass::CreateInfo info, EvaluatePass::CreateInfo evalInfo,
                   const PrefilterPass::FrameAttribs& frame, const EvaluatePass::FrameAttribs& ev, int bases,
                   int repeat, GpuTimes& t) {
  // The same passes with memoryLimit: the same reads and writes (prefilter) and the same fetches and
  // store (evaluation) without the math; the evaluation limit reads the real filtered basis.
  info.memoryLimit = true;
  evalInfo.memoryLimit = true;
  PrefilterPass prefilterLimit(info);
  EvaluatePass evaluateLimit(evalInfo);
  prefilterLimit.run(frame);
  evaluateLimit.run(ev);
  glFinish();
  t.prefilterLimit = medianMs(repeat, [&] {
    prefilterLimit.run(frame);
    glFinish();
  });
  t.evaluateLimit = medianMs(repeat, [&] {
    evaluateLimit.run(ev);
    glFinish();
  });
  for (const int perInvocation : {4, 8, 16, 32}) {
    PrefilterPass::CreateInfo writer = info;
    writer.options.basesPerInvocation = perInvocationFor(perInvocation, bases);
    PrefilterPass writeOnly(writer);
    const double ms = timePass(repeat, [&] { writeOnly.run(frame); });
    if (t.prefilterLimitFastestBases == 0 || ms < t.prefilterLimitFastest) {
      t.prefilterLimitFastest = ms;
      t.prefilterLimitFastestBases = writer.options.basesPerInvocation;
    }
  }
  const auto timeVariant = [&](const EvaluateOptions& options, const EvaluatePass::FrameAttribs& attribs) {
    EvaluatePass::CreateInfo vi;
    vi.bases = bases;
    vi.options = options;
    EvaluatePass variant(vi);
    return timePass(repeat, [&] { variant.run(attribs); });
  };
  EvaluateOptions perRegion, direct;
  perRegion.scatteringPrefix = false;
  direct.visibilityTableSamples = 0;
  t.evaluatePerRegion = timeVariant(perRegion, ev);
  t.evaluateDirect = timeVariant(direct, ev);
  const gl::Handle tinyDepth = gl::createTexture2D(GL_R32F, 8, 8),
                   tinyOut = gl::createTexture2D(GL_RGBA32F, 8, 8);
  const std::vector<float> half(64, 0.5f);
  glTextureSubImage2D(tinyDepth.get(), 0, 0, 0, 8, 8, GL_RED, GL_FLOAT, half.data());
  EvaluatePass::FrameAttribs tiny = ev;
  tiny.cameraDepth = tinyDepth.get();
  tiny.output = tinyOut.get();
  t.evaluateTablesOnly = timeVariant(EvaluateOptions{}, tiny);
  t.evaluateVisibilityTableOnly = timeVariant(perRegion, tiny);
}

/// The GPU prefilter (RGBA8) and evaluation of a set-up's frame at M = `bases`: medians of `repeat` runs.
GpuTimes timeGpu(const Setup& s, int bases, int repeat, const GpuRun& run = {}) {
  PrefilterPass::CreateInfo info;
  info.mapWidth = s.mapW;
  info.mapHeight = s.mapH;
  info.options.bases = bases;
  info.options.format = StorageFormat::RGBA8;
  info.options.regionsPerSplit = run.regionsPerSplit;
  info.options.basesPerInvocation = perInvocationFor(run.basesPerInvocation, bases);
  PrefilterPass prefilter(info);
  PrefilterPass::FrameAttribs frame;
  frame.rectifiedDepth = s.rectified.get();
  frame.layout = s.layout.get();
  frame.medium = &s.scene.medium;
  GpuTimes t{};
  t.prefilter = timePass(repeat, [&] { prefilter.run(frame); });
  if (!run.evaluate) return t;
  EvaluatePass::CreateInfo evalInfo;
  evalInfo.bases = bases;
  EvaluatePass evaluate(evalInfo);
  const EvaluatePass::FrameAttribs ev = evaluateAttribs(s, prefilter.filteredBasis());
  t.evaluate = timePass(repeat, [&] { evaluate.run(ev); });
  if (run.limits) timeGpuLimits(info, evalInfo, frame, ev, bases, repeat, t);
  return t;
}

/// Stages of a method run that are per-frame work (not one-time set-up: shader builds, pass creation,
/// or the rectified map, which every rectified method shares and which is reported on its own).
bool perFrameStage(const std::string& stage) {
  // --backend vulkan: the engine's camera depth (the scene's frame on OpenGL has it before the methods) and
  // the output's way back to GL are the tool's; the engine's shadow passes are "shadow pass" below.
  if (stage == "engine: camera depth (Vulkan)" || stage == "read back (Vulkan)") return false;
  for (const char* skip : {"setup", "shader", "rectify", "shadow pass", "resample", "upload"})
    if (stage.find(skip) != std::string::npos) return false;
  return true;
}

struct MethodRow {
  std::string name, used;
  double ms = 0.0;
  std::string stages;
  std::map<std::string, double> stageMs; ///< median per stage
};

/// The methods named in `only` (every method of the registry when empty) on one built-in scene's frame:
/// median per-frame milliseconds (sum of the median per-frame stages of `repeat` runs after a warm-up).
/// `mapMs` receives the rectified shadow pass of the warm-up (shared by the methods).
/// `base`: the settings to start from (map size and M are this run's), e.g. epipolar sampling's options.
std::vector<MethodRow> runMethods(const BenchOptions& o, const std::string& scene,
                                  const std::vector<std::string>& only, int repeat, double& mapMs,
                                  const tool::MethodSettings& base = {}) {
  tool::StageTimings setupTimings;
  tool::SceneFrame s = tool::makeSceneFrame(scene, o.screenWidth, o.screenHeight, o.mapWidth, setupTimings);
  tool::MethodSettings settings = base;
  settings.mapSize = o.mapWidth;
  settings.prefilter.bases = o.bases;
  std::vector<MethodRow> rows;
  // --backend vulkan: one engine and device for the scene's runs, so the warm-up builds its pipelines and
  // depth images once.
  std::unique_ptr<tool::VulkanSession> vulkan;
  for (const tool::Method& m : tool::methodRegistry()) {
    if (!only.empty() && std::find(only.begin(), only.end(), m.name) == only.end()) continue;
    std::map<std::string, std::vector<double>> stageMs;
    std::vector<std::string> order;
    std::string used;
    const bool onVulkan = o.backend == "vulkan" && tool::runsOnBackend(m.name);
    if (onVulkan && !vulkan) vulkan = std::make_unique<tool::VulkanSession>(*s.scene);
    for (int i = 0; i < repeat + 1; ++i) { // first run: warm-up (shader compilation, map)
      tool::MethodOutput out =
          onVulkan ? tool::runOnVulkan(s, m.name, settings, vulkan.get()) : m.run(*s.frame, settings);
      used = out.used + (onVulkan ? " on Vulkan" : "");
      if (i == 0) {
        for (const auto& r : out.timings.rows())
          if (r.stage.find("shadow pass (rectified)") != std::string::npos) mapMs = r.ms;
        continue;
      }
      // A stage that runs once per light (local lights) appears once per light: summed within the run.
      std::map<std::string, double> run;
      for (const auto& r : out.timings.rows()) {
        if (!run.count(r.stage) && !stageMs.count(r.stage)) order.push_back(r.stage);
        run[r.stage] += r.ms;
      }
      for (const auto& [stage, ms] : run)
        stageMs[stage].push_back(ms);
    }
    MethodRow row{m.name, used, 0.0, "", {}};
    for (const auto& stage : order) {
      const double ms = median(stageMs[stage]);
      row.stageMs[stage] = ms;
      if (!perFrameStage(stage)) continue;
      row.ms += ms;
      char buf[96];
      std::snprintf(buf, sizeof buf, "%s%s %.2f", row.stages.empty() ? "" : ", ", stage.c_str(), ms);
      row.stages += buf;
    }
    rows.push_back(row);
  }
  return rows;
}

double msOf(const std::vector<MethodRow>& rows, const std::string& name) {
  for (const MethodRow& r : rows)
    if (r.name == name) return r.ms;
  return 0.0;
}

void printRows(const std::vector<MethodRow>& rows) {
  const double prefilterMs = msOf(rows, "prefilter");
  std::printf("%-16s %12s %14s   %s\n", "method", "frame ms", "vs prefilter", "stages (ms)");
  for (const MethodRow& r : rows)
    std::printf("%-16s %12.2f %14.2f   %s%s\n", r.name.c_str(), r.ms,
                prefilterMs > 0 ? r.ms / prefilterMs : 0.0, r.stages.c_str(),
                r.used != r.name ? ("  [ran " + r.used + "]").c_str() : "");
}

bool squareMapOk(const BenchOptions& o, const char* what, int multiple) {
  if (o.mapWidth == o.mapHeight && o.mapWidth % multiple == 0) return true;
  std::printf("\n%s: skipped (needs a square map whose size is a multiple of %d)\n", what, multiple);
  return false;
}

/// The slow marches --quick leaves out (tens of times the prefiltered frame, seconds a frame on llvmpipe).
constexpr const char* kSlowMarches[] = {"reference", "brute"};

/// `names` (every method of the registry when empty) without the slow marches with --quick; `note` says
/// which were left out ("" when none).
std::vector<std::string> quickMethods(const BenchOptions& o, std::vector<std::string> names,
                                      std::string& note) {
  note.clear();
  if (!o.quick) return names;
  if (names.empty())
    for (const tool::Method& m : tool::methodRegistry())
      names.push_back(m.name);
  const auto slow = [](const std::string& name) {
    return std::find(std::begin(kSlowMarches), std::end(kSlowMarches), name) != std::end(kSlowMarches);
  };
  for (const std::string& name : names)
    if (slow(name)) note += (note.empty() ? "" : ", ") + name;
  std::erase_if(names, slow);
  if (!note.empty()) note = "(--quick leaves out the slow marches: " + note + ")\n";
  return names;
}

/// Every method of the registry on the same frame: median per-frame milliseconds and the ratio to the
/// prefiltered method.
void methodsSideBySide(const BenchOptions& o) {
  const tool::MethodSettings settings; // Scattering's defaults
  if (!squareMapOk(o, "methods side by side", Scattering::CreateInfo{}.mapSizeMultiple())) return;
  const int repeat = std::max(1, std::min(o.repeat, 3));
  double mapMs = 0.0;
  std::string note;
  const std::vector<MethodRow> rows = runMethods(o, o.scene, quickMethods(o, {}, note), repeat, mapMs);
  std::printf(
      "\nmethods side by side (scene %s, %dx%d, map %d^2, M = %d, reference %d steps; per-frame ms = sum of\n"
      "the median per-frame stages of %d runs after a warm-up; the rectified shadow pass, %.2f ms, is "
      "shared):\n",
      o.scene.c_str(), o.screenWidth, o.screenHeight, o.mapWidth, o.bases, settings.steps, repeat, mapMs);
  printRows(rows);
  std::printf("%s", note.c_str());
}

/// A method's per-frame milliseconds with its shadow input (the stage perFrameStage leaves out: the
/// rectified shadow pass of a projective frame, the resampling of an epipolar one).
double withShadowInput(const MethodRow& r) {
  double ms = r.ms;
  for (const char* input : {"shadow pass (rectified)", "resample (epipolar)", "resample (projective)"})
    if (r.stageMs.count(input)) ms += r.stageMs.at(input);
  return ms;
}

/// The sun in view (issues "every frame prefiltered" and "sun in view at the cost of any other frame"): the
/// "sunset" scene is the forest's mesh and camera with the sun in view, so every frame takes the epipolar
/// layout. At the run's size and at 640x360: the prefiltered method (crep::Scattering: resampling,
/// prefilter, evaluation, the epipole block tree-marched over the epipolar map) against the same frame with
/// the world-space block (the reference option), Yusov's epipolar sampling, the hybrid and, at 640x360 and
/// below, the per-pixel min/max march; and against the prefiltered method on the forest's own (projective)
/// frame. Ratios with the shadow inputs (resampling / rectified shadow pass), as a frame costs an engine.
void sunInView(const BenchOptions& o) {
  if (!squareMapOk(o, "sun in view", Scattering::CreateInfo{}.mapSizeMultiple())) return;
  const int repeat = std::max(1, std::min(o.repeat, 3));
  std::vector<std::pair<int, int>> sizes = {{o.screenWidth, o.screenHeight}};
  if (!o.quick && (o.screenWidth != 640 || o.screenHeight != 360)) sizes.push_back({640, 360});
  for (const auto& [w, h] : sizes) {
    BenchOptions sized = o;
    sized.screenWidth = w;
    sized.screenHeight = h;
    double mapMs = 0.0;
    std::vector<std::string> methods = {"prefilter", "epipolar-sampling", "epipolar-prefilter"};
    if (static_cast<long long>(w) * h <= 640LL * 360) methods.push_back("minmax"); // 20 s a frame at 1080p
    std::vector<MethodRow> sun = runMethods(sized, "sunset", methods, repeat, mapMs);
    tool::MethodSettings world;
    world.epipoleBlock = Scattering::EpipoleBlockMethod::WorldMarch;
    for (MethodRow r : runMethods(sized, "sunset", {"prefilter"}, repeat, mapMs, world)) {
      r.name = "prefilter-world";
      r.used += " (world-space block)";
      sun.push_back(r);
    }
    const std::vector<MethodRow> forest = runMethods(sized, "forest", {"prefilter"}, repeat, mapMs);
    std::printf(
        "\nsun in view (scene sunset: the forest toward the sun, epipolar layout; %dx%d, map %d^2, M = %d;\n"
        "per-frame ms as above, without the shadow inputs; prefilter-world: the epipole block marched in "
        "world\n"
        "space, CreateInfo::epipoleBlockMethod = WorldMarch):\n",
        w, h, o.mapWidth, o.bases);
    printRows(sun);
    const double projective = forest.empty() ? 0.0 : withShadowInput(forest.front());
    std::printf("%-16s %12.2f %14s   %s  [forest: projective]\n", "prefilter",
                forest.empty() ? 0.0 : forest.front().ms, "",
                forest.empty() ? "" : forest.front().stages.c_str());
    const auto row = [&](const char* name) -> const MethodRow* {
      for (const MethodRow& r : sun)
        if (r.name == name) return &r;
      return nullptr;
    };
    const MethodRow *pre = row("prefilter"), *yusov = row("epipolar-sampling"),
                    *worldRow = row("prefilter-world");
    if (!pre || !yusov || !worldRow || projective <= 0.0) continue;
    const double fallback = withShadowInput(*pre), yusovMs = withShadowInput(*yusov);
    const double correct = yusov->stageMs.count("correct") ? yusov->stageMs.at("correct") : 0.0;
    const double block =
        (pre->stageMs.count("min/max trees (epipole block)")
             ? pre->stageMs.at("min/max trees (epipole block)")
             : 0.0) +
        (pre->stageMs.count("epipole block (tree march)") ? pre->stageMs.at("epipole block (tree march)")
                                                          : 0.0);
    std::printf("with the shadow inputs (resampling %.2f ms / rectified shadow pass %.2f ms), %dx%d:\n"
                "  sunset prefilter / forest prefilter (goal <= 1.5): %.2f (%.2f ms / %.2f ms; world-space "
                "block %.2f)\n"
                "  sunset prefilter / sunset epipolar-sampling (goal <= 0.5): %.2f\n"
                "  epipolar-sampling's correction / its frame (goal <= 0.10): %.3f (%.2f ms)\n"
                "  epipole block (trees + tree march) / sunset prefilter frame: %.3f (%.2f ms; world-space "
                "block stage %.2f ms)\n",
                pre->stageMs.count("resample (epipolar)") ? pre->stageMs.at("resample (epipolar)") : 0.0,
                forest.front().stageMs.count("shadow pass (rectified)")
                    ? forest.front().stageMs.at("shadow pass (rectified)")
                    : 0.0,
                w, h, fallback / projective, fallback, projective, withShadowInput(*worldRow) / projective,
                fallback / yusovMs, correct / yusovMs, correct, block / fallback, block,
                worldRow->stageMs.count("epipole block (world march)")
                    ? worldRow->stageMs.at("epipole block (world march)")
                    : 0.0);
  }
}

/// Post effects (issue "postfx"): Mitchell's radial blur and the froxel fog filled by Wronski's ESM path
/// and by the prefiltered evaluation, beside the prefiltered per-pixel method on the same frame in one run:
/// on "sunset" (the sun in view, where the radial blur has work to do) and on this run's scene; then the
/// froxel fog's GPU memory (FroxelFog::memoryBytes of the default 160 x 90 x 64 grid).
void postEffects(const BenchOptions& o) {
  if (!squareMapOk(o, "post effects", Scattering::CreateInfo{}.mapSizeMultiple())) return;
  const int repeat = std::max(1, std::min(o.repeat, 3));
  const std::vector<std::string> methods = {"prefilter", "radial", "froxel-esm", "froxel-prefilter"};
  std::vector<std::string> scenes = {"sunset"};
  if (o.scene != "sunset") scenes.push_back(o.scene);
  for (const std::string& scene : scenes) {
    double mapMs = 0.0;
    const std::vector<MethodRow> rows = runMethods(o, scene, methods, repeat, mapMs);
    std::printf(
        "\npost effects (scene %s, %dx%d, map %d^2; per-frame ms as above; the froxel volume is 160 x "
        "90 x 64 at any screen size):\n",
        scene.c_str(), o.screenWidth, o.screenHeight, o.mapWidth);
    printRows(rows);
  }
  const auto mib = [](std::size_t b) { return double(b) / (1024.0 * 1024.0); };
  FroxelFog::CreateInfo info; // the defaults: RGBA16F, temporal on (current + two history volumes)
  const FroxelFog temporal(info);
  info.temporal.historyWeight = 0.0;
  const FroxelFog single(info);
  info.format = GL_RGBA32F;
  const FroxelFog single32(info);
  std::printf(
      "froxel fog GPU memory, 160 x 90 x 64 volumes (FroxelFog::memoryBytes before a frame; the ESM adds "
      "two R32F textures of the downsampled map): RGBA16F with temporal %.1f MiB, without %.1f MiB, RGBA32F "
      "without %.1f MiB\n",
      mib(temporal.memoryBytes()), mib(single.memoryBytes()), mib(single32.memoryBytes()));
}

/// Epipolar sampling (issue "epipolar sampling"; Yusov 2012, Sec. 9's stage table): Yusov's method
/// (epipolar-sampling: min/max march at the selected samples) and the hybrid (epipolar-prefilter) beside
/// the per-pixel min/max march, the prefiltered method and the brute-force march on the same frame in one
/// run, with each method's stages; at the run's size, plus 2560x1600 when that is the default 1920x1080
/// (without --quick); then how
/// the sampling's cost scales with the number of slices and of samples per slice (the run's size).
void epipolarSamplingBench(const BenchOptions& o) {
  if (!squareMapOk(o, "epipolar sampling", Scattering::CreateInfo{}.mapSizeMultiple())) return;
  std::string note;
  const std::vector<std::string> methods =
      quickMethods(o, {"epipolar-sampling", "epipolar-prefilter", "minmax", "prefilter", "brute"}, note);
  // The seed's size (2560x1600) joins the default 1920x1080 run; a smaller --size runs at that size only.
  std::vector<std::pair<int, int>> sizes = {{o.screenWidth, o.screenHeight}};
  if (!o.quick && o.screenWidth == 1920 && o.screenHeight == 1080) sizes.push_back({2560, 1600});
  const int repeat = o.quick ? 1 : std::max(1, std::min(o.repeat, 2));
  std::vector<std::string> scenes = {o.scene};
  if (o.scene != "sunset") scenes.push_back("sunset");
  for (const auto& [w, h] : sizes)
    for (const std::string& scene : scenes) {
      BenchOptions sized = o;
      sized.screenWidth = w;
      sized.screenHeight = h;
      double mapMs = 0.0;
      const std::vector<MethodRow> rows = runMethods(sized, scene, methods, repeat, mapMs);
      const EpipolarSamplingOptions d;
      std::printf("\nepipolar sampling (scene %s, %dx%d, map %d^2, %d slices x %d samples, initial step %d; "
                  "per-frame ms as above):\n",
                  scene.c_str(), w, h, o.mapWidth, d.slices, d.samples, d.initialStep);
      printRows(rows);
      std::printf("%s", note.c_str());
      const double yusov = msOf(rows, "epipolar-sampling"), minmax = msOf(rows, "minmax"),
                   brute = msOf(rows, "brute"), hybrid = msOf(rows, "epipolar-prefilter"),
                   prefilter = msOf(rows, "prefilter");
      char bruteRatio[64] = "";
      if (brute > 0.0 && yusov > 0.0)
        std::snprintf(bruteRatio, sizeof bruteRatio, ", brute / epipolar-sampling %.2f", brute / yusov);
      if (yusov > 0.0 && hybrid > 0.0)
        std::printf("ratios: minmax / epipolar-sampling %.2f%s, "
                    "prefilter / epipolar-prefilter %.2f, epipolar-prefilter / epipolar-sampling %.2f\n",
                    minmax / yusov, bruteRatio, prefilter / hybrid, hybrid / yusov);
    }
  // Scaling with slices and samples (the run's size and scene).
  std::printf(
      "\nepipolar sampling scaling (scene %s, %dx%d, map %d^2; per-frame ms, one run after a warm-up):\n",
      o.scene.c_str(), o.screenWidth, o.screenHeight, o.mapWidth);
  std::printf("%-8s %-8s %16s %18s   %s\n", "slices", "samples", "epipolar-sampling", "epipolar-prefilter",
              "epipolar-sampling stages (ms)");
  std::vector<std::pair<int, int>> grid = {{256, 256},  {512, 256},  {1024, 256}, {2048, 256},
                                           {1024, 128}, {1024, 512}, {1024, 1024}};
  if (o.quick) grid = {{256, 256}, {1024, 256}, {1024, 512}};
  for (const auto& [slices, samples] : grid) {
    tool::MethodSettings base;
    base.sampling.slices = slices;
    base.sampling.samples = samples;
    double mapMs = 0.0;
    const std::vector<MethodRow> rows =
        runMethods(o, o.scene, {"epipolar-sampling", "epipolar-prefilter"}, 1, mapMs, base);
    std::printf("%-8d %-8d %16.2f %18.2f   %s\n", slices, samples, msOf(rows, "epipolar-sampling"),
                msOf(rows, "epipolar-prefilter"), rows.empty() ? "" : rows.front().stages.c_str());
  }
}

/// The atmosphere tables of atmosphereBench computed from scratch side by side, their stages printed:
/// the default's and, without --quick, the reference (Yusov's size).
struct AtmosphereTableRuns {
  std::optional<tool::AtmosphereTableSet> kept, reference;
};

AtmosphereTableRuns atmosphereTableRuns(const BenchOptions& o, const tool::AtmosphereSettings& s) {
  struct TableRun {
    const char* name;
    AtmosphereMultipleScattering method;
    AtmosphereTableSize size;
  };
  std::vector<TableRun> runs = {{"4 orders (default)", AtmosphereMultipleScattering::Orders, s.tables.size},
                                {"multiple scattering LUT (Hillaire 2020, the option)",
                                 AtmosphereMultipleScattering::Lut, s.tables.size}};
  if (!o.quick)
    runs.push_back({"4 orders on Yusov's table (the reference)", AtmosphereMultipleScattering::Orders,
                    AtmosphereTableSize{32, 128, 64, 16}});
  std::vector<double> totals;
  AtmosphereTableRuns kept;
  for (const TableRun& run : runs) {
    tool::AtmosphereSettings m = s;
    m.tables.multipleScattering = run.method;
    m.tables.size = run.size;
    tool::StageTimings tableTimings;
    tool::AtmosphereTableSet tables = tool::atmosphereTables(m, tableTimings);
    const AtmosphereTableSize& n = run.size;
    const double megabytes =
        3.0 * 16.0 * n.height * n.viewZenith * n.sunZenith * n.sunView / (1024.0 * 1024.0);
    std::printf("\natmosphere tables from scratch, %s (%dx%dx%dx%d, %d sphere samples; optical depth %dx%d; "
                "three 4D RGBA32F tables, %.1f MiB; ms, one run, glFinish + wall clock per stage):\n",
                run.name, n.height, n.viewZenith, n.sunZenith, n.sunView, m.tables.sphereSamples,
                m.tables.opticalDepthHeight, m.tables.opticalDepthZenith, megabytes);
    double total = 0.0;
    for (const auto& [stage, ms] : tables.pass->stageTimes()) {
      std::printf("  %-28s %10.1f\n", stage.c_str(), ms);
      total += ms;
    }
    std::printf("  %-28s %10.1f\n", "total", total);
    totals.push_back(total);
    if (&run == &runs.front()) kept.kept.emplace(std::move(tables));
    if (&run == &runs.back() && runs.size() > 2) kept.reference.emplace(std::move(tables));
  }
  std::printf("  to the default: LUT %.3f", totals[1] / totals[0]);
  if (totals.size() > 2) std::printf(", reference %.3f", totals[2] / totals[0]);
  std::printf("\n");
  return kept;
}

/// The median per-frame ms of the atmosphere on `frame` (its stages summed, "setup" stages excluded) of
/// `repeat` runs after a warm-up (programs, textures); `stages` receives each stage's ms of those runs.
double atmosphereFrameMs(tool::SceneFrame& frame, const tool::MethodSettings& settings,
                         const tool::AtmosphereSettings& s, const AtmosphereTablesPass& tables, int repeat,
                         std::map<std::string, std::vector<double>>& stages) {
  std::vector<double> sums;
  for (int run = 0; run <= repeat; ++run) {
    tool::StageTimings t;
    (void)tool::runAtmosphere(*frame.frame, settings, s, tables, t);
    if (run == 0) continue; // warm-up
    double sum = 0.0;
    for (const auto& row : t.rows()) {
      if (row.stage.find("setup") != std::string::npos) continue;
      sum += row.ms;
      stages[row.stage].push_back(row.ms);
    }
    sums.push_back(sum);
  }
  return median(sums);
}

/// The atmosphere (Yusov 2013 tables after Bruneton and Neyret 2008): the tables' precomputation per stage,
/// side by side in one run: the default (4 orders on the 32x32x32x8 table of the higher orders; 8x16x16x4
/// with --quick), Hillaire 2020's multiple scattering table at the same size (the option) and the 4 orders
/// on Yusov's 32x128x64x16 table (the reference; not with --quick); then the per-frame cost of the sky,
/// aerial perspective and shafts with each shaft method on the terrain at the run's size (median of the
/// per-frame sums of `repeat` runs after a warm-up; "setup" stages excluded), and None through Eq. 8 on the
/// reference table for comparison.
void atmosphereBench(const BenchOptions& o) {
  tool::AtmosphereSettings s;
  s.cacheDirectory.clear(); // always compute: the precomputation's cost is the point
  if (o.quick) s.tables.size = {8, 16, 16, 4};
  const AtmosphereTableRuns tables = atmosphereTableRuns(o, s);

  // Per frame: the terrain at 20 degrees of sun elevation, the scene's sun azimuth.
  const std::string scene = "terrain";
  s.sunElevation = 20.0;
  const scenes::Scene base = scenes::makeScene(scene, double(o.screenWidth) / o.screenHeight);
  tool::SceneOverrides overrides;
  overrides.sun = tool::atmosphereSun(s, base.sun);
  tool::StageTimings sceneTimings;
  tool::SceneFrame frame =
      tool::makeSceneFrame(scene, o.screenWidth, o.screenHeight, o.mapWidth, sceneTimings, overrides);
  tool::MethodSettings settings;
  settings.mapSize = o.mapWidth;
  settings.prefilter.bases = o.bases;
  const int repeat = o.quick ? 1 : std::max(1, std::min(o.repeat, 3));
  std::printf(
      "\natmosphere per frame (scene %s, %dx%d, map %d^2, sun elevation %g; ms: median of %d runs after "
      "a warm-up):\n",
      scene.c_str(), o.screenWidth, o.screenHeight, o.mapWidth, s.sunElevation, repeat);
  std::printf("  %-12s %10s   %s\n", "shafts", "ms", "stages (ms)");
  std::map<AtmosphereShafts, double> perFrame;
  for (const AtmosphereShafts shafts :
       {AtmosphereShafts::None, AtmosphereShafts::Integrated, AtmosphereShafts::LitLengthTable,
        AtmosphereShafts::PrefilteredVisibility}) {
    s.shafts = shafts;
    std::map<std::string, std::vector<double>> stages;
    perFrame[shafts] = atmosphereFrameMs(frame, settings, s, *tables.kept->pass, repeat, stages);
    std::string breakdown;
    for (const auto& [stage, ms] : stages) {
      char buffer[160];
      std::snprintf(buffer, sizeof buffer, "%s%s %.1f", breakdown.empty() ? "" : ", ", stage.c_str(),
                    median(ms));
      breakdown += buffer;
    }
    std::printf("  %-12s %10.1f   %s\n", tool::atmosphereShaftsName(shafts), perFrame[shafts],
                breakdown.c_str());
  }
  if (tables.reference) { // None through Eq. 8 on the reference table (the single scattering of earlier
                          // versions)
    s.shafts = AtmosphereShafts::None;
    s.ray.single = AtmosphereSingleScattering::Table4D;
    std::map<std::string, std::vector<double>> stages;
    std::printf("  %-12s %10.1f   (Eq. 8 on the reference table)\n", "none (4D)",
                atmosphereFrameMs(frame, settings, s, *tables.reference->pass, repeat, stages));
  }
  const double a = perFrame[AtmosphereShafts::Integrated];
  if (a > 0.0)
    std::printf("ratios to (a) integrated: none %.2f, (b) lut %.2f, (c) prefiltered %.2f\n",
                perFrame[AtmosphereShafts::None] / a, perFrame[AtmosphereShafts::LitLengthTable] / a,
                perFrame[AtmosphereShafts::PrefilteredVisibility] / a);
}

/// A built-in scene's frame as crep::Scattering input: the tool's frame (camera depth, standard shadow map)
/// and an output texture.
struct ScatteringFrame {
  tool::SceneFrame scene;
  Scattering::ShadowMap shadow;
  gl::Handle output;
  ScatteringFrame(const BenchOptions& o, tool::StageTimings& timings)
      : scene(tool::makeSceneFrame(o.scene, o.screenWidth, o.screenHeight, o.mapWidth, timings)),
        shadow{scene.frame->shadowMap.get(), scene.frame->lightClipFromWorld, scene.frame->shadowBias},
        output(gl::createTexture2D(GL_RGBA32F, o.screenWidth, o.screenHeight)) {}
  /// crep::Scattering's defaults at this run's screen, square map and M; the stages timed in the frame
  /// (blockingTimings: the bench measures).
  static Scattering::CreateInfo createInfo(const BenchOptions& o) {
    Scattering::CreateInfo info;
    info.width = o.screenWidth;
    info.height = o.screenHeight;
    info.mapSize = o.mapWidth;
    info.prefilter.bases = o.bases;
    info.blockingTimings = true;
    return info;
  }
  Scattering::FrameAttribs attribs() const {
    Scattering::FrameAttribs a;
    a.camera = &scene.frame->camera;
    a.light = &scene.frame->light;
    a.medium = &scene.frame->medium;
    a.cameraDepth = scene.frame->cameraDepth.get();
    a.output = output.get();
    a.shadowMap = &shadow;
    return a;
  }
  /// attribs() with drawCasters drawing the scene's casters (null: the scene has no renderer).
  scenes::SceneRenderer* renderer() const { return scene.frame->renderer; }
  Scattering::FrameAttribs attribsWithCasters() const {
    Scattering::FrameAttribs a = attribs();
    scenes::SceneRenderer* r = renderer();
    a.drawCasters = [r](const glm::dmat4& m) { r->drawDepth(m); };
    return a;
  }
};

/// GPU memory per configuration (issue "performance", item 6): what crep::Scattering and the peers own,
/// from the same size functions the passes use, and Scattering::memoryBytes() after one frame of this run.
void memoryTable(const BenchOptions& o) {
  const Scattering::CreateInfo d;
  const int R = d.rectify.splits * d.prefilter.regionsPerSplit, Z = d.evaluate.visibilityTableSamples;
  const auto mib = [](std::size_t b) { return double(b) / (1024.0 * 1024.0); };
  std::printf(
      "\nGPU memory, MiB (M = %d; %d prefilter regions, scattering prefix table of %d samples,\n"
      "RGBA32F; rectified maps D32F + R32F;\n"
      "trees: min/max march only; own shadow map %d^2 D32F, fallback frames without an engine map):\n",
      o.bases, R, Z, d.ownShadowMapSize);
  std::printf("%-8s %10s %10s %10s %10s %10s %10s %10s\n", "map", "basis 8", "basis 16F", "basis 32F",
              "table", "maps", "trees", "own map");
  for (const int size : {512, 1024, 2048, 4096}) {
    const std::size_t map = std::size_t(size) * std::size_t(size) * 4;
    const std::size_t trees = std::size_t(MinMaxTrees::rowStrideFor(size)) * std::size_t(size) * 8;
    std::printf("%-8d %10.1f %10.1f %10.1f %10.1f %10.1f %10.1f %10.1f\n", size,
                mib(filteredBasisBytes(size, size, o.bases, StorageFormat::RGBA8)),
                mib(filteredBasisBytes(size, size, o.bases, StorageFormat::RGBA16F)),
                mib(filteredBasisBytes(size, size, o.bases, StorageFormat::RGBA32F)),
                mib(scatteringPrefixBytes(size, R, Z)), mib(2 * map), mib(trees),
                mib(std::size_t(d.ownShadowMapSize) * std::size_t(d.ownShadowMapSize) * 4));
  }
  if (o.mapWidth == o.mapHeight && o.mapWidth % d.mapSizeMultiple() == 0) {
    tool::StageTimings timings;
    const ScatteringFrame frame(o, timings);
    const Scattering::CreateInfo info = ScatteringFrame::createInfo(o);
    Scattering scattering(info);
    scattering.run(frame.attribs());
    std::printf("crep::Scattering::memoryBytes() after a frame of %s at %dx%d, map %d^2, RGBA8: %.1f MiB\n",
                o.scene.c_str(), o.screenWidth, o.screenHeight, o.mapWidth, mib(scattering.memoryBytes()));
  }
}

/// Reduced-resolution evaluation (issue "performance", item 4): crep::Scattering at evaluation scales 1,
/// 0.5 and 0.25 on this run's scene, one object each, per-stage wall-clock medians after a warm-up, and the
/// difference of the image from the full-resolution one.
void reducedResolution(const BenchOptions& o) {
  if (o.screenWidth % 4 != 0 || o.screenHeight % 4 != 0 || o.mapWidth != o.mapHeight) {
    std::printf(
        "\nreduced resolution: skipped (needs a screen size that is a multiple of 4 and a square map)\n");
    return;
  }
  tool::StageTimings timings;
  const ScatteringFrame input(o, timings);
  const Scattering::FrameAttribs a = input.attribs();
  const int repeat = std::max(1, std::min(o.repeat, 3));
  std::printf(
      "\nreduced resolution (%s, %dx%d, map %d^2; crep::Scattering, wall-clock medians of %d frames after\n"
      "a warm-up; difference to the full-resolution image as relative RMSE of the in-scattering):\n",
      o.scene.c_str(), o.screenWidth, o.screenHeight, o.mapWidth, repeat);
  std::printf("%-7s %12s %12s %12s %12s %12s\n", "scale", "evaluate ms", "resample ms", "frame ms",
              "vs scale 1", "difference");
  Image full;
  double fullMs = 0.0;
  for (const double scale : {1.0, 0.5, 0.25}) {
    Scattering::CreateInfo info = ScatteringFrame::createInfo(o);
    info.evaluationScale = scale;
    Scattering scattering(info);
    scattering.run(a); // warm-up: shader specialization on the first dispatch
    std::map<std::string, std::vector<double>> ms;
    for (int i = 0; i < repeat; ++i)
      for (const Scattering::Stage& st : scattering.run(a).stages)
        ms[st.name].push_back(st.wallMilliseconds);
    double frame = 0.0;
    for (auto& [name, v] : ms)
      if (name.find("resample") == std::string::npos && name.find("shadow") == std::string::npos)
        frame += median(v);
    const double evaluate = median(ms["evaluate"]);
    const double resample =
        ms.count("upsample") ? median(ms["upsample"]) + median(ms["downsample depth"]) : 0.0;
    const Image image =
        gl::readTexture(input.output.get(), o.screenWidth, o.screenHeight, gl::TexelData::Rgba);
    if (scale == 1.0) {
      full = image;
      fullMs = frame;
    }
    CompareOptions c;
    c.channels = 3;
    std::printf("%-7.2f %12.2f %12.2f %12.2f %12.2f %11.2f%%\n", scale, evaluate, resample, frame,
                frame / fullMs, 100.0 * compareImages(image, full, c).relativeRmse);
  }
}

/// The visibility reconstructions side by side (prefilter.h, VisibilityReconstruction): crep::Scattering with
/// the Fourier series and with the exact prefix on the same frames of forest (projective) and sunset (the sun
/// in view, epipolar), interleaved frame by frame so that the machine's load hits both alike; wall-clock
/// medians of the frame without its shadow passes, and the exact image's difference to the Fourier one.
void reconstructionBench(const BenchOptions& base) {
  const int repeat = std::max(1, base.repeat);
  std::printf(
      "\nvisibility reconstruction (%dx%d, map %d^2, M = %d; crep::Scattering, wall-clock medians of %d\n"
      "interleaved frames after a warm-up, shadow passes not counted):\n",
      base.screenWidth, base.screenHeight, base.mapWidth, base.bases, repeat);
  std::printf("%-8s %-10s %12s %12s %12s %12s\n", "scene", "layout", "fourier ms", "exact ms",
              "exact/fourier", "difference");
  for (const std::string name : {"forest", "sunset"}) {
    BenchOptions o = base;
    o.scene = name;
    tool::StageTimings timings;
    const ScatteringFrame input(o, timings);
    const Scattering::FrameAttribs a = input.attribs();
    Scattering::CreateInfo info = ScatteringFrame::createInfo(o);
    Scattering fourier(info);
    info.prefilter.reconstruction = VisibilityReconstruction::Exact;
    Scattering exact(info);
    std::map<std::string, std::vector<double>> stageMs[2];
    const auto frameMs = [&](Scattering& s, Scattering::FrameResult* result = nullptr) {
      Scattering::FrameResult r = s.run(a);
      double ms = 0.0;
      for (const Scattering::Stage& st : r.stages)
        if (st.name.find("shadow") == std::string::npos) {
          ms += st.wallMilliseconds;
          stageMs[&s == &exact][st.name].push_back(st.wallMilliseconds);
        }
      if (result) *result = std::move(r);
      return ms;
    };
    frameMs(fourier); // warm-up: shader specialization on the first dispatch
    frameMs(exact);
    std::vector<double> f, e;
    for (int i = 0; i < repeat; ++i) {
      f.push_back(frameMs(fourier));
      e.push_back(frameMs(exact));
    }
    Scattering::FrameResult r;
    frameMs(fourier, &r);
    const Image fourierImage =
        gl::readTexture(input.output.get(), o.screenWidth, o.screenHeight, gl::TexelData::Rgba);
    frameMs(exact);
    const Image exactImage =
        gl::readTexture(input.output.get(), o.screenWidth, o.screenHeight, gl::TexelData::Rgba);
    CompareOptions c;
    c.channels = 3;
    std::printf("%-8s %-10s %12.2f %12.2f %12.2f %11.2f%%\n", name.c_str(), layoutToken(r.layout), median(f),
                median(e), median(e) / median(f),
                100.0 * compareImages(exactImage, fourierImage, c).relativeRmse);
    for (const auto& [stage, v] : stageMs[0])
      if (stageMs[1].count(stage))
        std::printf("  %-30s %10.2f %12.2f\n", stage.c_str(), median(v), median(stageMs[1][stage]));
    std::fflush(stdout);
  }
}

/// Constant cost (Klehm et al. 2014, Sec. 5): the GPU prefilter and evaluation of the four projective
/// built-in scenes at the same sizes, timed interleaved (scene after scene, `repeat` rounds) so that a
/// change of the machine's load hits every scene alike; medians per scene and the largest / smallest.
void constantCost(const BenchOptions& o) {
  const std::vector<std::string> names = {"colonnade", "forest", "terrain", "boxes"};
  struct Scene {
    Setup setup;
    std::unique_ptr<PrefilterPass> prefilter;
    std::unique_ptr<EvaluatePass> evaluate;
    std::vector<double> prefilterMs, evaluateMs;
  };
  std::vector<Scene> scenes;
  for (const std::string& name : names) {
    Scene sc{makeSetup(name, o.screenWidth, o.screenHeight, o.mapWidth, o.mapHeight), {}, {}, {}, {}};
    PrefilterPass::CreateInfo info;
    info.mapWidth = o.mapWidth;
    info.mapHeight = o.mapHeight;
    info.options = Scattering::CreateInfo{}.prefilter;
    info.options.bases = o.bases;
    info.options.basesPerInvocation = perInvocationFor(info.options.basesPerInvocation, o.bases);
    sc.prefilter = std::make_unique<PrefilterPass>(info);
    EvaluatePass::CreateInfo evalInfo;
    evalInfo.bases = o.bases;
    evalInfo.reconstruction = info.options.reconstruction; // the front door's default (exact)
    sc.evaluate = std::make_unique<EvaluatePass>(evalInfo);
    scenes.push_back(std::move(sc));
  }
  const auto run = [&](Scene& sc, bool record) {
    const Setup& st = sc.setup;
    double ms = medianMs(1, [&] {
      sc.prefilter->run({st.rectified.get(), st.layout.get(), &st.scene.medium});
      glFinish();
    });
    if (record) sc.prefilterMs.push_back(ms);
    const EvaluatePass::FrameAttribs ev = evaluateAttribs(st, sc.prefilter->filteredBasis());
    ms = medianMs(1, [&] {
      sc.evaluate->run(ev);
      glFinish();
    });
    if (record) sc.evaluateMs.push_back(ms);
  };
  for (Scene& sc : scenes)
    run(sc, false); // warm-up
  for (int i = 0; i < std::max(3, o.repeat); ++i)
    for (Scene& sc : scenes)
      run(sc, true);
  std::printf(
      "\nconstant cost (GPU prefilter and evaluation of the four projective scenes, %dx%d, map %dx%d, "
      "M = %d;\ninterleaved, medians of %d rounds):\n",
      o.screenWidth, o.screenHeight, o.mapWidth, o.mapHeight, o.bases, std::max(3, o.repeat));
  std::printf("%-12s %12s %12s\n", "scene", "prefilter ms", "evaluate ms");
  double lo = 1e30, hi = 0.0;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const double e = median(scenes[i].evaluateMs);
    lo = std::min(lo, e);
    hi = std::max(hi, e);
    std::printf("%-12s %12.2f %12.2f\n", names[i].c_str(), median(scenes[i].prefilterMs), e);
  }
  std::printf("evaluation, largest / smallest: %.3f (goal: within 10%%)\n", hi / lo);
}

/// Local lights (issue "local lights", benchmark): crep::Scattering on this run's scene with the sun alone
/// and with one spot light off screen (projective: prefiltered), same object and frame, wall-clock medians
/// after a warm-up: the spot's cost against the sun's. Then the spot's own rectified map marched with the
/// min/max trees (RectifiedMarchPass, GPU) against its prefilter + evaluation.
void localLights(const BenchOptions& o) {
  const Scattering::CreateInfo d;
  if (o.mapWidth != o.mapHeight || o.mapWidth % d.mapSizeMultiple() != 0) {
    std::printf("\nlocal lights: skipped (needs a square map, a multiple of %d)\n", d.mapSizeMultiple());
    return;
  }
  tool::StageTimings timings;
  const ScatteringFrame input(o, timings);
  scenes::SceneRenderer* renderer = input.renderer();
  if (!renderer) return;
  const Scattering::FrameAttribs a = input.attribsWithCasters();
  const Camera& c = input.scene.frame->camera;
  const glm::dvec3 position = c.position() - 4.0 * c.forward() + 7.0 * c.up();
  const SpotLight spot({.position = position,
                        .direction = c.position() + 14.0 * c.forward() - position,
                        .innerConeAngle = 0.35,
                        .outerConeAngle = 0.55,
                        .intensity = 150.0,
                        .range = 200.0});
  const Scattering::CreateInfo info = ScatteringFrame::createInfo(o);
  Scattering scattering(info);
  const int repeat = std::max(1, std::min(o.repeat, 3));
  const auto frameMs = [&](const Scattering::FrameAttribs& f, double* spotMs, RectifyStatus* status) {
    scattering.run(f); // warm-up
    std::vector<double> total, local;
    for (int i = 0; i < repeat; ++i) {
      const Scattering::FrameResult r = scattering.run(f);
      double sum = 0.0;
      for (const Scattering::Stage& st : r.stages)
        sum += st.wallMilliseconds;
      total.push_back(sum);
      if (!r.localLights.empty()) {
        local.push_back(r.localLights[0].wallMilliseconds);
        *status = r.localLights[0].status;
      }
    }
    std::sort(total.begin(), total.end());
    std::sort(local.begin(), local.end());
    if (spotMs && !local.empty()) *spotMs = local[local.size() / 2];
    return total[total.size() / 2];
  };
  RectifyStatus status = RectifyStatus::Empty;
  const double sunMs = frameMs(a, nullptr, &status);
  Scattering::FrameAttribs withSpot = a;
  withSpot.spotLights = std::span<const SpotLight>(&spot, 1);
  double spotMs = 0.0;
  const double bothMs = frameMs(withSpot, &spotMs, &status);
  std::printf(
      "\nlocal lights (%s, %dx%d, map %d^2, M = %d; crep::Scattering wall-clock medians of %d frames\n"
      "after a warm-up, one spot light off screen):\n",
      o.scene.c_str(), o.screenWidth, o.screenHeight, o.mapWidth, o.bases, repeat);
  std::printf("  sun alone %.1f ms | sun + spot %.1f ms | the spot %.1f ms (%s) | spot / sun %.2f\n", sunMs,
              bothMs, spotMs, status == RectifyStatus::Projective ? "prefiltered" : "world-space march",
              spotMs / sunMs);
  if (status != RectifyStatus::Projective) return;
  // The same spot map marched with the min/max trees (the peer), timed as the prefilter + evaluation were.
  const Rectification rect = rectify(c, spot, info.rectify);
  const auto layout = std::make_shared<const ProjectiveLayout>(rect);
  RectifiedShadowPass shadow({o.mapWidth, o.mapWidth});
  shadow.run({&rect, [&](int, const glm::dmat4& m) { renderer->drawDepth(m); }});
  MinMaxTreePass trees({o.mapWidth, o.mapWidth});
  RectifiedMarchPass march({o.mapWidth, o.mapWidth, RectifiedMarchPass::Mode::MinMaxTree});
  const LocalLight light = LocalLight::spot(spot);
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, o.screenWidth, o.screenHeight);
  RectifiedMarchPass::FrameAttribs m;
  m.layout = layout.get();
  m.camera = &c;
  m.medium = &input.scene.frame->medium;
  m.cameraDepth = input.scene.frame->cameraDepth.get();
  m.rectifiedDepth = shadow.depthTexture();
  m.minMaxBuffer = trees.treeBuffer();
  m.output = out.get();
  m.localLight = &light;
  const double treeMs = medianMs(repeat, [&] {
    trees.run(shadow.depthTexture());
    march.run(m);
    glFinish();
  });
  std::printf(
      "  the spot's map: min/max trees + march %.1f ms | prefiltered spot (shadow pass included) %.1f ms"
      " | ratio %.2f\n",
      treeMs, spotMs, treeMs / spotMs);
}

/// Local lights on the spot scene (issue "local lights in the tool"): the night colonnade, three spot lamps
/// off screen and no sun, every lamp projective. The prefiltered method (crep::Scattering: per lamp its
/// rectified shadow pass, prefilter and evaluation) against the min/max march over the same lamps' rectified
/// maps (trees + march per lamp), methods side by side in one run: per-frame ms as in "methods side by
/// side" (the rectified shadow passes excluded, as for the sun).
void localLightScene(const BenchOptions& o) {
  if (!squareMapOk(o, "local lights (spot scene)", Scattering::CreateInfo{}.mapSizeMultiple())) return;
  const int repeat = std::max(1, std::min(o.repeat, 3));
  double mapMs = 0.0;
  const std::vector<MethodRow> rows =
      runMethods(o, "colonnade-night", {"prefilter", "minmax"}, repeat, mapMs);
  std::printf(
      "\nlocal lights, spot scene (colonnade-night: three spot lamps off screen, no sun; %dx%d, map "
      "%d^2, M = %d;\nper-frame ms as in \"methods side by side\", median of %d runs after a warm-up):\n",
      o.screenWidth, o.screenHeight, o.mapWidth, o.bases, repeat);
  printRows(rows);
  const double prefilterMs = msOf(rows, "prefilter"), minmaxMs = msOf(rows, "minmax");
  if (prefilterMs > 0.0) std::printf("minmax / prefilter on the spot scene: %.2f\n", minmaxMs / prefilterMs);
}

/// Local lights, scaling (issue "local lights", benchmark; `--section local-lights` with localLights and
/// localLightScene; not in the whole suite: its in-view spot is marched in world space, minutes at 1080p):
/// crep::Scattering on this run's scene with the sun alone and with 1, 2, 4 and 8 spot
/// lights off screen (behind and above the camera as localLights' spot, each at its own place and aimed at
/// its own point ahead of the camera: projective, prefiltered), and with one spot in the view (2 units
/// above the camera and 4 ahead, aimed forward and down: not projective, marched in world space; 2 above
/// the camera alone is still projective, its apex outside the view). One object and frame;
/// the variants alternate (sun alone, 1, 2, 4, 8, near, sun alone, ...) after one warm-up round, so load on
/// the shared machine falls on all alike. Per variant: the frame (median of the frames' summed stage wall
/// ms) and the spots' LightResult::wallMilliseconds summed per frame (median), per spot and per spot against
/// the sun's frame; the spots' rectification status is checked and printed, not assumed.
void localLightScaling(const BenchOptions& o) {
  if (!squareMapOk(o, "local lights, scaling", Scattering::CreateInfo{}.mapSizeMultiple())) return;
  tool::StageTimings timings;
  const ScatteringFrame input(o, timings);
  scenes::SceneRenderer* renderer = input.renderer();
  if (!renderer) return;
  const Scattering::FrameAttribs a = input.attribsWithCasters();
  const Camera& c = input.scene.frame->camera;
  // Spot k: 4-5.5 units behind and 7-8 above the camera, alternately left and right and farther out with k,
  // aimed at a point 10-19 units ahead and half as far to its side (localLights' spot: 4 back, 7 up, 14
  // ahead), so every spot is distinct and lights its own part of the view.
  constexpr int kMaxSpots = 8;
  std::vector<SpotLight> spots;
  for (int k = 0; k < kMaxSpots; ++k) {
    const double side = (k % 2 == 0 ? -1.0 : 1.0) * 1.5 * (1 + k / 2);
    const glm::dvec3 position = c.position() - (4.0 + 0.5 * (k / 2)) * c.forward() +
                                (7.0 + 0.5 * (k % 3)) * c.up() + side * c.right();
    const glm::dvec3 target = c.position() + (10.0 + 3.0 * (k / 2)) * c.forward() + 0.5 * side * c.right();
    spots.emplace_back(SpotLightParams{.position = position,
                                       .direction = target - position,
                                       .innerConeAngle = 0.35,
                                       .outerConeAngle = 0.55,
                                       .intensity = 150.0,
                                       .range = 200.0});
  }
  const SpotLight nearSpot({.position = c.position() + 4.0 * c.forward() + 2.0 * c.up(),
                            .direction = c.forward() - 0.5 * c.up(),
                            .innerConeAngle = 0.35,
                            .outerConeAngle = 0.55,
                            .intensity = 150.0,
                            .range = 200.0});
  struct Variant {
    std::span<const SpotLight> spots;
    std::vector<double> frameMs, spotsMs;
    std::vector<RectifyStatus> status; ///< of the last measured frame, one per spot
    bool epipolar = false;             ///< the last frame's first spot prefiltered on its epipolar layout
  };
  std::vector<Variant> variants;
  for (const int n : {0, 1, 2, 4, kMaxSpots})
    variants.push_back({std::span<const SpotLight>(spots.data(), static_cast<std::size_t>(n)), {}, {}, {}});
  variants.push_back({std::span<const SpotLight>(&nearSpot, 1), {}, {}, {}});
  Scattering scattering(ScatteringFrame::createInfo(o));
  const int repeat = std::max(1, std::min(o.repeat, 3));
  for (int i = 0; i < repeat + 1; ++i) // round 0: warm-up (shader builds, the local lights' textures)
    for (Variant& v : variants) {
      Scattering::FrameAttribs f = a;
      f.spotLights = v.spots;
      const Scattering::FrameResult r = scattering.run(f);
      if (i == 0) continue;
      double frame = 0.0, local = 0.0;
      for (const Scattering::Stage& st : r.stages)
        frame += st.wallMilliseconds;
      v.status.clear();
      v.epipolar = !r.localLights.empty() && r.localLights.front().epipolar;
      for (const Scattering::LightResult& l : r.localLights) {
        local += l.wallMilliseconds;
        v.status.push_back(l.status);
      }
      v.frameMs.push_back(frame);
      v.spotsMs.push_back(local);
    }
  const double sunMs = median(variants.front().frameMs);
  std::printf(
      "\nlocal lights, scaling (%s, %dx%d, map %d^2, M = %d; crep::Scattering, one object and frame, the\n"
      "variants alternating, wall-clock medians of %d frames after a warm-up round; N spots off screen,\n"
      "behind and above the camera, each aimed at its own point ahead; spots ms: their LightResult ms "
      "summed):\n",
      o.scene.c_str(), o.screenWidth, o.screenHeight, o.mapWidth, o.bases, repeat);
  std::printf("  %5s %10s %10s %12s %15s   %s\n", "N", "frame ms", "spots ms", "per spot ms",
              "per spot / sun", "status");
  std::printf("  %5d %10.2f %10s %12s %15s   sun alone\n", 0, sunMs, "-", "-", "-");
  for (std::size_t i = 1; i + 1 < variants.size(); ++i) {
    const Variant& v = variants[i];
    const int n = static_cast<int>(v.spots.size());
    const int prefiltered =
        static_cast<int>(std::count(v.status.begin(), v.status.end(), RectifyStatus::Projective));
    const double spotsMs = median(v.spotsMs), perSpot = spotsMs / n;
    std::printf("  %5d %10.2f %10.2f %12.2f %15.3f   prefiltered %d of %d\n", n, median(v.frameMs), spotsMs,
                perSpot, perSpot / sunMs, prefiltered, n);
  }
  std::string statuses;
  for (const RectifyStatus s : variants[variants.size() - 2].status)
    statuses += std::string(statuses.empty() ? "" : " ") + statusToken(s);
  std::printf("  the %d spots' rectification: %s\n", kMaxSpots, statuses.c_str());
  const Variant& nearRun = variants.back();
  const RectifyStatus nearStatus = nearRun.status.empty() ? RectifyStatus::Empty : nearRun.status.front();
  const double nearMs = median(nearRun.spotsMs);
  std::printf(
      "  a spot in the view (2 units above the camera, 4 ahead, aimed forward and down): %s (%s) | frame "
      "%.2f ms | the spot %.2f ms | spot / sun frame %.3f\n",
      statusToken(nearStatus),
      nearStatus == RectifyStatus::Projective ? "prefiltered"
      : nearStatus == RectifyStatus::Fallback
          ? (nearRun.epipolar ? "prefiltered on its epipolar layout" : "world-space march")
          : "outside the view, nothing done",
      median(nearRun.frameMs), nearMs, nearMs / sunMs);
}

/// Light textures (README "Light textures"; Klehm et al. 2014, Sec. 3.2): the stained-glass scene's
/// prefiltered frame (crep::Scattering, the tool's `prefilter` method) with the sun's stained-glass texture
/// and without it, on the same SceneFrame, measured side by side in one run: the two variants alternate
/// (textured, untextured, textured, ...) after one warm-up each, so load on the shared machine falls on
/// both alike; per-frame ms = the sum of the median per-frame stages (as in "methods side by side").
void lightTextures(const BenchOptions& o) {
  if (!squareMapOk(o, "light textures", Scattering::CreateInfo{}.mapSizeMultiple())) return;
  const int repeat = std::max(1, std::min(o.repeat, 5));
  tool::StageTimings setupTimings;
  tool::SceneFrame s =
      tool::makeSceneFrame("stained-glass", o.screenWidth, o.screenHeight, o.mapWidth, setupTimings);
  tool::MethodSettings settings;
  settings.mapSize = o.mapWidth;
  settings.prefilter.bases = o.bases;
  const tool::Method& prefilterMethod = tool::findMethod("prefilter");
  tool::LightTextureMap texture = std::move(s.frame->lightTexture);
  std::map<std::string, std::vector<double>> stageMs[2]; // [0] textured, [1] untextured
  std::vector<std::string> order[2];
  for (int i = 0; i < repeat + 1; ++i)
    for (int variant = 0; variant < 2; ++variant) {
      if (variant == 0) s.frame->lightTexture = std::move(texture);
      const tool::MethodOutput out = prefilterMethod.run(*s.frame, settings);
      if (variant == 0) texture = std::move(s.frame->lightTexture);
      if (i == 0) continue; // warm-up: shader builds, the textured passes on first use
      std::map<std::string, double> run;
      for (const auto& r : out.timings.rows()) {
        if (!run.count(r.stage) && !stageMs[variant].count(r.stage)) order[variant].push_back(r.stage);
        run[r.stage] += r.ms;
      }
      for (const auto& [stage, ms] : run)
        stageMs[variant][stage].push_back(ms);
    }
  double frameMs[2] = {0.0, 0.0};
  std::string stages[2];
  for (int variant = 0; variant < 2; ++variant)
    for (const std::string& stage : order[variant]) {
      if (!perFrameStage(stage)) continue;
      const double ms = median(stageMs[variant][stage]);
      frameMs[variant] += ms;
      char buf[96];
      std::snprintf(buf, sizeof buf, "%s%s %.2f", stages[variant].empty() ? "" : ", ", stage.c_str(), ms);
      stages[variant] += buf;
    }
  std::printf("\nlight textures (stained-glass: the sun through a window, a %dx%d stained-glass texture; "
              "%dx%d, map %d^2, M = %d;\ncrep::Scattering per-frame ms, textured and untextured alternating "
              "in one run, median of %d each after a warm-up):\n",
              texture.image.width(), texture.image.height(), o.screenWidth, o.screenHeight, o.mapWidth,
              o.bases, repeat);
  std::printf("  textured    %10.2f ms   %s\n", frameMs[0], stages[0].c_str());
  std::printf("  untextured  %10.2f ms   %s\n", frameMs[1], stages[1].c_str());
  if (frameMs[1] > 0.0) std::printf("textured / untextured: %.2f\n", frameMs[0] / frameMs[1]);
}

void printHowMeasured(const BenchOptions& o) {
  std::printf(
      "\nhow measured: wall-clock median of %d runs, each ending with glFinish (GPU) or on return (CPU);\n"
      "llvmpipe runs the GPU passes on the CPU cores, so CPU/GPU compares two CPU implementations here.\n",
      o.repeat);
  if (o.backend == "vulkan")
    std::printf(
        "--backend vulkan: the rows marked \"on Vulkan\" time each crep::Scattering stage on the\n"
        "wall clock, ended by the Vulkan backend's finish() (lavapipe here); the maps' read-back from GL\n"
        "and the output's way back are left out, as are the setup and the shadow inputs.\n");
}

/// Memory copies of the bytes the prefilter writes (W x H x ceil(M / 4) RGBA8 texels).
struct CopyTimes {
  std::size_t bytes = 0;
  double memcpyMs = 0.0, gpuCopyMs = 0.0; ///< memcpy (CPU), glCopyImageSubData (GPU)
};

CopyTimes timeCopies(const BenchOptions& o) {
  const int mapW = o.mapWidth, mapH = o.mapHeight, layers = layerCount(o.bases);
  CopyTimes c;
  c.bytes = std::size_t(mapW) * mapH * std::size_t(layers) * 4;
  std::vector<unsigned char> src(c.bytes, 1), dst(c.bytes);
  c.memcpyMs = medianMs(o.repeat, [&] { std::memcpy(dst.data(), src.data(), c.bytes); });
  gl::Handle a = gl::createTexture(GL_TEXTURE_2D_ARRAY), b = gl::createTexture(GL_TEXTURE_2D_ARRAY);
  glTextureStorage3D(a.get(), 1, GL_RGBA8, mapW, mapH, layers);
  glTextureStorage3D(b.get(), 1, GL_RGBA8, mapW, mapH, layers);
  c.gpuCopyMs = medianMs(o.repeat, [&] {
    glCopyImageSubData(a.get(), GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, b.get(), GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0,
                       mapW, mapH, layers);
    glFinish();
  });
  return c;
}

/// The CPU reference (all cores) of the prefilter and the evaluation on a set-up's frame.
struct CpuTimes {
  double prefilter = 0.0, evaluate = 0.0;
};

CpuTimes timeCpu(const BenchOptions& o, const Setup& s) {
  PrefilterOptions options = Scattering::CreateInfo{}.prefilter;
  options.reconstruction = VisibilityReconstruction::Fourier; // the paper's passes, as the GPU side measures
  options.bases = o.bases;
  const RectifiedMap map = makeRectifiedMap(s.layout, s.rectifiedImage);
  FilteredBasis basis;
  const int cpuRepeat = o.quick ? 1 : std::max(1, o.repeat / 2);
  CpuTimes t;
  t.prefilter = medianMs(cpuRepeat, [&] { basis = prefilter(map, s.scene.medium, options); });
  t.evaluate = medianMs(cpuRepeat, [&] {
    const Image img = evaluate(basis, s.cameraDepthImage, s.scene.camera, s.scene.sun, s.scene.medium);
    (void)img;
  });
  return t;
}

/// CPU vs GPU per stage, the limits and the evaluation variants.
void printPassTimes(const CpuTimes& cpu, const GpuTimes& gpu) {
  std::printf("\n%-34s %12s %12s %10s\n", "stage", "CPU ms", "GPU ms", "CPU/GPU");
  std::printf("%-34s %12.2f %12.2f %10.2f\n", "prefilter", cpu.prefilter, gpu.prefilter,
              cpu.prefilter / gpu.prefilter);
  std::printf("%-34s %12.2f %12.2f %10.2f\n", "evaluate", cpu.evaluate, gpu.evaluate,
              cpu.evaluate / gpu.evaluate);
  std::printf("\nlimits (the same pass stripped to its memory traffic, same run; goals: prefilter <= 2x,\n"
              "evaluation <= 1.3x):\n");
  std::printf(
      "  prefilter   %8.2f ms   write-only (same map reads, same basis writes) %8.2f ms   ratio %.2f\n",
      gpu.prefilter, gpu.prefilterLimit, gpu.prefilter / gpu.prefilterLimit);
  std::printf(
      "              (%d bases per invocation, the default; the fastest write-only, %d per invocation: "
      "%.2f ms, ratio %.2f)\n",
      PrefilterOptions{}.basesPerInvocation, gpu.prefilterLimitFastestBases, gpu.prefilterLimitFastest,
      gpu.prefilter / gpu.prefilterLimitFastest);
  std::printf(
      "  evaluate    %8.2f ms   fetch-only (same fetches and store, no math)    %8.2f ms   ratio %.2f\n",
      gpu.evaluate, gpu.evaluateLimit, gpu.evaluate / gpu.evaluateLimit);
  std::printf(
      "evaluation variants (same run): scattering prefix (default) %.2f ms, of which its per-frame\n"
      "tables %.2f ms (the evaluation of an 8x8 image; the visibility table alone %.2f ms); per-region\n"
      "loop over the visibility table %.2f ms (%.2fx); no table %.2f ms (%.2fx)\n",
      gpu.evaluate, gpu.evaluateTablesOnly, gpu.evaluateVisibilityTableOnly, gpu.evaluatePerRegion,
      gpu.evaluatePerRegion / gpu.evaluate, gpu.evaluateDirect, gpu.evaluateDirect / gpu.evaluate);
}

void printProfile(const BenchOptions& o, const Setup& s) {
  const int perSplit = Scattering::CreateInfo{}.prefilter.regionsPerSplit, bases = o.bases;
  const EvaluationProfile profile = profileEvaluation(s, perSplit);
  std::printf(
      "\nevaluation profile (%s, %d prefilter regions): %.2f regions crossed per pixel on average, at most\n"
      "%d; fetches per pixel: %.1f without the tables (M / 4 = %d per region), %.1f with the per-region\n"
      "loop over the visibility table (a table fetch per region crossed whole + M / 4), %d with the "
      "scattering\n"
      "prefix (the default: one prefix fetch + M / 4); pixels by regions crossed:",
      o.scene.c_str(), s.layout->regionCount() * perSplit, profile.meanRegions, profile.maxRegions,
      profile.meanRegions * layerCount(bases), layerCount(bases),
      profile.meanRegions - 1.0 + layerCount(bases), 1 + layerCount(bases));
  for (std::size_t i = 0; i < profile.histogram.size(); ++i)
    if (profile.histogram[i] >= 0.0005) std::printf(" %zu: %.1f%%", i + 1, 100.0 * profile.histogram[i]);
  std::printf("\n");
}

void printBandwidth(const CopyTimes& c, const CpuTimes& cpu, const GpuTimes& gpu) {
  const double mib = double(c.bytes) / (1024.0 * 1024.0);
  std::printf("\nbandwidth over the %.1f MiB the prefilter writes (RGBA8):\n", mib);
  std::printf("  memcpy (CPU)          %8.2f ms  %8.0f MiB/s\n", c.memcpyMs, mib / (c.memcpyMs / 1000.0));
  std::printf("  glCopyImageSubData    %8.2f ms  %8.0f MiB/s\n", c.gpuCopyMs, mib / (c.gpuCopyMs / 1000.0));
  std::printf("  GPU prefilter         %8.2f ms  %8.0f MiB/s  (%.1f%% of the GPU copy)\n", gpu.prefilter,
              mib / (gpu.prefilter / 1000.0), 100.0 * c.gpuCopyMs / gpu.prefilter);
  std::printf("  CPU prefilter         %8.2f ms  %8.0f MiB/s  (%.1f%% of memcpy)\n", cpu.prefilter,
              mib / (cpu.prefilter / 1000.0), 100.0 * c.memcpyMs / cpu.prefilter);
}

/// The Table 1/2 rows of a run for --plot: names and times relative to the run's map and M.
struct TablePlot {
  std::vector<std::string> scaleNames;
  std::vector<double> scalePrefilter, scaleEvaluate;
  std::vector<std::string> parNames;
  std::vector<double> parOurs, parPaper;
};

} // namespace

class BenchRun {
public:
  BenchRun(const BenchOptions& o, bool chosen) : options(o), named(chosen) {}
  const BenchOptions& options;
  const bool named; ///< the sections were chosen with --section
  /// The run's scene at its screen and map sizes, made on first use and shared by the sections.
  const Setup& setup() {
    if (!setup_)
      setup_.emplace(makeSetup(options.scene, options.screenWidth, options.screenHeight, options.mapWidth,
                               options.mapHeight));
    return *setup_;
  }
  std::optional<GpuTimes> passTimes; ///< the GPU passes at the run's map and M (the scaling rows' base)
  TablePlot plot;

private:
  std::optional<Setup> setup_;
};

namespace {

/// The prefilter and evaluation at the run's sizes: CPU reference (all cores) vs GPU pass on the same
/// inputs, the passes beside their memory-traffic limits, the evaluation variants and profile, and the
/// bandwidth of the prefilter against memory copies of the bytes it writes.
void passesSection(BenchRun& run) {
  const BenchOptions& o = run.options;
  const Setup& s = run.setup();
  const CopyTimes copies = timeCopies(o);
  const CpuTimes cpu = timeCpu(o, s);
  GpuRun limits;
  limits.limits = true;
  const GpuTimes gpu = timeGpu(s, o.bases, o.repeat, limits);
  run.passTimes = gpu;
  printPassTimes(cpu, gpu);
  printProfile(o, s);
  printBandwidth(copies, cpu, gpu);
}

void localLightsSection(BenchRun& run) {
  localLights(run.options);
  localLightScene(run.options);
  if (run.named || run.options.quick) localLightScaling(run.options);
}

/// Table 2's rows: scaling with map width, map height and M (GPU pass, RGBA8), relative to the run's map
/// and M (measured by the passes section, else here first). --quick: the half-height and M = 16 rows.
void scalingSection(BenchRun& run) {
  const BenchOptions& o = run.options;
  const int mapW = o.mapWidth, mapH = o.mapHeight, bases = o.bases;
  const Setup& s = run.setup();
  if (!run.passTimes) run.passTimes = timeGpu(s, bases, o.repeat);
  const GpuTimes gpu = *run.passTimes;
  std::printf("\nscaling (GPU pass, RGBA8; ratio = time / time of the %dx%d, M = %d row):\n", mapW, mapH,
              bases);
  std::printf("%-18s %6s %12s %12s %8s\n", "map", "M", "prefilter ms", "evaluate ms", "ratio");
  const double base = gpu.prefilter + gpu.evaluate;
  struct Row {
    int w, h, m;
  };
  std::vector<Row> rows = {{mapW / 2, mapH, bases}, {mapW * 2, mapH, bases}, {mapW, mapH / 2, bases},
                           {mapW, mapH * 2, bases}, {mapW, mapH, 16},        {mapW, mapH, 64}};
  if (o.quick) {
    rows = {{mapW, mapH, 16}};
    if (mapH >= 2) rows.insert(rows.begin(), {mapW, mapH / 2, bases});
  }
  for (const Row& r : rows) {
    std::optional<Setup> resized;
    if (r.w != mapW || r.h != mapH)
      resized.emplace(makeSetup(o.scene, o.screenWidth, o.screenHeight, r.w, r.h));
    const Setup& use = resized ? *resized : s;
    const GpuTimes t = timeGpu(use, r.m, o.repeat);
    std::printf("%6dx%-11d %6d %12.2f %12.2f %8.2f\n", r.w, r.h, r.m, t.prefilter, t.evaluate,
                (t.prefilter + t.evaluate) / base);
    run.plot.scaleNames.push_back(r.m != bases ? "M " + std::to_string(r.m)
                                               : std::to_string(r.w) + "x" + std::to_string(r.h));
    run.plot.scalePrefilter.push_back(t.prefilter / gpu.prefilter);
    run.plot.scaleEvaluate.push_back(t.evaluate / gpu.evaluate);
  }
}

/// The paper's Table 1 (NVIDIA Titan, San Miguel): prefix-sum ms for (regions, bases per thread), relative
/// to its first cell; -1 where it has none.
double paperTable1(int regions, int basesPerInvocation) {
  const double t[4][3] = {{1.85, 2.49, 4.05}, {1.19, 1.37, 2.03}, {1.50, 0.93, 1.32}, {1.28, 1.16, 1.10}};
  const int row = regions - 1, col = basesPerInvocation == 4    ? 0
                                     : basesPerInvocation == 8  ? 1
                                     : basesPerInvocation == 16 ? 2
                                                                : -1;
  return row >= 0 && row < 4 && col >= 0 ? t[row][col] / 1.85 : -1.0;
}

/// Table 1's study: the GPU prefilter at the run's map and M for regions per split x bases per invocation.
/// --quick: 1 and 2 regions per split.
void parallelizationSection(BenchRun& run) {
  const BenchOptions& o = run.options;
  const Setup& s = run.setup();
  const std::vector<int> perInvocation = {4, 8, 16, 32};
  const std::vector<int> regions =
      o.quick ? std::vector<int>{1, 2} : std::vector<int>{1, 2, kMaxRegionsPerSplit};
  std::printf("\nparallelization (Table 1; GPU prefilter ms):\n%-10s", "regions");
  for (int bpi : perInvocation)
    std::printf(" %8d", bpi);
  std::printf("   <- bases per invocation\n");
  double parBase = 0.0;
  for (int p : regions) {
    std::printf("%-10d", p);
    for (int bpi : perInvocation) {
      if (bpi > o.bases || o.bases % bpi != 0) {
        std::printf(" %8s", "-");
        continue;
      }
      GpuRun cell;
      cell.regionsPerSplit = p;
      cell.basesPerInvocation = bpi;
      cell.evaluate = false;
      const double ms = timeGpu(s, o.bases, o.repeat, cell).prefilter;
      std::printf(" %8.2f", ms);
      if (parBase == 0.0) parBase = ms;
      run.plot.parNames.push_back(std::to_string(p) + "/" + std::to_string(bpi));
      run.plot.parOurs.push_back(ms / parBase);
      run.plot.parPaper.push_back(paperTable1(p, bpi));
    }
    std::printf("\n");
  }
}

/// --plot: the Table 1/2 rows of the run beside the paper's, as an SVG bar chart.
void writeTablePlot(const BenchRun& run) {
  const BenchOptions& o = run.options;
  const int mapW = o.mapWidth, mapH = o.mapHeight, bases = o.bases;
  // The paper's Table 2 (prefix sum and scattering relative to its 1024x1024, M = 32 row), where it has
  // the row; our rows are relative to this run's map and M (the paper's are for 1024^2 too).
  const auto paperTable2 = [&](const std::string& name, bool prefix) -> double {
    if (mapW != 1024 || mapH != 1024 || bases != 32) return -1.0;
    if (name == "512x1024") return prefix ? 0.54 / 0.94 : 1.47 / 1.30;
    if (name == "2048x1024") return prefix ? 2.17 / 0.94 : 1.31 / 1.30;
    if (name == "1024x512") return prefix ? 0.97 / 0.94 : 1.47 / 1.30;
    if (name == "M 16") return prefix ? 0.96 / 0.94 : 0.92 / 1.30;
    if (name == "M 64") return prefix ? 3.07 / 0.94 : 2.63 / 1.30;
    return -1.0;
  };
  const TablePlot& p = run.plot;
  std::vector<double> paperPrefilter, paperEvaluate;
  for (const std::string& n : p.scaleNames) {
    paperPrefilter.push_back(paperTable2(n, true));
    paperEvaluate.push_back(paperTable2(n, false));
  }
  const std::string ours = "crepuscular, llvmpipe";
  const std::string paper = "Klehm et al. 2014, NVIDIA Titan";
  writeBarChartSvg(o.plot,
                   "Table 2 and Table 1 shapes: time relative to the " + std::to_string(mapW) + "x" +
                       std::to_string(mapH) + ", M = " + std::to_string(bases) + " row (" + o.scene + ", " +
                       std::to_string(o.screenWidth) + "x" + std::to_string(o.screenHeight) + ")",
                   {{"prefilter vs map size and M (Table 2)",
                     p.scaleNames,
                     {{ours, "#d95f02", p.scalePrefilter}, {paper, "#7570b3", paperPrefilter}}},
                    {"evaluation vs map size and M (Table 2)",
                     p.scaleNames,
                     {{ours, "#d95f02", p.scaleEvaluate}, {paper, "#7570b3", paperEvaluate}}},
                    {"prefilter: regions / bases per invocation (Table 1)",
                     p.parNames,
                     {{ours, "#d95f02", p.parOurs}, {paper, "#7570b3", p.parPaper}}}});
  std::printf("\nwrote %s (the Table 1/2 rows above beside the paper's)\n", o.plot.c_str());
}

/// What --quick does (BenchOptions::quick), for --help.
constexpr const char* kQuickHelp =
    "--quick: every section once at a reduced cost (a smoke test): --size 640x360\n"
    "  --map 512x512 --repeat 1 unless given; no second screen size; no reference or brute\n"
    "  march; 3 of the 7 slices x samples rows; atmosphere tables at 8x16x16x4 and no 4D\n"
    "  reference table; local-lights with its spot scaling; Table 2's half-height and\n"
    "  M = 16 rows; Table 1 at 1 and 2 regions per split";

/// Sections whose rows --plot draws.
constexpr const char* kPlotSections[] = {"scaling", "parallelization"};

} // namespace

const std::vector<BenchSection>& benchSections() {
  static const std::vector<BenchSection> sections = {
      {"passes", "CPU reference vs GPU prefilter and evaluation, limits, bandwidth", passesSection},
      {"memory", "GPU memory per map size, crep::Scattering::memoryBytes()",
       [](BenchRun& r) { memoryTable(r.options); }},
      {"local-lights", "a spot vs the sun, the spot scene; named or --quick: 1-8 spots", localLightsSection},
      {"light-textures", "the stained-glass sun with and without its light texture",
       [](BenchRun& r) { lightTextures(r.options); }},
      {"constant-cost", "the GPU passes on the four projective scenes, interleaved",
       [](BenchRun& r) { constantCost(r.options); }},
      {"reduced-resolution", "crep::Scattering at evaluation scales 1, 0.5 and 0.25",
       [](BenchRun& r) { reducedResolution(r.options); }},
      {"reconstruction", "the Fourier series vs the exact prefix on forest and sunset, interleaved",
       [](BenchRun& r) { reconstructionBench(r.options); }},
      {"methods", "every method of the tool's registry on the same frame",
       [](BenchRun& r) { methodsSideBySide(r.options); }},
      {"sun-in-view", "the sunset scene (epipolar) vs the forest's projective frame",
       [](BenchRun& r) { sunInView(r.options); }},
      {"post-effects", "radial blur and froxel fog beside the prefiltered method",
       [](BenchRun& r) { postEffects(r.options); }},
      {"epipolar-sampling", "Yusov's sampling, the hybrid and their peers; slices x samples",
       [](BenchRun& r) { epipolarSamplingBench(r.options); }},
      {"atmosphere", "atmosphere tables from scratch; sky and shafts per frame",
       [](BenchRun& r) { atmosphereBench(r.options); }},
      {"scaling", "Table 2: the GPU passes vs map width, map height and M", scalingSection},
      {"parallelization", "Table 1: prefilter regions per split x bases per invocation",
       parallelizationSection},
      {"backends", "the passes on the gpu::Backend seam: OpenGL vs Vulkan, the same frame",
       [](BenchRun& r) { backendsBench(r.options); }},
  };
  return sections;
}

std::string benchHelp() {
  const std::string indent(12, ' ');
  std::string text;
  const auto line = [&](const std::string& s) { text += indent + s + "\n"; };
  line("--scene NAME (forest) --size WxH (1920x1080) --map WxH (1024x1024)");
  line("--bases M (32; any even M in [4, 128]) --repeat N (5); the --map width is a");
  line("multiple of 32 (16 with --quick); --plot FILE.svg writes the Table 1/2 rows as a");
  line("chart beside the paper's (needs the scaling and parallelization sections, not --quick)");
  std::string quick = kQuickHelp;
  for (std::size_t at = 0, next; at < quick.size(); at = next + 1) {
    next = quick.find('\n', at);
    if (next == std::string::npos) next = quick.size();
    line(quick.substr(at, next - at));
  }
  line("--backend B: opengl (default) | vulkan: crep::Scattering's methods (prefilter, minmax,");
  line("epipolar-sampling, epipolar-prefilter) on a Vulkan device in the sections that run the");
  line("tool's methods (methods, sun-in-view, post-effects, epipolar-sampling, local-lights' spot");
  line("scene), the maps rasterized on Vulkan; the rest on OpenGL (backends: both)");
  line("--section NAME[,NAME...]: those sections alone (in the suite's order); the sections,");
  line("in the order the whole suite runs them:");
  for (const BenchSection& s : benchSections()) {
    std::string name = s.name;
    name.resize(std::max<std::size_t>(name.size(), 18), ' ');
    line("  " + name + " " + s.summary);
  }
  return text;
}

namespace {

/// --section's value: the names of benchSections() in the suite's order (a name given twice runs once).
std::vector<std::string> parseSections(const std::string& value) {
  std::vector<std::string> given;
  for (std::size_t at = 0, next; at <= value.size(); at = next + 1) {
    next = value.find(',', at);
    if (next == std::string::npos) next = value.size();
    given.push_back(value.substr(at, next - at));
  }
  std::string valid;
  for (const BenchSection& s : benchSections())
    valid += std::string(valid.empty() ? "" : ", ") + s.name;
  for (const std::string& name : given)
    if (std::none_of(benchSections().begin(), benchSections().end(),
                     [&](const BenchSection& s) { return name == s.name; }))
      throw tool::UsageError("option --section: '" + name + "' is not a section; the sections: " + valid);
  std::vector<std::string> sections;
  for (const BenchSection& s : benchSections())
    if (std::find(given.begin(), given.end(), s.name) != given.end()) sections.push_back(s.name);
  return sections;
}

/// The --map size: the rectification's splits lie side by side in the map (SplitLayout::Regions); without
/// --quick the parallelization rows split each into up to kMaxRegionsPerSplit regions and the scaling rows
/// halve the width (a multiple of splits * kMaxRegionsPerSplit halves to a multiple of splits) and double
/// the width and the height (the map is read back as an image); --quick's rows keep the width and halve
/// the height only when it is at least 2.
glm::ivec2 parseMapSize(const tool::Args& args, bool quick) {
  const glm::ivec2 fallback = quick ? glm::ivec2(512, 512) : glm::ivec2(1024, 1024);
  const int scale = quick ? 1 : 2;
  const glm::ivec2 map = args.size("map", fallback, Image::kMaxDimension / scale, Image::kMaxPixels / scale);
  const int splits = Scattering::CreateInfo{}.rectify.splits,
            perSplit = Scattering::CreateInfo{}.prefilter.regionsPerSplit;
  const int multiple = splits * (quick ? perSplit : std::max(perSplit, kMaxRegionsPerSplit));
  if (map.x % multiple != 0)
    throw tool::UsageError("option --map: width " + std::to_string(map.x) + " must be a multiple of " +
                           std::to_string(multiple) + " (the rectification's " + std::to_string(splits) +
                           " splits side by side" +
                           (quick ? ", " + std::to_string(perSplit) + " prefilter regions each)"
                                  : std::string(", each in up to ") + std::to_string(kMaxRegionsPerSplit) +
                                        " regions in the parallelization rows; --quick runs 1 and 2)"));
  if (map.y < scale)
    throw tool::UsageError("option --map: height " + std::to_string(map.y) +
                           " must be at least 2 (halved by the scaling rows; --quick skips that row)");
  return map;
}

} // namespace

BenchOptions parseBenchOptions(const std::vector<std::string>& argv) {
  const tool::Args args(argv, {"scene", "size", "map", "bases", "repeat", "plot", "section", "backend"},
                        {"quick"});
  BenchOptions o;
  o.scene = args.string("scene", o.scene);
  tool::requireSceneName(o.scene); // a usage error before any GL work
  o.quick = args.has("quick");
  const glm::ivec2 size =
      args.size("size", o.quick ? glm::ivec2(640, 360) : glm::ivec2(o.screenWidth, o.screenHeight),
                Image::kMaxDimension, Image::kMaxPixels);
  const glm::ivec2 map = parseMapSize(args, o.quick);
  o.screenWidth = size.x;
  o.screenHeight = size.y;
  o.mapWidth = map.x;
  o.mapHeight = map.y;
  o.bases = args.integer("bases", o.bases, kMinBases, kMaxBases);
  if (o.bases % 2 != 0) throw tool::UsageError("option --bases: must be even");
  o.repeat = args.integer("repeat", o.quick ? 1 : o.repeat, 1, 1000);
  o.plot = args.string("plot", "");
  if (args.has("section")) o.sections = parseSections(args.string("section", ""));
  o.backend = args.string("backend", o.backend);
  tool::requireBackend(o.backend);
  if (!o.plot.empty()) {
    for (const char* needed : kPlotSections)
      if (!o.sections.empty() && std::find(o.sections.begin(), o.sections.end(), needed) == o.sections.end())
        throw tool::UsageError("option --plot: needs the sections scaling and parallelization (the whole "
                               "suite or --section scaling,parallelization)");
    if (o.quick)
      throw tool::UsageError("option --plot: needs the Table 1/2 rows in full, which --quick reduces");
    if (!o.plot.ends_with(".svg")) throw tool::UsageError("option --plot: must end in .svg");
    tool::requireOutputFile({"--plot", o.plot}); // the output rule, before any work
  }
  return o;
}

void runBenchSuite(const BenchOptions& o) {
  scenes::registerShaders(); // the methods' reference march and the scene rasterizer (examples/glsl/)
  tool::StageTimings contextTimings;
  tool::ensureGlContext("bench", false, contextTimings);
  std::printf("crep bench: scene %s | screen %dx%d | map %dx%d | M = %d | median of %d runs%s\n",
              o.scene.c_str(), o.screenWidth, o.screenHeight, o.mapWidth, o.mapHeight, o.bases, o.repeat,
              o.backend == "opengl" ? ""
                                    : " | --backend vulkan: prefilter, minmax, epipolar-sampling and "
                                      "epipolar-prefilter on a Vulkan device where the tool's methods run");
  BenchRun run(o, !o.sections.empty());
  for (const BenchSection& section : benchSections())
    if (o.sections.empty() ||
        std::find(o.sections.begin(), o.sections.end(), section.name) != o.sections.end()) {
      section.run(run);
      std::fflush(stdout); // a section at a time through a pipe (`crep bench | tee`), not 4 KiB blocks
    }
  if (!o.plot.empty()) writeTablePlot(run);
  printHowMeasured(o);
}

} // namespace crep::bench
