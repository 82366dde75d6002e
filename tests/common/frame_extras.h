// What the front-door frame tests add to a built-in scene's frame: a spot light in view and a point light
// behind the camera (local lights on their epipolar and projective layouts), and a froxel volume of a
// backend with the frame's target on it.
#pragma once

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/gpu/backend.h>
#include <crep/pipeline/scattering.h>
#include <crep/scatter/froxel_grid.h>

namespace crep::test {

/// A spot 6 units ahead of `c` and 1 up, aimed down and forward: in view, so its rectification falls back
/// to its epipolar layout (Klehm et al. 2014, Sec. 4.1).
inline SpotLight spotInView(const Camera& c) {
  return SpotLight({.position = c.position() + 6.0 * c.forward() + 1.0 * c.up(),
                    .direction = c.forward() - 2.0 * c.up(),
                    .innerConeAngle = 0.4,
                    .outerConeAngle = 0.6,
                    .color = {1.0, 0.8, 0.6},
                    .intensity = 20.0,
                    .range = 40.0});
}

/// A point light behind `c`, to its left and above (off screen).
inline PointLight pointBehindLeft(const Camera& c) {
  return PointLight({.position = c.position() - 8.0 * c.right() + 4.0 * c.up() - 6.0 * c.forward(),
                     .color = {1.0, 0.8, 0.6},
                     .intensity = 60.0,
                     .range = 80.0});
}

/// A froxel volume of a backend (a 3D texture of the grid's size) and the frame's target on it, jittered
/// by (0.25, -0.25, 0.5) cells; default-constructed: none.
struct FroxelVolume {
  gpu::Texture texture;
  Scattering::FroxelTarget target;

  FroxelVolume() = default;
  FroxelVolume(gpu::Backend& b, const FroxelGrid& grid, gpu::Format format)
      : texture(b, {gpu::TextureType::Texture3D, format, grid.width, grid.height, grid.depth, "froxels"}),
        target{texture.id(), grid, glm::dvec3(0.25, -0.25, 0.5)} {}
};

} // namespace crep::test
