// The point light of the prefilter/ tests' regression on the colonnade: 3 units behind the camera, 5 to its
// left and 3 up; face -Z's rows span depths [0.003, 0.95] and their reference ray reached its horizon in the
// middle of the map (ProjectiveLayout::regionReferenceDepth).
#pragma once

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/rectify/rectify.h>

#include <array>

namespace crep::test {

inline PointLight colonnadePointLight(const Camera& c) {
  return PointLight({.position = c.position() - 5.0 * c.right() + 3.0 * c.up() - 3.0 * c.forward(),
                     .color = {1.0, 0.8, 0.6},
                     .intensity = 60.0,
                     .range = 80.0});
}

/// Its six faces rectified for the camera with 8 splits.
inline std::array<Rectification, 6> colonnadePointFaces(const Camera& c, const PointLight& point) {
  RectifyOptions ro;
  ro.splits = 8;
  return rectifyPointLight(c, point, ro);
}

} // namespace crep::test
