// gpu::Backend on Vulkan 1.1 (crep/vulkan/vulkan_backend.h). One command buffer records the calls in
// order; a read or finish() submits it and waits. Every Vulkan function is called through the table `Vk`,
// loaded from the given vkGetInstanceProcAddr / vkGetDeviceProcAddr (the engine's loader, or libvulkan's for
// a device of its own). Choices made for a real GPU are marked "GPU:".
#define VK_NO_PROTOTYPES // no Vulkan prototype may be called by mistake: only the table's pointers
#include "crep/bindings.h"

#include <crep/gpu/checks.h>
#include <crep/vulkan/vulkan_backend.h>

#include <shaderc/shaderc.hpp>
#include <vulkan/vulkan_core.h>

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>

// libvulkan's entry point (linked through Vulkan::Vulkan), for the backend's own device: VK_NO_PROTOTYPES
// hides the header's declaration.
extern "C" VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL vkGetInstanceProcAddr(VkInstance instance,
                                                                          const char* pName);

namespace crep::gpu {

namespace {

// The Vulkan functions the backend calls, by how they are loaded. Those of the first two lists and
// vkDestroyDevice / vkDeviceWaitIdle serve only a device of the backend's own: on an engine's device they are
// not even looked up.
#define CREP_VK_GLOBAL_FUNCTIONS(X) X(vkCreateInstance) X(vkEnumerateInstanceLayerProperties)
#define CREP_VK_OWN_INSTANCE_FUNCTIONS(X)                                                                    \
  X(vkDestroyInstance) X(vkEnumeratePhysicalDevices) X(vkCreateDevice) X(vkEnumerateDeviceExtensionProperties)
#define CREP_VK_INSTANCE_FUNCTIONS(X)                                                                        \
  X(vkGetPhysicalDeviceProperties)                                                                           \
  X(vkGetPhysicalDeviceQueueFamilyProperties)                                                                \
  X(vkGetPhysicalDeviceMemoryProperties)                                                                     \
  X(vkGetPhysicalDeviceFeatures)                                                                             \
  X(vkGetPhysicalDeviceFormatProperties)
#define CREP_VK_OWN_DEVICE_FUNCTIONS(X) X(vkDestroyDevice) X(vkDeviceWaitIdle) X(vkGetDeviceQueue)
#define CREP_VK_DEVICE_FUNCTIONS(X)                                                                          \
  X(vkCreateCommandPool)                                                                                     \
  X(vkDestroyCommandPool)                                                                                    \
  X(vkAllocateCommandBuffers)                                                                                \
  X(vkBeginCommandBuffer)                                                                                    \
  X(vkEndCommandBuffer)                                                                                      \
  X(vkResetCommandBuffer)                                                                                    \
  X(vkCreateFence)                                                                                           \
  X(vkDestroyFence)                                                                                          \
  X(vkWaitForFences)                                                                                         \
  X(vkResetFences)                                                                                           \
  X(vkQueueSubmit)                                                                                           \
  X(vkCreateQueryPool)                                                                                       \
  X(vkDestroyQueryPool)                                                                                      \
  X(vkGetQueryPoolResults)                                                                                   \
  X(vkCreateSampler)                                                                                         \
  X(vkDestroySampler)                                                                                        \
  X(vkCreateBuffer)                                                                                          \
  X(vkDestroyBuffer)                                                                                         \
  X(vkGetBufferMemoryRequirements)                                                                           \
  X(vkBindBufferMemory)                                                                                      \
  X(vkCreateImage)                                                                                           \
  X(vkDestroyImage)                                                                                          \
  X(vkGetImageMemoryRequirements)                                                                            \
  X(vkBindImageMemory)                                                                                       \
  X(vkCreateImageView)                                                                                       \
  X(vkDestroyImageView)                                                                                      \
  X(vkAllocateMemory)                                                                                        \
  X(vkFreeMemory)                                                                                            \
  X(vkMapMemory)                                                                                             \
  X(vkUnmapMemory)                                                                                           \
  X(vkCreateShaderModule)                                                                                    \
  X(vkDestroyShaderModule)                                                                                   \
  X(vkCreateDescriptorSetLayout)                                                                             \
  X(vkDestroyDescriptorSetLayout)                                                                            \
  X(vkCreatePipelineLayout)                                                                                  \
  X(vkDestroyPipelineLayout)                                                                                 \
  X(vkCreateComputePipelines)                                                                                \
  X(vkDestroyPipeline)                                                                                       \
  X(vkCreateDescriptorPool)                                                                                  \
  X(vkDestroyDescriptorPool)                                                                                 \
  X(vkResetDescriptorPool)                                                                                   \
  X(vkAllocateDescriptorSets)                                                                                \
  X(vkUpdateDescriptorSets)                                                                                  \
  X(vkCmdPipelineBarrier)                                                                                    \
  X(vkCmdCopyBuffer)                                                                                         \
  X(vkCmdUpdateBuffer)                                                                                       \
  X(vkCmdCopyBufferToImage)                                                                                  \
  X(vkCmdCopyImageToBuffer)                                                                                  \
  X(vkCmdBindPipeline)                                                                                       \
  X(vkCmdBindDescriptorSets)                                                                                 \
  X(vkCmdPushConstants)                                                                                      \
  X(vkCmdDispatch)                                                                                           \
  X(vkCmdDispatchIndirect)                                                                                   \
  X(vkCmdResetQueryPool)                                                                                     \
  X(vkCmdWriteTimestamp)

/// The function table: one pointer per function of the lists above, and the optional ones (null when not
/// loaded: the extension is not used).
struct Vk {
#define CREP_VK_MEMBER(name) PFN_##name name = nullptr;
  CREP_VK_GLOBAL_FUNCTIONS(CREP_VK_MEMBER)
  CREP_VK_OWN_INSTANCE_FUNCTIONS(CREP_VK_MEMBER)
  CREP_VK_INSTANCE_FUNCTIONS(CREP_VK_MEMBER)
  CREP_VK_OWN_DEVICE_FUNCTIONS(CREP_VK_MEMBER)
  CREP_VK_DEVICE_FUNCTIONS(CREP_VK_MEMBER)
#undef CREP_VK_MEMBER
  PFN_vkCmdPushDescriptorSetKHR vkCmdPushDescriptorSetKHR = nullptr;             ///< VK_KHR_push_descriptor
  PFN_vkCreateDebugUtilsMessengerEXT vkCreateDebugUtilsMessengerEXT = nullptr;   ///< own instance, validation
  PFN_vkDestroyDebugUtilsMessengerEXT vkDestroyDebugUtilsMessengerEXT = nullptr; ///< own instance, validation
};

/// `f` as the function type F; a VulkanError naming the function and the loader when it is null.
template <class F>
F loaded(PFN_vkVoidFunction f, const char* name, const char* loader) {
  if (f == nullptr)
    throw VulkanError(std::string("crep: VulkanBackend: ") + loader + " returned no " + name +
                      " (a function the backend calls)");
  return reinterpret_cast<F>(f);
}

void check(VkResult r, const char* what) {
  if (r != VK_SUCCESS)
    throw VulkanError("crep: " + std::string(what) + " failed (VkResult " + std::to_string(r) + ")");
}

std::string versionText(std::uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
         std::to_string(VK_API_VERSION_PATCH(v));
}

VkFormat vkFormat(Format f) {
  switch (f) {
  case Format::R32F:
    return VK_FORMAT_R32_SFLOAT;
  case Format::RG32F:
    return VK_FORMAT_R32G32_SFLOAT;
  case Format::RGBA32F:
    return VK_FORMAT_R32G32B32A32_SFLOAT;
  case Format::RGBA16F:
    return VK_FORMAT_R16G16B16A16_SFLOAT;
  case Format::Depth32F:
    return VK_FORMAT_D32_SFLOAT;
  case Format::RGBA8:
    return VK_FORMAT_R8G8B8A8_UNORM;
  case Format::RG32I:
    return VK_FORMAT_R32G32_SINT;
  }
  return VK_FORMAT_R32G32B32A32_SFLOAT;
}

/// Bytes per texel as stored.
std::size_t texelBytes(Format f) {
  return f == Format::RGBA16F ? 8 : f == Format::RGBA8 ? 4 : static_cast<std::size_t>(componentCount(f)) * 4;
}

// ---------------------------------------------------------------------------------------------------
// The requirements (VulkanBackend::requirements()), as tables the checks read.

constexpr std::uint32_t kApiVersion = VK_API_VERSION_1_1;

struct FeatureNeed {
  const char* name;
  VkBool32 VkPhysicalDeviceFeatures::*member;
  const char* why;
};
constexpr FeatureNeed kFeatures[] = {
    {"shaderStorageImageWriteWithoutFormat", &VkPhysicalDeviceFeatures::shaderStorageImageWriteWithoutFormat,
     "the froxel variant of the evaluation (EvaluatePass::FrameAttribs::froxels, Scattering's froxel target) "
     "writes its RGBA16F or RGBA32F volume through an image without a format qualifier"},
};

constexpr VkFormatFeatureFlags kTransfer =
    VK_FORMAT_FEATURE_TRANSFER_SRC_BIT | VK_FORMAT_FEATURE_TRANSFER_DST_BIT;
constexpr VkFormatFeatureFlags kColour =
    VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT | kTransfer;
constexpr VkFormatFeatureFlags kFloatColour = kColour | VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT;

struct FormatNeed {
  Format format;
  const char* name;
  VkFormatFeatureFlags features;
  const char* why;
};
constexpr const char* kFloatWhy =
    "every colour texture is created for sampling, storage and copies, and a "
    "float one is sampled with either filter (gpu::Resource::filter: the basis, "
    "the tables, the froxel volume); Vulkan guarantees linear filtering of the "
    "8- and 16-bit formats only";
constexpr FormatNeed kFormats[] = {
    {Format::R32F, "VK_FORMAT_R32_SFLOAT", kFloatColour, kFloatWhy},
    {Format::RG32F, "VK_FORMAT_R32G32_SFLOAT", kFloatColour, kFloatWhy},
    {Format::RGBA32F, "VK_FORMAT_R32G32B32A32_SFLOAT", kFloatColour, kFloatWhy},
    {Format::RGBA16F, "VK_FORMAT_R16G16B16A16_SFLOAT", kFloatColour, kFloatWhy},
    {Format::RGBA8, "VK_FORMAT_R8G8B8A8_UNORM", kFloatColour, kFloatWhy},
    {Format::RG32I, "VK_FORMAT_R32G32_SINT", kColour,
     "gpu::Format::RG32I (the epipolar sampling's integer textures): every colour texture is created for "
     "sampling, storage and copies"},
    {Format::Depth32F, "VK_FORMAT_D32_SFLOAT", VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | kTransfer,
     "depth maps (gpu::Format::Depth32F) are sampled and copied; Vulkan guarantees D16 only"},
};

std::string formatFeatureNames(VkFormatFeatureFlags f) {
  std::string s;
  for (const auto& [bit, name] :
       {std::pair{VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT, "SAMPLED_IMAGE"},
        std::pair{VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT, "STORAGE_IMAGE"},
        std::pair{VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT, "SAMPLED_IMAGE_FILTER_LINEAR"},
        std::pair{VK_FORMAT_FEATURE_TRANSFER_SRC_BIT, "TRANSFER_SRC"},
        std::pair{VK_FORMAT_FEATURE_TRANSFER_DST_BIT, "TRANSFER_DST"}})
    if ((f & static_cast<VkFormatFeatureFlags>(bit)) != 0) s += std::string(s.empty() ? "" : ", ") + name;
  return s;
}

constexpr const char* kPushWhy =
    "each dispatch pushes its descriptors into the command buffer (vkCmdPushDescriptorSetKHR); without it "
    "(or with CreateInfo::pushDescriptors false) each dispatch allocates a descriptor set from a pool, and "
    "the "
    "pools are reset once the submission that used them has completed";

std::uint32_t vulkanBinding(const Resource& r) {
  switch (r.kind) {
  case ResourceKind::SampledTexture:
    return CREP_VULKAN_UNIT_BASE + r.binding;
  case ResourceKind::StorageImage:
    return CREP_VULKAN_IMAGE_BASE + r.binding;
  case ResourceKind::UniformBuffer:
    return CREP_VULKAN_UNIFORM_BASE + r.binding;
  case ResourceKind::StorageBuffer:
    return CREP_VULKAN_STORAGE_BASE + r.binding;
  }
  return r.binding;
}

VkDescriptorType descriptorType(ResourceKind k) {
  switch (k) {
  case ResourceKind::SampledTexture:
    return VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  case ResourceKind::StorageImage:
    return VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
  case ResourceKind::UniformBuffer:
    return VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  case ResourceKind::StorageBuffer:
    return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  }
  return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
}

/// The index of a resource kind in DescriptorPool's counts.
std::size_t kindIndex(ResourceKind k) {
  switch (k) {
  case ResourceKind::SampledTexture:
    return 0;
  case ResourceKind::StorageImage:
    return 1;
  case ResourceKind::UniformBuffer:
    return 2;
  case ResourceKind::StorageBuffer:
    return 3;
  }
  return 3;
}
constexpr std::array<VkDescriptorType, 4> kPoolTypes = {
    VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE,
    VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};

/// Without push descriptors: a pool and what has been allocated from it since its last reset. GPU: 64 sets
/// of up to 512 descriptors of each type per pool, reset once per submission (the backend submits and waits
/// at each read or finish()); more pools are added when a submission needs more.
struct DescriptorPool {
  static constexpr std::uint32_t kSets = 64, kDescriptors = 512;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  std::uint32_t sets = 0;
  std::array<std::uint32_t, 4> descriptors{};
};

/// The validation layer's warnings and errors (its callback may run on any thread).
struct MessageLog {
  std::mutex mutex;
  std::vector<std::string> messages;
};

VKAPI_ATTR VkBool32 VKAPI_CALL onMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                         VkDebugUtilsMessageTypeFlagsEXT,
                                         const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* log = static_cast<MessageLog*>(user);
  const char* level = severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning";
  const std::lock_guard lock(log->mutex);
  log->messages.push_back(std::string(level) + ": " + (data->pMessage != nullptr ? data->pMessage : ""));
  return VK_FALSE;
}

struct ImageEntry {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE; ///< null for an engine's image (importTexture)
  VkImageView view = VK_NULL_HANDLE;
  TextureDesc desc;
  bool imported = false; ///< the engine's: never destroyed by the backend
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT;
  VkImageUsageFlags usage = 0;
  VkImageLayout home = VK_IMAGE_LAYOUT_GENERAL;    ///< its layout between the backend's calls and frames
  VkImageLayout current = VK_IMAGE_LAYOUT_GENERAL; ///< its layout at this point of the recorded commands
};

struct BufferEntry {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  std::size_t bytes = 0;
};

struct Pipeline {
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  std::array<std::uint32_t, 4> descriptors{}; ///< per kindIndex: the set's descriptors (pools only)
};

} // namespace

