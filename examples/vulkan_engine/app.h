// The example's frame loop (main.cpp, and the tests that drive it): a world, the engine of engine.h and the
// volumetrics of volumetrics.h, and per frame crepuscular's plan, the engine's depth pre-pass and the plan's
// shadow passes, crepuscular recorded after them, one submission. The camera strafes sideways 0.1 units a
// frame.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/pipeline/scattering.h>

#include "engine.h"
#include "volumetrics.h"

namespace vkengine {

/// What the engine draws and lights: a mesh, the camera of the first frame, the lights and the medium.
struct World {
  Mesh mesh;
  glm::dvec3 eye{0.0}, target{0.0, 0.0, -1.0}; ///< the first frame's camera looks from eye at target, y up
  double fovY = 0.9, near = 0.1, far = 100.0;  ///< radians, world units
  bool hasSun = true;
  crep::DirectionalLight sun{glm::dvec3(0.0, -1.0, 0.0), glm::dvec3(1.0)};
  std::vector<crep::SpotLight> spots;
  crep::Medium medium{crep::MediumCoefficients{.mieScattering = glm::dvec3(0.03), .hgG = 0.6}};
};

class App {
public:
  struct Options {
    std::uint32_t width = 640, height = 360; ///< the camera depth's and the output's size
    Engine::Options engine{};                ///< frames in flight (3), validation
    /// crepuscular's settings but the size and backend; mapSize and ownShadowMapSize are the sizes of the
    /// shadow maps the engine rasterizes for it (rectified, standard).
    crep::Scattering::CreateInfo settings{};
    PFN_vkGetInstanceProcAddr loader = vkGetInstanceProcAddr; ///< what crepuscular resolves Vulkan through
  };
  App(World world, const Options& options);

  /// Records and submits frame i (from 0); returns crepuscular's result for it.
  crep::Scattering::FrameResult frame(int i);
  /// Waits until every frame has completed (the engine's wait), and tells crepuscular so.
  void finish();

  Engine& engine() { return engine_; }
  const VolumetricImages& images() const { return images_; }
  Volumetrics& volumetrics() { return *volumetrics_; }
  const World& world() const { return world_; }
  /// The last frame's camera and lights; its plan and the engine's images of it: volumetrics().plan().
  const crep::Camera& camera() const { return camera_; }
  const VolumetricLights& lights() const { return lights_; }

private:
  World world_;
  Options options_;
  Engine engine_;
  VolumetricImages images_;
  std::unique_ptr<Volumetrics> volumetrics_;
  glm::dmat4 clipFromView_;
  crep::Camera camera_;
  VolumetricLights lights_;
  std::uint64_t frames_ = 0;
};

} // namespace vkengine
