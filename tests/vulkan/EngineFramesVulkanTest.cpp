// crep::Scattering recorded into the engine's own command buffers (gpu::VulkanBackend::beginFrame /
// endFrame), as a Vulkan engine runs it: the test is the engine, with its own instance (validation layer with
// synchronization validation), device, command buffers and fences, three frames in flight and a moving
// camera over ten frames, one submission per frame by the engine. Checked: while frames are recorded the
// backend makes no vkQueueSubmit and no host wait (counted through the loader it was given); each frame's
// output equals the same frame run on a self-submitting backend bit for bit; objects destroyed while frames
// are in flight outlive them; reads and finish() inside a frame are refused; the layer reports nothing.
#include "common/synthetic_engine_maps.h"
#include "common/vulkan_fixture.h"

#include <crep/core/error.h>
#include <crep/core/image.h>
#include <crep/pipeline/scattering.h>
#include <crep/scenes/engine_frame.h>
#include <crep/scenes/scene.h>
#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

using namespace crep;
using crep::test::EngineVulkanDevice;
using crep::test::LoaderSpy;

namespace {

constexpr int kWidth = 160, kHeight = 90, kFrames = 10;
constexpr std::uint32_t kInFlight = 3;

/// Frame i's camera: the scene's, strafed sideways by 0.05 units a frame.
Camera movedCamera(const Camera& c, int i) {
  const glm::dvec3 right = c.orientation() * glm::dvec3(1.0, 0.0, 0.0);
  return Camera(c.position() + 0.05 * i * right, c.orientation(), c.fovY(), c.aspect(), c.near(), c.far());
}

/// How many values of `got` are not bit for bit `want`'s (the sizes must agree).
std::size_t differingValues(const std::vector<float>& got, const std::vector<float>& want) {
  REQUIRE(got.size() == want.size());
  std::size_t differing = 0;
  for (std::size_t k = 0; k < got.size(); ++k)
    differing += got[k] != want[k] ? 1u : 0u;
  return differing;
}

/// The front door's defaults but the size: stage timings on, never waiting (deferred spans).
Scattering::CreateInfo frameInfo(gpu::Backend& b, Scattering::Method method) {
  Scattering::CreateInfo info;
  info.width = kWidth;
  info.height = kHeight;
  info.mapSize = 256;
  info.method = method;
  info.backend = &b;
  return info;
}

/// The engine's side: a command pool, one command buffer and fence per frame in flight.
struct EngineFrames {
  const EngineVulkanDevice& engine;
  VkCommandPool pool = VK_NULL_HANDLE;
  std::array<VkCommandBuffer, kInFlight> commands{};
  std::array<VkFence, kInFlight> fences{};
  std::array<std::uint64_t, kInFlight> frameOf{}; ///< the frame last submitted with each fence

  explicit EngineFrames(const EngineVulkanDevice& e) : engine(e) {
    VkCommandPoolCreateInfo pci{};
    pci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = e.queueFamily();
    REQUIRE(e.deviceFunction<PFN_vkCreateCommandPool>("vkCreateCommandPool")(e.device(), &pci, nullptr,
                                                                             &pool) == VK_SUCCESS);
    VkCommandBufferAllocateInfo ai{};
    ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    ai.commandPool = pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = kInFlight;
    REQUIRE(e.deviceFunction<PFN_vkAllocateCommandBuffers>("vkAllocateCommandBuffers")(
                e.device(), &ai, commands.data()) == VK_SUCCESS);
    VkFenceCreateInfo fi{};
    fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    fi.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    for (VkFence& f : fences)
      REQUIRE(e.deviceFunction<PFN_vkCreateFence>("vkCreateFence")(e.device(), &fi, nullptr, &f) ==
              VK_SUCCESS);
  }
  ~EngineFrames() {
    waitIdle();
    for (VkFence f : fences)
      engine.deviceFunction<PFN_vkDestroyFence>("vkDestroyFence")(engine.device(), f, nullptr);
    engine.deviceFunction<PFN_vkDestroyCommandPool>("vkDestroyCommandPool")(engine.device(), pool, nullptr);
  }
  void waitIdle() const { engine.deviceFunction<PFN_vkDeviceWaitIdle>("vkDeviceWaitIdle")(engine.device()); }

