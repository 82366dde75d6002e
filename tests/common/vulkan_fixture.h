// The Vulkan tests' device (tests/vulkan/): gpu::VulkanBackend with the validation layer on, and the check
// that the layer said nothing; and an engine's own instance and device (EngineVulkanDevice) with a loader
// that counts what the backend asks of it (LoaderSpy). Header-only: only the tests that link crep::vulkan
// include it.
#pragma once

#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace crep::test {

/// A VulkanBackend's CreateInfo with VK_LAYER_KHRONOS_validation on.
inline gpu::VulkanBackend::CreateInfo validatedVulkan() {
  gpu::VulkanBackend::CreateInfo info;
  info.validation = true;
  return info;
}

/// No warning or error of the validation layer among `messages` (every message printed on failure).
inline void checkNoValidationMessages(const std::vector<std::string>& messages) {
  std::string all;
  for (const std::string& m : messages)
    all += "\n" + m;
  CHECK_MESSAGE(messages.empty(), messages.size() << " validation messages:" << all);
}

/// No warning or error of the validation layer so far (every message printed on failure).
inline void checkNoValidationMessages(const gpu::VulkanBackend& vk) {
  checkNoValidationMessages(vk.validationMessages());
}

/// The loader's entry point as an engine that loads Vulkan itself gets it: libvulkan.so.1's
/// vkGetInstanceProcAddr by dlsym, no prototype called.
inline PFN_vkGetInstanceProcAddr loaderEntryPoint() {
  static void* const library = dlopen("libvulkan.so.1", RTLD_NOW | RTLD_LOCAL);
  REQUIRE_MESSAGE(library != nullptr, "libvulkan.so.1 cannot be opened");
  const auto entry = reinterpret_cast<PFN_vkGetInstanceProcAddr>(dlsym(library, "vkGetInstanceProcAddr"));
  const bool found = entry != nullptr;
  REQUIRE_MESSAGE(found, "libvulkan.so.1 has no vkGetInstanceProcAddr");
  return entry;
}

/// The loader handed to a backend: vkGetInstanceProcAddr and vkGetDeviceProcAddr that count each name asked
/// of them and hand out counting forms of vkCreateInstance, vkCreateDevice, vkDestroyDevice and
/// vkDestroyInstance (a backend on an engine's device must call none of them). One spy at a time (a plain
/// function pointer carries no state): reset() before each backend.
struct LoaderSpy {
  static inline PFN_vkGetInstanceProcAddr realInstanceProcAddr = nullptr;
  static inline PFN_vkGetDeviceProcAddr realDeviceProcAddr = nullptr;
  static inline std::map<std::string, int> instanceLookups, deviceLookups; ///< name -> times asked
  static inline int createInstanceCalls = 0, createDeviceCalls = 0, destroyDeviceCalls = 0,
                    destroyInstanceCalls = 0;
  /// What would make a frame wait: submissions and host waits by the backend (the engine's own calls go
  /// through its own pointers and are not counted). A query read counts as a wait when it asks to wait.
  static inline int queueSubmitCalls = 0, waitForFencesCalls = 0, queueWaitIdleCalls = 0,
                    deviceWaitIdleCalls = 0, waitingQueryReads = 0;
  static inline PFN_vkQueueSubmit realQueueSubmit = nullptr;
  static inline PFN_vkWaitForFences realWaitForFences = nullptr;
  static inline PFN_vkQueueWaitIdle realQueueWaitIdle = nullptr;
  static inline PFN_vkDeviceWaitIdle realDeviceWaitIdle = nullptr;
  static inline PFN_vkGetQueryPoolResults realGetQueryPoolResults = nullptr;
  /// Submissions and waits so far.
  static int stalls() {
    return queueSubmitCalls + waitForFencesCalls + queueWaitIdleCalls + deviceWaitIdleCalls +
           waitingQueryReads;
  }
  static inline PFN_vkCreateInstance realCreateInstance = nullptr;
  static inline PFN_vkCreateDevice realCreateDevice = nullptr;
  static inline PFN_vkDestroyDevice realDestroyDevice = nullptr;
  static inline PFN_vkDestroyInstance realDestroyInstance = nullptr;

