// crepuscular: the min/max tree walk along one row of a rectified map (Chen et al. 2011; Yusov 2012,
// Algorithm 2 and Sec. 4): the lit sections of a view ray mapped onto its row (crep/layout.glsl's
// crep_mapRowRay), shared by passes/epipolar/march_rectified.comp (the march, crep::minMaxMarch) and
// passes/atmosphere/atmosphere.comp (the atmosphere's light shafts, crep::minMaxLitSections). Float precision.
//
// GLSL has no callbacks: the includer declares, BEFORE including this file,
//   sampler2D rectifiedDepth                      the W x H map (texelFetch, level 0)
//   readonly buffer { vec2 crep_minMax[]; }       the MinMaxTreePass nodes (crep::MinMaxTrees layout)
//   void crep_walkLitNode(CrepRowRay r, int i, int next, float ta, float tb)
//       called once per lit node, in ascending order: texels [i, next) of row r.texelRow are all lit and
//       the ray's distances over them are [ta, tb] (clipped to [0, s], ascending; tb == the next node's ta)
// and defines CREP_MINMAX_WALK_INPUTS to say so. Without it this file declares nothing (so it compiles on its
// own, as every public include must).
#ifndef CREP_MINMAX_WALK_GLSL
#define CREP_MINMAX_WALK_GLSL
#include "crep/layout.glsl"
#ifdef CREP_MINMAX_WALK_INPUTS

#ifndef CREP_MAX_TREE_LEVELS
#define CREP_MAX_TREE_LEVELS 16
#endif

// Walks the row ray r (surface distance s) through the row's tree of `levels` levels (node rows of
// `rowStride` nodes per map row) and calls crep_walkLitNode for each lit node. Returns the nodes visited
// (the march's "steps").
int crep_minMaxWalk(CrepRowRay r, float s, ivec2 mapSize, int levels, int rowStride) {
  int steps = 0;
  int j = r.texelRow, end = r.last + 1;
  float z = r.depth;
  int rowBase = j * rowStride;
  int offsets[CREP_MAX_TREE_LEVELS + 1];
  offsets[0] = 0;
  offsets[1] = 0;
  for (int l = 1; l < levels && l < CREP_MAX_TREE_LEVELS; ++l)
    offsets[l + 1] = offsets[l] + ((mapSize.x + (1 << l) - 1) >> l);
  int i = 0, level = 0;
  float ta = 0.0;
  while (i < end) {
    // Algorithm 2 step 5.1: one level up where the position is aligned to it.
    if (level < levels && (i & ((2 << level) - 1)) == 0) ++level;
    bool lit = false;
    for (;;) {
      ++steps;
      vec2 mm;
      if (level == 0) {
        mm = vec2(texelFetch(rectifiedDepth, ivec2(i, j), 0).r);
      } else {
        mm = crep_minMax[rowBase + offsets[level] + (i >> level)];
      }
      if (mm.x >= z) { // every texel of the node is lit
        lit = true;
        break;
      }
      if (mm.y < z) break; // every texel is shadowed
      --level;
    }
    int next = min(i + (1 << level), end);
    float tb = next > r.last ? s : min(crep_rowRayDistance(r, next, mapSize), s);
    tb = max(tb, ta);
    if (lit) crep_walkLitNode(r, i, next, ta, tb);
    ta = tb;
    i = next;
  }
  return steps;
}

#endif // CREP_MINMAX_WALK_INPUTS
#endif // CREP_MINMAX_WALK_GLSL
