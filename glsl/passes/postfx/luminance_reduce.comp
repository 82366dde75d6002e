#version 450 core
// ToneMapPass, reduction pass 1 of 2 (crep/postfx/gpu_tone_mapping.h): each workgroup sums
// log(delta + Y) over a CREP_LUMINANCE_TILE x CREP_LUMINANCE_TILE block of the HDR input (Reinhard et al.
// 2002, Eq. 1; crep::luminanceStats is the CPU reference) and counts its finite pixels; pixels with a
// non-finite channel are skipped. One partial sum per workgroup goes to the storage buffer.
//
// GPU choice: a 16 x 16 workgroup where each invocation first sums 4 x 4 pixels strided by 16 (neighbouring
// invocations read neighbouring texels: coalesced fetches), then a tree reduction in shared memory
// (log2(256) = 8 barrier steps). Float sums: each partial adds at most 4096 terms.
#include "crep/bindings.h"
#include "crep/tone_mapping.glsl"

#ifndef CREP_LUMINANCE_GROUP
#define CREP_LUMINANCE_GROUP 16
#endif
#define CREP_LUMINANCE_PER_THREAD 4
#define CREP_LUMINANCE_TILE (CREP_LUMINANCE_GROUP * CREP_LUMINANCE_PER_THREAD)
#define CREP_LUMINANCE_THREADS (CREP_LUMINANCE_GROUP * CREP_LUMINANCE_GROUP)

layout(local_size_x = CREP_LUMINANCE_GROUP, local_size_y = CREP_LUMINANCE_GROUP) in;

layout(std140, binding = CREP_TONE_MAP_PARAMS_BINDING) uniform CrepToneMapBlock { CrepToneMapParams crep_toneMap; };
layout(std430, binding = CREP_TONE_MAP_LUMINANCE_PARTIALS_BINDING) restrict writeonly buffer CrepLuminancePartials { CrepLuminancePartial crep_partials[]; };
layout(binding = CREP_TONE_MAP_HDR_UNIT) uniform sampler2D crep_hdr;

shared float crep_sharedLogSum[CREP_LUMINANCE_THREADS];
shared uint crep_sharedCount[CREP_LUMINANCE_THREADS];

void main() {
  ivec2 size = crep_toneMap.sizes.xy;
  ivec2 base = ivec2(gl_WorkGroupID.xy) * CREP_LUMINANCE_TILE + ivec2(gl_LocalInvocationID.xy);
  float logSum = 0.0;
  uint count = 0u;
  for (int j = 0; j < CREP_LUMINANCE_PER_THREAD; ++j)
    for (int i = 0; i < CREP_LUMINANCE_PER_THREAD; ++i) {
      ivec2 p = base + ivec2(i, j) * CREP_LUMINANCE_GROUP;
      if (any(greaterThanEqual(p, size))) continue;
      vec3 rgb = texelFetch(crep_hdr, p, 0).rgb;
      if (!crep_finiteRgb(rgb)) continue;
      logSum += log(CREP_LOG_AVERAGE_DELTA + crep_luminance(max(rgb, vec3(0.0))));
      ++count;
    }
  uint t = gl_LocalInvocationIndex;
  crep_sharedLogSum[t] = logSum;
  crep_sharedCount[t] = count;
  barrier();
  for (uint stride = CREP_LUMINANCE_THREADS / 2; stride > 0u; stride >>= 1) {
    if (t < stride) {
      crep_sharedLogSum[t] += crep_sharedLogSum[t + stride];
      crep_sharedCount[t] += crep_sharedCount[t + stride];
    }
    barrier();
  }
  if (t == 0u) {
    uint group = gl_WorkGroupID.y * uint(crep_toneMap.sizes.z) + gl_WorkGroupID.x;
    crep_partials[group].logSum = crep_sharedLogSum[0];
    crep_partials[group].count = crep_sharedCount[0];
  }
}