std::vector<VulkanBackend::Requirement> VulkanBackend::requirements() {
  using K = Requirement::Kind;
  std::vector<Requirement> r;
  r.push_back({K::ApiVersion, "1.1", true,
               "the shaders are compiled to SPIR-V 1.3 for Vulkan 1.1 (shaderc's vulkan1.1 target); the "
               "physical device's apiVersion and the instance's (EngineDevice::apiVersion) must be >= 1.1"});
  r.push_back(
      {K::QueueFamily, "VK_QUEUE_COMPUTE_BIT", true,
       "every call is a compute dispatch, a copy or a buffer update on the one queue given (a compute "
       "family supports transfers too)"});
  r.push_back({K::QueueFamily, "timestampValidBits", false,
               "beginTimer / endTimer write timestamps on the queue; without them (0 bits, or a "
               "timestampPeriod of 0) the stages' GPU times are 0"});
  r.push_back({K::DeviceExtension, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME, false, kPushWhy});
  for (const FeatureNeed& f : kFeatures)
    r.push_back({K::DeviceFeature, f.name, true, f.why});
  for (const FormatNeed& f : kFormats)
    r.push_back({K::FormatFeature, std::string(f.name) + ": " + formatFeatureNames(f.features), true, f.why});
  return r;
}

struct VulkanBackend::Impl {
  Vk vk;
  PFN_vkGetInstanceProcAddr getInstanceProcAddr = nullptr;
  PFN_vkGetDeviceProcAddr getDeviceProcAddr = nullptr;
  bool ownsDevice = false; ///< the instance and device are the backend's (no CreateInfo::device)
  const VkAllocationCallbacks* allocator = nullptr;
  VkPipelineCache pipelineCache = VK_NULL_HANDLE;
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties{};
  VkPhysicalDeviceMemoryProperties memory{};
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  std::uint32_t family = 0;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkCommandBuffer ownCmd = VK_NULL_HANDLE; ///< the backend's own: calls outside frames, submitted by it
  VkCommandBuffer cmd = VK_NULL_HANDLE;    ///< where calls record now: ownCmd, or the frame's (beginFrame)
  VkFence fence = VK_NULL_HANDLE;
  bool recording = false; ///< ownCmd is recording

  // Frames recorded into the engine's command buffers (beginFrame / endFrame).
  std::uint32_t framesInFlight = 3;
  bool inFrame = false;
  std::uint64_t frameIndex = 0;     ///< the frame being recorded, or the last one recorded
  std::uint64_t completedFrame = 0; ///< every frame <= this one has completed (the engine said so)
  /// Objects released once the frame they were last used in has completed: staging buffers, textures and
  /// buffers destroyed while frames that may use them are in flight.
  struct Retired {
    std::uint64_t frame = 0;
    std::vector<BufferEntry> buffers;
    std::vector<ImageEntry> images;
  };
  std::vector<Retired> retired;
  std::vector<std::vector<DescriptorPool>> framePools; ///< per frame slot (pools mode)
  VkSampler nearest = VK_NULL_HANDLE, linear = VK_NULL_HANDLE;
  /// Two timestamps per span (beginTimer, endTimer or endTimerDeferred), kSpans spans as a ring; null
  /// without timestamps.
  VkQueryPool timestamps = VK_NULL_HANDLE;
  static constexpr std::uint32_t kSpans = 1024;
  TimerId lastSpan = 0;          ///< the newest span's id; its queries are 2 (id % kSpans) and the next
  std::uint64_t submissions = 0; ///< of ownCmd, each waited for
  /// Deferred spans not yet read: the frame they were recorded in (0: outside frames) and, outside frames,
  /// the submission that will carry them.
  struct PendingSpan {
    std::uint64_t frame = 0;
    std::uint64_t submission = 0;
  };
  std::map<TimerId, PendingSpan> pendingSpans;
  double spanMilliseconds(TimerId id, bool wait);
  std::uint32_t timestampBits = 0;             ///< the queue family's timestampValidBits
  bool timing = false;                         ///< a span's first timestamp is recorded
  bool pushDescriptors = false;                ///< vkCmdPushDescriptorSetKHR, else sets from descriptorPools
  std::vector<DescriptorPool> descriptorPools; ///< ownCmd's (pools mode); a frame's are in framePools
  std::size_t currentPool = 0;                 ///< the pool the next set comes from; those before it are full
  std::vector<std::size_t> frameCurrentPool;   ///< currentPool of each frame slot

  std::map<TextureId, ImageEntry> images;
  std::map<BufferId, BufferEntry> buffers;
  std::uint32_t nextId = 1;
  std::map<std::string, VkShaderModule> modules;
  ShaderBinaryProvider shaderBinary; ///< CreateInfo::shaderBinary: the engine's SPIR-V, else shaderc's
  std::map<std::string, Pipeline> pipelines;
  std::vector<BufferEntry> staging; ///< freed after the submission that used them

  MessageLog log;

  void createInstance(bool validation);
  void pickDevice(const std::string& name);
  void createDevice(bool wantPushDescriptors);
  void adoptDevice(const EngineDevice& e, bool wantPushDescriptors);
  void loadInstanceFunctions();
  void loadDeviceFunctions();
  void readPhysicalDevice(const char* field);
  void checkRequirements(const VkPhysicalDeviceFeatures& enabled, const char* field);
  void createObjects();
  std::uint32_t memoryType(std::uint32_t bits, VkMemoryPropertyFlags required,
                           VkMemoryPropertyFlags preferred) const;
  BufferEntry makeBuffer(std::size_t bytes, VkBufferUsageFlags usage);
  void freeBuffer(BufferEntry& b);
  void destroyImage(ImageEntry& e);
  void begin();
  void barrier();
  void transition(const ImageEntry& e, VkImageLayout from, VkImageLayout to);
  std::vector<TextureId> moved; ///< engine images out of their home layout in the recorded commands
  void useImage(TextureId id, ImageEntry& e, bool storage);
  void restoreImages();
  void submit();
  void refuseInFrame(const char* call) const;
  Retired& retiring();
  void release(std::uint64_t completed);
  void resetPools(std::vector<DescriptorPool>& pools);
  VkDescriptorSet allocateSet(const Pipeline& p);
  VkShaderModule module(const std::string& program, std::span<const ShaderDefine> defines);
  Pipeline& pipeline(const Dispatch& d, std::size_t pushBytes);
  ImageEntry& image(TextureId id, const char* what);
  /// image(), refused when it is an engine image whose format the transfers do not convert.
  ImageEntry& copyableImage(TextureId id, const char* what);
  BufferEntry& buffer(BufferId id, const char* what);
  ~Impl();
};

