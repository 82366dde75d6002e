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

#include "march.glsl"

#define CREP_LAYOUT_PROJECTIVE 0
#define CREP_LAYOUT_EPIPOLAR 1
#ifndef CREP_LAYOUT
#define CREP_LAYOUT CREP_LAYOUT_PROJECTIVE
#endif
#ifndef CREP_LAYOUT_BINDING
#define CREP_LAYOUT_BINDING 1
#endif
#ifndef CREP_SLICES_BINDING
#define CREP_SLICES_BINDING 1
#endif

// gpu::kMaxLayoutRegions
#define CREP_MAX_LAYOUT_REGIONS 64
#define CREP_NEVER 3.0e38

// A view ray mapped onto its row of a rectified map (crep/scatter/rectified_march.h).
struct CrepRowRay {
  float row;    // normalized row of the ray
  float depth;  // z_r, clamped to [0, 1]
  int texelRow; // j = clamp(floor(row H), 0, H - 1)
  int last;     // e: the last texel the ray crosses
  vec4 dist;    // layout data of crep_rowRayDistance
};

// A light ray: origin + t direction, t >= 0 in the direction light travels (crep::LightRay).
struct CrepLightRay {
  vec3 origin;
  vec3 direction;
};

// The texel e of a ray ending in region k at column u in [0, 1] of it (n texels per region).
int crep_lastTexel(int k, float u, int K, int n) {
  k = clamp(k, 0, K - 1);
  return k * n + clamp(int(ceil(clamp(u, 0.0, 1.0) * float(n))) - 1, 0, n - 1);
}

#include "projective_layout.glsl"
#include "epipolar_layout.glsl"

#endif // CREP_LAYOUT_GLSL
