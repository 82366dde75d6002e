// gpu::Backend on a Vulkan 1.1 device (Mesa's lavapipe here, any conformant driver elsewhere): the library's
// passes from the same descriptions as on GL, their shaders compiled from the same GLSL to SPIR-V at run
// time (shaderc), or taken precompiled from the engine (CreateInfo::shaderBinary), bindings as in
// docs/PORTABLE_SHADERS.md. On a device of its own (tools, tests) or on the engine's (CreateInfo::device).
// Rules and limits: docs/BACKENDS.md.
//
// Includes <vulkan/vulkan_core.h> for the handle types. An engine that loads Vulkan itself (volk and the
// like) defines VK_NO_PROTOTYPES before it, or includes its loader's header first; the backend itself calls
// every Vulkan function through the loader it is given.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <vulkan/vulkan_core.h>

#include <crep/core/error.h>
#include <crep/gpu/backend.h>

namespace crep::gpu {

/// A Vulkan call failed, or no device or queue could serve the backend, or the device lacks what the backend
/// needs (VulkanBackend::requirements()).
class VulkanError : public Error {
public:
  using Error::Error;
};

class VulkanBackend final : public Backend {
public:
  /// The engine's own Vulkan objects, for a backend that runs on them. The backend creates no instance and no
  /// device of its own and destroys none of these; it creates and destroys its own command pool, fence,
  /// samplers, query pool, descriptor pools, pipelines, images, buffers and their memory on `device`.
  /// The engine keeps every object here alive until the backend is destroyed.
  struct EngineDevice {
    VkInstance instance = VK_NULL_HANDLE;             ///< required
    VkPhysicalDevice physicalDevice = VK_NULL_HANDLE; ///< required: the one `device` was created on
    VkDevice device = VK_NULL_HANDLE;                 ///< required
    /// The family of `queue`; it must have VK_QUEUE_COMPUTE_BIT.
    std::uint32_t queueFamily = 0;
    /// Required: a queue of `queueFamily` the backend submits its own work on. Vulkan's external
    /// synchronization rule: while a call of the backend runs, no other thread may use this queue
    /// (vkQueueSubmit, vkQueueWaitIdle, vkQueuePresentKHR, ...) nor call vkDeviceWaitIdle. A call returns
    /// with its work either recorded (not yet submitted) or submitted and completed (a read, finish(),
    /// endTimer(), the destruction of a texture or buffer): the backend never leaves a submission running.
    VkQueue queue = VK_NULL_HANDLE;
    /// Required: the loader's entry point (libvulkan's, volk's vkGetInstanceProcAddr, ...). Every Vulkan
    /// function the backend calls is resolved through it, or through `getDeviceProcAddr`.
    PFN_vkGetInstanceProcAddr getInstanceProcAddr = nullptr;
    /// Optional: the device-level entry point; null: obtained from getInstanceProcAddr(instance, ...).
    PFN_vkGetDeviceProcAddr getDeviceProcAddr = nullptr;
    /// Optional: used by each vkCreateComputePipelines. One created with
    /// VK_PIPELINE_CACHE_CREATE_EXTERNALLY_SYNCHRONIZED_BIT must not be used by another thread meanwhile.
    VkPipelineCache pipelineCache = VK_NULL_HANDLE;
    /// Optional: the host allocator of every object the backend creates, allocates, destroys or frees.
    const VkAllocationCallbacks* allocator = nullptr;
    /// The apiVersion of the engine's VkApplicationInfo (VK_MAKE_API_VERSION); must be >= 1.1.
    std::uint32_t apiVersion = VK_API_VERSION_1_1;
    /// The device extensions enabled on `device` (VkDeviceCreateInfo::ppEnabledExtensionNames): the backend
    /// cannot query them of a device it did not create. VK_KHR_push_descriptor is used when listed.
    std::vector<std::string> enabledExtensions{};
    /// The features enabled on `device` (VkDeviceCreateInfo::pEnabledFeatures, or
    /// VkPhysicalDeviceFeatures2::features). The required ones (requirements()) must be VK_TRUE.
    VkPhysicalDeviceFeatures enabledFeatures{};
  };

