// The frame fixture of the pipeline/ tests: a built-in scene at 160 x 90 with its camera depth, the
// engine's standard shadow map (1024^2, fitted to the scene), the output texture, FrameAttribs for either
// shadow input, and the world-space reference march against a standard map (GPU pass, tested against the
// CPU); metrics near the epipole and the brute-force march over the map a frame used.
#pragma once

#include "common/analytic_reference.h"

#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/gpu/gl.h>
#include <crep/pipeline/scattering.h>
#include <crep/scatter/gpu_light_texture.h>
#include <crep/scatter/gpu_world_march.h>
#include <crep/scatter/ray_scattering.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <glm/gtc/matrix_transform.hpp>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cmath>
#include <string>

namespace crep::test {

constexpr int kWidth = 160, kHeight = 90, kMap = 256, kShadow = 1024;

struct ScatteringFixture {
  explicit ScatteringFixture(const std::string& name)
      : scene(scenes::makeScene(name, double(kWidth) / kHeight)), renderer(scene.mesh) {
    cameraDepth = scenes::createDepthTexture(kWidth, kHeight);
    renderer.renderDepth(scene.camera.clipFromWorld(), cameraDepth.get(), 0, 0, 0, kWidth, kHeight);
    output = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
    shadow.texture = shadowTexture.get();
    setLight(scene.sun);
  }
  void setCamera(const Camera& camera) {
    scene.camera = camera;
    renderer.renderDepth(scene.camera.clipFromWorld(), cameraDepth.get(), 0, 0, 0, kWidth, kHeight);
  }
  void setLight(const DirectionalLight& light) {
    scene.sun = light;
    shadow.lightClipFromWorld = scenes::standardLightClipFromWorld(light, scene.boundsMin, scene.boundsMax);
    shadow.bias = 1e-4;
    renderer.renderDepth(shadow.lightClipFromWorld, shadowTexture.get(), 0, 0, 0, kShadow, kShadow,
                         {.depthClamp = true});
  }
  /// Light toward the camera axes combination (forward, right, up).
  void lightToward(double f, double r, double u) {
    const Camera& c = scene.camera;
    setLight(DirectionalLight(-glm::normalize(f * c.forward() + r * c.right() + u * c.up()),
                              scene.sun.irradiance()));
  }
  Scattering::FrameAttribs attribs(bool casters, bool shadowMap) {
    Scattering::FrameAttribs a;
    a.camera = &scene.camera;
    a.light = &scene.sun;
    a.medium = &scene.medium;
    a.cameraDepth = cameraDepth.get();
    a.output = output.get();
    if (casters)
      a.drawCasters = [this](const glm::dmat4& clipFromWorld) { renderer.drawDepth(clipFromWorld); };
    if (shadowMap) a.shadowMap = &shadow;
    return a;
  }
  Image read() const { return gl::readTexture(output.get(), kWidth, kHeight, gl::TexelData::Rgba); }
  /// The world-space reference march against the standard shadow map (GPU pass, tested against the CPU).
  Image reference() { return reference(shadow); }
  Image reference(const Scattering::ShadowMap& map) {
    static WorldMarchPass pass({{.steps = 256, .refinements = 12}});
    const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
    WorldMarchPass::FrameAttribs f;
    f.camera = &scene.camera;
    f.light = &scene.sun;
    f.medium = &scene.medium;
    f.cameraDepth = cameraDepth.get();
    f.shadowMap = map.texture;
    f.lightClipFromWorld = map.lightClipFromWorld;
    f.bias = map.bias;
    f.output = out.get();
    pass.run(f);
    return gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba);
  }

  scenes::Scene scene;
  scenes::SceneRenderer renderer;
  gl::Handle cameraDepth, output, shadowTexture = scenes::createDepthTexture(kShadow, kShadow);
  Scattering::ShadowMap shadow;
};

inline Scattering::CreateInfo smallInfo() {
  Scattering::CreateInfo info;
  info.width = kWidth;
  info.height = kHeight;
  info.mapSize = kMap;
  info.ownShadowMapSize = kShadow;
  return info;
}

inline void checkStages(const Scattering::FrameResult& r) {
  std::string names;
  for (const Scattering::Stage& s : r.stages) {
    names += s.name + "; ";
    CHECK(std::isfinite(s.gpuMilliseconds));
    CHECK(s.gpuMilliseconds >= 0.0);
    CHECK(s.wallMilliseconds > 0.0);
  }
  MESSAGE("stages: " << names);
  CHECK(names.find("prefilter") != std::string::npos);
  CHECK(names.find("evaluate") != std::string::npos);
}

/// The brute-force march (exact visibility per texel) over the rectified map a frame was prefiltered from:
/// the accuracy floor the map itself sets, without the prefilter's approximations.
inline Image marchSameMap(ScatteringFixture& f, const Scattering::FrameResult& r) {
  const Scattering::FrameResult::RectifiedMapView& m = r.rectifiedMap;
  RectifiedMarchPass pass({m.width, m.height, RectifiedMarchPass::Mode::BruteForce});
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
  RectifiedMarchPass::FrameAttribs a;
  a.layout = m.layout.get();
  a.camera = &f.scene.camera;
  a.light = &f.scene.sun;
  a.medium = &f.scene.medium;
  a.cameraDepth = f.cameraDepth.get();
  a.rectifiedDepth = m.texture;
  a.output = out.get();
  pass.run(a);
  return gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba);
}

