// A minimal Vulkan renderer, standing in for an engine: its own instance, device and queue, a mesh, a
// depth-only graphics pipeline for its depth pre-pass and its shadow maps, and a frame loop with N frames
// in flight and one submission per frame. It knows nothing of crepuscular: volumetrics.h is the part that
// does, recorded into this engine's frames. Built on libvulkan (Vulkan 1.1, render passes) and lavapipe
// here; nothing in it is lavapipe-specific.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <vulkan/vulkan.h>

namespace vkengine {

/// An indexed triangle list in world space.
struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;
};

/// A depth image of the engine (its camera depth or a shadow map): D32_SFLOAT, written by depth passes,
/// sampled and copied after them. Between frames and after each depth pass it is in
/// VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL (its "home" layout).
struct DepthImage {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE; ///< the depth aspect, all of it
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  std::uint32_t width = 0, height = 0;
  static constexpr VkFormat kFormat = VK_FORMAT_D32_SFLOAT;
  static constexpr VkImageUsageFlags kUsage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
                                              VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  static constexpr VkImageLayout kLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL;
};

/// A colour image a compute pass writes (e.g. the volumetrics' output): R32G32B32A32_SFLOAT, always in
/// VK_IMAGE_LAYOUT_GENERAL.
struct ColorImage {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  std::uint32_t width = 0, height = 0;
  static constexpr VkFormat kFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
  static constexpr VkImageUsageFlags kUsage =
      VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  static constexpr VkImageLayout kLayout = VK_IMAGE_LAYOUT_GENERAL;
};

/// One draw of the mesh in a depth pass: gl_Position = clipFromWorld * position (Vulkan's clip space, z in
/// [0, w]) into `viewport` (its depth range [0, 1]), fragments kept inside `scissor`.
struct DepthDraw {
  glm::dmat4 clipFromWorld{1.0};
  VkViewport viewport{};
  VkRect2D scissor{};
};

/// The raster state of a depth pass: the target cleared once to `clearDepth`, the depth test LESS (or
/// GREATER for reversed-Z) with writes on, depth clamp on or off, no culling.
struct DepthPassState {
  float clearDepth = 1.0f;
  bool greater = false;
  bool depthClamp = false;
};

/// Vulkan's clip space of an OpenGL-convention matrix: z from [-w, w] to [0, w], x and y unchanged. A depth
/// pass rasterized with zeroToOne(M) stores the depth-buffer values OpenGL would store with M.
glm::dmat4 zeroToOne(const glm::dmat4& glClipFromWorld);

class Engine {
public:
  struct Options {
    std::uint32_t framesInFlight = 3; ///< command buffers and fences recorded ahead, >= 1
    /// VK_LAYER_KHRONOS_validation with synchronization validation, its messages kept
    /// (validationMessages()). Needs the Debian package vulkan-validationlayers.
    bool validation = false;
  };

  /// Creates the instance, picks the first device with a graphics and compute queue, creates the device
  /// (depthClamp, shaderStorageImageWriteWithoutFormat and VK_KHR_push_descriptor where the device has
  /// them), uploads `mesh`. Throws std::runtime_error naming the failed call.
  Engine(const Mesh& mesh, const Options& options);
  ~Engine();
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  std::uint32_t queueFamily() const { return family_; }
  std::uint32_t apiVersion() const { return VK_API_VERSION_1_1; }
  const VkPhysicalDeviceFeatures& enabledFeatures() const { return features_; }
  const std::vector<std::string>& enabledExtensions() const { return extensions_; }
  std::string deviceName() const;

  /// Images owned by the engine (destroyed with it); the references stay valid.
  DepthImage& createDepthImage(std::uint32_t width, std::uint32_t height);
  ColorImage& createColorImage(std::uint32_t width, std::uint32_t height);

  /// One frame: its command buffer (recording), its number (from 1) and the newest frame known complete.
  struct Frame {
    VkCommandBuffer commandBuffer = VK_NULL_HANDLE;
    std::uint64_t index = 0;
    std::uint64_t completed = 0;
  };
  /// Waits for the frame that last used this frame's slot (the oldest in flight), then begins recording.
  Frame beginFrame();
  /// Records a depth pass of the mesh into `target`: cleared once (state.clearDepth), then the mesh drawn
  /// once per entry of `draws`, each with its own matrix (a push constant), viewport and scissor (dynamic
  /// state): a shadow map of several splits, or one cascade atlas.
  void drawDepthPass(const Frame& frame, const DepthImage& target, const DepthPassState& state,
                     std::span<const DepthDraw> draws);
  /// The common case: one draw over the whole target, cleared to 1, LESS, `clipFromWorld` in Vulkan's clip
  /// space (z in [0, w]); `depthClamp` for shadow maps (casters in front of the light's near plane still
  /// cast).
  void drawDepth(const Frame& frame, const DepthImage& target, const glm::dmat4& clipFromWorld,
                 bool depthClamp);
  /// Ends the frame's command buffer and submits it with the slot's fence: the frame's one submission.
  void submit(const Frame& frame);
  void waitIdle();

  /// The image's texels (row 0 first) after waitIdle(): a copy through a host-visible buffer, outside frames.
  std::vector<float> download(const DepthImage& image);
  std::vector<float> download(const ColorImage& image);

  /// The validation layer's warnings and errors so far (Options::validation).
  std::vector<std::string> validationMessages() const;

private:
  struct Slot {
    VkCommandBuffer commands = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
  };
  void createDevice(bool validation);
  void createPipelines();
  VkDeviceMemory allocate(const VkMemoryRequirements& requirements, VkMemoryPropertyFlags properties);
  VkBuffer createBuffer(VkDeviceSize bytes, VkBufferUsageFlags usage, VkDeviceMemory& memory);
  /// Records `record` into a one-time command buffer, submits it and waits: set-up and downloads only.
  template <class F>
  void immediate(F&& record);
  void initialLayout(VkImage image, VkImageAspectFlags aspect, VkImageLayout layout);
  std::vector<float> download(VkImage image, VkImageAspectFlags aspect, VkImageLayout layout,
                              std::uint32_t width, std::uint32_t height, std::uint32_t channels);

  Options options_;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t family_ = 0;
  VkPhysicalDeviceFeatures features_{};
  std::vector<std::string> extensions_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  std::vector<Slot> slots_;
  std::uint64_t frameIndex_ = 0;
  VkRenderPass renderPass_ = VK_NULL_HANDLE;
  VkPipelineLayout pipelineLayout_ = VK_NULL_HANDLE;
  VkPipeline pipelines_[2][2] = {}; ///< [depth clamp][GREATER]
  VkBuffer vertices_ = VK_NULL_HANDLE, indices_ = VK_NULL_HANDLE;
  VkDeviceMemory vertexMemory_ = VK_NULL_HANDLE, indexMemory_ = VK_NULL_HANDLE;
  std::uint32_t indexCount_ = 0;
  std::deque<DepthImage> depthImages_;
  std::deque<ColorImage> colorImages_;
  struct Messages;
  std::unique_ptr<Messages> messages_;
};

} // namespace vkengine