  static void reset(PFN_vkGetInstanceProcAddr instanceProcAddr) {
    realInstanceProcAddr = instanceProcAddr;
    realDeviceProcAddr = nullptr;
    instanceLookups.clear();
    deviceLookups.clear();
    createInstanceCalls = createDeviceCalls = destroyDeviceCalls = destroyInstanceCalls = 0;
    queueSubmitCalls = waitForFencesCalls = queueWaitIdleCalls = deviceWaitIdleCalls = waitingQueryReads = 0;
  }
  static int lookups() {
    int n = 0;
    for (const auto& [name, count] : instanceLookups)
      n += count;
    for (const auto& [name, count] : deviceLookups)
      n += count;
    return n;
  }
  /// Whether `name` was asked of either entry point.
  static bool looked(const std::string& name) {
    return instanceLookups.count(name) != 0 || deviceLookups.count(name) != 0;
  }

  static VKAPI_ATTR VkResult VKAPI_CALL createInstance(const VkInstanceCreateInfo* ci,
                                                       const VkAllocationCallbacks* a, VkInstance* out) {
    ++createInstanceCalls;
    return realCreateInstance(ci, a, out);
  }
  static VKAPI_ATTR VkResult VKAPI_CALL createDevice(VkPhysicalDevice p, const VkDeviceCreateInfo* ci,
                                                     const VkAllocationCallbacks* a, VkDevice* out) {
    ++createDeviceCalls;
    return realCreateDevice(p, ci, a, out);
  }
  static VKAPI_ATTR void VKAPI_CALL destroyDevice(VkDevice d, const VkAllocationCallbacks* a) {
    ++destroyDeviceCalls;
    realDestroyDevice(d, a);
  }
  static VKAPI_ATTR void VKAPI_CALL destroyInstance(VkInstance i, const VkAllocationCallbacks* a) {
    ++destroyInstanceCalls;
    realDestroyInstance(i, a);
  }

  static VKAPI_ATTR VkResult VKAPI_CALL queueSubmit(VkQueue q, std::uint32_t n, const VkSubmitInfo* si,
                                                    VkFence f) {
    ++queueSubmitCalls;
    return realQueueSubmit(q, n, si, f);
  }
  static VKAPI_ATTR VkResult VKAPI_CALL waitForFences(VkDevice d, std::uint32_t n, const VkFence* f,
                                                      VkBool32 all, std::uint64_t timeout) {
    ++waitForFencesCalls;
    return realWaitForFences(d, n, f, all, timeout);
  }
  static VKAPI_ATTR VkResult VKAPI_CALL queueWaitIdle(VkQueue q) {
    ++queueWaitIdleCalls;
    return realQueueWaitIdle(q);
  }
  static VKAPI_ATTR VkResult VKAPI_CALL deviceWaitIdle(VkDevice d) {
    ++deviceWaitIdleCalls;
    return realDeviceWaitIdle(d);
  }
  static VKAPI_ATTR VkResult VKAPI_CALL getQueryPoolResults(VkDevice d, VkQueryPool p, std::uint32_t first,
                                                            std::uint32_t count, std::size_t size, void* data,
                                                            VkDeviceSize stride, VkQueryResultFlags flags) {
    if ((flags & VK_QUERY_RESULT_WAIT_BIT) != 0) ++waitingQueryReads;
    return realGetQueryPoolResults(d, p, first, count, size, data, stride, flags);
  }

