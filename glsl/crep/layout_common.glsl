// crepuscular: what the layouts of crep/layout.glsl share (the options, CrepRowRay, CrepLightRay). Included
// by crep/layout.glsl and by each layout file; include crep/layout.glsl, not this.
#ifndef CREP_LAYOUT_COMMON_GLSL
#define CREP_LAYOUT_COMMON_GLSL

#include "bindings.h"
#include "march.glsl"

#define CREP_LAYOUT_PROJECTIVE 0
#define CREP_LAYOUT_EPIPOLAR 1
#ifndef CREP_LAYOUT
#define CREP_LAYOUT CREP_LAYOUT_PROJECTIVE
#endif
#ifndef CREP_LAYOUT_BINDING
#define CREP_LAYOUT_BINDING CREP_LAYOUT_DEFAULT_BINDING
#endif
#ifndef CREP_SLICES_BINDING
#define CREP_SLICES_BINDING CREP_SLICES_DEFAULT_BINDING
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

#endif // CREP_LAYOUT_COMMON_GLSL
