// crepuscular in the Vulkan engine (volumetrics.h).
#include "volumetrics.h"

namespace vkengine {

namespace {

template <class Image>
crep::gpu::TextureId importAny(crep::gpu::VulkanBackend& vk, const Image& image, const char* label) {
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

crep::gpu::TextureId importImage(crep::gpu::VulkanBackend& backend, const DepthImage& image,
                                 const char* label) {
  return importAny(backend, image, label);
}

crep::gpu::TextureId importImage(crep::gpu::VulkanBackend& backend, const ColorImage& image,
                                 const char* label) {
  return importAny(backend, image, label);
}

DepthImagePool::Entry DepthImagePool::acquire(std::uint32_t width, std::uint32_t height) {
  taken_.resize(entries_.size(), false);
  for (std::size_t k = 0; k < entries_.size(); ++k)
    if (!taken_[k] && entries_[k].image->width == width && entries_[k].image->height == height) {
      taken_[k] = true;
      return entries_[k];
    }
  // A size, or a count of maps of a size, not seen before: one more image, imported once.
  const DepthImage& image = engine_.createDepthImage(width, height);
  entries_.push_back({&image, importImage(backend_, image, "shadow map")});
  taken_.push_back(true);
  return entries_.back();
}

crep::gpu::VulkanBackend::CreateInfo backendOnEngine(const Engine& e, PFN_vkGetInstanceProcAddr loader) {
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

// ClipConvention::Vulkan: the matrices are in Vulkan's clip space (z in [0, w]) and the viewports are used as
// they are (a positive height, no y flip: the first row in memory is NDC y = -1, as crepuscular reads its
// maps).
ShadowPassTarget targetOf(const crep::ShadowPass& pass, const DepthImage& image) {
  ShadowPassTarget t;
  t.pass = &pass;
  t.image = &image;
  t.state.clearDepth = static_cast<float>(pass.clearDepth);
  t.state.greater = pass.compare == crep::DepthCompare::Greater;
  t.state.depthClamp = pass.depthClamp;
  for (const crep::ShadowPass::Split& s : pass.splits) {
    const crep::ShadowPass::Rect& v = s.viewport;
    const crep::ShadowPass::Rect& c = s.scissor;
    t.draws.push_back({s.clipFromWorld,
                       {float(v.x), float(v.y), float(v.width), float(v.height), 0.0f, 1.0f},
                       {{c.x, c.y}, {std::uint32_t(c.width), std::uint32_t(c.height)}}});
  }
  return t;
}

PlannedMaps acquireMaps(const crep::ShadowPassPlan& plan, DepthImagePool& pool) {
  PlannedMaps m;
  m.planMaps.assign(plan.passes.size(), 0);
  for (std::size_t i = 0; i < plan.passes.size(); ++i) {
    const crep::ShadowPass& pass = plan.passes[i];
    if (!pass.needsMap()) continue;
    const DepthImagePool::Entry map =
        pool.acquire(static_cast<std::uint32_t>(pass.width), static_cast<std::uint32_t>(pass.height));
    m.planMaps[i] = map.texture;
    m.targets.push_back(targetOf(pass, *map.image));
  }
  return m;
}

Volumetrics::Volumetrics(Engine& engine, const VolumetricImages& images,
                         crep::Scattering::CreateInfo settings, PFN_vkGetInstanceProcAddr loader)
    : backend_(backendOnEngine(engine, loader)),
      cameraDepth_(importImage(backend_, *images.cameraDepth, "camera depth")),
      output_(importImage(backend_, *images.output, "volumetrics")),
      scattering_(withBackend(settings, backend_, *images.cameraDepth)), shadowMaps_(engine, backend_) {
  backend_.finish(); // the set-up's uploads (tables, buffers), once, before the first frame
}

crep::Scattering::FrameAttribs Volumetrics::attribs(const crep::Camera& camera,
                                                    const VolumetricLights& lights) const {
  crep::Scattering::FrameAttribs f;
  f.camera = &camera;
  f.light = lights.sun;
  f.medium = lights.medium;
  f.spotLights = lights.spots;
  return f;
}

const std::vector<ShadowPassTarget>& Volumetrics::plan(const crep::Camera& camera,
                                                       const VolumetricLights& lights) {
  plan_ = scattering_.plan(attribs(camera, lights), {.convention = crep::ClipConvention::Vulkan});
  shadowMaps_.release();
  maps_ = acquireMaps(plan_, shadowMaps_);
  return maps_.targets;
}

crep::Scattering::FrameResult Volumetrics::record(const Engine::Frame& frame, const crep::Camera& camera,
                                                  const VolumetricLights& lights) {
  crep::Scattering::FrameAttribs f = attribs(camera, lights);
  f.cameraDepth = cameraDepth_;
  f.output = output_;
  f.plan = &plan_;
  f.planMaps = maps_.planMaps;
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