  /// Waits for the frame that last used frame `index`'s slot; returns the newest frame known complete.
  std::uint64_t acquire(std::uint64_t index) {
    const std::size_t slot = index % kInFlight;
    const VkDevice d = engine.device();
    REQUIRE(engine.deviceFunction<PFN_vkWaitForFences>("vkWaitForFences")(d, 1, &fences[slot], VK_TRUE,
                                                                          UINT64_MAX) == VK_SUCCESS);
    REQUIRE(engine.deviceFunction<PFN_vkResetFences>("vkResetFences")(d, 1, &fences[slot]) == VK_SUCCESS);
    VkCommandBufferBeginInfo bi{};
    bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    REQUIRE(engine.deviceFunction<PFN_vkBeginCommandBuffer>("vkBeginCommandBuffer")(commands[slot], &bi) ==
            VK_SUCCESS);
    return index > kInFlight ? index - kInFlight : 0; // the fence of frame index - kInFlight was waited for
  }
  void submit(std::uint64_t index) {
    const std::size_t slot = index % kInFlight;
    REQUIRE(engine.deviceFunction<PFN_vkEndCommandBuffer>("vkEndCommandBuffer")(commands[slot]) ==
            VK_SUCCESS);
    VkSubmitInfo si{};
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &commands[slot];
    REQUIRE(engine.deviceFunction<PFN_vkQueueSubmit>("vkQueueSubmit")(engine.queue(), 1, &si, fences[slot]) ==
            VK_SUCCESS);
    frameOf[slot] = index;
  }
};

} // namespace

