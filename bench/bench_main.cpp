// crep_bench: prefilter and evaluation timings, CPU reference vs GPU pass (llvmpipe here), side by
// side in one run, plus the scaling rows of the paper's Table 2 and the achieved bandwidth of the
// prefilter against a memory copy measured in the same run. Prints ratios; never asserts on time.
//
// usage: crep_bench [--scene NAME] [--size WxH] [--map WxH] [--bases M] [--repeat N] [--quick]
#include <crep/core/error.h>
#include <crep/core/gl.h>
#include <crep/core/gl_context.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

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

struct Setup {
  crep::scenes::Scene scene;
  crep::Rectification rect;
  std::shared_ptr<crep::ProjectiveLayout> layout;
  crep::gl::Handle rectified, cameraDepth, scattering;
  crep::Image rectifiedImage, cameraDepthImage;
  int mapW, mapH, screenW, screenH;
};

Setup makeSetup(const std::string& sceneName, int screenW, int screenH, int mapW, int mapH) {
  Setup s{crep::scenes::makeScene(sceneName, double(screenW) / screenH), {}, {}, {}, {}, {}, {}, {}, mapW, mapH,
          screenW, screenH};
  s.rect = crep::rectify(s.scene.camera, s.scene.sun);
  if (!s.rect.projective()) throw crep::Error("scene " + sceneName + " is not projective: " + s.rect.message);
  s.layout = std::make_shared<crep::ProjectiveLayout>(s.rect);
  crep::scenes::SceneRenderer renderer(s.scene.mesh);
  s.rectified = crep::scenes::createDepthTexture(mapW, mapH, "--map");
  renderer.renderRectified(s.rect, s.rectified.get(), mapW, mapH);
  s.rectifiedImage = crep::scenes::readDepthTexture(s.rectified.get(), mapW, mapH);
  s.cameraDepth = crep::scenes::createDepthTexture(screenW, screenH, "--size");
  renderer.renderDepth(s.scene.camera.clipFromWorld(), s.cameraDepth.get(), 0, 0, 0, screenW, screenH);
  s.cameraDepthImage = crep::scenes::readDepthTexture(s.cameraDepth.get(), screenW, screenH);
  s.scattering = crep::gl::createTexture2D(GL_RGBA32F, screenW, screenH, "--size");
  glFinish();
  return s;
}

struct GpuTimes {
  double prefilter, evaluate;
};

GpuTimes timeGpu(const Setup& s, int bases, crep::StorageFormat format, int repeat, int regionsPerSplit = 1,
                 int basesPerInvocation = 8) {
  crep::PrefilterPass::CreateInfo info;
  info.width = s.mapW;
  info.height = s.mapH;
  info.bases = bases;
  info.format = format;
  info.regionsPerSplit = regionsPerSplit;
  info.basesPerInvocation = std::min(basesPerInvocation, bases);
  crep::PrefilterPass prefilter(info);
  crep::EvaluatePass::CreateInfo evalInfo;
  evalInfo.bases = bases;
  crep::EvaluatePass evaluate(evalInfo);
  crep::PrefilterPass::Frame frame;
  frame.rectifiedDepth = s.rectified.get();
  frame.layout = s.layout.get();
  frame.medium = &s.scene.medium;
  prefilter.run(frame); // warm-up (shader specialization on first dispatch)
  glFinish();
  GpuTimes t{};
  t.prefilter = medianMs(repeat, [&] {
    prefilter.run(frame);
    glFinish();
  });
  crep::EvaluatePass::Frame ev;
  ev.cameraDepth = s.cameraDepth.get();
  ev.output = s.scattering.get();
  ev.camera = &s.scene.camera;
  ev.light = &s.scene.sun;
  ev.medium = &s.scene.medium;
  ev.layout = s.layout.get();
  ev.basis = prefilter.filteredBasis();
  evaluate.run(ev);
  glFinish();
  t.evaluate = medianMs(repeat, [&] {
    evaluate.run(ev);
    glFinish();
  });
  return t;
}