/// The halo metric of the sun-in-view goal: over the pixels at distances in [inner, outer) (fractions of
/// the screen diagonal) from the epipole pixel, the RMS of the RGB error relative to the RMS of the local
/// reference radiance (relative RMSE restricted to the disc or ring); -1 when no pixel centre lies in it.
inline double discRelativeRmse(const Image& actual, const Image& reference, const glm::dvec2& centre,
                               double outer, double inner = 0.0) {
  const double diagonal = std::hypot(double(actual.width()), double(actual.height()));
  const double r = outer * diagonal, r0 = inner * diagonal;
  double e2 = 0.0, r2 = 0.0;
  int n = 0;
  for (int y = 0; y < actual.height(); ++y)
    for (int x = 0; x < actual.width(); ++x) {
      const double d = std::hypot(x + 0.5 - centre.x, y + 0.5 - centre.y);
      if (d >= r || d < r0) continue;
      ++n;
      for (int c = 0; c < 3; ++c) {
        const double e = double(actual.at(x, y, c)) - reference.at(x, y, c);
        e2 += e * e;
        r2 += double(reference.at(x, y, c)) * reference.at(x, y, c);
      }
    }
  return n == 0 ? -1.0 : std::sqrt(e2 / std::max(r2, 1e-300));
}

/// The world-space reference of one local light (a spot or a point-light face): its perspective shadow map
/// rendered from the scene (1024^2, depth clamp), the GPU march with 256 steps against it.
inline Image localReference(ScatteringFixture& f, const LocalLight& light,
                            const glm::dmat4& lightClipFromWorld) {
  static WorldMarchPass march({{.steps = 256, .refinements = 12}});
  const gl::Handle shadow = scenes::createDepthTexture(1024, 1024);
  f.renderer.renderDepth(lightClipFromWorld, shadow.get(), 0, 0, 0, 1024, 1024, {.depthClamp = true});
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
  WorldMarchPass::FrameAttribs b;
  b.camera = &f.scene.camera;
  b.localLight = &light;
  b.medium = &f.scene.medium;
  b.cameraDepth = f.cameraDepth.get();
  b.shadowMap = shadow.get();
  b.lightClipFromWorld = lightClipFromWorld;
  b.bias = 1e-4;
  b.output = out.get();
  march.run(b);
  return gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba);
}

/// The spot light of the local-light tests at `position`, aimed at the point 14 units in front of the camera
/// (cone 0.35 / 0.55 rad, warm white, intensity 150, range 80).
inline SpotLight spotToward(const Camera& c, const glm::dvec3& position) {
  return SpotLight({.position = position,
                    .direction = c.position() + 14.0 * c.forward() - position,
                    .innerConeAngle = 0.35,
                    .outerConeAngle = 0.55,
                    .color = {1.0, 0.85, 0.6},
                    .intensity = 150.0,
                    .range = 80.0});
}

/// The sun's window: an orthographic projection along the sun, 60 world units wide, centred on the point 14
/// units in front of the camera (the colour edge runs through the view).
inline glm::dmat4 sunWindowMatrix(const ScatteringFixture& f) {
  const Camera& c = f.scene.camera;
  const glm::dvec3 target = c.position() + 14.0 * c.forward(), d = f.scene.sun.direction();
  const glm::dvec3 up = std::abs(d.y) < 0.9 ? glm::dvec3(0.0, 1.0, 0.0) : glm::dvec3(1.0, 0.0, 0.0);
  return glm::ortho(-30.0, 30.0, -30.0, 30.0, 1.0, 1000.0) * glm::lookAt(target - 300.0 * d, target, up);
}

/// The light texture of the pipeline tests on the sun: an 8 x 8 RGBA32F window (left half 0.1 red, right
/// half 0.1 blue, the rest 1) through sunWindowMatrix().
struct SunWindow {
  gl::Handle texture;
  GpuLightTexture light;
};
inline SunWindow sunWindowTexture(const ScatteringFixture& f) {
  Image window(8, 8, 4, 1.0f);
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i)
      window.at(i, j, i < 4 ? 0 : 2) = 0.1f;
  SunWindow w;
  w.texture = gl::createTexture2D(GL_RGBA32F, 8, 8);
  glTextureSubImage2D(w.texture.get(), 0, 0, 0, 8, 8, GL_RGBA, GL_FLOAT, window.data().data());
  w.light = GpuLightTexture{w.texture.get(), sunWindowMatrix(f)};
  return w;
}

/// sum.rgb += add.rgb.
inline void addInto(Image& sum, const Image& add) {
  for (int y = 0; y < sum.height(); ++y)
    for (int x = 0; x < sum.width(); ++x)
      for (int c = 0; c < 3; ++c)
        sum.at(x, y, c) += add.at(x, y, c);
}

} // namespace crep::test
