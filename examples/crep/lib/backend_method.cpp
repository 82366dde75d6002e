// The front door's methods on another backend (backend_method.h): `crep render/compare/bench --backend`.
#include "backend_method.h"

#include "args.h"

#include <crep/core/error.h>
#include <crep/gpu/gl.h>
#include <crep/pipeline/scattering.h>
#include <crep/scatter/gpu_light_texture.h>
#include <crep/scenes/engine_frame.h>
#if CREP_HAS_VULKAN
#include <crep/vulkan/vulkan_backend.h>

#include <engine.h>      // examples/vulkan_engine: the engine that rasterizes the maps
#include <volumetrics.h> // its crepuscular glue: the backend on its device, plan passes as its draws
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

namespace {
vkengine::Mesh meshOf(const scenes::Scene& scene) {
  vkengine::Mesh m;
  m.positions = scene.mesh.positions;
  m.indices = scene.mesh.indices;
  return m;
}
} // namespace

struct VulkanSession::Impl {
  Impl(const scenes::Scene& scene, bool validation)
      : positions(scene.mesh.positions.size()), indices(scene.mesh.indices.size()),
        engine(meshOf(scene), {.framesInFlight = 1, .validation = validation}),
        backend(vkengine::backendOnEngine(engine)), maps(engine, backend) {}
  std::size_t positions, indices; ///< the scene's mesh, to refuse another scene's frame
  vkengine::Engine engine;
  gpu::VulkanBackend backend;
  vkengine::DepthImagePool maps; ///< camera depth and shadow maps, reused run after run
};

VulkanSession::VulkanSession(const scenes::Scene& scene, bool validation)
    : impl_(std::make_unique<Impl>(scene, validation)) {}
VulkanSession::~VulkanSession() = default;
std::vector<std::string> VulkanSession::validationMessages() const {
  return impl_->engine.validationMessages();
}
std::string VulkanSession::deviceName() const {
  return impl_->backend.deviceName();
}

namespace {

/// A run's depth images (from the session's pool) and what the engine draws into them.
struct VulkanMaps {
  vkengine::DepthImagePool::Entry cameraDepth;
  vkengine::PlannedMaps plan; ///< FrameAttribs::planMaps and the plan's passes that need a map
  bool sunStandard = false;   ///< the sun's pass is served by the frame's standard map: rendered too
  vkengine::DepthImagePool::Entry sunMap;
};

/// The engine rasterizes the camera depth, every plan pass that needs a map and, on a fallback frame, the
/// sun's standard map of the frame (as the OpenGL frame's: depth clamp, cleared to 1, LESS). Each stage is
/// its own submission, waited for: its time includes the GPU's work.
VulkanMaps rasterize(VulkanSession::Impl& v, const FrameInputs& frame, const ShadowPassPlan& plan,
                     StageTimings& timings) {
  VulkanMaps m;
  v.maps.release();
  const auto size = [](int w, int h) {
    return std::pair{static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(h)};
  };
  const auto [cw, ch] = size(frame.width, frame.height);
  m.cameraDepth = v.maps.acquire(cw, ch);
  m.plan = vkengine::acquireMaps(plan, v.maps);
  m.sunStandard = frame.directional && !plan.passes.empty() &&
                  plan.passes[0].light == ShadowPass::Light::Sun && plan.passes[0].served;
  if (m.sunStandard) {
    const auto [w, h] = size(frame.shadowWidth, frame.shadowHeight);
    m.sunMap = v.maps.acquire(w, h);
  }
  vkengine::Engine& engine = v.engine;
  timings.time("engine: camera depth (Vulkan)", [&] {
    const vkengine::Engine::Frame f = engine.beginFrame();
    // The camera's OpenGL matrix in Vulkan's clip space: the depth-buffer values GL would store.
    engine.drawDepth(f, *m.cameraDepth.image, vkengine::zeroToOne(frame.camera.clipFromWorld()), false);
    engine.submit(f);
    engine.waitIdle();
  });
  timings.time("engine: shadow passes (Vulkan)", [&] {
    const vkengine::Engine::Frame f = engine.beginFrame();
    for (const vkengine::ShadowPassTarget& t : m.plan.targets)
      engine.drawDepthPass(f, *t.image, t.state, t.draws);
    if (m.sunStandard)
      engine.drawDepth(f, *m.sunMap.image, vkengine::zeroToOne(frame.lightClipFromWorld), true);
    engine.submit(f);
    engine.waitIdle();
  });
  return m;
}

/// The frame's light textures uploaded to the backend: the sun's (the scene's window) and the spots'.
struct LightTextures {
  std::vector<gpu::Texture> textures;
  GpuLightTexture sun;
  std::vector<GpuLightTexture> spots; ///< empty, or one per spot (texture 0: untextured)
};
void uploadLightTextures(gpu::Backend& vk, const FrameInputs& frame, LightTextures& out) {
  const auto upload = [&](const LightTextureMap& m, const char* label) -> GpuLightTexture {
    const Image& rgb = m.image;
    out.textures.emplace_back(vk, gpu::TextureDesc{gpu::TextureType::Texture2D, gpu::Format::RGBA32F,
                                                   rgb.width(), rgb.height(), 1, label});
    vk.writeTexture(out.textures.back().id(), scenes::rgbaTexels(rgb));
    return {out.textures.back().id(), m.textureClipFromWorld};
  };
  if (frame.directional && frame.lightTexture.present())
    out.sun = upload(frame.lightTexture, "crep render: light texture");
  if (!frame.spotTextures.empty())
    for (std::size_t i = 0; i < frame.spotLights.size(); ++i)
      out.spots.push_back(frame.spotTexture(i) ? upload(*frame.spotTexture(i), "crep render: spot texture")
                                               : GpuLightTexture{});
}

} // namespace

