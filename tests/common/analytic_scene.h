// The analytic setup shared by the prefilter/ and epipolar/ tests: a camera over a ground plane,
// an infinite plane occluder (half-space shadow), a side light and a coloured medium, built with
// none of the code under test except the rectification that makes the layout.
#pragma once

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>

#include <doctest/doctest.h>

#include <memory>
#include <optional>

namespace crep::test {

/// 60 degree camera 2 units above the ground plane y = 0, near 0.1, far 80.
inline Camera groundCamera(int w = 160, int h = 90) {
  return Camera::lookAt({0, 2, 0}, {0, 1.5, -10}, {0, 1, 0}, glm::radians(60.0), static_cast<double>(w) / h,
                        0.1, 80.0);
}
inline DirectionalLight sideLight() {
  return DirectionalLight(glm::dvec3(1.0, -1.0, -0.3), glm::dvec3(2.0, 1.8, 1.5));
}
inline Medium colouredMedium() {
  return Medium({.mieScattering = glm::dvec3(0.03, 0.04, 0.05),
                 .hgG = 0.6,
                 .rayleighScattering = glm::dvec3(0.005, 0.01, 0.02),
                 .absorption = glm::dvec3(0.01)});
}

inline std::shared_ptr<const ProjectiveLayout>
projectiveLayout(const Camera& camera, const DirectionalLight& light, int splits = 4) {
  RectifyOptions options;
  options.splits = splits;
  Rectification r = rectify(camera, light, options);
  REQUIRE(r.projective());
  return std::make_shared<const ProjectiveLayout>(std::move(r));
}

/// GL depth-buffer value of a view-space distance (glDepthRange(0, 1)).
inline double depthBufferValue(const Camera& c, double viewDepth) {
  const double n = c.near(), f = c.far();
  const double ndc = (f + n) / (f - n) - 2.0 * f * n / ((f - n) * viewDepth);
  return 0.5 * ndc + 0.5;
}

/// Camera depth of the ground plane y = 0 (sky = 1 where it is farther than the far plane or missed).
inline Image groundDepth(const Camera& camera, int w, int h) {
  Image depth(w, h, 1, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::dvec3 v = camera.rayDirection(2.0 * (x + 0.5) / w - 1.0, 2.0 * (y + 0.5) / h - 1.0);
      if (v.y >= 0.0) continue;
      const double t = -camera.position().y / v.y;
      const double viewDepth = t * glm::dot(v, camera.forward());
      if (viewDepth < camera.far()) depth.at(x, y) = static_cast<float>(depthBufferValue(camera, viewDepth));
    }
  return depth;
}

/// The half-space occluder: points with dot(normal, x - point) > 0 (the side the light travels toward)
/// are shadowed.
struct HalfSpace {
  glm::dvec3 normal = glm::normalize(glm::dvec3(1.0, 0.5, 0.3));
  glm::dvec3 point{2.0, 1.0, -10.0};
};

/// The first hit of a light ray with the half-space's plane (any t: casters before the ray origin too).
inline std::optional<glm::dvec3> planeHit(const HalfSpace& plane, const LightRay& ray) {
  const double dn = glm::dot(plane.normal, ray.direction);
  if (dn == 0.0) return std::nullopt;
  return ray.origin + glm::dot(plane.normal, plane.point - ray.origin) / dn * ray.direction;
}

} // namespace crep::test
