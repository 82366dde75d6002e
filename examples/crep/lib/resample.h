// Point resampling of a standard shadow map into a projective rectified map on the CPU (Klehm et al.
// 2014, Sec. 4.1 "point-resampled", applied to the projective layout of Sec. 4.2): what `crep scatter
// --method prefilter` does with a user's standard shadow map until the GPU resampling pass of the
// epipolar module is wired in (frame.cpp, "HOOK(issue 5)").
//
// Rule, for texel (i, j) of a W x H map of `layout` (column (i + 0.5) / W, row (j + 0.5) / H):
//   ray = layout.lightRay(column, row); (x, y) = NDC of ray.origin under lightClipFromWorld (the same for
//   every point of the ray, as the matrix is an orthographic projection along the light, see
//   checkLightMatrix); outside [-1, 1]^2 -> 1 (nothing casts there); else d = the nearest texel of the
//   standard map; d >= 1 -> 1; else the occluder p = lightClipFromWorld^-1 (x, y, 2 d - 1, 1) lies on the
//   ray and the stored depth is clamp(layout.toRectified(p).depth, 0, 1) (clamping keeps casters between
//   the light and the frustum, like GL_DEPTH_CLAMP for the split matrices).
#pragma once

#include <crep/core/image.h>
#include <crep/rectify/rectified_map.h>

#include <glm/glm.hpp>

#include <string>

namespace crep::tool {

/// Throws crep::FormatError naming `field` unless `lightClipFromWorld` is finite, affine (last row
/// 0 0 0 1), invertible and projects `lightDirection` (unit) to a point of the map with depth growing
/// along it (an orthographic shadow matrix looking along the light).
void checkLightMatrix(const glm::dmat4& lightClipFromWorld, const glm::dvec3& lightDirection,
                      const std::string& field);

/// The rule at the top; `shadowDepth` is 1 channel (channel 0 used), finite. Rows in parallel.
Image pointResampleShadowMap(const RectifiedLayout& layout, int width, int height, const Image& shadowDepth,
                             const glm::dmat4& lightClipFromWorld);

} // namespace crep::tool
