#version 450 core
// Point resampling of a standard shadow map into a rectified map with blocker clamping (Klehm et al. 2014,
// Sec. 4.1; rules in crep/epipolar/resample.h), for the epipolar fallback layout (CREP_LAYOUT 1) or a
// projective layout (CREP_LAYOUT 0) of a directional light, spot light or point-light face. One invocation
// per texel of the rectified map.
//
// Resources: params block (binding 0: sizes.xy standard map, sizes.zw rectified map, lightClipFromWorld),
// layout block (binding 1) and slices (storage buffer 1, epipolar), standard shadow map (unit 0,
// texelFetch), output: R32F rectified map (image 0), worldFromLightClip (location 0), projectedDistance
// (location 1): 0 for a directional light (the ray origin is projected: an orthographic map), else the
// distance along the local light's ray of the projected point (its origin is the light, the perspective
// map's centre of projection).
//
// CREP_RESAMPLE_TREES 1 (with MinMaxTreePass's buffer at storage binding 0 and sizes.w-style tree info at
// location 2: ivec4(L, row stride, C, 0)): the map's 1D min/max trees' levels 1..C (C = max(0, L - 6); Chen
// et al. 2011, Yusov 2012 Sec. 6.3) are written too, from the texels this pass has at hand: one work group
// of 64 per row, invocation t resamples the 2^C texels [t 2^C, (t + 1) 2^C) in turn and builds their nodes,
// reading back only nodes it wrote itself (no barrier). MinMaxTreePass::completeUpperLevels builds the rest.
// Saves the tree pass's second read of the map (chosen for GPUs: the map is read once; measured on llvmpipe
// in README "Sun in view").
#include "crep/bindings.h"
#include "crep/layout.glsl"

#ifndef CREP_RESAMPLE_TREES
#define CREP_RESAMPLE_TREES 0
#endif

#if CREP_RESAMPLE_TREES
layout(local_size_x = 64) in;
layout(std430, binding = CREP_RESAMPLE_MIN_MAX_BINDING) buffer CrepMinMaxBlock { vec2 crep_minMax[]; };
#ifndef VULKAN
layout(location = 2) uniform ivec4 treeInfo; // L, row stride, C, 0
#endif
#else
layout(local_size_x = 8, local_size_y = 8) in;
#endif

layout(std140, binding = CREP_RESAMPLE_MARCH_BINDING) uniform CrepMarchBlock { CrepMarchParams crep_march; };
layout(binding = CREP_RESAMPLE_SHADOW_MAP_UNIT) uniform sampler2D shadowMap;
layout(binding = CREP_RESAMPLE_RECTIFIED_OUT_IMAGE, r32f) uniform writeonly image2D rectifiedOut;
// Vulkan (and so HLSL root constants, an MSL buffer): push constants; GL: uniform locations.
#ifdef VULKAN
layout(push_constant) uniform CrepResamplePush {
  mat4 worldFromLightClip;
  float projectedDistance;
#if CREP_RESAMPLE_TREES
  layout(offset = 80) ivec4 treeInfo; // L, row stride, C, 0
#endif
};
#else
layout(location = 0) uniform mat4 worldFromLightClip;
layout(location = 1) uniform float projectedDistance;
#endif

// The resampled depth of one texel of the rectified map (written to the output by the caller).
float crep_resampleTexel(ivec2 texel, ivec2 mapSize) {
  ivec2 shadowSize = crep_march.sizes.xy;
  vec2 cr = (vec2(texel) + 0.5) / vec2(mapSize);
  CrepLightRay ray = crep_layoutLightRay(cr.x, cr.y);
  vec4 q = crep_march.lightClipFromWorld * vec4(ray.origin + projectedDistance * ray.direction, 1.0);
  vec2 ndc = q.xy / q.w;
  float depth = 1.0;
  bool inFront = projectedDistance == 0.0 || q.w > 0.0; // a local light's ray behind its map: no information
  if (inFront && all(greaterThanEqual(ndc, vec2(-1.0))) && all(lessThanEqual(ndc, vec2(1.0)))) {
    ivec2 s = min(ivec2((ndc + 1.0) * 0.5 * vec2(shadowSize)), shadowSize - 1);
    float d = texelFetch(shadowMap, s, 0).r;
    if (d < 1.0) { // also false for NaN: an empty texel
      vec4 h = worldFromLightClip * vec4(ndc, 2.0 * d - 1.0, 1.0);
      vec4 p;
      if (crep_layoutToRectified(h.xyz / h.w, p)) depth = clamp(p.z, 0.0, 1.0);
    }
  }
  return depth;
}

void main() {
  ivec2 mapSize = crep_march.sizes.zw;
#if CREP_RESAMPLE_TREES
  int j = int(gl_WorkGroupID.x);
  if (j >= mapSize.y) return;
  int W = mapSize.x, C = treeInfo.z, base = j * treeInfo.y;
  int t = int(gl_LocalInvocationID.x);
  // Level 1 from this invocation's texel pairs (a lone last texel pairs with itself, as crep::MinMaxTrees).
  int first = t << C, last = min((t + 1) << C, W);
  for (int a = first; a < last; a += 2) {
    float da = crep_resampleTexel(ivec2(a, j), mapSize);
    imageStore(rectifiedOut, ivec2(a, j), vec4(da));
    float db = da;
    if (a + 1 < W) {
      db = crep_resampleTexel(ivec2(a + 1, j), mapSize);
      imageStore(rectifiedOut, ivec2(a + 1, j), vec4(db));
    }
    if (C >= 1) crep_minMax[base + (a >> 1)] = vec2(min(da, db), max(da, db));
  }
  // Levels 2..C from this invocation's own nodes.
  int below = (W + 1) >> 1, offBelow = 0, off = below;
  for (int l = 2; l <= C; ++l) {
    int size = (W + (1 << l) - 1) >> l;
    int m0 = t << (C - l), m1 = min((t + 1) << (C - l), size);
    for (int m = m0; m < m1; ++m) {
      vec2 na = crep_minMax[base + offBelow + 2 * m], nb = crep_minMax[base + offBelow + min(2 * m + 1, below - 1)];
      crep_minMax[base + off + m] = vec2(min(na.x, nb.x), max(na.y, nb.y));
    }
    below = size;
    offBelow = off;
    off += size;
  }
#else
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(texel, mapSize))) return;
  imageStore(rectifiedOut, texel, vec4(crep_resampleTexel(texel, mapSize)));
#endif
}
