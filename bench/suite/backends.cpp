#include "backends.h"

#include <crep/core/error.h>
#include <crep/core/gl_backend.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/epipolar/resample.h>
#include <crep/pipeline/scattering.h>
#include <crep/rectify/rectify.h>
#include <crep/scenes/engine_frame.h>
#include <crep/scenes/scene.h>
#if CREP_HAS_VULKAN
#include <crep/vulkan/vulkan_backend.h>
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <utility>
#include <vector>

namespace crep::bench {

namespace {

/// One backend's copy of the frame: the standard shadow map, the rectified map, and the passes.
struct BackendFrame {
  gpu::Backend& backend;
  gpu::Texture shadow, map;
  ShadowResamplePass resample;
  MinMaxTreePass trees;
  std::vector<double> ms;

  BackendFrame(gpu::Backend& b, const Image& shadowDepth, int W, int H)
      : backend(b), shadow(b, {gpu::TextureType::Texture2D, gpu::Format::Depth32F, shadowDepth.width(),
                               shadowDepth.height(), 1, "bench: shadow map"}),
        map(b, {gpu::TextureType::Texture2D, gpu::Format::R32F, W, H, 1, "bench: rectified map"}),
        resample({.mapWidth = W, .mapHeight = H, .backend = &b}),
        trees({.mapWidth = W, .mapHeight = H, .backend = &b}) {
    b.writeTexture(shadow.id(), shadowDepth.data());
    b.finish();
  }

  /// The rectified map resampled from the shadow map with its trees' low levels, then the upper levels:
  /// the epipolar fallback's map and trees of a frame (Yusov 2012, Sec. 6.3).
  void run(const RectifiedLayout& layout, const glm::dmat4& lightMatrix) {
    const auto start = std::chrono::steady_clock::now();
    ShadowResamplePass::FrameAttribs f;
    f.layout = &layout;
    f.shadowMap = shadow.id();
    f.lightClipFromWorld = lightMatrix;
    f.output = map.id();
    f.minMaxBuffer = trees.treeBuffer();
    resample.run(f);
    trees.completeUpperLevels();
    backend.finish();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }

  double median() const {
    std::vector<double> v = ms;
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
  }
};

#if CREP_HAS_VULKAN
/// The whole frame of a scene through crep::Scattering on one backend, from the engine's maps.
struct ScatteringFrame {
  gpu::Backend& backend;
  scenes::EngineFrame engine;
  gpu::Texture output;
  Scattering scattering;
  std::vector<double> ms;

  ScatteringFrame(gpu::Backend& b, const scenes::Scene& scene, const scenes::EngineMaps& maps, int width,
                  int height, int mapSize)
      : backend(b), engine(b, scene, maps),
        output(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, width, height, 1, "bench: output"}),
        scattering(createInfo(b, width, height, mapSize)) {}

  static Scattering::CreateInfo createInfo(gpu::Backend& b, int width, int height, int mapSize) {
    Scattering::CreateInfo info;
    info.width = width;
    info.height = height;
    info.mapSize = mapSize;
    info.stageTimings = false; // the frame whole, ended by the backend's finish()
    info.backend = &b;
    return info;
  }

