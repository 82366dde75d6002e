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
  images_.output = &engine_.createColorImage(options.width, options.height);
  volumetrics_ = std::make_unique<Volumetrics>(engine_, images_, options.settings, options.loader);
  lights_.sun = world_.hasSun ? &world_.sun : nullptr;
  lights_.spots = world_.spots;
  lights_.medium = &world_.medium;
}

crep::Scattering::FrameResult App::frame(int i) {
  // The engine's camera: y up, depth in [0, 1] (Vulkan's clip space), strafing sideways.
  const glm::dvec3 forward = glm::normalize(world_.target - world_.eye);
  const glm::dvec3 step = 0.1 * i * glm::normalize(glm::cross(forward, glm::dvec3(0.0, 1.0, 0.0)));
  const glm::dmat4 viewFromWorld =
      glm::lookAtRH(world_.eye + step, world_.target + step, glm::dvec3(0.0, 1.0, 0.0));
  camera_ = crep::Camera::fromMatrices(viewFromWorld, clipFromView_, crep::ClipDepth::ZeroToOne);

  // 1. crepuscular's plan (CPU): which shadow maps it needs this frame, in Vulkan's clip conventions.
  const std::vector<ShadowPassTarget>& shadowPasses = volumetrics_->plan(camera_, lights_);
  // 2. The engine's depth passes: the camera's pre-pass and the plan's shadow maps, its own pipeline.
  const Engine::Frame frame = engine_.beginFrame();
  engine_.drawDepth(frame, *images_.cameraDepth, clipFromView_ * viewFromWorld, false);
  for (const ShadowPassTarget& t : shadowPasses)
    engine_.drawDepthPass(frame, *t.image, t.state, t.draws);
  // 3. crepuscular's compute passes, after them in the same command buffer.
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
