// crepuscular in the Vulkan engine (volumetrics.h).
#include "volumetrics.h"

namespace vkengine {

namespace {

crep::gpu::VulkanBackend::CreateInfo onEngineDevice(const Engine& e, PFN_vkGetInstanceProcAddr loader) {
  crep::gpu::VulkanBackend::EngineDevice d;
  d.instance = e.instance();
  d.physicalDevice = e.physicalDevice();
  d.device = e.device();
  d.queueFamily = e.queueFamily();
  d.queue = e.queue();
  d.getInstanceProcAddr = loader;
  d.apiVersion = e.apiVersion();
  d.enabledExtensions = e.enabledExtensions();
  d.enabledFeatures = e.enabledFeatures();
  crep::gpu::VulkanBackend::CreateInfo info;
  info.device = d;
  return info;
}

template <class Image>
crep::gpu::TextureId import(crep::gpu::VulkanBackend& vk, const Image& image, const char* label) {
  return vk.importTexture({.image = image.image,
                           .view = image.view,
                           .format = Image::kFormat,
                           .width = image.width,
                           .height = image.height,
                           .usage = Image::kUsage,
                           .layout = Image::kLayout,
                           .label = label});
}

crep::Scattering::CreateInfo withBackend(crep::Scattering::CreateInfo info, crep::gpu::Backend& backend,
                                         const DepthImage& cameraDepth) {
  info.width = static_cast<int>(cameraDepth.width);
  info.height = static_cast<int>(cameraDepth.height);
  info.backend = &backend;
  return info;
}

} // namespace

Volumetrics::Volumetrics(const Engine& engine, const VolumetricImages& images,
                         crep::Scattering::CreateInfo settings, PFN_vkGetInstanceProcAddr loader)
    : backend_(onEngineDevice(engine, loader)),
      cameraDepth_(import(backend_, *images.cameraDepth, "camera depth")),
      sunMap_(images.sunMap != nullptr ? import(backend_, *images.sunMap, "sun map") : 0),
      output_(import(backend_, *images.output, "volumetrics")),
      scattering_(withBackend(settings, backend_, *images.cameraDepth)) {
  for (const DepthImage* spot : images.spotMaps)
    spotMaps_.push_back(import(backend_, *spot, "spot map"));
  backend_.finish(); // the set-up's uploads (tables, buffers), once, before the first frame
}

crep::Scattering::FrameResult Volumetrics::record(const Engine::Frame& frame, const crep::Camera& camera,
                                                  const VolumetricLights& lights) {
  const crep::Scattering::ShadowMap sun{sunMap_, lights.sunClipFromWorld, lights.bias};
  std::vector<crep::Scattering::ShadowMap> spots;
  for (std::size_t i = 0; i < lights.spots.size(); ++i)
    spots.push_back({spotMaps_.at(i), lights.spotClipFromWorld.at(i), lights.bias});
  crep::Scattering::FrameAttribs f;
  f.camera = &camera;
  f.light = lights.sun;
  f.medium = lights.medium;
  f.cameraDepth = cameraDepth_;
  f.output = output_;
  f.shadowMap = lights.sun != nullptr ? &sun : nullptr;
  f.spotLights = lights.spots;
  f.spotShadowMaps = spots;
  backend_.beginFrame({frame.commandBuffer, frame.index, frame.completed});
  try {
    const crep::Scattering::FrameResult result = scattering_.run(f);
    backend_.endFrame();
    return result;
  } catch (...) { // bad input is refused before anything is recorded; the frame stays submittable
    backend_.endFrame();
    throw;
  }
}

} // namespace vkengine
