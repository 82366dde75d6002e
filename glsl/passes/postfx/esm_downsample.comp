#version 450 core
// Exponential shadow map, step 1 (Annen et al. 2008 as used by Wronski 2014: the shadow map downsampled in
// exponent space; crep::buildEsm, rule 1 of crep/postfx/froxel_fog.h): ESM texel (i, j) = log(mean exp(c d))
// / c over its f x f block of shadow-map texels (clipped at the map's edge), evaluated around the block's
// largest d (log-space filtering: no float overflow for any c). A NaN texel counts as empty (d = 1).
// Resources: params block (binding 0), shadow map (unit 0, texelFetch), output R32F (image 0).
#include "crep/bindings.h"
#include "crep/froxel.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = CREP_ESM_FROXEL_BINDING) uniform CrepFroxelBlock { CrepFroxelParams crep_froxel; };
layout(binding = CREP_ESM_SHADOW_MAP_UNIT) uniform sampler2D shadowMap;
layout(binding = CREP_ESM_OUT_IMAGE, r32f) uniform writeonly image2D esmOut;

void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 mapSize = crep_froxel.sizes.xy;
  if (any(greaterThanEqual(texel, crep_froxel.sizes.zw))) return;
  int f = crep_froxel.info.x;
  float c = crep_froxel.esm.x;
  ivec2 lo = texel * f, hi = min(lo + f, mapSize);
  float m = 0.0;
  for (int y = lo.y; y < hi.y; ++y)
    for (int x = lo.x; x < hi.x; ++x) {
      float d = texelFetch(shadowMap, ivec2(x, y), 0).r;
      m = max(m, d >= 0.0 ? min(d, 1.0) : (d < 0.0 ? 0.0 : 1.0));
    }
  float sum = 0.0;
  for (int y = lo.y; y < hi.y; ++y)
    for (int x = lo.x; x < hi.x; ++x) {
      float d = texelFetch(shadowMap, ivec2(x, y), 0).r;
      d = d >= 0.0 ? min(d, 1.0) : (d < 0.0 ? 0.0 : 1.0); // NaN -> 1 (empty)
      sum += exp(c * (d - m));
    }
  ivec2 n = hi - lo;
  imageStore(esmOut, texel, vec4(m + log(sum / float(n.x * n.y)) / c));
}
