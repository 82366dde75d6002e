// The front door's methods on another backend (backend_method.h): `crep render/compare/bench --backend`.
#include "backend_method.h"

#include "args.h"

#include <crep/core/error.h>
#include <crep/gpu/gl.h>
#include <crep/pipeline/scattering.h>
#include <crep/scatter/gpu_light_texture.h>
#include <crep/scenes/engine_frame.h>
#include <crep/scenes/scene_renderer.h>
#if CREP_HAS_VULKAN
#include <crep/vulkan/vulkan_backend.h>
#endif

#include <epoxy/gl.h>

#include <optional>
#include <utility>
#include <vector>

namespace crep::tool {

std::string backendNames() {
  return CREP_HAS_VULKAN ? "opengl | vulkan" : "opengl";
}

namespace {
/// The front door's method and sampling of a tool method that is crep::Scattering's; nullopt for the others.
std::optional<std::pair<Scattering::Method, Scattering::Sampling>> frontDoorMethod(const std::string& name) {
  using M = Scattering::Method;
  using S = Scattering::Sampling;
  if (name == "prefilter") return std::pair{M::Prefiltered, S::PerPixel};
  if (name == "minmax") return std::pair{M::MinMaxMarch, S::PerPixel};
  if (name == "epipolar-sampling") return std::pair{M::MinMaxMarch, S::Epipolar};
  if (name == "epipolar-prefilter") return std::pair{M::Prefiltered, S::Epipolar};
  return std::nullopt;
}
} // namespace

bool runsOnBackend(const std::string& method) {
  return frontDoorMethod(method).has_value();
}

void requireBackend(const std::string& backend) {
  if (backend != "opengl" && (backend != "vulkan" || !CREP_HAS_VULKAN))
    throw UsageError("option --backend: unknown backend '" + backend + "' (one of: " + backendNames() + ")");
}

void requireBackend(const std::string& backend, const std::string& method) {
  requireBackend(backend);
  if (backend != "opengl" && !runsOnBackend(method))
    throw UsageError("option --backend vulkan: runs --method prefilter, minmax, epipolar-sampling or "
                     "epipolar-prefilter (crep::Scattering), not " +
                     method);
}

#if CREP_HAS_VULKAN

std::unique_ptr<gpu::Backend> makeVulkanBackend() {
  return std::make_unique<gpu::VulkanBackend>();
}

namespace {
std::string deviceName(const gpu::Backend& b) {
  const auto* vk = dynamic_cast<const gpu::VulkanBackend*>(&b);
  return vk != nullptr ? vk->deviceName() : std::string(b.name());
}
} // namespace

MethodOutput runOnVulkan(const SceneFrame& s, const std::string& method, const MethodSettings& settings,
                         gpu::Backend* vulkan) {
  requireBackend("vulkan", method); // a UsageError for a method that is not crep::Scattering's
  const scenes::Scene& scene = *s.scene;
  const FrameInputs& frame = *s.frame;
  MethodOutput out;
  out.used = method;
  // The frame's own maps, read back, as an engine hands them over: the camera depth, the sun's standard map
  // and each local light's perspective map (those the OpenGL methods and the reference use).
  const scenes::EngineMaps maps = out.timings.time("engine maps (read back from GL)", [&] {
    scenes::EngineMaps m;
    m.cameraDepth = scenes::readDepthTexture(frame.cameraDepth.get(), frame.width, frame.height);
    if (frame.directional) {
      m.sunMap = scenes::readDepthTexture(frame.shadowMap.get(), frame.shadowWidth, frame.shadowHeight);
      m.sunClipFromWorld = frame.lightClipFromWorld;
      m.sunBias = frame.shadowBias;
    }
    for (const LocalShadowMap& l : frame.spotShadows)
      m.spotMaps.push_back(scenes::readDepthTexture(l.texture.get(), l.width, l.height));
    for (const LocalShadowMap& l : frame.pointShadows)
      m.pointMaps.push_back(scenes::readDepthTexture(l.texture.get(), l.width, l.height));
    m.localBias = kLocalShadowBias;
    return m;
  });
  std::unique_ptr<gpu::Backend> own = vulkan == nullptr ? makeVulkanBackend() : nullptr;
  gpu::Backend& vk = vulkan != nullptr ? *vulkan : *own;
  const scenes::EngineFrame engine(vk, scene, maps);
  gpu::Texture output(vk, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, frame.width, frame.height, 1,
                           "crep render: scattering"});
  const auto [frontDoor, sampling] = *frontDoorMethod(method);
  Scattering::CreateInfo info = frontDoorCreateInfo(frame, settings, frontDoor, sampling);
  info.backend = &vk;
  Scattering scattering = out.timings.time("setup", [&] { return Scattering(info); });
  const Scattering::FrameResult r = scattering.run(engine.attribs(output.id()));
  for (const Scattering::Stage& stage : r.stages)
    out.timings.append({{stage.name, stage.wallMilliseconds}});
  // Back to GL for the composite (the tool's own passes).
  const std::vector<float> texels =
      out.timings.time("read back (Vulkan)", [&] { return vk.readTexture(output.id()); });
  out.scattering = gl::createTexture2D(GL_RGBA32F, frame.width, frame.height, "crep render --backend vulkan");
  glTextureSubImage2D(out.scattering.get(), 0, 0, 0, frame.width, frame.height, GL_RGBA, GL_FLOAT,
                      texels.data());
  out.detail = std::string(scene.hasSun ? layoutToken(r.layout) : "no directional light") + " layout, map " +
               std::to_string(settings.mapSize) + "^2, " + std::to_string(r.localLights.size()) +
               " local lights; on Vulkan (" + deviceName(vk) + ")";
  return out;
}
#else
std::unique_ptr<gpu::Backend> makeVulkanBackend() {
  throw UsageError(
      "option --backend vulkan: this build has no Vulkan backend (configure with -DCREP_VULKAN=ON)");
}

MethodOutput runOnVulkan(const SceneFrame&, const std::string&, const MethodSettings&, gpu::Backend*) {
  makeVulkanBackend();
  return {};
}
#endif

} // namespace crep::tool
