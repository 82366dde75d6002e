// gpu::VulkanBackend on an engine's own VkDevice (CreateInfo::device): the test is the engine. It loads
// Vulkan itself (libvulkan.so.1's vkGetInstanceProcAddr by dlsym), creates its instance with the validation
// layer and its own debug messenger, and its device with or without VK_KHR_push_descriptor, and hands the
// backend a loader that counts what is asked of it (crep::test::LoaderSpy). Checked: the backend creates no
// instance or device and destroys none, resolves its functions through the given loader; the same frames
// (crep::Scattering from the same synthetic engine maps: prefiltered with froxels, min/max march, Yusov's
// epipolar sampling; the atmosphere's tables) equal the self-created backend's, with push descriptors and
// with descriptor sets from pools; a device without a required feature, a missing loader or handle is named;
// the engine's layer reports nothing, the destruction of its device included (objects left behind).
#include "common/atmosphere_tables.h"
#include "common/frame_extras.h"
#include "common/synthetic_engine_maps.h"
#include "common/vulkan_fixture.h"

#include <crep/atmosphere/gpu_tables.h>
#include <crep/core/error.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/pipeline/scattering.h>
#include <crep/scenes/engine_frame.h>
#include <crep/scenes/scene.h>
#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

using namespace crep;
using crep::test::EngineVulkanDevice;
using crep::test::LoaderSpy;

namespace {

constexpr int kWidth = 160, kHeight = 90, kSunMap = 512;

scenes::EngineMaps syntheticMaps(const scenes::Scene& s) {
  return crep::test::syntheticMaps(s, kWidth, kHeight, kSunMap);
}

/// A named image read back from a backend.
struct Output {
  std::string name;
  std::vector<float> texels;
};

/// The frames every backend of this file runs, in order: crep::Scattering on forest (projective: prefiltered
/// with a froxel volume, then the min/max march) and sunset (the sun in view: epipolar layout, epipole
/// block), Yusov's epipolar sampling on forest (RG32I storage images), and the atmosphere's small tables
/// (RG32F optical depth).
std::vector<Output> runFrames(gpu::Backend& b) {
  std::vector<Output> out;
  for (const std::string name : {"forest", "sunset"}) {
    const scenes::Scene scene = scenes::makeScene(name, static_cast<double>(kWidth) / kHeight);
    const scenes::EngineMaps maps = syntheticMaps(scene);
    const scenes::EngineFrame engine(b, scene, maps);
    struct Variant {
      const char* label;
      Scattering::Method method;
      Scattering::Sampling sampling;
      bool froxels;
    };
    for (const Variant variant :
         {Variant{"prefiltered, froxels", Scattering::Method::Prefiltered, Scattering::Sampling::PerPixel,
                  true},
          Variant{"min/max march", Scattering::Method::MinMaxMarch, Scattering::Sampling::PerPixel, false},
          Variant{"epipolar sampling", Scattering::Method::Prefiltered, Scattering::Sampling::Epipolar,
                  false}}) {
      if (name == "sunset" && variant.sampling == Scattering::Sampling::Epipolar) continue;
      gpu::Texture output(b,
                          {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, kWidth, kHeight, 1, "output"});
      Scattering::CreateInfo info;
      info.width = kWidth;
      info.height = kHeight;
      info.mapSize = 256;
      info.method = variant.method;
      info.sampling = variant.sampling;
      info.epipolarSampling.slices = 128;
      info.epipolarSampling.samples = 64;
      info.backend = &b;
      Scattering scattering(info);
      Scattering::FrameAttribs f = engine.attribs(output.id());
      const FroxelGrid grid{.width = 20, .height = 12, .depth = 16};
      crep::test::FroxelVolume volume;
      if (variant.froxels) {
        volume = crep::test::FroxelVolume(b, grid, gpu::Format::RGBA32F);
        f.froxels = &volume.target;
      }
      scattering.run(f);
      const std::string label = name + ", " + variant.label;
      out.push_back({label, b.readTexture(output.id())});
      if (variant.froxels) out.push_back({label + ": volume", b.readTexture(volume.texture.id())});
    }
  }
  AtmosphereTablesPass tables(crep::test::smallAtmosphereTables(1, &b));
  tables.compute();
  out.push_back({"atmosphere: optical depth (RG32F)", b.readTexture(tables.opticalDepthTexture())});
  out.push_back({"atmosphere: single scattering", b.readTexture(tables.singleTexture())});
  return out;
}

/// Relative RMSE of `a` against `b`; `differing` counts the values that are not bit for bit equal.
double relativeRmse(const std::vector<float>& a, const std::vector<float>& b, long long& differing) {
  REQUIRE(a.size() == b.size());
  double squared = 0.0, reference = 0.0;
  differing = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    differing += a[i] != b[i] || std::isnan(a[i]) != std::isnan(b[i]);
    const double d = static_cast<double>(a[i]) - b[i];
    squared += d * d;
    reference += static_cast<double>(b[i]) * b[i];
  }
  return reference > 0.0 ? std::sqrt(squared / reference) : std::sqrt(squared);
}