  /// The SPIR-V of one program variant: `program` is the pass's path in crep::ShaderLibrary (e.g.
  /// "passes/epipolar/resample.comp"), `defines` its variant's defines in the order the pass gives them (as
  /// crep::programVariantsBuilt() and the "variants" of the installed resources.json list them; empty: the
  /// default variant). Called on the thread that calls the backend, once per distinct variant, when a pass
  /// prepares it (prepareProgram) or first dispatches it; the module is kept for the backend's lifetime.
  ///
  /// Returns the module's bytes, or nothing to have the backend compile that variant's GLSL itself. A
  /// module must be what the backend would have compiled (docs/PORTABLE_SHADERS.md, "Bindings" and "Push
  /// constants"; the installed share/crepuscular/shaders/spirv/ files are such modules):
  /// - SPIR-V 1.0 to 1.3 (Vulkan 1.1), in host byte order, with a compute entry point named "main" of the
  ///   pass's work-group size;
  /// - every resource in descriptor set 0, at binding gpu::Resource::binding plus its kind's base: a
  ///   sampled texture at + 0, one VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER (an OpTypeSampledImage
  ///   variable, not a separate image and sampler), a storage image at + 16, a uniform block at + 24, a
  ///   storage block at + 32, the blocks in the std140 / std430 layouts of the library's gpu::*Params;
  /// - the per-dispatch values (gpu::Dispatch::push) as one push-constant block, each member at the next
  ///   std430 offset of its type, in the order they are given (gpu::packPushConstants);
  /// - a storage image that is read declares its format (the backend does not enable
  ///   shaderStorageImageReadWithoutFormat); one written without a format needs
  ///   shaderStorageImageWriteWithoutFormat, which the backend requires.
  /// Checked: the size is a non-zero multiple of 4 bytes and the first word is the SPIR-V magic number
  /// 0x07230203, else InvalidArgument naming CreateInfo::shaderBinary and the program. The rest is the
  /// engine's: a module that breaks the rules is undefined behaviour (the validation layer reports most).
  /// An exception thrown by the provider leaves the call that needed the module.
  using ShaderBinaryProvider =
      std::function<std::vector<std::byte>(std::string_view program, std::span<const ShaderDefine> defines)>;

  struct CreateInfo {
    /// Self-created device only: turns on VK_LAYER_KHRONOS_validation (Debian package
    /// vulkan-validationlayers) and records each of its warnings and errors (validationMessages()). Default
    /// off: a cost for every call. With an engine device the engine's instance has its own layers and
    /// messenger: `validation` must be false there.
    bool validation = false;
    /// Self-created device only: a part of the physical device's name to pick it by; empty: the first with a
    /// compute queue. Must be empty with an engine device.
    std::string deviceName{};
    /// The engine's device to run on; empty (default): the backend creates its own instance, device and
    /// compute queue (and destroys them).
    std::optional<EngineDevice> device{};
    /// Use VK_KHR_push_descriptor where the device has it enabled (engine device) or supports it (own
    /// device). false, or without the extension: descriptor sets allocated from descriptor pools, which are
    /// recycled after the submission that used them has completed. Default true.
    bool pushDescriptors = true;
    /// Frames the engine records before it waits for the oldest of them (beginFrame()): the rings of
    /// per-frame data (descriptor sets, staging, retired objects) hold this many. In [1, 16], default 3.
    std::uint32_t framesInFlight = 3;
    /// Optional: the engine's precompiled SPIR-V for a program variant, e.g. shipped with the engine and
    /// loaded from disk, so that no shader is compiled at run time. Empty (default): every variant is
    /// compiled from the library's GLSL with shaderc, as ShaderBinaryProvider says for an empty result.
    ShaderBinaryProvider shaderBinary{};
  };

  /// One frame recorded into the engine's command buffer (docs/VULKAN_STATE.md).
  struct Frame {
    /// The engine's primary command buffer, recording, outside a render pass, of a family with compute.
    VkCommandBuffer commandBuffer = VK_NULL_HANDLE;
    /// The frame's number, > every earlier frame's (e.g. the engine's frame counter from 1).
    std::uint64_t index = 0;
    /// Every frame with an index <= `completed` has completed on the GPU (the engine's fence or timeline
    /// value); 0: none yet. In [index - framesInFlight, index - 1], and never less than before.
    std::uint64_t completed = 0;
  };

  /// What the backend needs of a device or uses when present, each with why.
  struct Requirement {
    enum class Kind {
      ApiVersion,      ///< `name` "1.1": of the physical device and of the instance
      QueueFamily,     ///< a capability of the queue's family
      DeviceExtension, ///< `name` an extension to enable on the device
      DeviceFeature,   ///< `name` a member of VkPhysicalDeviceFeatures to enable
      FormatFeature,   ///< `name` "VK_FORMAT_...: FEATURE": optimal-tiling format features of the device
    };
    Kind kind;
    std::string name;
    bool required; ///< false: used when present, with the fallback `why` names
    std::string why;
  };
  /// The list checked at creation: a missing required entry is a VulkanError naming it and, on an engine
  /// device, the CreateInfo field it was looked up in. Not listed because not needed:
  /// shaderStorageImageExtendedFormats (the shaders store to R32F, RG32F, RG32I, RGBA8, RGBA16F and RGBA32F,
  /// each a storage format every Vulkan device has) and shaderFloat64 (float-only shaders).
  static std::vector<Requirement> requirements();

  /// Creates its own instance, device and compute queue, or runs on `info.device`. VulkanError when there
  /// is no Vulkan driver, no matching device, (with validation) no validation layer, or when the device
  /// lacks a required entry of requirements(); InvalidArgument naming the CreateInfo field when an engine
  /// device is given without one of its required handles or loader, or with `validation` / `deviceName`.
  explicit VulkanBackend(const CreateInfo& info);
  VulkanBackend(); ///< default CreateInfo
  ~VulkanBackend() override;
  VulkanBackend(const VulkanBackend&) = delete;
  VulkanBackend& operator=(const VulkanBackend&) = delete;