void VulkanBackend::Impl::loadInstanceFunctions() {
#define CREP_VK_LOAD(name)                                                                                   \
  vk.name = loaded<PFN_##name>(getInstanceProcAddr(instance, #name), #name, "vkGetInstanceProcAddr");
  if (ownsDevice) {
    CREP_VK_OWN_INSTANCE_FUNCTIONS(CREP_VK_LOAD)
  }
  CREP_VK_INSTANCE_FUNCTIONS(CREP_VK_LOAD)
#undef CREP_VK_LOAD
  if (getDeviceProcAddr == nullptr)
    getDeviceProcAddr = loaded<PFN_vkGetDeviceProcAddr>(getInstanceProcAddr(instance, "vkGetDeviceProcAddr"),
                                                        "vkGetDeviceProcAddr", "vkGetInstanceProcAddr");
}

void VulkanBackend::Impl::loadDeviceFunctions() {
#define CREP_VK_LOAD(name)                                                                                   \
  vk.name = loaded<PFN_##name>(getDeviceProcAddr(device, #name), #name, "vkGetDeviceProcAddr");
  if (ownsDevice) {
    CREP_VK_OWN_DEVICE_FUNCTIONS(CREP_VK_LOAD)
  }
  CREP_VK_DEVICE_FUNCTIONS(CREP_VK_LOAD)
  if (pushDescriptors) {
    CREP_VK_LOAD(vkCmdPushDescriptorSetKHR)
  }
#undef CREP_VK_LOAD
}

void VulkanBackend::Impl::createInstance(bool validation) {
  getInstanceProcAddr = ::vkGetInstanceProcAddr;
#define CREP_VK_LOAD(name)                                                                                   \
  vk.name = loaded<PFN_##name>(getInstanceProcAddr(VK_NULL_HANDLE, #name), #name,                            \
                               "libvulkan's vkGetInstanceProcAddr");
  CREP_VK_GLOBAL_FUNCTIONS(CREP_VK_LOAD)
#undef CREP_VK_LOAD
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "crepuscular";
  app.pEngineName = "crepuscular";
  app.apiVersion = kApiVersion;
  const char* layers[] = {"VK_LAYER_KHRONOS_validation"};
  const char* extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
  if (validation) {
    std::uint32_t count = 0;
    vk.vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> available(count);
    vk.vkEnumerateInstanceLayerProperties(&count, available.data());
    if (std::none_of(available.begin(), available.end(),
                     [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, layers[0]) == 0; }))
      throw VulkanError(
          "crep: VulkanBackend::CreateInfo.validation: VK_LAYER_KHRONOS_validation is not installed "
          "(Debian package vulkan-validationlayers)");
  }
  VkDebugUtilsMessengerCreateInfoEXT debug{};
  debug.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  debug.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  debug.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                      VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                      VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  debug.pfnUserCallback = onMessage;
  debug.pUserData = &log;
  VkInstanceCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  ci.pApplicationInfo = &app;
  if (validation) {
    ci.enabledLayerCount = 1;
    ci.ppEnabledLayerNames = layers;
    ci.enabledExtensionCount = 1;
    ci.ppEnabledExtensionNames = extensions;
    ci.pNext = &debug; // messages of instance creation too
  }
  check(vk.vkCreateInstance(&ci, allocator, &instance),
        "vkCreateInstance (is a Vulkan driver installed? Debian: mesa-vulkan-drivers)");
  loadInstanceFunctions();
  if (validation) {
    vk.vkCreateDebugUtilsMessengerEXT = loaded<PFN_vkCreateDebugUtilsMessengerEXT>(
        getInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"), "vkCreateDebugUtilsMessengerEXT",
        "vkGetInstanceProcAddr");
    vk.vkDestroyDebugUtilsMessengerEXT = loaded<PFN_vkDestroyDebugUtilsMessengerEXT>(
        getInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"), "vkDestroyDebugUtilsMessengerEXT",
        "vkGetInstanceProcAddr");
    check(vk.vkCreateDebugUtilsMessengerEXT(instance, &debug, allocator, &messenger),
          "vkCreateDebugUtilsMessengerEXT");
  }
}

void VulkanBackend::Impl::pickDevice(const std::string& name) {
  std::uint32_t count = 0;
  vk.vkEnumeratePhysicalDevices(instance, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  vk.vkEnumeratePhysicalDevices(instance, &count, devices.data());
  std::string seen;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p;
    vk.vkGetPhysicalDeviceProperties(d, &p);
    seen += std::string(seen.empty() ? "" : ", ") + p.deviceName;
    if (!name.empty() && std::string(p.deviceName).find(name) == std::string::npos) continue;
    std::uint32_t families = 0;
    vk.vkGetPhysicalDeviceQueueFamilyProperties(d, &families, nullptr);
    std::vector<VkQueueFamilyProperties> props(families);
    vk.vkGetPhysicalDeviceQueueFamilyProperties(d, &families, props.data());
    for (std::uint32_t i = 0; i < families; ++i)
      if ((props[i].queueFlags & VK_QUEUE_COMPUTE_BIT) != 0) {
        physical = d;
        family = i;
        return;
      }
  }
  throw VulkanError("crep: VulkanBackend: no Vulkan device with a compute queue" +
                    (name.empty() ? std::string() : " named like \"" + name + "\"") +
                    " (devices: " + (seen.empty() ? "none" : seen) + ")");
}