TEST_CASE("Vulkan backend on an engine's device: ten frames of a moving camera recorded into the engine's "
          "command buffers, three in flight, with no submission or wait by the library") {
  struct Case {
    Scattering::Method method;
    const char* name;
    bool pushDescriptor; ///< else descriptor sets from the frame slots' pools
  };
  for (const Case c : {Case{Scattering::Method::Prefiltered, "forest", true},
                       Case{Scattering::Method::Prefiltered, "sunset", true},
                       Case{Scattering::Method::MinMaxMarch, "forest", true},
                       Case{Scattering::Method::MinMaxMarch, "sunset", true},
                       Case{Scattering::Method::Prefiltered, "forest", false}}) {
    const Scattering::Method method = c.method;
    const std::string name = c.name;
    CAPTURE(method == Scattering::Method::Prefiltered ? "prefiltered" : "min/max march");
    CAPTURE(name);
    CAPTURE(c.pushDescriptor);
    {
      const scenes::Scene scene = scenes::makeScene(name, static_cast<double>(kWidth) / kHeight);
      const scenes::EngineMaps maps = crep::test::syntheticMaps(scene, kWidth, kHeight, 512);
      std::vector<Camera> cameras;
      for (int i = 0; i < kFrames; ++i)
        cameras.push_back(movedCamera(scene.camera, i));

      // The reference: the same frames on a self-submitting backend, one after the other.
      std::vector<std::vector<float>> expected;
      {
        gpu::VulkanBackend ref(crep::test::validatedVulkan());
        const scenes::EngineFrame engine(ref, scene, maps);
        Scattering scattering(frameInfo(ref, method));
        gpu::Texture output(ref,
                            {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, kWidth, kHeight, 1, "out"});
        for (int i = 0; i < kFrames; ++i) {
          Scattering::FrameAttribs f = engine.attribs(output.id());
          f.camera = &cameras[static_cast<std::size_t>(i)];
          scattering.run(f);
          expected.push_back(ref.readTexture(output.id()));
        }
        crep::test::checkNoValidationMessages(ref);
      }

      EngineVulkanDevice device({.pushDescriptor = c.pushDescriptor, .synchronizationValidation = true});
      {
        gpu::VulkanBackend vk({.device = device.engineDevice(), .framesInFlight = kInFlight});
        CHECK(vk.usesPushDescriptors() == c.pushDescriptor);
        const scenes::EngineFrame engine(vk, scene, maps);
        Scattering scattering(frameInfo(vk, method));
        std::vector<gpu::Texture> outputs;
        for (int i = 0; i < kFrames; ++i)
          outputs.emplace_back(vk, gpu::TextureDesc{gpu::TextureType::Texture2D, gpu::Format::RGBA32F, kWidth,
                                                    kHeight, 1, "out " + std::to_string(i)});
        vk.finish(); // the set-up (uploads, creations) submitted before the first frame
        EngineFrames frames(device);
        const int stallsBefore = LoaderSpy::stalls();
        int timedFrames = 0;
        for (int i = 0; i < kFrames; ++i) {
          const std::uint64_t index = static_cast<std::uint64_t>(i) + 1;
          const std::uint64_t completed = frames.acquire(index);
          vk.beginFrame({frames.commands[index % kInFlight], index, completed});
          Scattering::FrameAttribs f = engine.attribs(outputs[static_cast<std::size_t>(i)].id());
          f.camera = &cameras[static_cast<std::size_t>(i)];
          const Scattering::FrameResult result = scattering.run(f);
          // The GPU times of an earlier, completed frame arrive with a later one (timestamps, never waited).
          if (result.gpuTimes) {
            ++timedFrames;
            CHECK(result.gpuTimes->frame < result.frame);
            CHECK(result.gpuTimes->frame + 1 <= completed); // FrameResult::frame counts from 0
            CHECK(result.gpuTimes->stages.size() > 2);
            CHECK(std::isfinite(result.gpuTimes->totalMilliseconds()));
            CHECK(result.gpuTimes->totalMilliseconds() > 0.0);
          }
          if (i == 4) {
            // Inside a frame nothing waits: reads and finish() are refused, naming the call.
            CHECK_THROWS_WITH_AS(vk.finish(), doctest::Contains("finish"), InvalidArgument);
            CHECK_THROWS_WITH_AS(vk.readTexture(outputs[0].id()), doctest::Contains("readTexture"),
                                 InvalidArgument);
            // A texture destroyed mid-frame outlives the frames that may use it.
            gpu::Texture scratch(vk, {gpu::TextureType::Texture2D, gpu::Format::R32F, 8, 8, 1, "scratch"});
          }
          vk.endFrame();
          frames.submit(index);
        }
        const int stalls = LoaderSpy::stalls() - stallsBefore;
        MESSAGE("library submissions and waits over " << kFrames << " frames: " << stalls << "; frames whose "
                                                      << "GPU times arrived: " << timedFrames);
        CHECK(stalls == 0);
        CHECK(timedFrames >= kFrames - static_cast<int>(kInFlight) - 1);
        frames.waitIdle();
        vk.frameCompleted(kFrames);
        for (int i = 0; i < kFrames; ++i) {
          CAPTURE(i);
          const std::vector<float>& want = expected[static_cast<std::size_t>(i)];
          double signal = 0.0;
          for (float v : want)
            signal += std::abs(v);
          CHECK(signal > 0.0);
          CHECK(differingValues(vk.readTexture(outputs[static_cast<std::size_t>(i)].id()), want) == 0);
        }
        // The frame index must grow, and the engine must have waited for the oldest frame in flight.
        EngineFrames more(device);
        more.acquire(kFrames + 1);
        CHECK_THROWS_WITH_AS(vk.beginFrame({more.commands[0], kFrames, kFrames - 1}),
                             doctest::Contains("frame.index"), InvalidArgument);
        CHECK_THROWS_WITH_AS(vk.beginFrame({more.commands[0], kFrames + 5, kFrames}),
                             doctest::Contains("frame.completed"), InvalidArgument);
        more.submit(kFrames + 1); // an empty submission, so that the engine's fence is signalled again
      }
      device.destroy();
      crep::test::checkNoValidationMessages(device.messages());
    }
  }
}

namespace {

/// The engine's own images: created, filled and read back with its own commands (one-shot submissions of
/// its own, outside the frames), never through the backend.
struct EngineImages {
  const EngineVulkanDevice& engine;
  struct Owned {
    VkImage image = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
  };
  std::vector<Owned> owned;