  /// The counting form of `name`, or `real` itself.
  static PFN_vkVoidFunction wrap(const char* name, PFN_vkVoidFunction real) {
    if (real == nullptr) return nullptr;
    const std::string n = name;
    if (n == "vkCreateInstance") {
      realCreateInstance = reinterpret_cast<PFN_vkCreateInstance>(real);
      return reinterpret_cast<PFN_vkVoidFunction>(&createInstance);
    }
    if (n == "vkCreateDevice") {
      realCreateDevice = reinterpret_cast<PFN_vkCreateDevice>(real);
      return reinterpret_cast<PFN_vkVoidFunction>(&createDevice);
    }
    if (n == "vkDestroyDevice") {
      realDestroyDevice = reinterpret_cast<PFN_vkDestroyDevice>(real);
      return reinterpret_cast<PFN_vkVoidFunction>(&destroyDevice);
    }
    if (n == "vkDestroyInstance") {
      realDestroyInstance = reinterpret_cast<PFN_vkDestroyInstance>(real);
      return reinterpret_cast<PFN_vkVoidFunction>(&destroyInstance);
    }
#define CREP_TEST_COUNT(vkName, member, wrapper)                                                             \
  if (n == #vkName) {                                                                                        \
    member = reinterpret_cast<PFN_##vkName>(real);                                                           \
    return reinterpret_cast<PFN_vkVoidFunction>(&wrapper);                                                   \
  }
    CREP_TEST_COUNT(vkQueueSubmit, realQueueSubmit, queueSubmit)
    CREP_TEST_COUNT(vkWaitForFences, realWaitForFences, waitForFences)
    CREP_TEST_COUNT(vkQueueWaitIdle, realQueueWaitIdle, queueWaitIdle)
    CREP_TEST_COUNT(vkDeviceWaitIdle, realDeviceWaitIdle, deviceWaitIdle)
    CREP_TEST_COUNT(vkGetQueryPoolResults, realGetQueryPoolResults, getQueryPoolResults)
#undef CREP_TEST_COUNT
    if (n == "vkGetInstanceProcAddr") return reinterpret_cast<PFN_vkVoidFunction>(&getInstanceProcAddr);
    if (n == "vkGetDeviceProcAddr") {
      realDeviceProcAddr = reinterpret_cast<PFN_vkGetDeviceProcAddr>(real);
      return reinterpret_cast<PFN_vkVoidFunction>(&getDeviceProcAddr);
    }
    return real;
  }
  static VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL getInstanceProcAddr(VkInstance instance, const char* name) {
    ++instanceLookups[name];
    return wrap(name, realInstanceProcAddr(instance, name));
  }
  static VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL getDeviceProcAddr(VkDevice device, const char* name) {
    ++deviceLookups[name];
    return wrap(name, realDeviceProcAddr(device, name));
  }
};

/// Host allocation callbacks that count what goes through them (malloc-backed, any alignment up to 4096).
struct CountingAllocator {
  std::mutex mutex;
  std::map<void*, std::size_t> live; ///< pointer -> size
  long long allocations = 0, frees = 0;
  VkAllocationCallbacks callbacks{this, &allocate, &reallocate, &release, nullptr, nullptr};

  long long liveCount() {
    const std::lock_guard lock(mutex);
    return static_cast<long long>(live.size());
  }

private:
  static VKAPI_ATTR void* VKAPI_CALL allocate(void* user, std::size_t size, std::size_t alignment,
                                              VkSystemAllocationScope) {
    auto* self = static_cast<CountingAllocator*>(user);
    void* p = nullptr;
    if (posix_memalign(&p, std::max(alignment, sizeof(void*)), std::max<std::size_t>(size, 1)) != 0)
      return nullptr;
    const std::lock_guard lock(self->mutex);
    self->live[p] = size;
    ++self->allocations;
    return p;
  }
  static VKAPI_ATTR void* VKAPI_CALL reallocate(void* user, void* original, std::size_t size,
                                                std::size_t alignment, VkSystemAllocationScope scope) {
    if (original == nullptr) return allocate(user, size, alignment, scope);
    if (size == 0) {
      release(user, original);
      return nullptr;
    }
    auto* self = static_cast<CountingAllocator*>(user);
    std::size_t old = 0;
    {
      const std::lock_guard lock(self->mutex);
      old = self->live.at(original);
    }
    void* p = allocate(user, size, alignment, scope);
    if (p == nullptr) return nullptr;
    std::memcpy(p, original, std::min(old, size));
    release(user, original);
    return p;
  }
  static VKAPI_ATTR void VKAPI_CALL release(void* user, void* memory) {
    if (memory == nullptr) return;
    auto* self = static_cast<CountingAllocator*>(user);
    {
      const std::lock_guard lock(self->mutex);
      self->live.erase(memory);
      ++self->frees;
    }
    std::free(memory);
  }
};

/// An engine's own Vulkan: its instance with VK_LAYER_KHRONOS_validation and its own debug messenger
/// (messages()), the first physical device with a compute queue, and a device with the features and
/// extensions it is told to enable, all loaded through loaderEntryPoint(). engineDevice() describes them to
/// gpu::VulkanBackend with the counting loader (LoaderSpy, reset there).
class EngineVulkanDevice {
public:
  struct Options {
    bool pushDescriptor = true;                 ///< enable VK_KHR_push_descriptor
    bool storageImageWriteWithoutFormat = true; ///< enable shaderStorageImageWriteWithoutFormat
    bool giveDeviceProcAddr = true;             ///< hand the backend vkGetDeviceProcAddr too
    bool giveAllocator = false;                 ///< hand the backend allocator() for its objects
    bool givePipelineCache = false;             ///< create a VkPipelineCache and hand it to the backend
    bool synchronizationValidation = false;     ///< the layer's synchronization validation on too
  };

