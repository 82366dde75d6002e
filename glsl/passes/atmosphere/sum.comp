#version 450 core
// AtmosphereTablesPass, table sums: accumulator += addend, texel by texel (L_H = L2 + ... + LN).
// CREP_ATMOSPHERE_SUM_MODE 1: accumulator = addend (L_H = L2, a copy); 2: accumulator = 0 (L_H of one order).
#include "crep/bindings.h"
#ifndef CREP_ATMOSPHERE_SUM_MODE
#define CREP_ATMOSPHERE_SUM_MODE 0
#endif
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(binding = CREP_ATMOSPHERE_TABLES_SUM_ACCUMULATOR_IMAGE, rgba32f) uniform restrict image3D crep_accumulator;
#if CREP_ATMOSPHERE_SUM_MODE != 2
layout(binding = CREP_ATMOSPHERE_TABLES_SUM_ADDEND_IMAGE, rgba32f) uniform restrict readonly image3D crep_addend;
#endif

void main() {
  ivec3 p = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(p, imageSize(crep_accumulator)))) return;
#if CREP_ATMOSPHERE_SUM_MODE == 0
  imageStore(crep_accumulator, p, vec4(imageLoad(crep_accumulator, p).rgb + imageLoad(crep_addend, p).rgb, 0.0));
#elif CREP_ATMOSPHERE_SUM_MODE == 1
  imageStore(crep_accumulator, p, imageLoad(crep_addend, p));
#else
  imageStore(crep_accumulator, p, vec4(0.0));
#endif
}