  template <class F>
  F fn(const char* name) const {
    return engine.deviceFunction<F>(name);
  }
  std::uint32_t memoryType(std::uint32_t bits, VkMemoryPropertyFlags want) const {
    VkPhysicalDeviceMemoryProperties props;
    engine.instanceFunction<PFN_vkGetPhysicalDeviceMemoryProperties>("vkGetPhysicalDeviceMemoryProperties")(
        engine.physicalDevice(), &props);
    for (std::uint32_t i = 0; i < props.memoryTypeCount; ++i)
      if ((bits & (1u << i)) != 0 && (props.memoryTypes[i].propertyFlags & want) == want) return i;
    FAIL("no memory type");
    return 0;
  }
  /// A host-visible buffer of `bytes`, mapped.
  std::pair<VkBuffer, VkDeviceMemory> hostBuffer(std::size_t bytes, void** mapped) const {
    VkBufferCreateInfo bi{};
    bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bi.size = bytes;
    bi.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VkBuffer buffer = VK_NULL_HANDLE;
    REQUIRE(fn<PFN_vkCreateBuffer>("vkCreateBuffer")(engine.device(), &bi, nullptr, &buffer) == VK_SUCCESS);
    VkMemoryRequirements req;
    fn<PFN_vkGetBufferMemoryRequirements>("vkGetBufferMemoryRequirements")(engine.device(), buffer, &req);
    VkMemoryAllocateInfo ai{};
    ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = memoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                                            VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    VkDeviceMemory memory = VK_NULL_HANDLE;
    REQUIRE(fn<PFN_vkAllocateMemory>("vkAllocateMemory")(engine.device(), &ai, nullptr, &memory) ==
            VK_SUCCESS);
    REQUIRE(fn<PFN_vkBindBufferMemory>("vkBindBufferMemory")(engine.device(), buffer, memory, 0) ==
            VK_SUCCESS);
    REQUIRE(fn<PFN_vkMapMemory>("vkMapMemory")(engine.device(), memory, 0, VK_WHOLE_SIZE, 0, mapped) ==
            VK_SUCCESS);
    return {buffer, memory};
  }
  void freeBuffer(std::pair<VkBuffer, VkDeviceMemory> b) const {
    fn<PFN_vkDestroyBuffer>("vkDestroyBuffer")(engine.device(), b.first, nullptr);
    fn<PFN_vkFreeMemory>("vkFreeMemory")(engine.device(), b.second, nullptr);
  }
  void layoutBarrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkImageLayout from,
                     VkImageLayout to) const {
    VkImageMemoryBarrier b{};
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    b.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {aspect, 0, 1, 0, 1};
    fn<PFN_vkCmdPipelineBarrier>("vkCmdPipelineBarrier")(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                                                         VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0,
                                                         nullptr, 1, &b);
  }
  /// Runs `record` in a command buffer of the engine's, submitted and waited for by the engine.
  template <class Record>
  void oneShot(const Record& record) const {
    EngineFrames once(engine);
    once.acquire(1);
    record(once.commands[1]);
    once.submit(1);
    once.waitIdle();
  }
  /// A 2D image of the engine, filled with `texels` (4-byte values) and left in `layout`.
  gpu::VulkanBackend::EngineImage create(VkFormat format, int width, int height, VkImageUsageFlags usage,
                                         VkImageLayout layout, const std::vector<float>& texels) {
    const bool depth = format == VK_FORMAT_D32_SFLOAT;
    const VkImageAspectFlags aspect = depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    Owned o;
    VkImageCreateInfo ci{};
    ci.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = format;
    ci.extent = {static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height), 1};
    ci.mipLevels = ci.arrayLayers = 1;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.tiling = VK_IMAGE_TILING_OPTIMAL;
    ci.usage = usage | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    REQUIRE(fn<PFN_vkCreateImage>("vkCreateImage")(engine.device(), &ci, nullptr, &o.image) == VK_SUCCESS);
    VkMemoryRequirements req;
    fn<PFN_vkGetImageMemoryRequirements>("vkGetImageMemoryRequirements")(engine.device(), o.image, &req);
    VkMemoryAllocateInfo ai{};
    ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = memoryType(req.memoryTypeBits, 0);
    REQUIRE(fn<PFN_vkAllocateMemory>("vkAllocateMemory")(engine.device(), &ai, nullptr, &o.memory) ==
            VK_SUCCESS);
    REQUIRE(fn<PFN_vkBindImageMemory>("vkBindImageMemory")(engine.device(), o.image, o.memory, 0) ==
            VK_SUCCESS);
    VkImageViewCreateInfo vi{};
    vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    vi.image = o.image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = format;
    vi.subresourceRange = {aspect, 0, 1, 0, 1};
    REQUIRE(fn<PFN_vkCreateImageView>("vkCreateImageView")(engine.device(), &vi, nullptr, &o.view) ==
            VK_SUCCESS);
    void* mapped = nullptr;
    const auto staging = hostBuffer(std::max<std::size_t>(texels.size() * 4, 4), &mapped);
    std::memcpy(mapped, texels.data(), texels.size() * 4);
    oneShot([&](VkCommandBuffer cmd) {
      layoutBarrier(cmd, o.image, aspect, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
      if (!texels.empty()) {
        VkBufferImageCopy region{};
        region.imageSubresource = {aspect, 0, 0, 1};
        region.imageExtent = ci.extent;
        fn<PFN_vkCmdCopyBufferToImage>("vkCmdCopyBufferToImage")(
            cmd, staging.first, o.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
      }
      layoutBarrier(cmd, o.image, aspect, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, layout);
    });
    freeBuffer(staging);
    owned.push_back(o);
    gpu::VulkanBackend::EngineImage e;
    e.image = o.image;
    e.view = o.view;
    e.format = format;
    e.width = static_cast<std::uint32_t>(width);
    e.height = static_cast<std::uint32_t>(height);
    e.usage = ci.usage;
    e.layout = layout;
    return e;
  }
  /// An RGBA32F image of the engine's read back with the engine's own copy, from and back to `layout`.
  std::vector<float> read(const gpu::VulkanBackend::EngineImage& e, VkImageLayout layout) const {
    void* mapped = nullptr;
    const std::size_t count = static_cast<std::size_t>(e.width) * e.height * 4;
    const auto staging = hostBuffer(count * 4, &mapped);
    oneShot([&](VkCommandBuffer cmd) {
      layoutBarrier(cmd, e.image, VK_IMAGE_ASPECT_COLOR_BIT, layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
      VkBufferImageCopy region{};
      region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      region.imageExtent = {e.width, e.height, 1};
      fn<PFN_vkCmdCopyImageToBuffer>("vkCmdCopyImageToBuffer")(
          cmd, e.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.first, 1, &region);
      layoutBarrier(cmd, e.image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layout);
    });
    std::vector<float> out(count);
    std::memcpy(out.data(), mapped, count * 4);
    freeBuffer(staging);
    return out;
  }
  ~EngineImages() {
    for (const Owned& o : owned) {
      fn<PFN_vkDestroyImageView>("vkDestroyImageView")(engine.device(), o.view, nullptr);
      fn<PFN_vkDestroyImage>("vkDestroyImage")(engine.device(), o.image, nullptr);
      fn<PFN_vkFreeMemory>("vkFreeMemory")(engine.device(), o.memory, nullptr);
    }
  }
};

std::vector<float> texelsOf(const Image& image) {
  return std::vector<float>(image.data().begin(), image.data().end());
}

} // namespace

TEST_CASE("Vulkan backend on an engine's device: the engine's own images in place (its camera depth and "
          "shadow map in a read-only depth layout, its output in SHADER_READ_ONLY_OPTIMAL), no host copy") {
  const scenes::Scene scene = scenes::makeScene("forest", static_cast<double>(kWidth) / kHeight);
  const scenes::EngineMaps maps = crep::test::syntheticMaps(scene, kWidth, kHeight, 512);
  constexpr int kImageFrames = 3;
  std::vector<Camera> cameras;
  for (int i = 0; i < kImageFrames; ++i)
    cameras.push_back(movedCamera(scene.camera, i));
  std::vector<std::vector<float>> expected;
  {
    gpu::VulkanBackend ref(crep::test::validatedVulkan());
    const scenes::EngineFrame engine(ref, scene, maps);
    Scattering scattering(frameInfo(ref, Scattering::Method::Prefiltered));
    gpu::Texture output(ref, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, kWidth, kHeight, 1, "out"});
    for (int i = 0; i < kImageFrames; ++i) {
      Scattering::FrameAttribs f = engine.attribs(output.id());
      f.camera = &cameras[static_cast<std::size_t>(i)];
      scattering.run(f);
      expected.push_back(ref.readTexture(output.id()));
    }
  }

