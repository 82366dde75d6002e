// The light-texture tests' fixtures (Klehm et al. 2014, Sec. 3.2 coloured light textures): a two-colour and
// a constant texture, the projections of a window over the sun and of a spot light's gobo, and the analytic
// frame of one textured light (the ground camera, the plane or the wall cast into a projective map of 8
// splits, the texture's projection and the shadow matrix) for the sun and for the analytic spot light.
#pragma once

#include "common/analytic_reference.h"
#include "common/analytic_scene.h"
#include "common/local_light_scene.h"

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>

#include <glm/gtc/matrix_transform.hpp>

#include <memory>
#include <optional>

namespace crep::test {

/// 64 x 64: the left half red, the right half blue (a little of every channel in both).
inline Image twoColourTexture() {
  Image t(64, 64, 3);
  for (int j = 0; j < 64; ++j)
    for (int i = 0; i < 64; ++i) {
      const glm::vec3 c = i < 32 ? glm::vec3(1.0f, 0.1f, 0.05f) : glm::vec3(0.05f, 0.1f, 1.0f);
      for (int k = 0; k < 3; ++k)
        t.at(i, j, k) = c[k];
    }
  return t;
}

/// 4 x 4 of the colour c.
inline Image constantTexture(const glm::dvec3& c) {
  Image t(4, 4, 3);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
      for (int k = 0; k < 3; ++k)
        t.at(i, j, k) = static_cast<float>(c[k]);
  return t;
}

/// A stained-glass window over the sun: an orthographic projection along the light, 80 x 80 units
/// centred on `target` (the colour edge, the texture's middle column, runs through it).
inline glm::dmat4 sunWindow(const DirectionalLight& light, const glm::dvec3& target) {
  return glm::ortho(-40.0, 40.0, -40.0, 40.0, 1.0, 400.0) *
         glm::lookAt(target - 100.0 * light.direction(), target, glm::dvec3(0.0, 1.0, 0.0));
}

/// A gobo of a spot light: a 90-degree perspective projection from the light aimed at `target`.
inline glm::dmat4 spotGobo(const SpotLight& spot, const glm::dvec3& target) {
  return glm::perspective(glm::radians(90.0), 1.0, 0.1, 100.0) *
         glm::lookAt(spot.position(), target, glm::dvec3(0.0, 1.0, 0.0));
}

/// The analytic frame of one textured light: the sun (`local` empty) or a local light.
struct LightTextureFrame {
  explicit LightTextureFrame(const Camera& c) : camera(c) {}

  Camera camera;
  Image depth;
  Medium medium = colouredMedium();
  DirectionalLight sun = sideLight();
  std::optional<LocalLight> local;
  std::shared_ptr<const ProjectiveLayout> layout;
  RectifiedMap map;
  glm::dmat4 textureClipFromWorld{1.0}, shadowClipFromWorld{1.0};
  HalfSpace plane; ///< the occluder cast into the map
};

/// The sun (sideLight) over the ground plane for a width x height camera image: the plane's half-space
/// cast into a mapWidth x mapHeight map, the window centred 12 units ahead of the camera, 1 unit up, and
/// the standard shadow matrix around the view (analyticLightMatrix).
inline LightTextureFrame sunTextureFrame(int width, int height, int mapWidth, int mapHeight) {
  LightTextureFrame f(groundCamera(width, height));
  f.depth = groundDepth(f.camera, width, height);
  f.layout = projectiveLayout(f.camera, f.sun, 8);
  f.map = castRectifiedMap(f.layout, mapWidth, mapHeight,
                           [&](const LightRay& ray) { return planeHit(f.plane, ray); });
  f.textureClipFromWorld = sunWindow(f.sun, {0.0, 1.0, -12.0});
  f.shadowClipFromWorld = analyticLightMatrix(f.sun);
  return f;
}

/// The analytic spot light behind the wall (analyticSpot, wall()) for a width x height camera image: the
/// wall cast into a mapWidth x mapHeight map, the gobo aimed at (2, 0, -6), the spot's own shadow matrix.
inline LightTextureFrame spotTextureFrame(int width, int height, int mapWidth, int mapHeight) {
  LightTextureFrame f(groundCamera(width, height));
  f.depth = groundDepth(f.camera, width, height);
  const SpotLight spot = analyticSpot();
  f.local = LocalLight::spot(spot);
  RectifyOptions ro;
  ro.splits = 8;
  f.layout = std::make_shared<const ProjectiveLayout>(rectify(f.camera, spot, ro));
  f.map = castRectifiedMap(f.layout, mapWidth, mapHeight, wallHitFromLight);
  f.textureClipFromWorld = spotGobo(spot, {2.0, 0.0, -6.0});
  f.shadowClipFromWorld = spot.lightClipFromWorld();
  f.plane = wall();
  return f;
}

/// The spot's frame or the sun's.
inline LightTextureFrame lightTextureFrame(bool spot, int width, int height, int mapWidth, int mapHeight) {
  return spot ? spotTextureFrame(width, height, mapWidth, mapHeight)
              : sunTextureFrame(width, height, mapWidth, mapHeight);
}

} // namespace crep::test
