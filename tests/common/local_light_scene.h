// The analytic scene of the local-light tests: the ground camera of common/analytic_scene.h, a wall
// (half-space x > 2 shadowed) and a spot and a point light on its lit side; the closed form of the lit part
// of every view ray (the wall plane cuts it exactly) integrated by RayScattering (itself checked against an
// independent quadrature of Eq. 1 in RayScatteringTest).
#pragma once

#include "common/analytic_scene.h"

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/ray.h>
#include <crep/scatter/ray_scattering.h>

#include <cmath>
#include <optional>
#include <vector>

namespace crep::test {

/// What the local-light tests see: the ground camera (width x height), its ground depth, the coloured medium
/// and the rectify options of their layouts (8 splits).
struct LocalLightView {
  Camera camera;
  Image depth;
  Medium medium;
  RectifyOptions rectify;
};

inline LocalLightView localLightView(int width, int height) {
  LocalLightView v{groundCamera(width, height), {}, colouredMedium(), {}};
  v.depth = groundDepth(v.camera, width, height);
  v.rectify.splits = 8;
  return v;
}

/// The occluder: x > 2 is shadowed (the lights are at x < 2).
inline HalfSpace wall() {
  return HalfSpace{.normal = {1.0, 0.0, 0.0}, .point = {2.0, 0.0, -10.0}};
}

/// A spot above, behind and left of the ground camera (off screen: a projective rectification), aimed
/// into the view, its cone cut by the wall.
inline SpotLight analyticSpot() {
  return SpotLight({.position = {-6.0, 8.0, 4.0},
                    .direction = {7.0, -8.0, -14.0},
                    .innerConeAngle = 0.45,
                    .outerConeAngle = 0.7,
                    .color = {1.0, 0.85, 0.7},
                    .intensity = 30.0,
                    .range = 60.0});
}

/// A point light left of the ground camera (off screen), left of the wall.
inline PointLight analyticPoint() {
  return PointLight(
      {.position = {-8.0, 3.0, -2.0}, .color = {1.0, 0.9, 0.8}, .intensity = 20.0, .range = 60.0});
}

/// A spot in the ground camera's view, left of the wall, aimed down across it (its rectification falls
/// back: the epipolar layout of the light).
inline SpotLight analyticViewSpot() {
  return SpotLight({.position = {-1.0, 4.0, -8.0},
                    .direction = {4.0, -4.0, -4.0},
                    .innerConeAngle = 0.45,
                    .outerConeAngle = 0.7,
                    .color = {1.0, 0.85, 0.7},
                    .intensity = 30.0,
                    .range = 60.0});
}

/// A point light in the ground camera's view, left of the wall.
inline PointLight analyticViewPoint() {
  return PointLight(
      {.position = {-1.0, 3.0, -6.0}, .color = {1.0, 0.9, 0.8}, .intensity = 20.0, .range = 60.0});
}

/// The first hit of a light ray from a local light with the wall's plane, in front of the light only.
inline std::optional<glm::dvec3> wallHitFromLight(const LightRay& ray) {
  const HalfSpace plane = wall();
  const double dn = glm::dot(plane.normal, ray.direction);
  if (dn == 0.0) return std::nullopt;
  const double t = glm::dot(plane.normal, plane.point - ray.origin) / dn;
  if (!(t > 0.0)) return std::nullopt;
  return ray.origin + t * ray.direction;
}

/// Closed form per pixel: the in-scattering of the part of the ray on the lit side of the wall (or of the
/// whole ray without it), summed over `lights`; A = grey transmittance.
inline Image closedFormLocal(const Image& depth, const Camera& camera, const std::vector<LocalLight>& lights,
                             const Medium& medium, bool withWall = true) {
  const HalfSpace plane = wall();
  Image out(depth.width(), depth.height(), 4);
  const double grey = weightExtinction(medium);
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x) {
      const glm::dvec3 v =
          camera.rayDirection(2.0 * (x + 0.5) / depth.width() - 1.0, 2.0 * (y + 0.5) / depth.height() - 1.0);
      const double d = depth.at(x, y);
      const double s = (d >= 1.0 ? camera.far() : camera.linearDepth(d)) / glm::dot(v, camera.forward());
      const double f0 = glm::dot(plane.normal, camera.position() - plane.point),
                   fv = glm::dot(plane.normal, v);
      double lo = 0.0, hi = s;
      if (withWall) {
        if (fv > 0.0)
          hi = std::min(s, -f0 / fv);
        else if (fv < 0.0)
          lo = std::max(0.0, -f0 / fv);
      }
      glm::dvec3 L(0.0);
      for (const LocalLight& light : lights)
        L += RayScattering(light, medium, camera.position(), v).segment(lo, hi);
      storeScattering(out, x, y, L, std::exp(-grey * s));
    }
  return out;
}

} // namespace crep::test