  EngineVulkanDevice device({.synchronizationValidation = true});
  {
    EngineImages images{device, {}};
    const VkImageLayout depthLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL;
    const VkImageLayout outLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    // Depth buffers as engines have them: attachments of their passes, sampled afterwards.
    const VkImageUsageFlags depthUsage =
        VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
    const auto depthImage = images.create(VK_FORMAT_D32_SFLOAT, kWidth, kHeight, depthUsage, depthLayout,
                                          texelsOf(maps.cameraDepth));
    const auto sunImage = images.create(VK_FORMAT_D32_SFLOAT, maps.sunMap.width(), maps.sunMap.height(),
                                        depthUsage, depthLayout, texelsOf(maps.sunMap));
    const auto outImage =
        images.create(VK_FORMAT_R32G32B32A32_SFLOAT, kWidth, kHeight,
                      VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT, outLayout, {});
    gpu::VulkanBackend vk({.device = device.engineDevice(), .framesInFlight = kInFlight});
    const gpu::TextureId depth = vk.importTexture(depthImage);
    const gpu::TextureId sun = vk.importTexture(sunImage);
    const gpu::TextureId out = vk.importTexture(outImage);
    CHECK(vk.describe(depth).format == gpu::Format::Depth32F);
    CHECK(vk.describe(out).width == kWidth);
    Scattering scattering(frameInfo(vk, Scattering::Method::Prefiltered));
    vk.finish();
    const scenes::EngineFrame reference(vk, scene, maps); // for its attribs: the sun map's matrix and bias
    vk.finish();
    const int stallsBefore = LoaderSpy::stalls();
    for (int i = 0; i < kImageFrames; ++i) {
      CAPTURE(i);
      EngineFrames frames(device);
      const std::uint64_t index = static_cast<std::uint64_t>(i) + 1;
      frames.acquire(index);
      vk.beginFrame({frames.commands[index % kInFlight], index, index - 1});
      Scattering::FrameAttribs f = reference.attribs(out);
      f.cameraDepth = depth;
      Scattering::ShadowMap sunMap = *f.shadowMap;
      sunMap.texture = sun;
      f.shadowMap = &sunMap;
      f.camera = &cameras[static_cast<std::size_t>(i)];
      scattering.run(f);
      vk.endFrame();
      frames.submit(index);
      frames.waitIdle();
      // The engine reads its output with its own copy, from the layout the library left it in.
      CHECK(differingValues(images.read(outImage, outLayout), expected[static_cast<std::size_t>(i)]) == 0);
    }
    CHECK(LoaderSpy::stalls() - stallsBefore == 0);
    vk.frameCompleted(kImageFrames);
    // Bad imports are named.
    gpu::VulkanBackend::EngineImage bad = outImage;
    bad.format = VK_FORMAT_R8_UNORM;
    CHECK_THROWS_WITH_AS(vk.importTexture(bad), doctest::Contains("image.format"), InvalidArgument);
    bad = outImage;
    bad.layout = VK_IMAGE_LAYOUT_UNDEFINED;
    CHECK_THROWS_WITH_AS(vk.importTexture(bad), doctest::Contains("image.layout"), InvalidArgument);
    bad = outImage;
    bad.view = VK_NULL_HANDLE;
    CHECK_THROWS_WITH_AS(vk.importTexture(bad), doctest::Contains("image.view"), InvalidArgument);
    vk.destroyTexture(depth);
    CHECK_THROWS_AS(vk.describe(depth), InvalidArgument);
  }
  device.destroy();
  crep::test::checkNoValidationMessages(device.messages());
}
