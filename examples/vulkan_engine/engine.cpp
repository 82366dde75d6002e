// The minimal Vulkan renderer of engine.h.
#include "engine.h"

#include <cstring>
#include <functional>
#include <mutex>
#include <stdexcept>

namespace vkengine {

namespace {

// depth.vert compiled by glslc at build time (-mfmt=num: the words as C numbers).
constexpr std::uint32_t kDepthVertex[] = {
#include "depth.vert.inc"
};

void check(VkResult r, const char* call) {
  if (r != VK_SUCCESS)
    throw std::runtime_error(std::string(call) + " failed (VkResult " + std::to_string(r) + ")");
}

} // namespace

glm::dmat4 zeroToOne(const glm::dmat4& m) {
  glm::dmat4 t(1.0);
  t[2][2] = 0.5; // z' = 0.5 z + 0.5 w
  t[3][2] = 0.5;
  return t * m;
}

struct Engine::Messages {
  mutable std::mutex mutex;
  std::vector<std::string> list;
  static VKAPI_ATTR VkBool32 VKAPI_CALL callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                 VkDebugUtilsMessageTypeFlagsEXT,
                                                 const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                 void* user) {
    auto* self = static_cast<Messages*>(user);
    const std::lock_guard lock(self->mutex);
    self->list.push_back(
        std::string(severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error: " : "warning: ") +
        (data->pMessage != nullptr ? data->pMessage : ""));
    return VK_FALSE;
  }
};

Engine::Engine(const Mesh& mesh, const Options& options)
    : options_(options), messages_(std::make_unique<Messages>()) {
  if (options.framesInFlight == 0) throw std::runtime_error("Engine::Options::framesInFlight must be >= 1");
  createDevice(options.validation);
  VkCommandPoolCreateInfo pci{};
  pci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = family_;
  check(vkCreateCommandPool(device_, &pci, nullptr, &pool_), "vkCreateCommandPool");
  slots_.resize(options.framesInFlight);
  for (Slot& s : slots_) {
    VkCommandBufferAllocateInfo ai{};
    ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    ai.commandPool = pool_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    check(vkAllocateCommandBuffers(device_, &ai, &s.commands), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fi{};
    fi.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    fi.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    check(vkCreateFence(device_, &fi, nullptr, &s.fence), "vkCreateFence");
  }
  createPipelines();
  // Host-visible vertex and index buffers: enough for an example (a real engine stages to device memory).
  const auto upload = [&](const void* data, std::size_t bytes, VkBufferUsageFlags usage,
                          VkDeviceMemory& memory) {
    const VkBuffer b = createBuffer(bytes, usage, memory);
    void* mapped = nullptr;
    check(vkMapMemory(device_, memory, 0, bytes, 0, &mapped), "vkMapMemory");
    std::memcpy(mapped, data, bytes);
    vkUnmapMemory(device_, memory);
    return b;
  };
  if (mesh.indices.empty() || mesh.positions.empty()) throw std::runtime_error("Engine: the mesh is empty");
  vertices_ = upload(mesh.positions.data(), mesh.positions.size() * sizeof(glm::vec3),
                     VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, vertexMemory_);
  indices_ = upload(mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t),
                    VK_BUFFER_USAGE_INDEX_BUFFER_BIT, indexMemory_);
  indexCount_ = static_cast<std::uint32_t>(mesh.indices.size());
}

void Engine::createDevice(bool validation) {
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "crepuscular Vulkan engine example";
  app.apiVersion = apiVersion();
  const char* layers[] = {"VK_LAYER_KHRONOS_validation"};
  const char* instanceExtensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME,
                                      VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
  VkDebugUtilsMessengerCreateInfoEXT debug{};
  debug.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  debug.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  debug.messageType =
      VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  debug.pfnUserCallback = &Messages::callback;
  debug.pUserData = messages_.get();
  const VkValidationFeatureEnableEXT synchronization =
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
  VkValidationFeaturesEXT features{};
  features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = &synchronization;
  features.pNext = &debug;
  VkInstanceCreateInfo ici{};
  ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  ici.pApplicationInfo = &app;
  if (validation) {
    ici.pNext = &features;
    ici.enabledLayerCount = 1;
    ici.ppEnabledLayerNames = layers;
    ici.enabledExtensionCount = 2;
    ici.ppEnabledExtensionNames = instanceExtensions;
  }
  check(vkCreateInstance(&ici, nullptr, &instance_), "vkCreateInstance");
  if (validation) {
    const auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    check(create(instance_, &debug, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
  }

  std::uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance_, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  vkEnumeratePhysicalDevices(instance_, &count, devices.data());
  const VkQueueFlags wanted = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
  for (VkPhysicalDevice d : devices) {
    std::uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(d, &n, nullptr);
    std::vector<VkQueueFamilyProperties> families(n);
    vkGetPhysicalDeviceQueueFamilyProperties(d, &n, families.data());
    for (std::uint32_t i = 0; i < n && physical_ == VK_NULL_HANDLE; ++i)
      if ((families[i].queueFlags & wanted) == wanted) {
        physical_ = d;
        family_ = i;
      }
  }
  if (physical_ == VK_NULL_HANDLE)
    throw std::runtime_error("no Vulkan device with a graphics and compute queue");

  VkPhysicalDeviceFeatures supported{};
  vkGetPhysicalDeviceFeatures(physical_, &supported);
  features_.depthClamp = supported.depthClamp;
  features_.shaderStorageImageWriteWithoutFormat = supported.shaderStorageImageWriteWithoutFormat;
  std::uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(physical_, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> available(n);
  vkEnumerateDeviceExtensionProperties(physical_, nullptr, &n, available.data());
  for (const VkExtensionProperties& e : available)
    if (std::strcmp(e.extensionName, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME) == 0)
      extensions_.push_back(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
  std::vector<const char*> names;
  for (const std::string& e : extensions_)
    names.push_back(e.c_str());
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo q{};
  q.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  q.queueFamilyIndex = family_;
  q.queueCount = 1;
  q.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{};
  dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &q;
  dci.enabledExtensionCount = static_cast<std::uint32_t>(names.size());
  dci.ppEnabledExtensionNames = names.data();
  dci.pEnabledFeatures = &features_;
  check(vkCreateDevice(physical_, &dci, nullptr, &device_), "vkCreateDevice");
  vkGetDeviceQueue(device_, family_, 0, &queue_);
}

void Engine::createPipelines() {
  // One depth-only render pass for every depth image: cleared, stored, left in the home layout for the
  // compute passes and copies that read it. The dependencies order it after earlier reads of the image
  // (the previous frame's compute passes) and before later ones.
  VkAttachmentDescription depth{};
  depth.format = DepthImage::kFormat;
  depth.samples = VK_SAMPLE_COUNT_1_BIT;
  depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  depth.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  depth.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  depth.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  depth.finalLayout = DepthImage::kLayout;
  const VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.pDepthStencilAttachment = &ref;
  const VkPipelineStageFlags tests =
      VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  const VkPipelineStageFlags readers = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
  const VkSubpassDependency dependencies[] = {
      {VK_SUBPASS_EXTERNAL, 0, readers | tests, tests, VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
       VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, 0},
      {0, VK_SUBPASS_EXTERNAL, tests, readers, VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
       VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT, 0}};
  VkRenderPassCreateInfo rp{};
  rp.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
  rp.attachmentCount = 1;
  rp.pAttachments = &depth;
  rp.subpassCount = 1;
  rp.pSubpasses = &subpass;
  rp.dependencyCount = 2;
  rp.pDependencies = dependencies;
  check(vkCreateRenderPass(device_, &rp, nullptr, &renderPass_), "vkCreateRenderPass");

  const VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof(glm::mat4)};
  VkPipelineLayoutCreateInfo pl{};
  pl.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  pl.pushConstantRangeCount = 1;
  pl.pPushConstantRanges = &push;
  check(vkCreatePipelineLayout(device_, &pl, nullptr, &pipelineLayout_), "vkCreatePipelineLayout");

  VkShaderModuleCreateInfo mi{};
  mi.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  mi.codeSize = sizeof(kDepthVertex);
  mi.pCode = kDepthVertex;
  VkShaderModule vertex = VK_NULL_HANDLE;
  check(vkCreateShaderModule(device_, &mi, nullptr, &vertex), "vkCreateShaderModule");
  VkPipelineShaderStageCreateInfo stage{};
  stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  stage.stage = VK_SHADER_STAGE_VERTEX_BIT;
  stage.module = vertex;
  stage.pName = "main";
  const VkVertexInputBindingDescription binding{0, sizeof(glm::vec3), VK_VERTEX_INPUT_RATE_VERTEX};
  const VkVertexInputAttributeDescription attribute{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0};
  VkPipelineVertexInputStateCreateInfo vi{};
  vi.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
  vi.vertexBindingDescriptionCount = 1;
  vi.pVertexBindingDescriptions = &binding;
  vi.vertexAttributeDescriptionCount = 1;
  vi.pVertexAttributeDescriptions = &attribute;
  VkPipelineInputAssemblyStateCreateInfo ia{};
  ia.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
  ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  VkPipelineViewportStateCreateInfo vp{};
  vp.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
  vp.viewportCount = 1;
  vp.scissorCount = 1;
  VkPipelineRasterizationStateCreateInfo rs{};
  rs.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
  rs.polygonMode = VK_POLYGON_MODE_FILL;
  rs.cullMode = VK_CULL_MODE_NONE;
  rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  rs.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo ms{};
  ms.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo ds{};
  ds.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
  ds.depthTestEnable = VK_TRUE;
  ds.depthWriteEnable = VK_TRUE;
  ds.depthCompareOp = VK_COMPARE_OP_LESS;
  const VkDynamicState dynamic[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dy{};
  dy.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
  dy.dynamicStateCount = 2;
  dy.pDynamicStates = dynamic;
  VkPipelineColorBlendStateCreateInfo cb{};
  cb.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
  VkGraphicsPipelineCreateInfo gp{};
  gp.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
  gp.stageCount = 1; // depth only: no fragment shader
  gp.pStages = &stage;
  gp.pVertexInputState = &vi;
  gp.pInputAssemblyState = &ia;
  gp.pViewportState = &vp;
  gp.pRasterizationState = &rs;
  gp.pMultisampleState = &ms;
  gp.pDepthStencilState = &ds;
  gp.pColorBlendState = &cb;
  gp.pDynamicState = &dy;
  gp.layout = pipelineLayout_;
  gp.renderPass = renderPass_;
  for (const int clamp : {0, 1})
    for (const int greater : {0, 1}) {
      rs.depthClampEnable = clamp != 0 && features_.depthClamp;
      ds.depthCompareOp = greater != 0 ? VK_COMPARE_OP_GREATER : VK_COMPARE_OP_LESS;
      check(vkCreateGraphicsPipelines(device_, VK_NULL_HANDLE, 1, &gp, nullptr, &pipelines_[clamp][greater]),
            "vkCreateGraphicsPipelines");
    }
  vkDestroyShaderModule(device_, vertex, nullptr);
}

Engine::~Engine() {
  if (device_ != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(device_);
    for (DepthImage& d : depthImages_) {
      vkDestroyFramebuffer(device_, d.framebuffer, nullptr);
      vkDestroyImageView(device_, d.view, nullptr);
      vkDestroyImage(device_, d.image, nullptr);
      vkFreeMemory(device_, d.memory, nullptr);
    }
    for (ColorImage& c : colorImages_) {
      vkDestroyImageView(device_, c.view, nullptr);
      vkDestroyImage(device_, c.image, nullptr);
      vkFreeMemory(device_, c.memory, nullptr);
    }
    vkDestroyBuffer(device_, vertices_, nullptr);
    vkDestroyBuffer(device_, indices_, nullptr);
    vkFreeMemory(device_, vertexMemory_, nullptr);
    vkFreeMemory(device_, indexMemory_, nullptr);
    for (auto& row : pipelines_)
      for (VkPipeline p : row)
        vkDestroyPipeline(device_, p, nullptr);
    vkDestroyPipelineLayout(device_, pipelineLayout_, nullptr);
    vkDestroyRenderPass(device_, renderPass_, nullptr);
    for (Slot& s : slots_)
      vkDestroyFence(device_, s.fence, nullptr);
    vkDestroyCommandPool(device_, pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (messenger_ != VK_NULL_HANDLE)
    reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"))(instance_, messenger_, nullptr);
  if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
}

std::string Engine::deviceName() const {
  VkPhysicalDeviceProperties p{};
  vkGetPhysicalDeviceProperties(physical_, &p);
  return p.deviceName;
}

VkDeviceMemory Engine::allocate(const VkMemoryRequirements& req, VkMemoryPropertyFlags properties) {
  VkPhysicalDeviceMemoryProperties mp{};
  vkGetPhysicalDeviceMemoryProperties(physical_, &mp);
  for (std::uint32_t i = 0; i < mp.memoryTypeCount; ++i)
    if ((req.memoryTypeBits & (1u << i)) != 0 &&
        (mp.memoryTypes[i].propertyFlags & properties) == properties) {
      VkMemoryAllocateInfo ai{};
      ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
      ai.allocationSize = req.size;
      ai.memoryTypeIndex = i;
      VkDeviceMemory memory = VK_NULL_HANDLE;
      check(vkAllocateMemory(device_, &ai, nullptr, &memory), "vkAllocateMemory");
      return memory;
    }
  throw std::runtime_error("no Vulkan memory type with the properties asked for");
}

VkBuffer Engine::createBuffer(VkDeviceSize bytes, VkBufferUsageFlags usage, VkDeviceMemory& memory) {
  VkBufferCreateInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  bi.size = bytes;
  bi.usage = usage;
  VkBuffer b = VK_NULL_HANDLE;
  check(vkCreateBuffer(device_, &bi, nullptr, &b), "vkCreateBuffer");
  VkMemoryRequirements req{};
  vkGetBufferMemoryRequirements(device_, b, &req);
  memory = allocate(req, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  check(vkBindBufferMemory(device_, b, memory, 0), "vkBindBufferMemory");
  return b;
}

template <class F>
void Engine::immediate(F&& record) {
  VkCommandBufferAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  ai.commandPool = pool_;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  check(vkAllocateCommandBuffers(device_, &ai, &cb), "vkAllocateCommandBuffers");
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(cb, &bi), "vkBeginCommandBuffer");
  record(cb);
  check(vkEndCommandBuffer(cb), "vkEndCommandBuffer");
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  check(vkQueueSubmit(queue_, 1, &si, VK_NULL_HANDLE), "vkQueueSubmit");
  check(vkQueueWaitIdle(queue_), "vkQueueWaitIdle");
  vkFreeCommandBuffers(device_, pool_, 1, &cb);
}

namespace {
template <class Image>
void createImage(VkDevice device, Image& out, std::uint32_t width, std::uint32_t height,
                 VkImageAspectFlags aspect,
                 const std::function<VkDeviceMemory(const VkMemoryRequirements&)>& allocate) {
  out.width = width;
  out.height = height;
  VkImageCreateInfo ii{};
  ii.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  ii.imageType = VK_IMAGE_TYPE_2D;
  ii.format = Image::kFormat;
  ii.extent = {width, height, 1};
  ii.mipLevels = 1;
  ii.arrayLayers = 1;
  ii.samples = VK_SAMPLE_COUNT_1_BIT;
  ii.tiling = VK_IMAGE_TILING_OPTIMAL;
  ii.usage = Image::kUsage;
  ii.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  check(vkCreateImage(device, &ii, nullptr, &out.image), "vkCreateImage");
  VkMemoryRequirements req{};
  vkGetImageMemoryRequirements(device, out.image, &req);
  out.memory = allocate(req);
  check(vkBindImageMemory(device, out.image, out.memory, 0), "vkBindImageMemory");
  VkImageViewCreateInfo vi{};
  vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  vi.image = out.image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = Image::kFormat;
  vi.subresourceRange = {aspect, 0, 1, 0, 1};
  check(vkCreateImageView(device, &vi, nullptr, &out.view), "vkCreateImageView");
}
} // namespace

void Engine::initialLayout(VkImage image, VkImageAspectFlags aspect, VkImageLayout layout) {
  // Once, at creation: the image is in its home layout before its first use.
  immediate([&](VkCommandBuffer cb) {
    VkImageMemoryBarrier b{};
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = layout;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {aspect, 0, 1, 0, 1};
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0,
                         nullptr, 0, nullptr, 1, &b);
  });
}

DepthImage& Engine::createDepthImage(std::uint32_t width, std::uint32_t height) {
  DepthImage& d = depthImages_.emplace_back();
  createImage(device_, d, width, height, VK_IMAGE_ASPECT_DEPTH_BIT, [&](const VkMemoryRequirements& r) {
    return allocate(r, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  });
  VkFramebufferCreateInfo fi{};
  fi.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
  fi.renderPass = renderPass_;
  fi.attachmentCount = 1;
  fi.pAttachments = &d.view;
  fi.width = width;
  fi.height = height;
  fi.layers = 1;
  check(vkCreateFramebuffer(device_, &fi, nullptr, &d.framebuffer), "vkCreateFramebuffer");
  initialLayout(d.image, VK_IMAGE_ASPECT_DEPTH_BIT, DepthImage::kLayout);
  return d;
}

ColorImage& Engine::createColorImage(std::uint32_t width, std::uint32_t height) {
  ColorImage& c = colorImages_.emplace_back();
  createImage(device_, c, width, height, VK_IMAGE_ASPECT_COLOR_BIT, [&](const VkMemoryRequirements& r) {
    return allocate(r, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  });
  initialLayout(c.image, VK_IMAGE_ASPECT_COLOR_BIT, ColorImage::kLayout);
  return c;
}

Engine::Frame Engine::beginFrame() {
  const std::uint64_t index = ++frameIndex_;
  const Slot& s = slots_[index % slots_.size()];
  // The engine's own wait: for the oldest frame in flight, the one that last used this slot.
  check(vkWaitForFences(device_, 1, &s.fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  check(vkResetFences(device_, 1, &s.fence), "vkResetFences");
  check(vkResetCommandBuffer(s.commands, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(s.commands, &bi), "vkBeginCommandBuffer");
  const std::uint64_t n = slots_.size();
  return {s.commands, index, index > n ? index - n : 0};
}

void Engine::drawDepthPass(const Frame& frame, const DepthImage& target, const DepthPassState& state,
                           std::span<const DepthDraw> draws) {
  const VkCommandBuffer cb = frame.commandBuffer;
  const VkClearValue clear{.depthStencil = {state.clearDepth, 0}};
  VkRenderPassBeginInfo rb{};
  rb.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  rb.renderPass = renderPass_;
  rb.framebuffer = target.framebuffer;
  rb.renderArea = {{0, 0}, {target.width, target.height}};
  rb.clearValueCount = 1;
  rb.pClearValues = &clear; // the whole target, once (the render pass's load operation)
  vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelines_[state.depthClamp][state.greater]);
  const VkDeviceSize offset = 0;
  vkCmdBindVertexBuffers(cb, 0, 1, &vertices_, &offset);
  vkCmdBindIndexBuffer(cb, indices_, 0, VK_INDEX_TYPE_UINT32);
  for (const DepthDraw& d : draws) {
    vkCmdSetViewport(cb, 0, 1, &d.viewport);
    vkCmdSetScissor(cb, 0, 1, &d.scissor);
    const glm::mat4 matrix(d.clipFromWorld);
    vkCmdPushConstants(cb, pipelineLayout_, VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof(matrix), &matrix);
    vkCmdDrawIndexed(cb, indexCount_, 1, 0, 0, 0);
  }
  vkCmdEndRenderPass(cb);
}

void Engine::drawDepth(const Frame& frame, const DepthImage& target, const glm::dmat4& clipFromWorld,
                       bool depthClamp) {
  // No y flip: row 0 of the image is NDC y = -1, as crepuscular reads its inputs (OpenGL's texel order).
  const DepthDraw all{clipFromWorld,
                      {0.0f, 0.0f, float(target.width), float(target.height), 0.0f, 1.0f},
                      {{0, 0}, {target.width, target.height}}};
  drawDepthPass(frame, target, {.clearDepth = 1.0f, .greater = false, .depthClamp = depthClamp}, {&all, 1});
}

void Engine::submit(const Frame& frame) {
  check(vkEndCommandBuffer(frame.commandBuffer), "vkEndCommandBuffer");
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &frame.commandBuffer;
  check(vkQueueSubmit(queue_, 1, &si, slots_[frame.index % slots_.size()].fence), "vkQueueSubmit");
}

void Engine::waitIdle() {
  check(vkDeviceWaitIdle(device_), "vkDeviceWaitIdle");
}

std::vector<float> Engine::download(VkImage image, VkImageAspectFlags aspect, VkImageLayout layout,
                                    std::uint32_t width, std::uint32_t height, std::uint32_t channels) {
  const VkDeviceSize bytes = VkDeviceSize(width) * height * channels * sizeof(float);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  const VkBuffer buffer = createBuffer(bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, memory);
  immediate([&](VkCommandBuffer cb) {
    VkImageMemoryBarrier b{};
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    b.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    b.oldLayout = layout;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {aspect, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                         nullptr, 0, nullptr, 1, &b);
    VkBufferImageCopy region{};
    region.imageSubresource = {aspect, 0, 0, 1};
    region.imageExtent = {width, height, 1};
    vkCmdCopyImageToBuffer(cb, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer, 1, &region);
    std::swap(b.oldLayout, b.newLayout);
    b.srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    VkBufferMemoryBarrier host{};
    host.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER;
    host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    host.srcQueueFamilyIndex = host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    host.buffer = buffer;
    host.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0,
                         nullptr, 0, nullptr, 1, &b);
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, nullptr, 1,
                         &host, 0, nullptr);
  });
  std::vector<float> texels(static_cast<std::size_t>(bytes / sizeof(float)));
  void* mapped = nullptr;
  check(vkMapMemory(device_, memory, 0, bytes, 0, &mapped), "vkMapMemory");
  std::memcpy(texels.data(), mapped, static_cast<std::size_t>(bytes));
  vkUnmapMemory(device_, memory);
  vkDestroyBuffer(device_, buffer, nullptr);
  vkFreeMemory(device_, memory, nullptr);
  return texels;
}

std::vector<float> Engine::download(const DepthImage& d) {
  return download(d.image, VK_IMAGE_ASPECT_DEPTH_BIT, DepthImage::kLayout, d.width, d.height, 1);
}

std::vector<float> Engine::download(const ColorImage& c) {
  return download(c.image, VK_IMAGE_ASPECT_COLOR_BIT, ColorImage::kLayout, c.width, c.height, 4);
}

std::vector<std::string> Engine::validationMessages() const {
  const std::lock_guard lock(messages_->mutex);
  return messages_->list;
}

} // namespace vkengine