int parseInt(const char* text, const char* option) {
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  if (!*text || *end || v < 1 || v > 1 << 15) {
    std::fprintf(stderr, "crep_bench: option %s: '%s' is not a positive integer\n", option, text);
    std::exit(2);
  }
  return static_cast<int>(v);
}

void parseSize(const char* text, const char* option, int& w, int& h) {
  if (std::sscanf(text, "%dx%d", &w, &h) != 2 || w < 1 || h < 1) {
    std::fprintf(stderr, "crep_bench: option %s: '%s' is not WIDTHxHEIGHT\n", option, text);
    std::exit(2);
  }
}

} // namespace

int main(int argc, char** argv) {
  std::string sceneName = "forest";
  int screenW = 1920, screenH = 1080, mapW = 1024, mapH = 1024, bases = 32, repeat = 5;
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "crep_bench: option %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--scene") sceneName = next();
    else if (a == "--size") parseSize(next(), "--size", screenW, screenH);
    else if (a == "--map") parseSize(next(), "--map", mapW, mapH);
    else if (a == "--bases") bases = parseInt(next(), "--bases");
    else if (a == "--repeat") repeat = parseInt(next(), "--repeat");
    else if (a == "--quick") quick = true;
    else {
      std::fprintf(stderr, "crep_bench: unknown option %s\n", a.c_str());
      return 2;
    }
  }
  try {
    static crep::GlContext* context = new crep::GlContext(); // process lifetime (see gl_context.h)
    std::printf("crep_bench: %s | %s | scene %s | screen %dx%d | map %dx%d | M = %d | median of %d runs\n",
                context->renderer().c_str(), context->version().c_str(), sceneName.c_str(), screenW, screenH, mapW,
                mapH, bases, repeat);
    const Setup s = makeSetup(sceneName, screenW, screenH, mapW, mapH);

    // Memory copy baselines over the bytes the prefilter writes (W x H x M/4 RGBA8 texels).
    const std::size_t outBytes = std::size_t(mapW) * mapH * std::size_t(bases); // RGBA8: 1 byte per basis
    std::vector<unsigned char> src(outBytes, 1), dst(outBytes);
    const double memcpyMs = medianMs(repeat, [&] { std::memcpy(dst.data(), src.data(), outBytes); });
    crep::gl::Handle a = crep::gl::createTexture(GL_TEXTURE_2D_ARRAY), b = crep::gl::createTexture(GL_TEXTURE_2D_ARRAY);
    glTextureStorage3D(a.get(), 1, GL_RGBA8, mapW, mapH, bases / 4);
    glTextureStorage3D(b.get(), 1, GL_RGBA8, mapW, mapH, bases / 4);
    const double gpuCopyMs = medianMs(repeat, [&] {
      glCopyImageSubData(a.get(), GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, b.get(), GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, mapW, mapH,
                         bases / 4);
      glFinish();
    });

    // CPU reference (all cores) vs GPU pass, same inputs.
    crep::PrefilterOptions options;
    options.bases = bases;
    const crep::RectifiedMap map = crep::makeRectifiedMap(s.layout, s.rectifiedImage);
    crep::FilteredBasis basis;
    const double cpuPrefilterMs = medianMs(quick ? 1 : std::max(1, repeat / 2), [&] {
      basis = crep::prefilter(map, s.scene.medium, options);
    });
    const double cpuEvaluateMs = medianMs(quick ? 1 : std::max(1, repeat / 2), [&] {
      const crep::Image img = crep::evaluate(basis, s.cameraDepthImage, s.scene.camera, s.scene.sun, s.scene.medium);
      (void)img;
    });
    const GpuTimes gpu = timeGpu(s, bases, crep::StorageFormat::RGBA8, repeat);

    std::printf("\n%-34s %12s %12s %10s\n", "stage", "CPU ms", "GPU ms", "CPU/GPU");
    std::printf("%-34s %12.2f %12.2f %10.2f\n", "prefilter", cpuPrefilterMs, gpu.prefilter, cpuPrefilterMs / gpu.prefilter);
    std::printf("%-34s %12.2f %12.2f %10.2f\n", "evaluate", cpuEvaluateMs, gpu.evaluate, cpuEvaluateMs / gpu.evaluate);
    const double mib = double(outBytes) / (1024.0 * 1024.0);
    std::printf("\nbandwidth over the %.1f MiB the prefilter writes (RGBA8):\n", mib);
    std::printf("  memcpy (CPU)          %8.2f ms  %8.0f MiB/s\n", memcpyMs, mib / (memcpyMs / 1000.0));
    std::printf("  glCopyImageSubData    %8.2f ms  %8.0f MiB/s\n", gpuCopyMs, mib / (gpuCopyMs / 1000.0));
    std::printf("  GPU prefilter         %8.2f ms  %8.0f MiB/s  (%.1f%% of the GPU copy)\n", gpu.prefilter,
                mib / (gpu.prefilter / 1000.0), 100.0 * gpuCopyMs / gpu.prefilter);
    std::printf("  CPU prefilter         %8.2f ms  %8.0f MiB/s  (%.1f%% of memcpy)\n", cpuPrefilterMs,
                mib / (cpuPrefilterMs / 1000.0), 100.0 * memcpyMs / cpuPrefilterMs);

    if (!quick) {
      // Table 2's rows: scaling with map width, map height and M (GPU pass, RGBA8).
      std::printf("\nscaling (GPU pass, RGBA8; ratio = time / time of the %dx%d, M = %d row):\n", mapW, mapH, bases);
      std::printf("%-18s %6s %12s %12s %8s\n", "map", "M", "prefilter ms", "evaluate ms", "ratio");
      const double base = gpu.prefilter + gpu.evaluate;
      struct Row {
        int w, h, m;
      };
      const Row rows[] = {{mapW / 2, mapH, bases},     {mapW * 2, mapH, bases}, {mapW, mapH / 2, bases},
                          {mapW, mapH * 2, bases},     {mapW, mapH, 16},        {mapW, mapH, 64}};
      for (const Row& r : rows) {
        std::optional<Setup> resized;
        if (r.w != mapW || r.h != mapH) resized.emplace(makeSetup(sceneName, screenW, screenH, r.w, r.h));
        const Setup& use = resized ? *resized : s;
        const GpuTimes t = timeGpu(use, r.m, crep::StorageFormat::RGBA8, repeat);
        std::printf("%6dx%-11d %6d %12.2f %12.2f %8.2f\n", r.w, r.h, r.m, t.prefilter, t.evaluate,
                    (t.prefilter + t.evaluate) / base);
      }
      // Table 1's study: regions per split x bases per invocation.
      std::printf("\nparallelization (Table 1; GPU prefilter ms):\n%-10s", "regions");
      for (int bpi : {4, 8, 16, 32}) std::printf(" %8d", bpi);
      std::printf("   <- bases per invocation\n");
      for (int p : {1, 2, 4}) {
        std::printf("%-10d", p);
        for (int bpi : {4, 8, 16, 32}) {
          if (bpi > bases || bases % bpi != 0) {
            std::printf(" %8s", "-");
            continue;
          }
          std::printf(" %8.2f", timeGpu(s, bases, crep::StorageFormat::RGBA8, repeat, p, bpi).prefilter);
        }
        std::printf("\n");
      }
    }
    std::printf("\nhow measured: wall-clock median of %d runs, each ending with glFinish (GPU) or on return (CPU);\n"
                "llvmpipe runs the GPU passes on the CPU cores, so CPU/GPU compares two CPU implementations here.\n",
                repeat);
  } catch (const crep::Error& e) {
    std::fprintf(stderr, "crep_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