void VulkanBackend::Impl::readPhysicalDevice(const char* field) {
  vk.vkGetPhysicalDeviceProperties(physical, &properties);
  vk.vkGetPhysicalDeviceMemoryProperties(physical, &memory);
  const std::string where = std::string(field) + " (\"" + properties.deviceName + "\")";
  if (properties.apiVersion < kApiVersion)
    throw VulkanError("crep: " + where + ": Vulkan " + versionText(properties.apiVersion) +
                      ", the backend needs 1.1 (" + requirements()[0].why + ")");
  std::uint32_t families = 0;
  vk.vkGetPhysicalDeviceQueueFamilyProperties(physical, &families, nullptr);
  std::vector<VkQueueFamilyProperties> props(families);
  vk.vkGetPhysicalDeviceQueueFamilyProperties(physical, &families, props.data());
  if (family >= families || (props[family].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0)
    throw VulkanError(
        "crep: " + (ownsDevice ? where : std::string("VulkanBackend::CreateInfo.device.queueFamily")) +
        ": family " + std::to_string(family) +
        (family >= families ? " does not exist (the device has " + std::to_string(families) + ")"
                            : " has no VK_QUEUE_COMPUTE_BIT") +
        " (" + requirements()[1].why + ")");
  timestampBits = props[family].timestampValidBits;
}

void VulkanBackend::Impl::checkRequirements(const VkPhysicalDeviceFeatures& enabled, const char* field) {
  for (const FeatureNeed& f : kFeatures)
    if (enabled.*f.member != VK_TRUE)
      throw VulkanError("crep: " + std::string(field) + ": " + f.name + " is not " +
                        (ownsDevice ? "supported" : "enabled") + " (" + f.why + ")");
  for (const FormatNeed& f : kFormats) {
    VkFormatProperties p{};
    vk.vkGetPhysicalDeviceFormatProperties(physical, vkFormat(f.format), &p);
    const VkFormatFeatureFlags missing = f.features & ~p.optimalTilingFeatures;
    if (missing != 0)
      throw VulkanError("crep: VulkanBackend: the physical device \"" + std::string(properties.deviceName) +
                        "\" lacks " + f.name + ": " + formatFeatureNames(missing) +
                        " in optimalTilingFeatures (" + f.why + ")");
  }
}

void VulkanBackend::Impl::createDevice(bool wantPushDescriptors) {
  readPhysicalDevice("VulkanBackend: the physical device");
  VkPhysicalDeviceFeatures supported{};
  vk.vkGetPhysicalDeviceFeatures(physical, &supported);
  checkRequirements(
      supported,
      ("VulkanBackend: the physical device \"" + std::string(properties.deviceName) + "\"").c_str());
  std::uint32_t count = 0;
  vk.vkEnumerateDeviceExtensionProperties(physical, nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> available(count);
  vk.vkEnumerateDeviceExtensionProperties(physical, nullptr, &count, available.data());
  pushDescriptors = wantPushDescriptors &&
                    std::any_of(available.begin(), available.end(), [](const VkExtensionProperties& e) {
                      return std::strcmp(e.extensionName, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME) == 0;
                    });
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo q{};
  q.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  q.queueFamilyIndex = family;
  q.queueCount = 1;
  q.pQueuePriorities = &priority;
  VkPhysicalDeviceFeatures features{}; // what requirements() lists, nothing more
  for (const FeatureNeed& f : kFeatures)
    features.*f.member = VK_TRUE;
  const char* extensions[] = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
  VkDeviceCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  ci.queueCreateInfoCount = 1;
  ci.pQueueCreateInfos = &q;
  ci.enabledExtensionCount = pushDescriptors ? 1 : 0;
  ci.ppEnabledExtensionNames = extensions;
  ci.pEnabledFeatures = &features;
  check(vk.vkCreateDevice(physical, &ci, allocator, &device), "vkCreateDevice");
  loadDeviceFunctions();
  vk.vkGetDeviceQueue(device, family, 0, &queue);
}

void VulkanBackend::Impl::adoptDevice(const EngineDevice& e, bool wantPushDescriptors) {
  const auto missing = [](const char* field, const char* what) {
    throw InvalidArgument(std::string("VulkanBackend::CreateInfo.device.") + field, "null",
                          std::string("must be ") + what);
  };
  if (e.getInstanceProcAddr == nullptr)
    missing("getInstanceProcAddr", "the loader's vkGetInstanceProcAddr (libvulkan's, volk's, ...)");
  if (e.instance == VK_NULL_HANDLE) missing("instance", "the engine's VkInstance");
  if (e.physicalDevice == VK_NULL_HANDLE)
    missing("physicalDevice", "the VkPhysicalDevice the engine's device was created on");
  if (e.device == VK_NULL_HANDLE) missing("device", "the engine's VkDevice");
  if (e.queue == VK_NULL_HANDLE) missing("queue", "a VkQueue of queueFamily the backend may submit on");
  if (e.apiVersion < kApiVersion)
    throw InvalidArgument("VulkanBackend::CreateInfo.device.apiVersion", versionText(e.apiVersion),
                          "must be >= 1.1: " + requirements()[0].why);
  getInstanceProcAddr = e.getInstanceProcAddr;
  getDeviceProcAddr = e.getDeviceProcAddr;
  allocator = e.allocator;
  pipelineCache = e.pipelineCache;
  instance = e.instance;
  physical = e.physicalDevice;
  device = e.device;
  queue = e.queue;
  family = e.queueFamily;
  loadInstanceFunctions();
  readPhysicalDevice("VulkanBackend::CreateInfo.device.physicalDevice");
  checkRequirements(e.enabledFeatures, "VulkanBackend::CreateInfo.device.enabledFeatures");
  pushDescriptors =
      wantPushDescriptors && std::find(e.enabledExtensions.begin(), e.enabledExtensions.end(),
                                       VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME) != e.enabledExtensions.end();
  loadDeviceFunctions();
}

void VulkanBackend::Impl::createObjects() {
  VkCommandPoolCreateInfo pci{};
  pci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = family;
  check(vk.vkCreateCommandPool(device, &pci, allocator, &pool), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ai.commandPool = pool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  check(vk.vkAllocateCommandBuffers(device, &ai, &ownCmd), "vkAllocateCommandBuffers");
  cmd = ownCmd;
  VkFenceCreateInfo fi{};
  fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  check(vk.vkCreateFence(device, &fi, allocator, &fence), "vkCreateFence");
  if (timestampBits > 0 && properties.limits.timestampPeriod > 0.0f) {
    VkQueryPoolCreateInfo qi{};
    qi.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
    qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qi.queryCount = 2 * kSpans;
    check(vk.vkCreateQueryPool(device, &qi, allocator, &timestamps), "vkCreateQueryPool (timestamps)");
  }
  for (auto [filter, sampler] :
       {std::pair{VK_FILTER_NEAREST, &nearest}, std::pair{VK_FILTER_LINEAR, &linear}}) {
    VkSamplerCreateInfo si{};
    si.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
    si.magFilter = si.minFilter = filter;
    si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    si.maxLod = 0.0f;
    check(vk.vkCreateSampler(device, &si, allocator, sampler), "vkCreateSampler");
  }
}

std::uint32_t VulkanBackend::Impl::memoryType(std::uint32_t bits, VkMemoryPropertyFlags required,
                                              VkMemoryPropertyFlags preferred) const {
  for (VkMemoryPropertyFlags want : {required | preferred, required})
    for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i)
      if ((bits & (1u << i)) != 0 && (memory.memoryTypes[i].propertyFlags & want) == want) return i;
  throw VulkanError("crep: VulkanBackend: no memory type with the properties needed");
}

BufferEntry VulkanBackend::Impl::makeBuffer(std::size_t bytes, VkBufferUsageFlags usage) {
  BufferEntry b;
  b.bytes = bytes;
  VkBufferCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  ci.size = bytes;
  ci.usage = usage;
  ci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check(vk.vkCreateBuffer(device, &ci, allocator, &b.buffer), "vkCreateBuffer");
  VkMemoryRequirements req;
  vk.vkGetBufferMemoryRequirements(device, b.buffer, &req);
  VkMemoryAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  ai.allocationSize = req.size;
  // GPU: host-visible memory, device-local where the device has such (resizable BAR, integrated and CPU
  // devices); the writes are recorded in the command stream either way (writeBuffer), so a discrete GPU
  // without it only reads its buffers over the bus.
  ai.memoryTypeIndex = memoryType(req.memoryTypeBits,
                                  VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                                  VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  check(vk.vkAllocateMemory(device, &ai, allocator, &b.memory), "vkAllocateMemory (buffer)");
  check(vk.vkBindBufferMemory(device, b.buffer, b.memory, 0), "vkBindBufferMemory");
  check(vk.vkMapMemory(device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
  return b;
}

void VulkanBackend::Impl::freeBuffer(BufferEntry& b) {
  if (b.memory != VK_NULL_HANDLE) vk.vkUnmapMemory(device, b.memory);
  vk.vkDestroyBuffer(device, b.buffer, allocator);
  vk.vkFreeMemory(device, b.memory, allocator);
  b = {};
}

void VulkanBackend::Impl::begin() {
  if (inFrame || recording) return; // a frame records into the engine's command buffer
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vk.vkBeginCommandBuffer(ownCmd, &bi), "vkBeginCommandBuffer");
  recording = true;
}

void VulkanBackend::Impl::refuseInFrame(const char* call) const {
  if (inFrame)
    throw InvalidArgument(call, "inside frame " + std::to_string(frameIndex),
                          "would wait for the GPU: call it outside beginFrame() / endFrame()");
}

VulkanBackend::Impl::Retired& VulkanBackend::Impl::retiring() {
  // What the frame being recorded (or the last one recorded, outside frames) may still use.
  if (retired.empty() || retired.back().frame != frameIndex) retired.push_back({frameIndex, {}, {}});
  return retired.back();
}

void VulkanBackend::Impl::release(std::uint64_t completed) {
  std::size_t kept = 0;
  for (std::size_t i = 0; i < retired.size(); ++i) {
    Retired& r = retired[i];
    if (r.frame > completed) {
      if (kept != i) retired[kept] = std::move(r);
      ++kept;
      continue;
    }
    for (BufferEntry& b : r.buffers)
      freeBuffer(b);
    for (ImageEntry& image : r.images)
      destroyImage(image);
  }
  retired.resize(kept);
}

void VulkanBackend::Impl::resetPools(std::vector<DescriptorPool>& pools) {
  for (DescriptorPool& dp : pools) {
    if (dp.sets == 0) continue;
    check(vk.vkResetDescriptorPool(device, dp.pool, 0), "vkResetDescriptorPool");
    dp.sets = 0;
    dp.descriptors = {};
  }
}

void VulkanBackend::Impl::barrier() {
  // Every call sees the writes of the calls before it (the Backend's contract). GPU: one global barrier
  // per call; an engine's render graph would place narrower ones.
  VkMemoryBarrier m{};
  m.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  m.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  m.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_UNIFORM_READ_BIT |
                    VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT |
                    VK_ACCESS_INDIRECT_COMMAND_READ_BIT; // work lists' group counts (Dispatch::indirect)
  vk.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT |
                              VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                          0, 1, &m, 0, nullptr, 0, nullptr);
}

namespace {
VkImageSubresourceRange wholeImage(const ImageEntry& e) {
  return {e.aspect, 0, 1, 0,
          e.desc.type == TextureType::Texture2DArray ? static_cast<std::uint32_t>(e.desc.depth) : 1u};
}
bool sampleable(VkImageLayout l) {
  return l == VK_IMAGE_LAYOUT_GENERAL || l == VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL ||
         l == VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL;
}
} // namespace

void VulkanBackend::Impl::useImage(TextureId id, ImageEntry& e, bool storage) {
  // An engine's image is sampled in its own layout when it can be, else moved to GENERAL until the
  // frame's end (or the submission's, outside frames), then moved back (docs/VULKAN_STATE.md).
  const VkImageLayout needed = storage || !sampleable(e.current) ? VK_IMAGE_LAYOUT_GENERAL : e.current;
  if (needed == e.current) return;
  transition(e, e.current, needed);
  if (e.current == e.home) moved.push_back(id);
  e.current = needed;
}

void VulkanBackend::Impl::restoreImages() {
  for (TextureId id : moved) {
    const auto it = images.find(id);
    if (it == images.end() || it->second.current == it->second.home) continue;
    transition(it->second, it->second.current, it->second.home);
    it->second.current = it->second.home;
  }
  moved.clear();
}

namespace {
/// The whole image as one buffer copy (writeTexture, readTexture): layers after each other, tightly packed.
VkBufferImageCopy wholeCopy(const ImageEntry& e) {
  const VkImageSubresourceRange range = wholeImage(e);
  VkBufferImageCopy region{};
  region.imageSubresource = {range.aspectMask, 0, 0, range.layerCount};
  region.imageExtent = {static_cast<std::uint32_t>(e.desc.width), static_cast<std::uint32_t>(e.desc.height),
                        e.desc.type == TextureType::Texture3D ? static_cast<std::uint32_t>(e.desc.depth)
                                                              : 1u};
  return region;
}
} // namespace

void VulkanBackend::Impl::transition(const ImageEntry& e, VkImageLayout from, VkImageLayout to) {
  VkImageMemoryBarrier b{};
  b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                    VK_ACCESS_TRANSFER_WRITE_BIT;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = e.image;
  b.subresourceRange = wholeImage(e);
  vk.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                          nullptr, 0, nullptr, 1, &b);
}

void VulkanBackend::Impl::submit() {
  if (!recording) return;
  restoreImages();
  VkMemoryBarrier m{};
  m.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  m.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  m.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vk.vkCmdPipelineBarrier(ownCmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                          VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &m, 0, nullptr, 0, nullptr);
  check(vk.vkEndCommandBuffer(ownCmd), "vkEndCommandBuffer");
  recording = false;
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &ownCmd;
  check(vk.vkQueueSubmit(queue, 1, &si, fence), "vkQueueSubmit");
  ++submissions;
  check(vk.vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  check(vk.vkResetFences(device, 1, &fence), "vkResetFences");
  check(vk.vkResetCommandBuffer(ownCmd, 0), "vkResetCommandBuffer");
  for (BufferEntry& b : staging)
    freeBuffer(b);
  staging.clear();
  // The submission has completed: its descriptor sets may go (pools mode).
  resetPools(descriptorPools);
  currentPool = 0;
}

VkDescriptorSet VulkanBackend::Impl::allocateSet(const Pipeline& p) {
  // A frame's sets come from its slot's pools, reset when the slot is reused (its frame has completed).
  const std::size_t slot = static_cast<std::size_t>(frameIndex % framesInFlight);
  std::vector<DescriptorPool>& pools = inFrame ? framePools[slot] : descriptorPools;
  std::size_t& current = inFrame ? frameCurrentPool[slot] : currentPool;
  const auto fits = [&](const DescriptorPool& dp) {
    if (dp.sets + 1 > DescriptorPool::kSets) return false;
    for (std::size_t k = 0; k < 4; ++k)
      if (dp.descriptors[k] + p.descriptors[k] > DescriptorPool::kDescriptors) return false;
    return true;
  };
  for (;; ++current) {
    if (current == pools.size()) {
      // Grow: one more pool (kept, and reused after the next submission).
      std::array<VkDescriptorPoolSize, 4> sizes{};
      for (std::size_t k = 0; k < 4; ++k)
        sizes[k] = {kPoolTypes[k], DescriptorPool::kDescriptors};
      VkDescriptorPoolCreateInfo ci{};
      ci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
      ci.maxSets = DescriptorPool::kSets;
      ci.poolSizeCount = static_cast<std::uint32_t>(sizes.size());
      ci.pPoolSizes = sizes.data();
      DescriptorPool dp;
      check(vk.vkCreateDescriptorPool(device, &ci, allocator, &dp.pool), "vkCreateDescriptorPool");
      pools.push_back(dp);
    }
    DescriptorPool& dp = pools[current];
    if (!fits(dp)) continue;
    VkDescriptorSetAllocateInfo ai{};
    ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    ai.descriptorPool = dp.pool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &p.setLayout;
    VkDescriptorSet set = VK_NULL_HANDLE;
    const VkResult r = vk.vkAllocateDescriptorSets(device, &ai, &set);
    if (r == VK_ERROR_OUT_OF_POOL_MEMORY || r == VK_ERROR_FRAGMENTED_POOL) {
      dp.sets = DescriptorPool::kSets; // the driver counts otherwise: full until the next reset
      continue;
    }
    check(r, "vkAllocateDescriptorSets");
    ++dp.sets;
    for (std::size_t k = 0; k < 4; ++k)
      dp.descriptors[k] += p.descriptors[k];
    return set;
  }
}

VkShaderModule VulkanBackend::Impl::module(const std::string& program,
                                           std::span<const ShaderDefine> defines) {
  const std::string key = variantKey(program, defines);
  if (auto it = modules.find(key); it != modules.end()) return it->second;
  const auto create = [&](const std::uint32_t* code, std::size_t bytes) {
    VkShaderModuleCreateInfo ci{};
    ci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    ci.codeSize = bytes;
    ci.pCode = code;
    VkShaderModule m = VK_NULL_HANDLE;
    check(vk.vkCreateShaderModule(device, &ci, allocator, &m), "vkCreateShaderModule");
    modules[key] = m;
    return m;
  };
  if (shaderBinary) {
    const std::vector<std::byte> binary = shaderBinary(program, defines);
    if (!binary.empty()) {
      constexpr std::uint32_t kMagic = 0x07230203; // the SPIR-V specification's magic number, host order
      std::vector<std::uint32_t> words(binary.size() / 4);
      std::memcpy(words.data(), binary.data(), words.size() * 4);
      const std::string field = "VulkanBackend::CreateInfo.shaderBinary(\"" + program + "\")";
      if (binary.size() % 4 != 0)
        throw InvalidArgument(field, std::to_string(binary.size()) + " bytes",
                              "must be SPIR-V: a whole number of 4-byte words");
      if (words.front() != kMagic) {
        char first[16];
        std::snprintf(first, sizeof first, "0x%08x", words.front());
        throw InvalidArgument(field, std::string("a module whose first word is ") + first,
                              "must be SPIR-V: its first word the magic number 0x07230203 (in host byte "
                              "order)");
      }
      return create(words.data(), binary.size());
    }
  }
  const ExpandedShader expanded = ShaderLibrary::expand(program, defines);
  shaderc::CompileOptions options;
  options.SetTargetEnvironment(shaderc_target_env_vulkan, shaderc_env_version_vulkan_1_1);
  options.SetBindingBase(shaderc_uniform_kind_texture, CREP_VULKAN_UNIT_BASE);
  options.SetBindingBase(shaderc_uniform_kind_sampler, CREP_VULKAN_UNIT_BASE);
  options.SetBindingBase(shaderc_uniform_kind_image, CREP_VULKAN_IMAGE_BASE);
  options.SetBindingBase(shaderc_uniform_kind_buffer, CREP_VULKAN_UNIFORM_BASE);
  options.SetBindingBase(shaderc_uniform_kind_storage_buffer, CREP_VULKAN_STORAGE_BASE);
  options.SetOptimizationLevel(shaderc_optimization_level_performance);
  const shaderc::Compiler compiler;
  const shaderc::SpvCompilationResult result =
      compiler.CompileGlslToSpv(expanded.text, shaderc_compute_shader, program.c_str(), options);
  if (result.GetCompilationStatus() != shaderc_compilation_status_success) {
    std::string variant;
    for (const ShaderDefine& d : defines)
      variant += " " + d.name + "=" + d.value;
    throw ShaderError("crep: cannot compile compute shader \"" + program + "\"" +
                      (variant.empty() ? "" : " (" + variant.substr(1) + ")") + " for Vulkan:\n" +
                      expanded.translateLog(result.GetErrorMessage()));
  }
  const std::vector<std::uint32_t> words(result.cbegin(), result.cend());
  return create(words.data(), words.size() * 4);
}

Pipeline& VulkanBackend::Impl::pipeline(const Dispatch& d, std::size_t pushBytes) {
  // One pipeline per variant and resource signature (the descriptor layout follows the dispatch).
  std::string key = variantKey(d.program, d.defines) + "\n#";
  std::vector<VkDescriptorSetLayoutBinding> bindings;
  std::array<std::uint32_t, 4> descriptors{};
  for (const Resource& r : d.resources) {
    ++descriptors[kindIndex(r.kind)];
    VkDescriptorSetLayoutBinding b{};
    b.binding = vulkanBinding(r);
    b.descriptorType = descriptorType(r.kind);
    b.descriptorCount = 1;
    b.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    bindings.push_back(b);
    key += " " + std::to_string(b.binding) + ":" + std::to_string(b.descriptorType);
  }
  key += " push " + std::to_string(pushBytes);
  if (auto it = pipelines.find(key); it != pipelines.end()) return it->second;

  Pipeline p;
  p.descriptors = descriptors;
  VkDescriptorSetLayoutCreateInfo li{};
  li.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  li.flags = pushDescriptors ? static_cast<VkDescriptorSetLayoutCreateFlags>(
                                   VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR)
                             : 0u;
  li.bindingCount = static_cast<std::uint32_t>(bindings.size());
  li.pBindings = bindings.data();
  check(vk.vkCreateDescriptorSetLayout(device, &li, allocator, &p.setLayout), "vkCreateDescriptorSetLayout");
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, static_cast<std::uint32_t>(pushBytes)};
  VkPipelineLayoutCreateInfo pl{};
  pl.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &p.setLayout;
  pl.pushConstantRangeCount = pushBytes == 0 ? 0 : 1;
  pl.pPushConstantRanges = &range;
  check(vk.vkCreatePipelineLayout(device, &pl, allocator, &p.layout), "vkCreatePipelineLayout");
  VkComputePipelineCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  ci.stage = {};
  ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = module(d.program, d.defines);
  ci.stage.pName = "main";
  ci.layout = p.layout;
  check(vk.vkCreateComputePipelines(device, pipelineCache, 1, &ci, allocator, &p.pipeline),
        "vkCreateComputePipelines");
  return pipelines[key] = p;
}

ImageEntry& VulkanBackend::Impl::image(TextureId id, const char* what) {
  const auto it = images.find(id);
  if (it == images.end())
    throw InvalidArgument(what, std::to_string(id), "must be a texture of this VulkanBackend");
  return it->second;
}

ImageEntry& VulkanBackend::Impl::copyableImage(TextureId id, const char* what) {
  ImageEntry& e = image(id, what);
  if (e.format != vkFormat(e.desc.format))
    throw InvalidArgument(what, std::to_string(id),
                          "is an engine image in a format the backend does not copy (" +
                              std::to_string(static_cast<int>(e.format)) + ")");
  return e;
}

BufferEntry& VulkanBackend::Impl::buffer(BufferId id, const char* what) {
  const auto it = buffers.find(id);
  if (it == buffers.end())
    throw InvalidArgument(what, std::to_string(id), "must be a buffer of this VulkanBackend");
  return it->second;
}

void VulkanBackend::Impl::destroyImage(ImageEntry& e) {
  vk.vkDestroyImageView(device, e.view, allocator);
  vk.vkDestroyImage(device, e.image, allocator);
  vk.vkFreeMemory(device, e.memory, allocator);
  e = {};
}

VulkanBackend::Impl::~Impl() {
  // Every submission was waited for (submit()); what is recorded and not submitted is dropped with the
  // command pool. On an engine's device nothing waits on the device or its queue (the engine may use them).
  if (device != VK_NULL_HANDLE && vk.vkDestroyCommandPool != nullptr) {
    if (ownsDevice) vk.vkDeviceWaitIdle(device);
    // On an engine's device every frame recorded must have completed (the backend's contract).
    release(UINT64_MAX);
    for (BufferEntry& b : staging)
      freeBuffer(b);
    for (auto& [id, b] : buffers)
      freeBuffer(b);
    for (auto& [id, i] : images)
      if (!i.imported) destroyImage(i); // the engine's images are the engine's
    for (auto& [key, p] : pipelines) {
      vk.vkDestroyPipeline(device, p.pipeline, allocator);
      vk.vkDestroyPipelineLayout(device, p.layout, allocator);
      vk.vkDestroyDescriptorSetLayout(device, p.setLayout, allocator);
    }
    for (auto& [key, m] : modules)
      vk.vkDestroyShaderModule(device, m, allocator);
    for (DescriptorPool& dp : descriptorPools)
      vk.vkDestroyDescriptorPool(device, dp.pool, allocator);
    for (std::vector<DescriptorPool>& pools : framePools)
      for (DescriptorPool& dp : pools)
        vk.vkDestroyDescriptorPool(device, dp.pool, allocator);
    vk.vkDestroySampler(device, nearest, allocator);
    vk.vkDestroySampler(device, linear, allocator);
    vk.vkDestroyFence(device, fence, allocator);
    if (timestamps != VK_NULL_HANDLE) vk.vkDestroyQueryPool(device, timestamps, allocator);
    vk.vkDestroyCommandPool(device, pool, allocator);
  }
  if (!ownsDevice) return; // the engine's instance and device stay
  if (device != VK_NULL_HANDLE && vk.vkDestroyDevice != nullptr) vk.vkDestroyDevice(device, allocator);
  if (messenger != VK_NULL_HANDLE) vk.vkDestroyDebugUtilsMessengerEXT(instance, messenger, allocator);
  if (instance != VK_NULL_HANDLE && vk.vkDestroyInstance != nullptr)
    vk.vkDestroyInstance(instance, allocator);
}

// ---------------------------------------------------------------------------------------------------

VulkanBackend::VulkanBackend() : VulkanBackend(CreateInfo{}) {}

VulkanBackend::VulkanBackend(const CreateInfo& info) : impl_(std::make_unique<Impl>()) {
  Impl& v = *impl_;
  if (info.device) {
    if (info.validation)
      throw InvalidArgument(
          "VulkanBackend::CreateInfo.validation", "true",
          "must be false with an engine device (CreateInfo.device): the engine's instance has "
          "its own layers and debug messenger");
    if (!info.deviceName.empty())
      throw InvalidArgument("VulkanBackend::CreateInfo.deviceName", "\"" + info.deviceName + "\"",
                            "must be empty with an engine device (CreateInfo.device)");
    v.adoptDevice(*info.device, info.pushDescriptors);
  } else {
    v.ownsDevice = true;
    v.createInstance(info.validation);
    v.pickDevice(info.deviceName);
    v.createDevice(info.pushDescriptors);
  }
  if (info.framesInFlight < 1 || info.framesInFlight > 16)
    throw InvalidArgument("VulkanBackend::CreateInfo.framesInFlight", std::to_string(info.framesInFlight),
                          "must be in [1, 16]");
  v.framesInFlight = info.framesInFlight;
  v.shaderBinary = info.shaderBinary;
  v.framePools.resize(info.framesInFlight);
  v.frameCurrentPool.assign(info.framesInFlight, 0);
  v.createObjects();
}

VulkanBackend::~VulkanBackend() = default;

int VulkanBackend::maxTextureSize() const {
  return static_cast<int>(impl_->properties.limits.maxImageDimension2D);
}

int VulkanBackend::maxArrayLayers() const {
  return static_cast<int>(impl_->properties.limits.maxImageArrayLayers);
}

int VulkanBackend::max3DTextureSize() const {
  return static_cast<int>(impl_->properties.limits.maxImageDimension3D);
}

ComputeLimits VulkanBackend::computeLimits() const {
  const VkPhysicalDeviceLimits& v = impl_->properties.limits;
  ComputeLimits l;
  for (int axis = 0; axis < 3; ++axis) {
    l.groupSize[axis] = static_cast<int>(v.maxComputeWorkGroupSize[axis]);
    l.groupCount[axis] =
        static_cast<int>(std::min<std::uint32_t>(v.maxComputeWorkGroupCount[axis], 0x7fffffffu));
  }
  l.invocations = static_cast<int>(v.maxComputeWorkGroupInvocations);
  return l;
}

VulkanBackend::EngineDevice VulkanBackend::runsOn() const {
  const Impl& v = *impl_;
  EngineDevice e;
  e.instance = v.instance;
  e.physicalDevice = v.physical;
  e.device = v.device;
  e.queueFamily = v.family;
  e.queue = v.queue;
  e.getInstanceProcAddr = v.getInstanceProcAddr;
  e.getDeviceProcAddr = v.getDeviceProcAddr;
  e.pipelineCache = v.pipelineCache;
  e.allocator = v.allocator;
  return e;
}

std::string VulkanBackend::deviceName() const {
  return impl_->properties.deviceName;
}

bool VulkanBackend::usesPushDescriptors() const {
  return impl_->pushDescriptors;
}

std::vector<std::string> VulkanBackend::validationMessages() const {
  const std::lock_guard lock(impl_->log.mutex);
  return impl_->log.messages;
}

TextureDesc VulkanBackend::describe(TextureId texture) const {
  TextureDesc d = impl_->image(texture, "gpu::VulkanBackend texture").desc;
  d.label.clear();
  return d;
}

std::size_t VulkanBackend::bufferBytes(BufferId buffer) const {
  return impl_->buffer(buffer, "gpu::VulkanBackend buffer").bytes;
}

void VulkanBackend::prepareProgram(const std::string& program, std::span<const ShaderDefine> defines) {
  impl_->module(program, defines);
}

TextureId VulkanBackend::createTexture(const TextureDesc& desc) {
  checkTextureSize(*this, "gpu::TextureDesc.width/height", desc.width, desc.height);
  if (desc.depth < 1 || (desc.type == TextureType::Texture2D && desc.depth != 1))
    throw InvalidArgument("gpu::TextureDesc.depth", std::to_string(desc.depth),
                          "must be >= 1 (1 for a Texture2D)");
  const int max3D = max3DTextureSize();
  if (desc.type == TextureType::Texture3D &&
      (desc.width > max3D || desc.height > max3D || desc.depth > max3D))
    throw InvalidArgument("gpu::TextureDesc.width/height/depth",
                          std::to_string(desc.width) + " x " + std::to_string(desc.height) + " x " +
                              std::to_string(desc.depth),
                          "must each be <= maxImageDimension3D (" + std::to_string(max3D) + ")");
  Impl& v = *impl_;
  ImageEntry e;
  e.desc = desc;
  const bool depth = desc.format == Format::Depth32F;
  VkImageCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  ci.imageType = desc.type == TextureType::Texture3D ? VK_IMAGE_TYPE_3D : VK_IMAGE_TYPE_2D;
  ci.format = vkFormat(desc.format);
  ci.extent = {static_cast<std::uint32_t>(desc.width), static_cast<std::uint32_t>(desc.height),
               desc.type == TextureType::Texture3D ? static_cast<std::uint32_t>(desc.depth) : 1u};
  ci.mipLevels = 1;
  ci.arrayLayers = desc.type == TextureType::Texture2DArray ? static_cast<std::uint32_t>(desc.depth) : 1u;
  ci.samples = VK_SAMPLE_COUNT_1_BIT;
  ci.tiling = VK_IMAGE_TILING_OPTIMAL;
  ci.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
             (depth ? 0u : static_cast<VkImageUsageFlags>(VK_IMAGE_USAGE_STORAGE_BIT));
  ci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  check(v.vk.vkCreateImage(v.device, &ci, v.allocator, &e.image), "vkCreateImage");
  VkMemoryRequirements req;
  v.vk.vkGetImageMemoryRequirements(v.device, e.image, &req);
  VkMemoryAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = v.memoryType(req.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  check(v.vk.vkAllocateMemory(v.device, &ai, v.allocator, &e.memory), "vkAllocateMemory (image)");
  check(v.vk.vkBindImageMemory(v.device, e.image, e.memory, 0), "vkBindImageMemory");
  VkImageViewCreateInfo vi{};
  vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  vi.image = e.image;
  vi.viewType = desc.type == TextureType::Texture3D        ? VK_IMAGE_VIEW_TYPE_3D
                : desc.type == TextureType::Texture2DArray ? VK_IMAGE_VIEW_TYPE_2D_ARRAY
                                                           : VK_IMAGE_VIEW_TYPE_2D;
  vi.format = ci.format;
  vi.subresourceRange = {
      static_cast<VkImageAspectFlags>(depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT), 0, 1, 0,
      ci.arrayLayers};
  check(v.vk.vkCreateImageView(v.device, &vi, v.allocator, &e.view), "vkCreateImageView");
  e.format = ci.format;
  e.aspect = vi.subresourceRange.aspectMask;
  e.usage = ci.usage;
  // GPU: every image lives in VK_IMAGE_LAYOUT_GENERAL (sampled, stored and copied without transitions); some
  // GPUs sample faster from SHADER_READ_ONLY_OPTIMAL.
  v.begin();
  VkImageMemoryBarrier b{};
  b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  b.srcAccessMask = 0;
  b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  b.newLayout = VK_IMAGE_LAYOUT_GENERAL;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = e.image;
  b.subresourceRange = vi.subresourceRange;
  v.vk.vkCmdPipelineBarrier(v.cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                            VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                            nullptr, 0, nullptr, 1, &b);
  const TextureId id = v.nextId++;
  v.images[id] = e;
  return id;
}

void VulkanBackend::destroyTexture(TextureId texture) {
  Impl& v = *impl_;
  const auto it = v.images.find(texture);
  if (it == v.images.end()) return;
  if (it->second.imported) {
    // The engine's image: forgotten, never destroyed; it must still be in its home layout.
    if (it->second.current != it->second.home)
      throw InvalidArgument(
          "gpu::VulkanBackend::destroyTexture texture", std::to_string(texture),
          "is an engine image in use by the frame being recorded: forget it after endFrame()");
    v.images.erase(it);
    return;
  }
  if (v.inFrame || v.frameIndex > v.completedFrame) {
    v.retiring().images.push_back(it->second); // frames in flight may use it: released once they complete
  } else {
    v.submit(); // the recorded calls may use it
    v.destroyImage(it->second);
  }
  v.images.erase(it);
}

namespace {
/// The seam's format of an engine image's VkFormat (any depth format reads as Depth32F); false if none.
bool seamFormat(VkFormat f, Format& out, VkImageAspectFlags& aspect) {
  aspect = VK_IMAGE_ASPECT_COLOR_BIT;
  switch (f) {
  case VK_FORMAT_D32_SFLOAT_S8_UINT:
  case VK_FORMAT_D24_UNORM_S8_UINT:
  case VK_FORMAT_D16_UNORM_S8_UINT:
    aspect = VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
    out = Format::Depth32F;
    return true;
  case VK_FORMAT_D32_SFLOAT:
  case VK_FORMAT_X8_D24_UNORM_PACK32:
  case VK_FORMAT_D16_UNORM:
    aspect = VK_IMAGE_ASPECT_DEPTH_BIT;
    out = Format::Depth32F;
    return true;
  default:
    break;
  }
  for (Format candidate :
       {Format::R32F, Format::RG32F, Format::RGBA32F, Format::RGBA16F, Format::RGBA8, Format::RG32I})
    if (vkFormat(candidate) == f) {
      out = candidate;
      return true;
    }
  return false;
}
} // namespace

TextureId VulkanBackend::importTexture(const EngineImage& image) {
  Impl& v = *impl_;
  const std::string field = "gpu::VulkanBackend::importTexture image.";
  if (image.image == VK_NULL_HANDLE)
    throw InvalidArgument(field + "image", "null", "must be the engine's VkImage");
  if (image.view == VK_NULL_HANDLE)
    throw InvalidArgument(field + "view", "null",
                          "must be a view of the whole image (its depth aspect for depth)");
  ImageEntry e;
  if (!seamFormat(image.format, e.desc.format, e.aspect))
    throw InvalidArgument(field + "format", std::to_string(static_cast<int>(image.format)),
                          "must be R32_SFLOAT, R32G32_SFLOAT, R32G32B32A32_SFLOAT, R16G16B16A16_SFLOAT, "
                          "R8G8B8A8_UNORM, R32G32_SINT or a depth format");
  if (image.width == 0 || image.height == 0 || image.depth == 0)
    throw InvalidArgument(field + "width/height/depth",
                          std::to_string(image.width) + " x " + std::to_string(image.height) + " x " +
                              std::to_string(image.depth),
                          "must each be > 0");
  if ((image.usage & (VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT)) == 0)
    throw InvalidArgument(field + "usage", std::to_string(image.usage),
                          "must include VK_IMAGE_USAGE_SAMPLED_BIT or VK_IMAGE_USAGE_STORAGE_BIT");
  if (image.layout == VK_IMAGE_LAYOUT_UNDEFINED || image.layout == VK_IMAGE_LAYOUT_PREINITIALIZED)
    throw InvalidArgument(field + "layout", std::to_string(static_cast<int>(image.layout)),
                          "must be the layout its contents are in");
  e.desc.type = image.type;
  e.desc.width = static_cast<int>(image.width);
  e.desc.height = static_cast<int>(image.height);
  e.desc.depth = static_cast<int>(image.depth);
  e.desc.label = image.label;
  e.image = image.image;
  e.view = image.view;
  e.imported = true;
  e.format = image.format;
  e.usage = image.usage;
  e.home = e.current = image.layout;
  const TextureId id = v.nextId++;
  v.images[id] = e;
  return id;
}

void VulkanBackend::setTextureLayout(TextureId texture, VkImageLayout layout) {
  Impl& v = *impl_;
  ImageEntry& e = v.image(texture, "gpu::VulkanBackend::setTextureLayout texture");
  if (!e.imported || e.current != e.home)
    throw InvalidArgument("gpu::VulkanBackend::setTextureLayout texture", std::to_string(texture),
                          e.imported ? "is in use by the frame being recorded (set it before its first use)"
                                     : "must be an engine image (importTexture)");
  if (layout == VK_IMAGE_LAYOUT_UNDEFINED || layout == VK_IMAGE_LAYOUT_PREINITIALIZED)
    throw InvalidArgument("gpu::VulkanBackend::setTextureLayout layout",
                          std::to_string(static_cast<int>(layout)), "must be the layout its contents are in");
  e.home = e.current = layout;
}

BufferId VulkanBackend::createBuffer(std::size_t bytes, std::string_view) {
  if (bytes == 0) throw InvalidArgument("gpu::Backend::createBuffer bytes", "0", "must be > 0");
  Impl& v = *impl_;
  const BufferId id = v.nextId++;
  v.buffers[id] =
      v.makeBuffer(bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT |
                              VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                              VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  return id;
}

void VulkanBackend::destroyBuffer(BufferId buffer) {
  Impl& v = *impl_;
  const auto it = v.buffers.find(buffer);
  if (it == v.buffers.end()) return;
  if (v.inFrame || v.frameIndex > v.completedFrame) {
    v.retiring().buffers.push_back(it->second);
  } else {
    v.submit();
    v.freeBuffer(it->second);
  }
  v.buffers.erase(it);
}

void VulkanBackend::writeBuffer(BufferId buffer, std::size_t offset, std::span<const std::byte> bytes) {
  Impl& v = *impl_;
  BufferEntry& b = v.buffer(buffer, "gpu::VulkanBackend::writeBuffer buffer");
  if (offset + bytes.size() > b.bytes)
    throw InvalidArgument("gpu::VulkanBackend::writeBuffer bytes", std::to_string(offset + bytes.size()),
                          "must fit in the buffer's " + std::to_string(b.bytes) + " bytes");
  if (bytes.empty()) return;
  // In the command stream, after the calls recorded before it (a host write would overtake them).
  v.begin();
  v.barrier();
  if (bytes.size() <= 65536 && offset % 4 == 0 && bytes.size() % 4 == 0) {
    // Small writes (a pass's blocks) go into the command buffer itself: no allocation per write.
    v.vk.vkCmdUpdateBuffer(v.cmd, b.buffer, offset, bytes.size(), bytes.data());
    return;
  }
  BufferEntry s = v.makeBuffer(bytes.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  std::memcpy(s.mapped, bytes.data(), bytes.size());
  const VkBufferCopy region{0, offset, bytes.size()};
  v.vk.vkCmdCopyBuffer(v.cmd, s.buffer, b.buffer, 1, &region);
  (v.inFrame ? v.retiring().buffers : v.staging).push_back(s);
}

void VulkanBackend::writeTexture(TextureId texture, std::span<const float> texels) {
  Impl& v = *impl_;
  ImageEntry& e = v.copyableImage(texture, "gpu::VulkanBackend::writeTexture texture");
  const TextureDesc& d = e.desc;
  const std::size_t count = static_cast<std::size_t>(d.width) * static_cast<std::size_t>(d.height) *
                            static_cast<std::size_t>(d.depth);
  const std::size_t components = static_cast<std::size_t>(componentCount(d.format));
  if (texels.size() != count * components)
    throw InvalidArgument("gpu::Backend::writeTexture texels", std::to_string(texels.size()),
                          "must hold " + std::to_string(count * components) + " floats (the whole texture)");
  BufferEntry s = v.makeBuffer(count * texelBytes(d.format), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  if (d.format == Format::RGBA16F) {
    auto* out = static_cast<std::uint16_t*>(s.mapped);
    for (std::size_t i = 0; i < texels.size(); ++i)
      out[i] = halfBits(texels[i]);
  } else if (d.format == Format::RGBA8) {
    auto* out = static_cast<std::uint8_t*>(s.mapped);
    for (std::size_t i = 0; i < texels.size(); ++i)
      out[i] = static_cast<std::uint8_t>(std::lround(std::clamp(texels[i], 0.0f, 1.0f) * 255.0f));
  } else if (d.format == Format::RG32I) {
    auto* out = static_cast<std::int32_t*>(s.mapped);
    for (std::size_t i = 0; i < texels.size(); ++i)
      out[i] = static_cast<std::int32_t>(std::lround(texels[i]));
  } else {
    std::memcpy(s.mapped, texels.data(), texels.size_bytes());
  }
  v.begin();
  v.barrier();
  const VkBufferImageCopy region = wholeCopy(e);
  // Copies in the transfer layouts (GPU: the fast path of a copy engine), then back to GENERAL.
  v.transition(e, e.current, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
  v.vk.vkCmdCopyBufferToImage(v.cmd, s.buffer, e.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  v.transition(e, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, e.current);
  (v.inFrame ? v.retiring().buffers : v.staging).push_back(s);
}

std::vector<std::byte> VulkanBackend::readBuffer(BufferId buffer, std::size_t offset, std::size_t bytes) {
  Impl& v = *impl_;
  v.refuseInFrame("gpu::VulkanBackend::readBuffer");
  BufferEntry& b = v.buffer(buffer, "gpu::VulkanBackend::readBuffer buffer");
  if (offset + bytes > b.bytes)
    throw InvalidArgument("gpu::VulkanBackend::readBuffer bytes", std::to_string(offset + bytes),
                          "must fit in the buffer's " + std::to_string(b.bytes) + " bytes");
  v.submit();
  std::vector<std::byte> out(bytes);
  std::memcpy(out.data(), static_cast<const std::byte*>(b.mapped) + offset, bytes);
  return out;
}

std::vector<float> VulkanBackend::readTexture(TextureId texture) {
  Impl& v = *impl_;
  v.refuseInFrame("gpu::VulkanBackend::readTexture");
  ImageEntry& e = v.copyableImage(texture, "gpu::VulkanBackend::readTexture texture");
  const TextureDesc& d = e.desc;
  const std::size_t count = static_cast<std::size_t>(d.width) * static_cast<std::size_t>(d.height) *
                            static_cast<std::size_t>(d.depth);
  BufferEntry s = v.makeBuffer(count * texelBytes(d.format), VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  v.begin();
  v.barrier();
  const VkBufferImageCopy region = wholeCopy(e);
  v.transition(e, e.current, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  v.vk.vkCmdCopyImageToBuffer(v.cmd, e.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, s.buffer, 1, &region);
  v.transition(e, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, e.current);
  v.submit();
  std::vector<float> out(count * static_cast<std::size_t>(componentCount(d.format)));
  if (d.format == Format::RGBA16F) {
    const auto* in = static_cast<const std::uint16_t*>(s.mapped);
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = glm::unpackHalf1x16(in[i]);
  } else if (d.format == Format::RGBA8) {
    const auto* in = static_cast<const std::uint8_t*>(s.mapped);
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = static_cast<float>(in[i]) / 255.0f;
  } else if (d.format == Format::RG32I) {
    const auto* in = static_cast<const std::int32_t*>(s.mapped);
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = static_cast<float>(in[i]);
  } else {
    std::memcpy(out.data(), s.mapped, out.size() * sizeof(float));
  }
  v.freeBuffer(s);
  return out;
}

void VulkanBackend::dispatch(const Dispatch& given) {
  // The resources in binding order, for the descriptor layout and the writes alike (one pipeline per
  // signature whatever order a pass lists them in); a binding given twice is the pass's error.
  Dispatch d = given;
  std::stable_sort(d.resources.begin(), d.resources.end(),
                   [](const Resource& a, const Resource& b) { return vulkanBinding(a) < vulkanBinding(b); });
  for (std::size_t i = 1; i < d.resources.size(); ++i)
    if (vulkanBinding(d.resources[i]) == vulkanBinding(d.resources[i - 1]))
      throw InvalidArgument(d.label + " resources",
                            "binding " + std::to_string(vulkanBinding(d.resources[i])), "is given twice");
  Impl& v = *impl_;
  const std::vector<std::byte> push = packPushConstants(d.push);
  const Pipeline& p = v.pipeline(d, push.size());
  std::vector<VkDescriptorImageInfo> imageInfos(d.resources.size());
  std::vector<VkDescriptorBufferInfo> bufferInfos(d.resources.size());
  std::vector<VkWriteDescriptorSet> writes;
  v.begin();
  v.barrier();
  for (const Resource& r : d.resources) {
    if (r.kind != ResourceKind::SampledTexture && r.kind != ResourceKind::StorageImage) continue;
    ImageEntry& e = v.image(r.texture, (d.label + " texture").c_str());
    const bool storage = r.kind == ResourceKind::StorageImage;
    if ((e.usage & (storage ? VK_IMAGE_USAGE_STORAGE_BIT : VK_IMAGE_USAGE_SAMPLED_BIT)) == 0)
      throw InvalidArgument(d.label + " texture", std::to_string(r.texture),
                            storage ? "must have VK_IMAGE_USAGE_STORAGE_BIT (the pass writes it)"
                                    : "must have VK_IMAGE_USAGE_SAMPLED_BIT (the pass samples it)");
    if (e.imported) v.useImage(r.texture, e, storage);
  }
  for (std::size_t i = 0; i < d.resources.size(); ++i) {
    const Resource& r = d.resources[i];
    VkWriteDescriptorSet w{};
    w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    w.dstBinding = vulkanBinding(r);
    w.descriptorCount = 1;
    w.descriptorType = descriptorType(r.kind);
    if (r.kind == ResourceKind::SampledTexture || r.kind == ResourceKind::StorageImage) {
      const ImageEntry& e = v.image(r.texture, (d.label + " texture").c_str());
      imageInfos[i] = {r.kind == ResourceKind::SampledTexture
                           ? (r.filter == Filter::Linear ? v.linear : v.nearest)
                           : VK_NULL_HANDLE,
                       e.view, e.current};
      w.pImageInfo = &imageInfos[i];
    } else {
      const BufferEntry& b = v.buffer(r.buffer, (d.label + " buffer").c_str());
      bufferInfos[i] = {b.buffer, r.offset, r.size != 0 ? r.size : VK_WHOLE_SIZE};
      w.pBufferInfo = &bufferInfos[i];
    }
    writes.push_back(w);
  }
  v.vk.vkCmdBindPipeline(v.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  if (!writes.empty() && v.pushDescriptors) {
    v.vk.vkCmdPushDescriptorSetKHR(v.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0,
                                   static_cast<std::uint32_t>(writes.size()), writes.data());
  } else if (!writes.empty()) {
    // A set of its own per dispatch, written before it is bound (never updated after).
    const VkDescriptorSet set = v.allocateSet(p);
    for (VkWriteDescriptorSet& w : writes)
      w.dstSet = set;
    v.vk.vkUpdateDescriptorSets(v.device, static_cast<std::uint32_t>(writes.size()), writes.data(), 0,
                                nullptr);
    v.vk.vkCmdBindDescriptorSets(v.cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &set, 0, nullptr);
  }
  if (!push.empty())
    v.vk.vkCmdPushConstants(v.cmd, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0,
                            static_cast<std::uint32_t>(push.size()), push.data());
  if (d.indirect != 0)
    v.vk.vkCmdDispatchIndirect(v.cmd, v.buffer(d.indirect, (d.label + " indirect").c_str()).buffer,
                               d.indirectOffset);
  else if (d.groups.x > 0 && d.groups.y > 0 && d.groups.z > 0)
    v.vk.vkCmdDispatch(v.cmd, d.groups.x, d.groups.y, d.groups.z);
}

void VulkanBackend::finish() {
  impl_->refuseInFrame("gpu::VulkanBackend::finish");
  impl_->submit();
}

void VulkanBackend::beginFrame(const Frame& frame) {
  Impl& v = *impl_;
  const char* field = "gpu::VulkanBackend::beginFrame frame";
  if (v.inFrame)
    throw InvalidArgument(std::string(field) + ".index", std::to_string(frame.index),
                          "frame " + std::to_string(v.frameIndex) + " is still being recorded (endFrame())");
  if (frame.commandBuffer == VK_NULL_HANDLE)
    throw InvalidArgument(std::string(field) + ".commandBuffer", "null", "must be the engine's, recording");
  if (frame.index <= v.frameIndex)
    throw InvalidArgument(std::string(field) + ".index", std::to_string(frame.index),
                          "must be > the last frame's index " + std::to_string(v.frameIndex));
  if (frame.completed >= frame.index || frame.completed < v.completedFrame)
    throw InvalidArgument(std::string(field) + ".completed", std::to_string(frame.completed),
                          "must be < index " + std::to_string(frame.index) + " and >= the last frame's " +
                              std::to_string(v.completedFrame));
  if (frame.index - frame.completed > v.framesInFlight)
    throw InvalidArgument(
        std::string(field) + ".completed", std::to_string(frame.completed),
        "must be >= index - framesInFlight = " + std::to_string(frame.index - v.framesInFlight) +
            " (wait for that frame before recording this one)");
  // Work recorded outside frames since the last one (pass creation, uploads) goes first, submitted and
  // waited for here: call finish() after setting up so that no frame starts with a wait.
  v.submit();
  v.completedFrame = frame.completed;
  v.release(frame.completed);
  v.frameIndex = frame.index;
  const std::size_t slot = static_cast<std::size_t>(frame.index % v.framesInFlight);
  v.resetPools(v.framePools[slot]); // its last frame (index - framesInFlight) has completed
  v.frameCurrentPool[slot] = 0;
  v.inFrame = true;
  v.cmd = frame.commandBuffer;
  // Entry: the engine's earlier writes (any stage) are visible to the library's compute and transfer work.
  VkMemoryBarrier m{};
  m.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  m.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
  m.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_UNIFORM_READ_BIT |
                    VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT |
                    VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
  v.vk.vkCmdPipelineBarrier(v.cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                            VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT |
                                VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                            0, 1, &m, 0, nullptr, 0, nullptr);
}

void VulkanBackend::endFrame() {
  Impl& v = *impl_;
  if (!v.inFrame)
    throw InvalidArgument("gpu::VulkanBackend::endFrame", "no frame", "must follow beginFrame()");
  v.restoreImages(); // the engine's images back in their layouts
  // Exit: the library's writes (compute, transfer) are visible to whatever the engine records next.
  VkMemoryBarrier m{};
  m.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  m.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  m.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
  v.vk.vkCmdPipelineBarrier(v.cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                            VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &m, 0, nullptr, 0, nullptr);
  v.inFrame = false;
  v.cmd = v.ownCmd;
}

void VulkanBackend::frameCompleted(std::uint64_t completed) {
  Impl& v = *impl_;
  if (completed > v.frameIndex || completed < v.completedFrame)
    throw InvalidArgument("gpu::VulkanBackend::frameCompleted completed", std::to_string(completed),
                          "must be in [" + std::to_string(v.completedFrame) + ", " +
                              std::to_string(v.frameIndex) + "]");
  v.completedFrame = completed;
  v.release(completed);
}

bool VulkanBackend::inFrame() const {
  return impl_->inFrame;
}

double VulkanBackend::Impl::spanMilliseconds(TimerId id, bool wait) {
  const std::uint32_t first = 2 * static_cast<std::uint32_t>(id % kSpans);
  std::uint64_t ticks[2] = {0, 0};
  check(vk.vkGetQueryPoolResults(device, timestamps, first, 2, sizeof ticks, ticks, sizeof ticks[0],
                                 VK_QUERY_RESULT_64_BIT |
                                     (wait ? static_cast<VkQueryResultFlags>(VK_QUERY_RESULT_WAIT_BIT) : 0u)),
        "vkGetQueryPoolResults (timestamps)");
  const std::uint64_t mask = timestampBits >= 64 ? ~0ull : (1ull << timestampBits) - 1ull;
  const std::uint64_t elapsed = (ticks[1] - ticks[0]) & mask; // a wrapped counter too
  return static_cast<double>(elapsed) * static_cast<double>(properties.limits.timestampPeriod) * 1e-6;
}

void VulkanBackend::beginTimer() {
  Impl& v = *impl_;
  if (v.timestamps == VK_NULL_HANDLE) return;
  v.begin();
  // A span's two queries in the ring, reset in the command stream before its first timestamp.
  const TimerId id = ++v.lastSpan;
  if (id > Impl::kSpans) v.pendingSpans.erase(id - Impl::kSpans); // its slot's previous span: dropped
  const std::uint32_t first = 2 * static_cast<std::uint32_t>(id % Impl::kSpans);
  v.vk.vkCmdResetQueryPool(v.cmd, v.timestamps, first, 2);
  v.vk.vkCmdWriteTimestamp(v.cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, v.timestamps, first);
  v.timing = true;
}

double VulkanBackend::endTimer() {
  Impl& v = *impl_;
  v.refuseInFrame("gpu::VulkanBackend::endTimer");
  if (!v.timing) {
    finish();
    return 0.0;
  }
  v.begin();
  v.vk.vkCmdWriteTimestamp(v.cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, v.timestamps,
                           2 * static_cast<std::uint32_t>(v.lastSpan % Impl::kSpans) + 1);
  v.timing = false;
  v.submit();
  return v.spanMilliseconds(v.lastSpan, true);
}

TimerId VulkanBackend::endTimerDeferred() {
  Impl& v = *impl_;
  if (!v.timing) return 0;
  v.begin();
  v.vk.vkCmdWriteTimestamp(v.cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, v.timestamps,
                           2 * static_cast<std::uint32_t>(v.lastSpan % Impl::kSpans) + 1);
  v.timing = false;
  v.pendingSpans[v.lastSpan] = {v.inFrame ? v.frameIndex : 0, v.submissions + 1};
  return v.lastSpan;
}

std::optional<double> VulkanBackend::timerResult(TimerId id) {
  Impl& v = *impl_;
  const auto it = v.pendingSpans.find(id);
  if (it == v.pendingSpans.end()) return 0.0; // none, read, or dropped (its slot reused)
  // Its queries hold its timestamps only once the commands that reset and wrote them have completed: the
  // engine's frame (Frame::completed), or the backend's own submission (each one waited for). Never waits.
  const bool done =
      it->second.frame != 0 ? it->second.frame <= v.completedFrame : it->second.submission <= v.submissions;
  if (!done) return std::nullopt;
  v.pendingSpans.erase(it);
  return v.spanMilliseconds(id, false);
}

void VulkanBackend::cancelTimer() noexcept {
  impl_->timing = false; // the span's queries stay unread; its slot is reset when the ring comes round
}

} // namespace crep::gpu
