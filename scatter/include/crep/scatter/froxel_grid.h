// A camera-aligned froxel volume (Wronski 2014, "Volumetric Fog", the frustum-aligned volume with an
// exponential depth distribution): width x height cells over the camera's image, `depth` slices along
// view-space depth Z (the distance along -Z of view space, not along the ray). Shared by the froxel fog of
// postfx/ (both fills, the accumulation, the per-pixel lookup, the temporal reprojection) and the
// prefiltered fill of prefilter/'s evaluation pass. GLSL twin: glsl/crep/froxel.glsl.
//
// Coordinates. A point of the volume is uvw in [0, 1]^3:
//   u, v: normalized device coordinates (2u - 1, 2v - 1) of the camera (row 0 at the bottom), so cell
//         (x, y) covers the pixels of that cell of the image and its ray is camera.rayDirection(ndc);
//   w:    the slice coordinate of view depth Z: w = log(Z / near) / log(far / near) (exponential slices:
//         each slice is the same multiple deeper than the previous one), Z = near (far / near)^w.
// Cell (x, y, z) covers [x, x + 1] / width x [y, y + 1] / height x [z, z + 1] / depth; its centre is at
// (x + 0.5, y + 0.5, z + 0.5) / size. Depths in front of `near` belong to no cell: a lookup there
// interpolates between the camera (nothing scattered, transmittance 1) and the first slice's centre.
// A sample point jittered by j in [-0.5, 0.5]^3 cells is at (x + 0.5 + j.x, ...) / size (temporal jitter).
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

/// Throws InvalidArgument naming `owner`.field (e.g. "FroxelFog::CreateInfo.grid.width"): sizes < 1 or
/// above 2048 (a 3D texture's usual limit; the GL passes check the driver's own), non-finite or negative
/// depths, farDepth <= nearDepth when both are set.
void validate(const FroxelGrid& grid, const char* owner);

/// The depth range of `grid` for `camera` (zeros replaced by the camera's near() and far()). Throws
/// InvalidArgument naming `owner`.grid.farDepth unless near < far.
struct FroxelDepthRange {
  double near = 0.0, far = 0.0;
};
FroxelDepthRange froxelDepthRange(const FroxelGrid& grid, const Camera& camera, const char* owner);

/// Slice coordinate w of view depth Z > 0 (may fall outside [0, 1]) and its inverse (see top).
double froxelSliceCoord(const FroxelDepthRange& range, double viewDepth);
double froxelViewDepth(const FroxelDepthRange& range, double sliceCoord);

/// World position of the volume point uvw (see top) for `camera`.
glm::dvec3 froxelWorldPoint(const Camera& camera, const FroxelDepthRange& range, const glm::dvec3& uvw);
/// The volume point uvw of a world position (inverse of froxelWorldPoint; may fall outside [0, 1]^3; z of
/// a point behind the camera is -infinity). Used to reproject last frame's volume.
glm::dvec3 froxelCoord(const Camera& camera, const FroxelDepthRange& range, const glm::dvec3& world);
/// The distance along the unit view ray through (u, v) to view depth Z: Z / dot(ray, forward).
double froxelRayDistance(const Camera& camera, const glm::dvec3& uvw, double viewDepth);

/// The temporal jitter of frame `frameIndex`, in cells, each component in [-0.5, 0.5): the Halton
/// sequence in bases 2, 3, 5 (a low-discrepancy sequence: any N consecutive frames cover the cell
/// evenly). Frame index i uses element (i mod 1024) + 1.
glm::dvec3 froxelJitter(int frameIndex);

} // namespace crep
