// A camera-aligned froxel volume (Wronski 2014, "Volumetric Fog"): cells over the image, exponential
// slices in view depth, Halton jitter; shared by postfx/'s fog and prefilter/'s fill. GLSL twin:
// glsl/crep/froxel.glsl. The uvw coordinates: scatter/README.md, "crep/scatter/froxel_grid.h".
#pragma once

#include <crep/core/camera.h>

#include <glm/glm.hpp>

namespace crep {

/// The froxel volume's size and depth range.
struct FroxelGrid {
  int width = 160; ///< cells across the image (Wronski 2014: 160 x 90 x 64 or 128)
  int height = 90; ///< cells up the image
  int depth = 64;  ///< slices along view depth
  /// View depth of the first slice's front face, world units: 0 = the camera's near plane.
  double nearDepth = 0.0;
  /// View depth of the last slice's back face, world units: 0 = the camera's far() (its integration far).
  double farDepth = 0.0;
};

/// Throws InvalidArgument naming `owner`.field (e.g. "FroxelFog::CreateInfo.grid.width"): sizes outside
/// [1, 2048], non-finite or negative depths, farDepth <= nearDepth when both are set.
void validate(const FroxelGrid& grid, const char* owner);

/// The depth range of `grid` for `camera` (zeros: the camera's near(), far()). InvalidArgument naming
/// `owner`.grid.farDepth unless near < far.
struct FroxelDepthRange {
  double near = 0.0, far = 0.0;
};
FroxelDepthRange froxelDepthRange(const FroxelGrid& grid, const Camera& camera, const char* owner);

/// Slice coordinate w = log(Z / near) / log(far / near) of view depth Z > 0, and its inverse.
double froxelSliceCoord(const FroxelDepthRange& range, double viewDepth);
double froxelViewDepth(const FroxelDepthRange& range, double sliceCoord);

/// World position of the volume point uvw for `camera`.
glm::dvec3 froxelWorldPoint(const Camera& camera, const FroxelDepthRange& range, const glm::dvec3& uvw);
/// The volume point uvw of a world position (inverse of froxelWorldPoint; may leave [0, 1]^3).
glm::dvec3 froxelCoord(const Camera& camera, const FroxelDepthRange& range, const glm::dvec3& world);
/// The distance along the unit view ray through (u, v) to view depth Z: Z / dot(ray, forward).
double froxelRayDistance(const Camera& camera, const glm::dvec3& uvw, double viewDepth);

/// The temporal jitter of frame `frameIndex`, cells, each component in [-0.5, 0.5): Halton 2, 3, 5.
glm::dvec3 froxelJitter(int frameIndex);

} // namespace crep