  std::string_view name() const override { return "Vulkan"; }
  BackendKind kind() const override { return BackendKind::Vulkan; }
  int maxTextureSize() const override;
  int maxArrayLayers() const override;
  int max3DTextureSize() const override;
  ComputeLimits computeLimits() const override;
  TextureDesc describe(TextureId texture) const override;
  std::size_t bufferBytes(BufferId buffer) const override;
  void prepareProgram(const std::string& program, std::span<const ShaderDefine> defines) override;
  TextureId createTexture(const TextureDesc& desc) override;
  void destroyTexture(TextureId texture) override;
  BufferId createBuffer(std::size_t bytes, std::string_view label) override;
  void destroyBuffer(BufferId buffer) override;
  void writeBuffer(BufferId buffer, std::size_t offset, std::span<const std::byte> bytes) override;
  void writeTexture(TextureId texture, std::span<const float> texels) override;
  std::vector<std::byte> readBuffer(BufferId buffer, std::size_t offset, std::size_t bytes) override;
  std::vector<float> readTexture(TextureId texture) override;
  void dispatch(const Dispatch& dispatch) override;
  void finish() override;
  /// Timestamp queries on the compute queue (0 where its family has no timestamp bits), a ring of 1024
  /// spans: a deferred span not read before 1024 newer ones began reads 0.0. A deferred span's result comes
  /// once its frame has completed (Frame::completed, frameCompleted()) or, outside frames, once the
  /// backend's own submission that carried it has been waited for.
  void beginTimer() override;
  double endTimer() override;
  TimerId endTimerDeferred() override;
  std::optional<double> timerResult(TimerId id) override;
  void cancelTimer() noexcept override;

  /// An engine's image, used where it is (docs/VULKAN_STATE.md, "The engine's images").
  struct EngineImage {
    VkImage image = VK_NULL_HANDLE; ///< required; never destroyed by the backend
    /// Required: a view of the whole image, its depth aspect only for a depth format (sampled as depth).
    VkImageView view = VK_NULL_HANDLE;
    /// R32_SFLOAT, R32G32_SFLOAT, R32G32B32A32_SFLOAT, R16G16B16A16_SFLOAT, R8G8B8A8_UNORM, R32G32_SINT, or
    /// a depth format (D32_SFLOAT, D24_UNORM_S8_UINT, ...; read as gpu::Format::Depth32F).
    VkFormat format = VK_FORMAT_UNDEFINED;
    TextureType type = TextureType::Texture2D;
    std::uint32_t width = 0, height = 0; ///< texels, > 0
    std::uint32_t depth = 1;             ///< layers (2D array) or slices (3D), > 0
    /// Its usage flags: SAMPLED for what a pass reads, STORAGE for what it writes (checked per dispatch).
    VkImageUsageFlags usage = 0;
    /// The layout the image is in whenever the backend's calls or frames begin, and is left in when they
    /// end (e.g. SHADER_READ_ONLY_OPTIMAL, DEPTH_STENCIL_READ_ONLY_OPTIMAL, GENERAL).
    VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
    std::string label{};
  };
  /// An id for `image` that every pass takes like the backend's own textures (a camera depth, shadow maps,
  /// outputs, froxel volumes), with no copy. The engine keeps it alive while frames that use it are in
  /// flight; destroyTexture() forgets it. InvalidArgument naming the EngineImage field.
  TextureId importTexture(const EngineImage& image);
  /// The layout an engine image is in from now on (outside the library's use of it): a frame's own state,
  /// e.g. after the engine moved it between frames. InvalidArgument for another texture or one in use.
  void setTextureLayout(TextureId texture, VkImageLayout layout);

  /// Records every call until endFrame() into `frame.commandBuffer`: no submission and no wait by the
  /// library. Reads, finish() and endTimer() are refused there (InvalidArgument naming the call). Objects
  /// destroyed, staging and descriptor sets are released once `completed` of a later frame covers this one.
  /// Work recorded outside frames since the last one is submitted and waited for first (call finish()
  /// after setting up). InvalidArgument naming the Frame field for a null buffer, an index not after the
  /// last one, or a `completed` out of its range.
  void beginFrame(const Frame& frame);
  /// Records the exit barrier (docs/VULKAN_STATE.md); later calls go to the backend's own command buffer.
  void endFrame();
  /// Outside frames: every frame <= `completed` has completed (its retired objects are released now).
  void frameCompleted(std::uint64_t completed);
  bool inFrame() const;

  /// The objects the backend runs on (its own or CreateInfo::device's) and the loader it uses, e.g. for a
  /// tool that records frames (beginFrame) on the backend's own device. They stay the backend's on its own
  /// device: destroy none of them. enabledExtensions and enabledFeatures are left empty.
  EngineDevice runsOn() const;

  std::string deviceName() const; ///< the physical device's name
  /// Whether dispatches push their descriptors (VK_KHR_push_descriptor) rather than allocate sets from pools.
  bool usesPushDescriptors() const;
  /// The validation layer's warnings and errors so far (CreateInfo::validation), oldest first.
  std::vector<std::string> validationMessages() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace crep::gpu