/// The backend's loader use on an engine device: no instance or device created or destroyed, not even
/// looked up; some functions resolved through the given loader.
void checkLoaderUse(bool deviceProcAddrGiven) {
  MESSAGE("functions looked up through the given loader: "
          << LoaderSpy::lookups() << " (" << LoaderSpy::instanceLookups.size()
          << " names through vkGetInstanceProcAddr, " << LoaderSpy::deviceLookups.size()
          << " through vkGetDeviceProcAddr)");
  CHECK(LoaderSpy::createInstanceCalls == 0);
  CHECK(LoaderSpy::createDeviceCalls == 0);
  CHECK(LoaderSpy::destroyDeviceCalls == 0);
  CHECK(LoaderSpy::destroyInstanceCalls == 0);
  for (const char* name : {"vkCreateInstance", "vkCreateDevice", "vkDestroyDevice", "vkDestroyInstance",
                           "vkDeviceWaitIdle", "vkQueueWaitIdle", "vkEnumeratePhysicalDevices"}) {
    CAPTURE(std::string(name));
    CHECK_FALSE(LoaderSpy::looked(name));
  }
  CHECK(LoaderSpy::instanceLookups.size() > 0);
  CHECK(LoaderSpy::deviceLookups.size() > 40); // every device function: through the device's own entry
  CHECK(LoaderSpy::looked("vkQueueSubmit"));
  // Without a vkGetDeviceProcAddr of the engine's, the backend took it from the given instance loader.
  CHECK(LoaderSpy::instanceLookups.count("vkGetDeviceProcAddr") == (deviceProcAddrGiven ? 0u : 1u));
}

} // namespace

TEST_CASE("Vulkan backend on an engine's device: no instance or device of its own, every function through "
          "the given loader, the engine's objects left alive") {
  for (const bool push : {true, false})
    for (const bool giveDeviceProcAddr : {true, false}) {
      CAPTURE(push);
      CAPTURE(giveDeviceProcAddr);
      // The engine's host allocator and pipeline cache with push descriptors, none without.
      EngineVulkanDevice engine({.pushDescriptor = push,
                                 .giveDeviceProcAddr = giveDeviceProcAddr,
                                 .giveAllocator = push,
                                 .givePipelineCache = push});
      for (int round = 0; round < 2;
           ++round) { // a second backend on the same device: the first left it alive
        gpu::VulkanBackend::CreateInfo info;
        info.device = engine.engineDevice();
        gpu::VulkanBackend vk(info);
        CHECK(vk.usesPushDescriptors() == push);
        CHECK_FALSE(vk.deviceName().empty());
        // MinMaxTreePass gives the CPU trees bit for bit, as on the backend's own device.
        const int W = 200, H = 5;
        Image depth(W, H, 1);
        for (int j = 0; j < H; ++j)
          for (int i = 0; i < W; ++i)
            depth.at(i, j) = static_cast<float>(((i * 7919 + j * 104729 + round) % 1009) / 1008.0);
        gpu::Texture map(vk, {gpu::TextureType::Texture2D, gpu::Format::R32F, W, H, 1, "rectified depth"});
        vk.writeTexture(map.id(), depth.data());
        MinMaxTreePass pass({.mapWidth = W, .mapHeight = H, .backend = &vk});
        pass.run(map.id());
        const MinMaxTrees cpu(depth);
        const std::vector<float> nodes = pass.readNodes();
        REQUIRE(nodes.size() == cpu.data().size());
        CHECK(std::equal(nodes.begin(), nodes.end(), cpu.data().begin()));
        checkLoaderUse(giveDeviceProcAddr);
      }
      if (push) { // every object the backend made went through the engine's allocator, and came back to it
        MESSAGE("the engine's allocation callbacks: " << engine.allocator().allocations << " allocations, "
                                                      << engine.allocator().frees << " frees");
        CHECK(engine.allocator().allocations > 0);
        CHECK(engine.allocator().liveCount() == 0);
      }
      // The backends are gone; the engine's device and instance are not (the layer would report their use
      // after destruction, and any object a backend left at vkDestroyDevice).
      engine.destroy();
      crep::test::checkNoValidationMessages(engine.messages());
    }
}

