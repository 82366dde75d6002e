#include "backends.h"

#include <crep/atmosphere/gpu_pass.h>
#include <crep/atmosphere/gpu_tables.h>
#include <crep/core/error.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/epipolar/resample.h>
#include <crep/gpu/gl_backend.h>
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
#include <string>
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
/// A row of the whole-frame table: a scene and what differs from the front door's defaults.
struct FrameVariant {
  const char* scene;
  const char* label;
  double evaluationScale = 1.0;
  bool epipolarSampling = false;
};

/// The whole frame of a scene through crep::Scattering on one backend, from the engine's maps.
struct ScatteringFrame {
  gpu::Backend& backend;
  scenes::EngineFrame engine;
  gpu::Texture output;
  Scattering scattering;
  std::vector<double> ms;

  ScatteringFrame(gpu::Backend& b, const scenes::Scene& scene, const scenes::EngineMaps& maps, int width,
                  int height, int mapSize, const FrameVariant& v)
      : backend(b), engine(b, scene, maps),
        output(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, width, height, 1, "bench: output"}),
        scattering(createInfo(b, width, height, mapSize, v)) {}

  static Scattering::CreateInfo createInfo(gpu::Backend& b, int width, int height, int mapSize,
                                           const FrameVariant& v) {
    Scattering::CreateInfo info;
    info.width = width;
    info.height = height;
    info.mapSize = mapSize;
    info.evaluationScale = v.evaluationScale;
    if (v.epipolarSampling) info.sampling = Scattering::Sampling::Epipolar;
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

/// The same frame recorded into an engine's command buffer (VulkanBackend::beginFrame / endFrame) on the
/// backend's own device, as a Vulkan engine runs it: the CPU time of recording it, then the frame's wall
/// time to the end of the engine's fence wait.
struct RecordedFrame {
  gpu::VulkanBackend& backend;
  scenes::EngineFrame engine;
  gpu::Texture output;
  Scattering scattering;
  gpu::VulkanBackend::EngineDevice device;
  PFN_vkGetDeviceProcAddr proc = nullptr;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  std::uint64_t& index; ///< the backend's frame counter, shared by every RecordedFrame on it
  std::vector<double> recordMs, ms;

  template <class F>
  F fn(const char* name) const {
    return reinterpret_cast<F>(proc(device.device, name));
  }

  RecordedFrame(gpu::VulkanBackend& b, std::uint64_t& frameCounter, const scenes::Scene& scene,
                const scenes::EngineMaps& maps, int width, int height, int mapSize, const FrameVariant& v)
      : backend(b), engine(b, scene, maps),
        output(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, width, height, 1, "bench: output"}),
        scattering(ScatteringFrame::createInfo(b, width, height, mapSize, v)), device(b.runsOn()),
        index(frameCounter) {
    proc = device.getDeviceProcAddr != nullptr
               ? device.getDeviceProcAddr
               : reinterpret_cast<PFN_vkGetDeviceProcAddr>(
                     device.getInstanceProcAddr(device.instance, "vkGetDeviceProcAddr"));
    VkCommandPoolCreateInfo pci{};
    pci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = device.queueFamily;
    fn<PFN_vkCreateCommandPool>("vkCreateCommandPool")(device.device, &pci, nullptr, &pool);
    VkCommandBufferAllocateInfo ai{};
    ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    ai.commandPool = pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    fn<PFN_vkAllocateCommandBuffers>("vkAllocateCommandBuffers")(device.device, &ai, &cmd);
    VkFenceCreateInfo fi{};
    fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    fn<PFN_vkCreateFence>("vkCreateFence")(device.device, &fi, nullptr, &fence);
    b.finish(); // the set-up, before the first frame
  }
  RecordedFrame(const RecordedFrame&) = delete;
  RecordedFrame& operator=(const RecordedFrame&) = delete;
  ~RecordedFrame() {
    fn<PFN_vkDestroyFence>("vkDestroyFence")(device.device, fence, nullptr);
    fn<PFN_vkDestroyCommandPool>("vkDestroyCommandPool")(device.device, pool, nullptr);
  }

  void run() {
    const auto start = std::chrono::steady_clock::now();
    fn<PFN_vkResetCommandBuffer>("vkResetCommandBuffer")(cmd, 0);
    VkCommandBufferBeginInfo bi{};
    bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    fn<PFN_vkBeginCommandBuffer>("vkBeginCommandBuffer")(cmd, &bi);
    ++index;
    const auto recordStart = std::chrono::steady_clock::now();
    backend.beginFrame({cmd, index, index - 1});
    scattering.run(engine.attribs(output.id()));
    backend.endFrame();
    recordMs.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - recordStart).count());
    fn<PFN_vkEndCommandBuffer>("vkEndCommandBuffer")(cmd);
    VkSubmitInfo si{};
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    fn<PFN_vkQueueSubmit>("vkQueueSubmit")(device.queue, 1, &si, fence);
    fn<PFN_vkWaitForFences>("vkWaitForFences")(device.device, 1, &fence, VK_TRUE, UINT64_MAX);
    fn<PFN_vkResetFences>("vkResetFences")(device.device, 1, &fence);
    backend.frameCompleted(index);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
};

