// A built-in scene of crep_scenes (crep/scenes/scene.h) as the example's World: in the source tree's build
// only (crep-vulkan-engine --scene, and the tests).
#pragma once

#include <string_view>

#include <crep/scenes/scene.h>

#include "app.h"

namespace vkengine {

inline World worldOf(const crep::scenes::Scene& s) {
  World w;
  w.mesh.positions = s.mesh.positions;
  w.mesh.indices = s.mesh.indices;
  w.eye = s.camera.position();
  w.target = s.camera.position() + s.camera.forward();
  w.fovY = s.camera.fovY();
  w.near = s.camera.near();
  w.far = s.camera.far();
  w.hasSun = s.hasSun;
  w.sun = s.sun;
  w.spots = s.spotLights;
  w.medium = s.medium;
  return w;
}

} // namespace vkengine