TEST_CASE("Vulkan backend on an engine's device, with and without push descriptors: the self-created "
          "backend's frames") {
  std::vector<Output> reference;
  {
    gpu::VulkanBackend self(crep::test::validatedVulkan());
    REQUIRE(self.usesPushDescriptors()); // lavapipe has VK_KHR_push_descriptor
    reference = runFrames(self);
    crep::test::checkNoValidationMessages(self);
  }
  REQUIRE(reference.size() == 9);
  for (const Output& o : reference) { // frames with light in them, not a trivial agreement on zeros
    CAPTURE(o.name);
    float largest = 0.0f;
    long long nonFinite = 0;
    for (const float v : o.texels) {
      nonFinite += !std::isfinite(v);
      largest = std::max(largest, std::abs(v));
    }
    CHECK(nonFinite == 0);
    CHECK(largest > 0.0f);
    if (o.name.find("froxels") != std::string::npos && o.name.find("volume") == std::string::npos) {
      int lit = 0; // pixels with in-scattering
      for (std::size_t i = 0; i < o.texels.size(); i += 4)
        lit += o.texels[i] > 0.0f;
      MESSAGE(o.name << ": " << lit << " of " << kWidth * kHeight << " pixels with in-scattering");
      // The synthetic casters shadow whole rays of the sunset frame: the exact reconstruction gives those
      // pixels exactly 0 (measured: forest all 14400 lit, sunset 4734), where the Fourier series' ringing
      // left none at 0.
      CHECK(lit > kWidth * kHeight / 5);
    }
  }
  const auto compare = [&](const std::string& backend, const std::vector<Output>& got) {
    REQUIRE(got.size() == reference.size());
    for (std::size_t k = 0; k < got.size(); ++k) {
      CAPTURE(backend);
      CAPTURE(got[k].name);
      long long differing = 0;
      const double e = relativeRmse(got[k].texels, reference[k].texels, differing);
      MESSAGE(backend << ", " << got[k].name << ": relative RMSE " << e
                      << " against the self-created backend, " << differing << " of " << got[k].texels.size()
                      << " values not bit for bit equal");
      CHECK(e <= 1e-6);
    }
  };
  for (const bool push : {true, false}) {
    // The engine enables what requirements() asks and nothing more: no shaderStorageImageExtendedFormats,
    // though the frames store to RG32F and RG32I images.
    EngineVulkanDevice engine({.pushDescriptor = push});
    {
      gpu::VulkanBackend::CreateInfo info;
      info.device = engine.engineDevice();
      gpu::VulkanBackend vk(info);
      CHECK(vk.usesPushDescriptors() == push);
      compare(push ? "engine device, push descriptors" : "engine device, descriptor sets from pools",
              runFrames(vk));
      checkLoaderUse(true);
    }
    engine.destroy();
    crep::test::checkNoValidationMessages(engine.messages());
  }
  // The backend's own device without push descriptors (CreateInfo::pushDescriptors false).
  gpu::VulkanBackend::CreateInfo info = crep::test::validatedVulkan();
  info.pushDescriptors = false;
  gpu::VulkanBackend sets(info);
  CHECK_FALSE(sets.usesPushDescriptors());
  compare("own device, descriptor sets from pools", runFrames(sets));
  crep::test::checkNoValidationMessages(sets);
}

TEST_CASE("Vulkan backend with descriptor sets from pools: more dispatches in one submission than a pool "
          "holds, and the pools reused after it") {
  gpu::VulkanBackend::CreateInfo info = crep::test::validatedVulkan();
  info.pushDescriptors = false;
  gpu::VulkanBackend vk(info);
  REQUIRE_FALSE(vk.usesPushDescriptors());
  const int W = 64, H = 3;
  Image depth(W, H, 1);
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i)
      depth.at(i, j) = static_cast<float>(((i * 7919 + j * 104729) % 1009) / 1008.0);
  const MinMaxTrees cpu(depth);
  gpu::Texture map(vk, {gpu::TextureType::Texture2D, gpu::Format::R32F, W, H, 1, "rectified depth"});
  vk.writeTexture(map.id(), depth.data());
  MinMaxTreePass pass({.mapWidth = W, .mapHeight = H, .backend = &vk});
  for (int submission = 0; submission < 2; ++submission) {
    CAPTURE(submission);
    for (int k = 0; k < 300; ++k) // each run one dispatch or more, each a set: 300 sets > 4 pools of 64
      pass.run(map.id());
    const std::vector<float> nodes = pass.readNodes(); // the submission; the pools are reset after it
    REQUIRE(nodes.size() == cpu.data().size());
    CHECK(std::equal(nodes.begin(), nodes.end(), cpu.data().begin()));
  }
  crep::test::checkNoValidationMessages(vk);
}

