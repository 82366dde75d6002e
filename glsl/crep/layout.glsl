// crepuscular: mapping of world points and view rays into a rectified map (this file: what both layouts
// share; the layouts are crep/projective_layout.glsl and crep/epipolar_layout.glsl, included below), for shaders that march or
// resample rectified maps (passes/epipolar/march_rectified.comp, passes/epipolar/resample.comp) or evaluate the
// prefiltered scattering on the epipolar fallback layout. Two layouts (crep/rectify/rectified_map.h):
//   CREP_LAYOUT_PROJECTIVE  Klehm et al. 2014 Sec. 4.2 (crep::ProjectiveLayout): frame + split zetas
//   CREP_LAYOUT_EPIPOLAR    Sec. 4.1 epipolar resampling (crep::EpipolarLayout, crep/epipolar/epipolar.h)
// The uniform blocks are member for member the structs of crep/epipolar/gpu_layout.h (std140/std430).
//
// Public include (conventions in crep/common.glsl). Options (#define before the include):
//   CREP_LAYOUT           CREP_LAYOUT_PROJECTIVE (default) or CREP_LAYOUT_EPIPOLAR: which block exists
//   CREP_LAYOUT_BINDING   uniform buffer binding of the layout block (default 1)
//   CREP_SLICES_BINDING   storage buffer binding of the epipolar per-slice table (default 1)
//
// What every layout provides:
//   bool  crep_mapRowRay(vec3 dir, float surface, ivec2 mapSize, out CrepRowRay r)
//         a view ray (unit dir from the camera, surface distance) -> its texel row, depth z_r and last texel
//   float crep_rowRayDistance(CrepRowRay r, int i, ivec2 mapSize)
//         the ray's own world distance at texel boundary i (unclamped; 3e38 = never)
//   bool  crep_layoutToRectified(vec3 world, out vec4 p)   p = (row, column, depth, region)
//   bool  crep_mapRowRayPoint(vec3 dir, float surface, ivec2 mapSize, out CrepRowRay r, out vec4 p)
//         crep_mapRowRay and crep_layoutToRectified of the end point camera + surface dir at once
//   CrepRowRay crep_rowRayAt(float row, float depth, ivec2 mapSize)
//         the row ray of a normalized row and depth (its `last` left 0)
//   CrepLightRay crep_layoutLightRay(float column, float row)
//   vec3  crep_layoutViewDirection(float row, float depth)   unit direction of the view ray there
#ifndef CREP_LAYOUT_GLSL
#define CREP_LAYOUT_GLSL

#include "layout_common.glsl"
#include "projective_layout.glsl"
#include "epipolar_layout.glsl"

// A view ray (unit dir from the camera, surface distance) -> its row ray; false where the layout cannot
// map its end point.
bool crep_mapRowRay(vec3 dir, float surface, ivec2 mapSize, out CrepRowRay r) {
  vec4 p;
  return crep_mapRowRayPoint(dir, surface, mapSize, r, p);
}

#endif // CREP_LAYOUT_GLSL
