#version 450 core
// The 1D min/max binary tree of every row of a rectified map (Chen et al. 2011; Yusov 2012,
// Sec. 6.3: level 1 from pairs of texels, level l from pairs of nodes of level l - 1), in the storage
// layout of crep::MinMaxTrees (crep/epipolar/march.h): per row, levels 1..L one after the other, level l
// with ceil(W / 2^l) nodes (min, max). One work group per row; the levels are built in turn.
//
// Resources: rectified map depth (unit 0, texelFetch), nodes (storage buffer 0), sizes (location 0:
// W, H, L, row stride).

layout(local_size_x = 64) in;

layout(binding = 0) uniform sampler2D rectifiedDepth;
layout(std430, binding = 0) buffer CrepMinMaxBlock { vec2 crep_minMax[]; };
layout(location = 0) uniform ivec4 sizes;

void main() {
  int W = sizes.x, L = sizes.z;
  int j = int(gl_WorkGroupID.x);
  if (j >= sizes.y) return;
  int base = j * sizes.w;
  int below = W, offBelow = 0, off = 0;
  for (int l = 1; l <= L; ++l) {
    int size = (W + (1 << l) - 1) >> l;
    for (int m = int(gl_LocalInvocationID.x); m < size; m += int(gl_WorkGroupSize.x)) {
      int a = 2 * m, b = min(2 * m + 1, below - 1);
      vec2 node;
      if (l == 1) {
        float da = texelFetch(rectifiedDepth, ivec2(a, j), 0).r, db = texelFetch(rectifiedDepth, ivec2(b, j), 0).r;
        node = vec2(min(da, db), max(da, db));
      } else {
        vec2 na = crep_minMax[base + offBelow + a], nb = crep_minMax[base + offBelow + b];
        node = vec2(min(na.x, nb.x), max(na.y, nb.y));
      }
      crep_minMax[base + off + m] = node;
    }
    memoryBarrierBuffer();
    barrier();
    below = size;
    offBelow = off;
    off += size;
  }
}