TEST_CASE("Vulkan backend on an engine's device: a missing feature, loader or handle is named") {
  {
    // The engine did not enable shaderStorageImageWriteWithoutFormat, and says so.
    EngineVulkanDevice engine({.storageImageWriteWithoutFormat = false});
    gpu::VulkanBackend::CreateInfo info;
    info.device = engine.engineDevice();
    CHECK_THROWS_WITH_AS(gpu::VulkanBackend{info},
                         doctest::Contains("crep: VulkanBackend::CreateInfo.device.enabledFeatures: "
                                           "shaderStorageImageWriteWithoutFormat is not enabled (the froxel"),
                         gpu::VulkanError);
    CHECK(LoaderSpy::createDeviceCalls == 0);
    engine.destroy();
    crep::test::checkNoValidationMessages(engine.messages());
  }
  EngineVulkanDevice engine({});
  const auto rejects = [&](const std::function<void(gpu::VulkanBackend::CreateInfo&)>& spoil,
                           const char* field) {
    CAPTURE(std::string(field));
    gpu::VulkanBackend::CreateInfo info;
    info.device = engine.engineDevice();
    spoil(info);
    CHECK_THROWS_WITH_AS(gpu::VulkanBackend{info}, doctest::Contains(field), InvalidArgument);
  };
  rejects([](auto& i) { i.device->getInstanceProcAddr = nullptr; },
          "VulkanBackend::CreateInfo.device.getInstanceProcAddr");
  rejects([](auto& i) { i.device->device = VK_NULL_HANDLE; }, "VulkanBackend::CreateInfo.device.device");
  rejects([](auto& i) { i.device->instance = VK_NULL_HANDLE; }, "VulkanBackend::CreateInfo.device.instance");
  rejects([](auto& i) { i.device->physicalDevice = VK_NULL_HANDLE; },
          "VulkanBackend::CreateInfo.device.physicalDevice");
  rejects([](auto& i) { i.device->queue = VK_NULL_HANDLE; }, "VulkanBackend::CreateInfo.device.queue");
  rejects([](auto& i) { i.device->apiVersion = VK_API_VERSION_1_0; },
          "VulkanBackend::CreateInfo.device.apiVersion");
  rejects([](auto& i) { i.validation = true; }, "VulkanBackend::CreateInfo.validation");
  rejects([](auto& i) { i.deviceName = "llvmpipe"; }, "VulkanBackend::CreateInfo.deviceName");
  {
    gpu::VulkanBackend::CreateInfo info;
    info.device = engine.engineDevice();
    info.device->queueFamily = 99;
    CHECK_THROWS_WITH_AS(gpu::VulkanBackend{info},
                         doctest::Contains("VulkanBackend::CreateInfo.device.queueFamily"), gpu::VulkanError);
  }
  engine.destroy();
  crep::test::checkNoValidationMessages(engine.messages());
}

TEST_CASE("Vulkan backend: requirements() lists what it needs and uses, each with why") {
  const std::vector<gpu::VulkanBackend::Requirement> r = gpu::VulkanBackend::requirements();
  using K = gpu::VulkanBackend::Requirement::Kind;
  const auto find = [&](K kind, const std::string& name) -> const gpu::VulkanBackend::Requirement* {
    for (const auto& q : r)
      if (q.kind == kind && q.name.rfind(name, 0) == 0) return &q;
    return nullptr;
  };
  for (const auto& q : r) {
    CAPTURE(q.name);
    CHECK_FALSE(q.why.empty());
  }
  REQUIRE(find(K::ApiVersion, "1.1") != nullptr);
  CHECK(find(K::ApiVersion, "1.1")->required);
  REQUIRE(find(K::DeviceFeature, "shaderStorageImageWriteWithoutFormat") != nullptr);
  CHECK(find(K::DeviceFeature, "shaderStorageImageWriteWithoutFormat")->required);
  CHECK(find(K::DeviceFeature, "shaderStorageImageExtendedFormats") == nullptr); // not needed: see the header
  REQUIRE(find(K::DeviceExtension, "VK_KHR_push_descriptor") != nullptr);
  CHECK_FALSE(find(K::DeviceExtension, "VK_KHR_push_descriptor")->required);
  REQUIRE(find(K::QueueFamily, "VK_QUEUE_COMPUTE_BIT") != nullptr);
  REQUIRE(find(K::QueueFamily, "timestampValidBits") != nullptr);
  CHECK_FALSE(find(K::QueueFamily, "timestampValidBits")->required);
  CHECK(find(K::FormatFeature, "VK_FORMAT_R32G32B32A32_SFLOAT") != nullptr);
  CHECK(find(K::FormatFeature, "VK_FORMAT_D32_SFLOAT") != nullptr);
}
