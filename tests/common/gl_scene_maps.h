// GL fixtures of the GPU march and work-list tests (tests/epipolar/MarchGLTest.cpp, MarchListGLTest.cpp,
// tests/prefilter/EvaluateListGLTest.cpp): a built-in scene with its projective rectified map rasterized
// on the GPU (SceneRenderer, GL_DEPTH_CLAMP) and the march attributes over it; the analytic spot-light
// scene of tests/common/local_light_scene.h with its map cast exactly, map and depth uploaded. GL tests
// only.
#pragma once

#include "common/analytic_reference.h"
#include "common/local_light_scene.h"

#include <crep/epipolar/gpu_march.h>
#include <crep/gpu/gl.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/ray_scattering.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>

namespace crep::test {

/// A scene with its projective rectified map rendered on the GPU (kept as a texture and read back).
struct SceneMaps {
  scenes::Scene scene;
  std::shared_ptr<const ProjectiveLayout> layout;
  gl::Handle mapTexture, cameraTexture;
  RectifiedMap map;
  Image cameraDepth;
};

/// Built-in scene `name` for a width x height camera image; its map (4 splits) mapWidth x mapHeight.
inline SceneMaps renderSceneMaps(const std::string& name, int width, int height, int mapWidth,
                                 int mapHeight) {
  SceneMaps s{scenes::makeScene(name, static_cast<double>(width) / height), {}, {}, {}, {}, {}};
  RectifyOptions options;
  options.splits = 4;
  Rectification r = rectify(s.scene.camera, s.scene.sun, options);
  INFO(name << ": " << r.message);
  REQUIRE(r.projective());
  scenes::SceneRenderer renderer(s.scene.mesh);
  s.mapTexture = scenes::createDepthTexture(mapWidth, mapHeight);
  for (int k = 0; k < r.splitCount(); ++k) {
    const SplitViewport v = r.splitViewport(k, mapWidth, mapHeight);
    renderer.renderDepth(r.splits[static_cast<std::size_t>(k)].rectClipFromWorld, s.mapTexture.get(), v.layer,
                         v.x, v.y, v.width, v.height, {.depthClamp = true});
  }
  s.layout = std::make_shared<const ProjectiveLayout>(std::move(r));
  s.map = makeRectifiedMap(s.layout, scenes::readDepthTexture(s.mapTexture.get(), mapWidth, mapHeight));
  s.cameraTexture = scenes::createDepthTexture(width, height);
  renderer.renderDepth(s.scene.camera.clipFromWorld(), s.cameraTexture.get(), 0, 0, 0, width, height);
  s.cameraDepth = scenes::readDepthTexture(s.cameraTexture.get(), width, height);
  return s;
}

/// RectifiedMarchPass attributes of `s` (layout, camera, sun, medium, map) with the trees in `minMaxBuffer`;
/// the camera depth, outputs and list are the caller's.
inline RectifiedMarchPass::FrameAttribs marchAttribs(const SceneMaps& s, std::uint32_t minMaxBuffer) {
  RectifiedMarchPass::FrameAttribs f;
  f.layout = s.layout.get();
  f.camera = &s.scene.camera;
  f.light = &s.scene.sun;
  f.medium = &s.scene.medium;
  f.rectifiedDepth = s.mapTexture.get();
  f.minMaxBuffer = minMaxBuffer;
  return f;
}

/// The analytic spot scene (analyticSpot behind the wall, the ground camera, colouredMedium) with its map
/// cast exactly (wallHitFromLight) on a projective layout of 8 splits, map and camera depth as R32F textures.
struct SpotMaps {
  Camera camera;
  Image depth;
  Medium medium;
  LocalLight light;
  std::shared_ptr<const ProjectiveLayout> layout;
  RectifiedMap map;
  gl::Handle mapTexture, depthTexture;
};

/// SpotMaps for a width x height camera image and a mapWidth x mapHeight map.
inline SpotMaps uploadSpotMaps(int width, int height, int mapWidth, int mapHeight) {
  const Camera camera = groundCamera(width, height);
  RectifyOptions ro;
  ro.splits = 8;
  const SpotLight spot = analyticSpot();
  auto layout = std::make_shared<const ProjectiveLayout>(rectify(camera, spot, ro));
  SpotMaps s{camera,
             groundDepth(camera, width, height),
             colouredMedium(),
             LocalLight::spot(spot),
             layout,
             castRectifiedMap(layout, mapWidth, mapHeight, wallHitFromLight),
             gl::createTexture2D(GL_R32F, mapWidth, mapHeight),
             gl::createTexture2D(GL_R32F, width, height)};
  glTextureSubImage2D(s.mapTexture.get(), 0, 0, 0, mapWidth, mapHeight, GL_RED, GL_FLOAT,
                      s.map.depth.data().data());
  glTextureSubImage2D(s.depthTexture.get(), 0, 0, 0, width, height, GL_RED, GL_FLOAT, s.depth.data().data());
  return s;
}

} // namespace crep::test
