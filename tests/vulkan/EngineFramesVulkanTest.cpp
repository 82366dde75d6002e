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
#include <crep/pipeline/scattering.h>
#include <crep/scenes/engine_frame.h>
#include <crep/scenes/scene.h>
#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <array>
#include <cmath>
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

Scattering::CreateInfo frameInfo(gpu::Backend& b, Scattering::Method method) {
  Scattering::CreateInfo info;
  info.width = kWidth;
  info.height = kHeight;
  info.mapSize = 256;
  info.method = method;
  info.stageTimings = false; // blocking timers wait; this frame must not
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
        for (int i = 0; i < kFrames; ++i) {
          const std::uint64_t index = static_cast<std::uint64_t>(i) + 1;
          const std::uint64_t completed = frames.acquire(index);
          vk.beginFrame({frames.commands[index % kInFlight], index, completed});
          Scattering::FrameAttribs f = engine.attribs(outputs[static_cast<std::size_t>(i)].id());
          f.camera = &cameras[static_cast<std::size_t>(i)];
          scattering.run(f);
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
        MESSAGE("library submissions and waits over " << kFrames << " frames: " << stalls);
        CHECK(stalls == 0);
        frames.waitIdle();
        vk.frameCompleted(kFrames);
        for (int i = 0; i < kFrames; ++i) {
          CAPTURE(i);
          const std::vector<float> got = vk.readTexture(outputs[static_cast<std::size_t>(i)].id());
          const std::vector<float>& want = expected[static_cast<std::size_t>(i)];
          REQUIRE(got.size() == want.size());
          std::size_t differing = 0;
          double signal = 0.0;
          for (std::size_t k = 0; k < got.size(); ++k) {
            if (got[k] != want[k]) ++differing;
            signal += std::abs(want[k]);
          }
          CHECK(signal > 0.0);
          CHECK(differing == 0);
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