  void run() {
    const auto start = std::chrono::steady_clock::now();
    scattering.run(engine.attribs(output.id()));
    backend.finish();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

/// The frames of the port's goal (forest, sunset with the sun in view, colonnade-night's local lights) at
/// 320x180 and at the bench's size, crep::Scattering on each backend, interleaved.
void scatteringFrames(const BenchOptions& o, gpu::Backend& vk, gpu::Backend& gl) {
  const int repeats = std::max(o.repeat, 3);
  std::printf("\n  crep::Scattering, the whole frame from the engine's maps (sun 2048^2, local lights "
              "512^2), map %d^2, wall ms, median of %d, interleaved:\n",
              o.mapWidth, repeats);
  std::printf("  %-18s %-10s %12s %12s %8s\n", "scene", "size", "OpenGL", "Vulkan", "ratio");
  for (const char* name : {"forest", "sunset", "colonnade-night"})
    for (const auto& [w, h] : {std::pair{320, 180}, std::pair{o.screenWidth, o.screenHeight}}) {
      const scenes::Scene scene = scenes::makeScene(name, static_cast<double>(w) / h);
      const scenes::EngineMaps maps = scenes::renderEngineMaps(scene, w, h, 2048, 512);
      ScatteringFrame frames[] = {{gl, scene, maps, w, h, o.mapWidth}, {vk, scene, maps, w, h, o.mapWidth}};
      for (ScatteringFrame& f : frames) // warm-up: programs, pipelines, the tables made on first use
        f.run();
      for (ScatteringFrame& f : frames)
        f.ms.clear();
      for (int r = 0; r < repeats; ++r)
        for (ScatteringFrame& f : frames)
          f.run();
      const double a = median(frames[0].ms), b = median(frames[1].ms);
      std::printf("  %-18s %4dx%-5d %12.2f %12.2f %8.2f\n", name, w, h, a, b, b / a);
    }
}
#endif

} // namespace

void backendsBench(const BenchOptions& o) {
  std::printf(
      "\nbackends (the passes on the gpu::Backend seam: shadow map resampled into the %dx%d rectified "
      "map with its min/max trees; wall ms per frame with the backend's finish(), median of %d, "
      "interleaved; then the whole frame):\n",
      o.mapWidth, o.mapHeight, std::max(o.repeat, 3));
#if CREP_HAS_VULKAN
  const scenes::Scene scene = scenes::makeScene(o.scene, static_cast<double>(o.screenWidth) / o.screenHeight);
  const glm::dmat4 lightMatrix =
      scenes::standardLightClipFromWorld(scene.sun, scene.boundsMin, scene.boundsMax);
  const ProjectiveLayout layout(rectify(scene.camera, scene.sun, RectifyOptions{}));
  // A standard shadow map of twice the rectified map's width: smooth slopes and steps.
  const int S = std::min(2 * o.mapWidth, 4096);
  Image shadow(S, S, 1);
  for (int j = 0; j < S; ++j)
    for (int i = 0; i < S; ++i) {
      const double u = (i + 0.5) / S, v = (j + 0.5) / S;
      const bool box = (i * 8 / S + j * 11 / S) % 3 == 0;
      shadow.at(i, j) =
          static_cast<float>(0.55 + 0.25 * std::sin(6.0 * u) * std::cos(4.0 * v) - (box ? 0.2 : 0.0));
    }
  std::unique_ptr<gpu::VulkanBackend> vk;
  try {
    vk = std::make_unique<gpu::VulkanBackend>();
  } catch (const Error& e) {
    std::printf("  no Vulkan device: %s\n", e.what());
    return;
  }
  gpu::GlBackend gl;
  BackendFrame frames[] = {{gl, shadow, o.mapWidth, o.mapHeight}, {*vk, shadow, o.mapWidth, o.mapHeight}};
  for (BackendFrame& f : frames)
    f.run(layout, lightMatrix); // warm-up: programs and pipelines
  for (BackendFrame& f : frames)
    f.ms.clear();
  for (int r = 0; r < std::max(o.repeat, 3); ++r)
    for (BackendFrame& f : frames)
      f.run(layout, lightMatrix);
  std::printf("  %-24s %10.2f ms\n", "OpenGL", frames[0].median());
  std::printf("  %-24s %10.2f ms   (%s)\n", "Vulkan", frames[1].median(), vk->deviceName().c_str());
  std::printf("  %-24s %10.2f\n", "ratio Vulkan / OpenGL", frames[1].median() / frames[0].median());
  scatteringFrames(o, *vk, gl);
#else
  std::printf("  not built: configure with -DCREP_VULKAN=ON (the Vulkan backend)\n");
#endif
}

} // namespace crep::bench
