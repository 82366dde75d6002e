// The example's frame loop (app.h).
#include "app.h"

#include <glm/gtc/matrix_transform.hpp>

namespace vkengine {

App::App(World world, const Options& options)
    : world_(std::move(world)), options_(options), engine_(world_.mesh, options.engine),
      clipFromView_(glm::perspectiveRH_ZO(world_.fovY, double(options.width) / options.height, world_.near,
                                          world_.far)),
      camera_(crep::Camera::fromMatrices(glm::lookAtRH(world_.eye, world_.target, glm::dvec3(0.0, 1.0, 0.0)),
                                         clipFromView_, crep::ClipDepth::ZeroToOne)) {
  images_.cameraDepth = &engine_.createDepthImage(options.width, options.height);
  if (world_.hasSun) images_.sunMap = &engine_.createDepthImage(options.sunMapSize, options.sunMapSize);
  for (std::size_t i = 0; i < world_.spots.size(); ++i)
    images_.spotMaps.push_back(&engine_.createDepthImage(options.spotMapSize, options.spotMapSize));
  images_.output = &engine_.createColorImage(options.width, options.height);
  volumetrics_ = std::make_unique<Volumetrics>(engine_, images_, options.settings, options.loader);
  lights_.sun = world_.hasSun ? &world_.sun : nullptr;
  lights_.spots = world_.spots;
  for (const crep::SpotLight& s : world_.spots)
    lights_.spotClipFromWorld.push_back(s.lightClipFromWorld());
  lights_.medium = &world_.medium;
}

crep::Scattering::FrameResult App::frame(int i) {
  // The engine's camera: y up, depth in [0, 1] (Vulkan's clip space), strafing sideways.
  const glm::dvec3 forward = glm::normalize(world_.target - world_.eye);
  const glm::dvec3 step = 0.1 * i * glm::normalize(glm::cross(forward, glm::dvec3(0.0, 1.0, 0.0)));
  const glm::dmat4 viewFromWorld =
      glm::lookAtRH(world_.eye + step, world_.target + step, glm::dvec3(0.0, 1.0, 0.0));
  camera_ = crep::Camera::fromMatrices(viewFromWorld, clipFromView_, crep::ClipDepth::ZeroToOne);
  // The sun's map fitted to the view frustum (an engine's first cascade).
  lights_.sunClipFromWorld = crep::orthographicLightClipFromWorld(world_.sun, camera_.frustumCorners());

  const Engine::Frame frame = engine_.beginFrame();
  engine_.drawDepth(frame, *images_.cameraDepth, clipFromView_ * viewFromWorld, false);
  if (images_.sunMap != nullptr)
    engine_.drawDepth(frame, *images_.sunMap, zeroToOne(lights_.sunClipFromWorld), true);
  for (std::size_t s = 0; s < images_.spotMaps.size(); ++s)
    engine_.drawDepth(frame, *images_.spotMaps[s], zeroToOne(lights_.spotClipFromWorld[s]), false);
  const crep::Scattering::FrameResult result = volumetrics_->record(frame, camera_, lights_);
  engine_.submit(frame);
  frames_ = frame.index;
  return result;
}

void App::finish() {
  engine_.waitIdle();
  volumetrics_->backend().frameCompleted(frames_);
}

} // namespace vkengine
