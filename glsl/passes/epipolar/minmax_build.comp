#version 450 core
// The 1D min/max binary tree of every row of a rectified map (Chen et al. 2011; Yusov 2012,
// Sec. 6.3: level 1 from pairs of texels, level l from pairs of nodes of level l - 1), in the storage
// layout of crep::MinMaxTrees (crep/epipolar/march.h): per row, levels 1..L one after the other, level l
// with ceil(W / 2^l) nodes (min, max). One work group per row.
//
// Two phases (min and max are exact, so the nodes are those of any order): levels 1..C (C = max(0, L - 6):
// level C has at most 64 nodes) are built by each invocation alone over its own 2^C texels, reading back
// only nodes it wrote itself (no barrier); then levels C + 1..L, a barrier per level. Each invocation reads
// contiguous texels in phase 1 (measured on llvmpipe, 1024^2 map: 31-33 ms a build with a barrier per level
// throughout, 22-25 ms so; one barrier and a serial tail by one invocation gave no more, 22.5 ms).
//
// Resources: rectified map depth (unit 0, texelFetch), nodes (storage buffer 0), sizes (location 0:
// W, H, L, row stride).

// CREP_TREE_UPPER_ONLY 1: levels 1..C are in the buffer already (written by the epipolar resampling,
// passes/epipolar/resample.comp with CREP_RESAMPLE_TREES); only levels C + 1..L are built, the map is not read.
#include "crep/bindings.h"
#ifndef CREP_TREE_UPPER_ONLY
#define CREP_TREE_UPPER_ONLY 0
#endif

layout(local_size_x = 64) in;

layout(binding = CREP_MIN_MAX_TREE_RECTIFIED_DEPTH_UNIT) uniform sampler2D rectifiedDepth;
layout(std430, binding = CREP_MIN_MAX_TREE_MIN_MAX_BINDING) buffer CrepMinMaxBlock { vec2 crep_minMax[]; };
// Vulkan (and so HLSL root constants, an MSL buffer): push constants; GL: uniform locations.
#ifdef VULKAN
layout(push_constant) uniform CrepMinMaxBuildPush { ivec4 sizes; };
#else
layout(location = 0) uniform ivec4 sizes;
#endif

// Node m of level l from level l - 1 (size `below`, at offset offBelow) or, for l = 1, from the texels.
vec2 crep_buildNode(int l, int m, int j, int base, int below, int offBelow) {
  int a = 2 * m, b = min(2 * m + 1, below - 1);
  if (l == 1) {
#if CREP_TREE_UPPER_ONLY
    return vec2(0.0); // not reached (levels 1..C, C >= 1, are in the buffer): the variant reads no texture
#else
    float da = texelFetch(rectifiedDepth, ivec2(a, j), 0).r, db = texelFetch(rectifiedDepth, ivec2(b, j), 0).r;
    return vec2(min(da, db), max(da, db));
#endif
  }
  vec2 na = crep_minMax[base + offBelow + a], nb = crep_minMax[base + offBelow + b];
  return vec2(min(na.x, nb.x), max(na.y, nb.y));
}

void main() {
  int W = sizes.x, L = sizes.z;
  int j = int(gl_WorkGroupID.x);
  if (j >= sizes.y) return;
  int base = j * sizes.w;
  int t = int(gl_LocalInvocationID.x);
  int C = max(0, L - 6);
  // Phase 1: invocation t owns nodes [t 2^(C - l), (t + 1) 2^(C - l)) of every level l <= C.
  int below = W, offBelow = 0, off = 0;
  for (int l = 1; l <= C; ++l) {
    int size = (W + (1 << l) - 1) >> l;
    int first = t << (C - l), last = min((t + 1) << (C - l), size);
#if !CREP_TREE_UPPER_ONLY
    for (int m = first; m < last; ++m) crep_minMax[base + off + m] = crep_buildNode(l, m, j, base, below, offBelow);
#endif
    below = size;
    offBelow = off;
    off += size;
  }
  memoryBarrierBuffer();
  barrier();
  // Phase 2: the top levels, at most 64 nodes each, one node per invocation.
  for (int l = C + 1; l <= L; ++l) {
    int size = (W + (1 << l) - 1) >> l;
    for (int m = t; m < size; m += int(gl_WorkGroupSize.x))
      crep_minMax[base + off + m] = crep_buildNode(l, m, j, base, below, offBelow);
    memoryBarrierBuffer();
    barrier();
    below = size;
    offBelow = off;
    off += size;
  }
}