MethodOutput runOnVulkan(const SceneFrame& s, const std::string& method, const MethodSettings& settings,
                         VulkanSession* session) {
  requireBackend("vulkan", method); // a UsageError for a method that is not crep::Scattering's
  const scenes::Scene& scene = *s.scene;
  const FrameInputs& frame = *s.frame;
  MethodOutput out;
  out.used = method;
  std::unique_ptr<VulkanSession> own;
  if (session == nullptr)
    own = out.timings.time("engine setup (Vulkan)", [&] { return std::make_unique<VulkanSession>(scene); });
  VulkanSession::Impl& v = session != nullptr ? session->impl() : own->impl();
  if (v.positions != scene.mesh.positions.size() || v.indices != scene.mesh.indices.size())
    throw InvalidArgument("runOnVulkan: session", "of another scene", "must be made with this frame's scene");
  gpu::VulkanBackend& vk = v.backend;
  const auto [frontDoor, sampling] = *frontDoorMethod(method);
  Scattering::CreateInfo info = frontDoorCreateInfo(frame, settings, frontDoor, sampling);
  info.backend = &vk;
  Scattering scattering = out.timings.time("setup", [&] { return Scattering(info); });

  // The frame as the OpenGL method gives it (runFrontDoor): camera, lights, medium, the sun's standard map
  // (frame.lightClipFromWorld: what its fallback reads) and the scene's casters for the rest, here the
  // plan's passes in Vulkan's clip conventions.
  Scattering::ShadowMap sunMap{0, frame.lightClipFromWorld, frame.shadowBias};
  Scattering::FrameAttribs a;
  a.camera = &frame.camera;
  a.light = frame.directional ? &frame.light : nullptr;
  a.medium = &frame.medium;
  a.spotLights = frame.spotLights;
  a.pointLights = frame.pointLights;
  a.shadowMap = frame.directional ? &sunMap : nullptr;
  const ShadowPassPlan plan = scattering.plan(a, {.convention = ClipConvention::Vulkan});
  const VulkanMaps maps = rasterize(v, frame, plan, out.timings);
  LightTextures textures;
  uploadLightTextures(vk, frame, textures);
  if (textures.sun.texture != 0) a.lightTexture = &textures.sun;
  a.spotLightTextures = textures.spots;

  gpu::Texture output(vk, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, frame.width, frame.height, 1,
                           "crep render: scattering"});
  a.cameraDepth = maps.cameraDepth.texture;
  a.output = output.id();
  sunMap.texture = maps.sunMap.texture;
  if (!maps.sunStandard) a.shadowMap = nullptr; // projective: the plan's rectified map alone (the same plan)
  a.plan = &plan;
  a.planMaps = maps.plan.planMaps;
  const Scattering::FrameResult r = scattering.run(a);
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
               " local lights; camera depth and " +
               std::to_string(maps.plan.targets.size() + maps.sunStandard) +
               " shadow maps rasterized on Vulkan (" + vk.deviceName() + ")";
  return out;
}
#else
struct VulkanSession::Impl {};

VulkanSession::VulkanSession(const scenes::Scene&, bool) {
  throw UsageError(
      "option --backend vulkan: this build has no Vulkan backend (configure with -DCREP_VULKAN=ON)");
}
VulkanSession::~VulkanSession() = default;
std::vector<std::string> VulkanSession::validationMessages() const {
  return {};
}
std::string VulkanSession::deviceName() const {
  return {};
}

MethodOutput runOnVulkan(const SceneFrame& s, const std::string&, const MethodSettings&, VulkanSession*) {
  VulkanSession session(*s.scene);
  return {};
}
#endif

} // namespace crep::tool
