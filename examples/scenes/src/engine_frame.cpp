// A scene's frame as an engine hands it to crep::Scattering on any backend (crep/scenes/engine_frame.h).
#include <crep/scenes/engine_frame.h>
#include <crep/scenes/scene_renderer.h>

namespace crep::scenes {

std::vector<float> rgbaTexels(const Image& rgb) {
  std::vector<float> out(rgb.pixelCount() * 4, 1.0f);
  float* p = out.data();
  for (int y = 0; y < rgb.height(); ++y)
    for (int x = 0; x < rgb.width(); ++x, p += 4)
      for (int c = 0; c < 3; ++c)
        p[c] = rgb.at(x, y, c);
  return out;
}

EngineMaps renderEngineMaps(const Scene& s, int width, int height, int sunMapSize, int localMapSize) {
  EngineMaps m;
  SceneRenderer renderer(s.mesh);
  m.cameraDepth = renderer.renderDepthImage(s.camera.clipFromWorld(), width, height);
  if (s.hasSun) {
    // Fitted to the view frustum, as an engine's (first) cascade is and as crep::Scattering fits its own map
    // on a fallback frame; casters between the light and the frustum are kept by the depth clamp.
    const auto corners = s.camera.frustumCorners();
    m.sunClipFromWorld = orthographicLightClipFromWorld(s.sun, corners);
    m.sunMap = renderer.renderDepthImage(m.sunClipFromWorld, sunMapSize, sunMapSize, {.depthClamp = true});
  }
  for (const SpotLight& spot : s.spotLights)
    m.spotMaps.push_back(renderer.renderDepthImage(spot.lightClipFromWorld(), localMapSize, localMapSize));
  for (const PointLight& point : s.pointLights)
    for (int face = 0; face < 6; ++face)
      m.pointMaps.push_back(
          renderer.renderDepthImage(point.faceClipFromWorld(face), localMapSize, localMapSize));
  return m;
}

namespace {
gpu::Texture depthTexture(gpu::Backend& b, const Image& image, const char* label) {
  gpu::Texture t(
      b, {gpu::TextureType::Texture2D, gpu::Format::Depth32F, image.width(), image.height(), 1, label});
  b.writeTexture(t.id(), image.data());
  return t;
}
} // namespace

EngineFrame::EngineFrame(gpu::Backend& b, const Scene& scene, const EngineMaps& m)
    : scene_(scene), depth_(depthTexture(b, m.cameraDepth, "engine frame: camera depth")) {
  if (scene.hasSun) {
    sun_ = depthTexture(b, m.sunMap, "engine frame: sun map");
    sunMap_ = {sun_.id(), m.sunClipFromWorld, m.sunBias};
    if (scene.sunTexture) {
      const Image& rgb = scene.sunTexture->rgb;
      window_ = gpu::Texture(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, rgb.width(), rgb.height(),
                                 1, "engine frame: light texture"});
      b.writeTexture(window_.id(), rgbaTexels(rgb));
      lightTexture_ = {window_.id(), scene.sunTexture->textureClipFromWorld};
    }
  }
  locals_.reserve(m.spotMaps.size() + m.pointMaps.size());
  for (std::size_t i = 0; i < m.spotMaps.size(); ++i) {
    locals_.push_back(depthTexture(b, m.spotMaps[i], "engine frame: spot map"));
    spotMaps_.push_back({locals_.back().id(), scene.spotLights[i].lightClipFromWorld(), m.localBias});
  }
  for (std::size_t i = 0; i < m.pointMaps.size(); ++i) {
    locals_.push_back(depthTexture(b, m.pointMaps[i], "engine frame: point face map"));
    pointMaps_.push_back({locals_.back().id(),
                          scene.pointLights[i / 6].faceClipFromWorld(static_cast<int>(i % 6)), m.localBias});
  }
}

Scattering::FrameAttribs EngineFrame::attribs(std::uint32_t output) const {
  Scattering::FrameAttribs f;
  f.camera = &scene_.camera;
  f.light = scene_.hasSun ? &scene_.sun : nullptr;
  f.medium = &scene_.medium;
  f.cameraDepth = depth_.id();
  f.output = output;
  f.shadowMap = scene_.hasSun ? &sunMap_ : nullptr;
  f.spotLights = scene_.spotLights;
  f.pointLights = scene_.pointLights;
  f.spotShadowMaps = spotMaps_;
  f.pointShadowMaps = pointMaps_;
  if (lightTexture_.texture != 0) f.lightTexture = &lightTexture_;
  return f;
}

} // namespace crep::scenes
