#include "scene_frame.h"

#include "args.h"

#include <crep/core/error.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <epoxy/gl.h>

#include <algorithm>

namespace crep::tool {

SceneFrame::SceneFrame() = default;
SceneFrame::~SceneFrame() = default;
SceneFrame::SceneFrame(SceneFrame&&) noexcept = default;
SceneFrame& SceneFrame::operator=(SceneFrame&&) noexcept = default;

std::vector<std::string> builtInSceneNames() {
  std::vector<std::string> names = scenes::sceneNames();
  for (const std::string& n : scenes::localLightSceneNames())
    names.push_back(n);
  for (const std::string& n : scenes::lightTextureSceneNames())
    names.push_back(n);
  return names;
}

void requireSceneName(const std::string& name, const std::string& option) {
  const std::vector<std::string> names = builtInSceneNames();
  if (std::find(names.begin(), names.end(), name) != names.end()) return;
  std::string list;
  for (const std::string& n : names)
    list += (list.empty() ? "" : " | ") + n;
  throw UsageError("option " + option + ": '" + name + "' is not a built-in scene (" + list + ")");
}

SceneFrame makeSceneFrame(const std::string& name, int width, int height, int shadowMapSize,
                          StageTimings& timings, const SceneOverrides& overrides) {
  SceneFrame s;
  s.scene = timings.time("scene build", [&] {
    return std::make_unique<scenes::Scene>(scenes::makeScene(name, double(width) / double(height)));
  });
  gl::checkTextureSize("--map-size", shadowMapSize, shadowMapSize);
  gl::checkTextureSize("--size", width, height);
  if (overrides.sun) s.scene->sun = *overrides.sun;
  if (overrides.camera) s.scene->camera = *overrides.camera;
  const scenes::Scene& scene = *s.scene;
  s.renderer = timings.time("scene upload + shaders", [&] {
    auto r = std::make_unique<scenes::SceneRenderer>(scene.mesh);
    glFinish();
    return r;
  });
  s.frame = std::make_unique<FrameInputs>(scene.camera, scene.sun, scene.medium);
  FrameInputs& f = *s.frame;
  f.width = width;
  f.height = height;
  f.renderer = s.renderer.get();
  // Standard shadow map: lit surfaces and the reference march.
  f.lightClipFromWorld = scenes::standardLightClipFromWorld(scene.sun, scene.boundsMin, scene.boundsMax);
  f.shadowWidth = f.shadowHeight = shadowMapSize;
  f.shadowMap = scenes::createDepthTexture(shadowMapSize, shadowMapSize, "--map-size");
  timings.time("shadow pass (standard)", [&] {
    s.renderer->renderDepth(f.lightClipFromWorld, f.shadowMap.get(), 0, 0, 0, shadowMapSize, shadowMapSize,
                            {.depthClamp = true});
    glFinish();
  });
  // Local lights: their perspective shadow maps (one per spot, six per point light; the reference's and
  // what --export-frame writes), shadowMapSize^2 each, with depth clamping like the library's.
  f.directional = scene.hasSun;
  f.spotLights = scene.spotLights;
  f.pointLights = scene.pointLights;
  const auto localMap = [&](const glm::dmat4& matrix) {
    LocalShadowMap m;
    m.width = m.height = shadowMapSize;
    m.lightClipFromWorld = matrix;
    m.bias = kLocalShadowBias;
    m.texture = scenes::createDepthTexture(shadowMapSize, shadowMapSize, "--map-size");
    s.renderer->renderDepth(matrix, m.texture.get(), 0, 0, 0, shadowMapSize, shadowMapSize,
                            {.depthClamp = true});
    return m;
  };
  if (f.hasLocalLights())
    timings.time("shadow pass (local lights, perspective)", [&] {
      for (const SpotLight& spot : f.spotLights)
        f.spotShadows.push_back(localMap(spot.lightClipFromWorld()));
      for (const PointLight& point : f.pointLights)
        for (int k = 0; k < 6; ++k)
          f.pointShadows.push_back(localMap(point.faceClipFromWorld(k)));
      glFinish();
    });
  // The sun's light texture (a stained-glass window): every method's and the surfaces'.
  if (scene.sunTexture)
    timings.time("light texture upload", [&] {
      f.lightTexture =
          makeLightTextureMap(scene.sunTexture->rgb, scene.sunTexture->textureClipFromWorld, "light texture");
      glFinish();
    });
  s.color = gl::createTexture2D(GL_RGBA32F, width, height, "--size");
  f.cameraDepth = scenes::createDepthTexture(width, height, "--size");
  timings.time("camera pass", [&] {
    scenes::SceneRenderer::ShadeInputs in;
    in.clipFromWorld = scene.camera.clipFromWorld();
    in.shadowClipFromWorld = f.lightClipFromWorld;
    in.shadowMap = f.shadowMap.get();
    in.lightDirection = scene.sun.direction();
    in.lightIrradiance = overrides.shadeIrradiance.value_or(scene.sun.irradiance());
    if (overrides.shadeAmbient) in.ambient = *overrides.shadeAmbient;
    for (std::size_t i = 0; i < f.spotLights.size() && i < scenes::SceneRenderer::kMaxShadeSpots; ++i)
      in.spots.push_back(
          {&f.spotLights[i], f.spotShadows[i].lightClipFromWorld, f.spotShadows[i].texture.get()});
    in.sunTexture = f.lightTexture.texture.get();
    in.sunTextureClipFromWorld = f.lightTexture.textureClipFromWorld;
    s.renderer->renderShaded(in, s.color.get(), f.cameraDepth.get(), width, height);
    glFinish();
  });
  return s;
}

} // namespace crep::tool