  explicit EngineVulkanDevice(Options options) : options_(options) {
    gipa_ = loaderEntryPoint();
    const auto global = [&](const char* name) { return gipa_(VK_NULL_HANDLE, name); };
    const auto createInstance = reinterpret_cast<PFN_vkCreateInstance>(global("vkCreateInstance"));
    VkApplicationInfo app{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "crepuscular test engine";
    app.apiVersion = VK_API_VERSION_1_1;
    const char* layers[] = {"VK_LAYER_KHRONOS_validation"};
    const char* instanceExtensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME,
                                        VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
    VkDebugUtilsMessengerCreateInfoEXT debug{};
    debug.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    debug.messageSeverity =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    debug.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    debug.pfnUserCallback = &EngineVulkanDevice::onMessage;
    debug.pUserData = this;
    const VkValidationFeatureEnableEXT syncValidation =
        VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkValidationFeaturesEXT features{};
    features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    features.enabledValidationFeatureCount = 1;
    features.pEnabledValidationFeatures = &syncValidation;
    features.pNext = &debug;
    VkInstanceCreateInfo ici{};
    ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ici.pNext = options.synchronizationValidation ? static_cast<const void*>(&features) : &debug;
    ici.pApplicationInfo = &app;
    ici.enabledLayerCount = 1;
    ici.ppEnabledLayerNames = layers;
    ici.enabledExtensionCount = options.synchronizationValidation ? 2u : 1u;
    ici.ppEnabledExtensionNames = instanceExtensions;
    REQUIRE(createInstance(&ici, nullptr, &instance_) == VK_SUCCESS);
    const auto createMessenger =
        instanceFunction<PFN_vkCreateDebugUtilsMessengerEXT>("vkCreateDebugUtilsMessengerEXT");
    REQUIRE(createMessenger(instance_, &debug, nullptr, &messenger_) == VK_SUCCESS);

    const auto enumerate = instanceFunction<PFN_vkEnumeratePhysicalDevices>("vkEnumeratePhysicalDevices");
    const auto families = instanceFunction<PFN_vkGetPhysicalDeviceQueueFamilyProperties>(
        "vkGetPhysicalDeviceQueueFamilyProperties");
    std::uint32_t count = 0;
    enumerate(instance_, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    enumerate(instance_, &count, devices.data());
    for (VkPhysicalDevice d : devices) {
      std::uint32_t n = 0;
      families(d, &n, nullptr);
      std::vector<VkQueueFamilyProperties> props(n);
      families(d, &n, props.data());
      for (std::uint32_t i = 0; i < n && physical_ == VK_NULL_HANDLE; ++i)
        if ((props[i].queueFlags & VK_QUEUE_COMPUTE_BIT) != 0) {
          physical_ = d;
          family_ = i;
        }
    }
    REQUIRE_MESSAGE(physical_ != VK_NULL_HANDLE, "no Vulkan device with a compute queue");

    const float priority = 1.0f;
    VkDeviceQueueCreateInfo q{};
    q.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    q.queueFamilyIndex = family_;
    q.queueCount = 1;
    q.pQueuePriorities = &priority;
    features_.shaderStorageImageWriteWithoutFormat =
        options.storageImageWriteWithoutFormat ? VK_TRUE : VK_FALSE;
    if (options.pushDescriptor) extensions_.push_back(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
    std::vector<const char*> names;
    for (const std::string& e : extensions_)
      names.push_back(e.c_str());
    VkDeviceCreateInfo dci{};
    dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &q;
    dci.enabledExtensionCount = static_cast<std::uint32_t>(names.size());
    dci.ppEnabledExtensionNames = names.data();
    dci.pEnabledFeatures = &features_;
    REQUIRE(instanceFunction<PFN_vkCreateDevice>("vkCreateDevice")(physical_, &dci, nullptr, &device_) ==
            VK_SUCCESS);
    gdpa_ = instanceFunction<PFN_vkGetDeviceProcAddr>("vkGetDeviceProcAddr");
    reinterpret_cast<PFN_vkGetDeviceQueue>(gdpa_(device_, "vkGetDeviceQueue"))(device_, family_, 0, &queue_);
    if (options.givePipelineCache) {
      VkPipelineCacheCreateInfo pci{};
      pci.sType = VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO;
      REQUIRE(reinterpret_cast<PFN_vkCreatePipelineCache>(gdpa_(device_, "vkCreatePipelineCache"))(
                  device_, &pci, nullptr, &cache_) == VK_SUCCESS);
    }
  }

  ~EngineVulkanDevice() { destroy(); }
  EngineVulkanDevice(const EngineVulkanDevice&) = delete;
  EngineVulkanDevice& operator=(const EngineVulkanDevice&) = delete;

  /// The device, messenger and instance destroyed (the layer reports there any object a backend left).
  void destroy() {
    if (cache_ != VK_NULL_HANDLE)
      reinterpret_cast<PFN_vkDestroyPipelineCache>(gdpa_(device_, "vkDestroyPipelineCache"))(device_, cache_,
                                                                                             nullptr);
    cache_ = VK_NULL_HANDLE;
    if (device_ != VK_NULL_HANDLE)
      reinterpret_cast<PFN_vkDestroyDevice>(gdpa_(device_, "vkDestroyDevice"))(device_, nullptr);
    device_ = VK_NULL_HANDLE;
    if (messenger_ != VK_NULL_HANDLE)
      instanceFunction<PFN_vkDestroyDebugUtilsMessengerEXT>("vkDestroyDebugUtilsMessengerEXT")(
          instance_, messenger_, nullptr);
    messenger_ = VK_NULL_HANDLE;
    if (instance_ != VK_NULL_HANDLE)
      instanceFunction<PFN_vkDestroyInstance>("vkDestroyInstance")(instance_, nullptr);
    instance_ = VK_NULL_HANDLE;
  }

  /// The objects as a backend takes them, its loader the counting one (LoaderSpy, reset here).
  gpu::VulkanBackend::EngineDevice engineDevice() const {
    LoaderSpy::reset(gipa_);
    gpu::VulkanBackend::EngineDevice e;
    e.instance = instance_;
    e.physicalDevice = physical_;
    e.device = device_;
    e.queueFamily = family_;
    e.queue = queue_;
    e.getInstanceProcAddr = &LoaderSpy::getInstanceProcAddr;
    if (options_.giveDeviceProcAddr) {
      LoaderSpy::realDeviceProcAddr = gdpa_;
      e.getDeviceProcAddr = &LoaderSpy::getDeviceProcAddr;
    }
    if (options_.giveAllocator) e.allocator = &allocator_.callbacks;
    e.pipelineCache = cache_;
    e.enabledExtensions = extensions_;
    e.enabledFeatures = features_;
    return e;
  }

  /// A device-level function of the engine's own (not through the backend's counting loader).
  template <class F>
  F deviceFunction(const char* name) const {
    const PFN_vkVoidFunction f = gdpa_(device_, name);
    const bool found = f != nullptr;
    REQUIRE_MESSAGE(found, name);
    return reinterpret_cast<F>(f);
  }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  std::uint32_t queueFamily() const { return family_; }

  /// The allocation callbacks handed to the backend (Options::giveAllocator).
  CountingAllocator& allocator() { return allocator_; }

  /// The validation layer's warnings and errors on this instance so far.
  std::vector<std::string> messages() const {
    const std::lock_guard lock(mutex_);
    return messages_;
  }

  VkPhysicalDevice physicalDevice() const { return physical_; }
  /// An instance-level function of the engine's own.
  template <class F>
  F instanceFunction(const char* name) const {
    const PFN_vkVoidFunction f = gipa_(instance_, name);
    const bool found = f != nullptr;
    REQUIRE_MESSAGE(found, name);
    return reinterpret_cast<F>(f);
  }

private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL onMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                  VkDebugUtilsMessageTypeFlagsEXT,
                                                  const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                  void* user) {
    auto* self = static_cast<EngineVulkanDevice*>(user);
    const std::lock_guard lock(self->mutex_);
    self->messages_.push_back(
        std::string(severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error: " : "warning: ") +
        (data->pMessage != nullptr ? data->pMessage : ""));
    return VK_FALSE;
  }

  Options options_;
  PFN_vkGetInstanceProcAddr gipa_ = nullptr;
  PFN_vkGetDeviceProcAddr gdpa_ = nullptr;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  std::uint32_t family_ = 0;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkPipelineCache cache_ = VK_NULL_HANDLE;
  VkPhysicalDeviceFeatures features_{};
  mutable CountingAllocator allocator_;
  std::vector<std::string> extensions_;
  mutable std::mutex mutex_;
  std::vector<std::string> messages_;
};

} // namespace crep::test
