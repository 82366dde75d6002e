// crepuscular: the froxel volume's coordinates (crep/scatter/froxel_grid.h; Wronski 2014, frustum-aligned
// cells with exponential depth slices). Public include.
//
// uvw in [0, 1]^3: (u, v) = ((ndc.x + 1) / 2, (ndc.y + 1) / 2) of the camera image, w = log(Z / near) /
// log(far / near) of view depth Z. `range` = (near, far) of the volume (FroxelDepthRange).
#ifndef CREP_FROXEL_GLSL
#define CREP_FROXEL_GLSL

// Slice coordinate w of view depth Z > 0.
float crep_froxelSliceCoord(vec2 range, float viewDepth) {
  return log(viewDepth / range.x) / log(range.y / range.x);
}

// View depth Z of slice coordinate w.
float crep_froxelViewDepth(vec2 range, float sliceCoord) {
  return range.x * exp2(sliceCoord * log2(range.y / range.x));
}

#endif
