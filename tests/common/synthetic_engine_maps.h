// A scene's engine maps made up on the CPU, for the Vulkan tests that run without GL: a camera depth with
// sky, steps and slopes, and an orthographic sun map over the view frustum with boxes and smooth relief.
#pragma once

#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/scenes/engine_frame.h>
#include <crep/scenes/scene.h>

#include <cmath>

namespace crep::test {

inline scenes::EngineMaps syntheticMaps(const scenes::Scene& s, int width, int height, int sunMap) {
  scenes::EngineMaps m;
  m.cameraDepth = Image(width, height, 1);
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i) {
      const double u = (i + 0.5) / width, v = (j + 0.5) / height;
      const bool sky = v > 0.65 + 0.1 * std::sin(9.0 * u);
      const bool trunk = (i / 12) % 4 == 1 && v < 0.8;
      m.cameraDepth.at(i, j) =
          sky ? 1.0f : static_cast<float>(trunk ? 0.985 : 0.995 - 0.02 * v + 0.002 * std::sin(20.0 * u));
    }
  const auto corners = s.camera.frustumCorners();
  m.sunClipFromWorld = orthographicLightClipFromWorld(s.sun, corners);
  m.sunMap = Image(sunMap, sunMap, 1);
  for (int j = 0; j < sunMap; ++j)
    for (int i = 0; i < sunMap; ++i) {
      const double u = (i + 0.5) / sunMap, v = (j + 0.5) / sunMap;
      const bool box = (i / 40 + j / 56) % 3 == 0;
      m.sunMap.at(i, j) =
          static_cast<float>(0.6 + 0.2 * std::sin(7.0 * u) * std::cos(5.0 * v) - (box ? 0.3 : 0.0));
    }
  return m;
}

} // namespace crep::test