/// 320x180 and the bench's size (once when they are the same).
std::vector<std::pair<int, int>> benchSizes(const BenchOptions& o) {
  std::vector<std::pair<int, int>> sizes = {{320, 180}};
  if (o.screenWidth != 320 || o.screenHeight != 180) sizes.emplace_back(o.screenWidth, o.screenHeight);
  return sizes;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

/// Runs each of `frames` once (warm-up: programs, pipelines, tables made on first use), then `repeats`
/// times interleaved; the medians.
template <class Frame>
std::pair<double, double> interleaved(Frame (&frames)[2], int repeats) {
  for (Frame& f : frames)
    f.run();
  for (Frame& f : frames)
    f.ms.clear();
  for (int r = 0; r < repeats; ++r)
    for (Frame& f : frames)
      f.run();
  return {median(frames[0].ms), median(frames[1].ms)};
}

/// The frames of the port's goal (forest, sunset with the sun in view, colonnade-night's local lights), a
/// reduced evaluation scale and Yusov's epipolar sampling, at 320x180 and at the bench's size,
/// crep::Scattering on each backend, interleaved; on Vulkan also recorded into an engine's command buffer.
void scatteringFrames(const BenchOptions& o, gpu::VulkanBackend& vk, gpu::Backend& gl) {
  const int repeats = std::max(o.repeat, 3);
  std::printf("\n  crep::Scattering, the whole frame from the engine's maps (sun 2048^2, local lights "
              "512^2), map %d^2, wall ms, median of %d, interleaved; \"recorded\": the same frame recorded "
              "into an engine's command buffer (beginFrame/endFrame), its CPU recording time and its wall "
              "time to the engine's fence:\n",
              o.mapWidth, repeats);
  std::printf("  %-38s %-10s %10s %10s %7s %10s %10s %7s\n", "frame", "size", "OpenGL", "Vulkan", "ratio",
              "record CPU", "recorded", "ratio");
  const FrameVariant variants[] = {{"forest", ""},
                                   {"sunset", ""},
                                   {"colonnade-night", ""},
                                   {"forest", ", evaluationScale 0.5", 0.5},
                                   {"sunset", ", epipolar sampling", 1.0, true}};
  std::uint64_t frameCounter = 0;
  for (const FrameVariant& v : variants)
    for (const auto& [w, h] : benchSizes(o)) {
      if (v.evaluationScale < 1.0 && (w % 2 != 0 || h % 2 != 0)) continue; // the scale needs even sizes
      const scenes::Scene scene = scenes::makeScene(v.scene, static_cast<double>(w) / h);
      const scenes::EngineMaps maps = scenes::renderEngineMaps(scene, w, h, 2048, 512);
      ScatteringFrame frames[] = {{gl, scene, maps, w, h, o.mapWidth, v},
                                  {vk, scene, maps, w, h, o.mapWidth, v}};
      RecordedFrame recorded(vk, frameCounter, scene, maps, w, h, o.mapWidth, v);
      recorded.run(); // warm-up
      recorded.ms.clear();
      recorded.recordMs.clear();
      for (ScatteringFrame& f : frames)
        f.run();
      for (ScatteringFrame& f : frames)
        f.ms.clear();
      for (int r = 0; r < repeats; ++r) {
        for (ScatteringFrame& f : frames)
          f.run();
        recorded.run();
      }
      const double a = median(frames[0].ms), b = median(frames[1].ms), c = median(recorded.ms);
      std::printf("  %-38s %4dx%-5d %10.2f %10.2f %7.2f %10.2f %10.2f %7.2f\n",
                  (std::string(v.scene) + v.label).c_str(), w, h, a, b, b / a, median(recorded.recordMs), c,
                  c / a);
    }
}

/// One backend's atmosphere: tables computed once (not timed), then AtmospherePass per frame.
struct AtmosphereFrame {
  gpu::Backend& backend;
  gpu::Texture depth, output;
  AtmosphereTablesPass tables;
  AtmospherePass pass;
  const scenes::Scene& scene;
  AtmospherePlacement placement;
  std::vector<double> ms;

  AtmosphereFrame(gpu::Backend& b, const scenes::Scene& s, const Image& cameraDepth)
      : backend(b), depth(b, {gpu::TextureType::Texture2D, gpu::Format::Depth32F, cameraDepth.width(),
                              cameraDepth.height(), 1, "bench: camera depth"}),
        output(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, cameraDepth.width(),
                   cameraDepth.height(), 1, "bench: atmosphere"}),
        tables(tablesInfo(b)), pass(passInfo(b)), scene(s) {
    b.writeTexture(depth.id(), cameraDepth.data());
    tables.compute();
    placement.metersPerUnit = 50.0;
  }

  static AtmospherePass::CreateInfo passInfo(gpu::Backend& b) {
    AtmospherePass::CreateInfo info;
    info.backend = &b;
    return info;
  }

  static AtmosphereTablesPass::CreateInfo tablesInfo(gpu::Backend& b) {
    AtmosphereTablesPass::CreateInfo info;
    info.options.size = {16, 64, 16, 8}; // the frame reads them; their size barely changes its cost
    info.options.orders = 2;
    info.backend = &b;
    return info;
  }

  void run() {
    const auto start = std::chrono::steady_clock::now();
    AtmospherePass::FrameAttribs f;
    f.tables = &tables;
    f.placement = &placement;
    f.camera = &scene.camera;
    f.sun = &scene.sun;
    f.cameraDepth = depth.id();
    f.output = output.id();
    pass.run(f);
    backend.finish();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
};

/// The atmosphere's per-frame pass (sky and aerial perspective from the view tables, no shafts) on each
/// backend, the terrain scene's camera depth.
void atmosphereFrames(const BenchOptions& o, gpu::Backend& vk, gpu::Backend& gl) {
  const int repeats = std::max(o.repeat, 3);
  std::printf("\n  AtmospherePass (terrain, no shafts, view tables), wall ms, median of %d, interleaved:\n",
              repeats);
  for (const auto& [w, h] : benchSizes(o)) {
    const scenes::Scene scene = scenes::makeScene("terrain", static_cast<double>(w) / h);
    const scenes::EngineMaps maps = scenes::renderEngineMaps(scene, w, h, 256, 256);
    AtmosphereFrame frames[] = {{gl, scene, maps.cameraDepth}, {vk, scene, maps.cameraDepth}};
    const auto [a, b] = interleaved(frames, repeats);
    std::printf("  %-38s %4dx%-5d %12.2f %12.2f %8.2f\n", "terrain, atmosphere", w, h, a, b, b / a);
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
  atmosphereFrames(o, *vk, gl);
#else
  std::printf("  not built: configure with -DCREP_VULKAN=ON (the Vulkan backend)\n");
#endif
}

} // namespace crep::bench
