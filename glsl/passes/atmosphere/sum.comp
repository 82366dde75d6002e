#version 450 core
// AtmosphereTablesPass, table sums: accumulator += addend, texel by texel (L_H = L2 + ... + LN).
#include "crep/bindings.h"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(binding = CREP_ATMOSPHERE_TABLES_SUM_ACCUMULATOR_IMAGE, rgba32f) uniform restrict image3D crep_accumulator;
layout(binding = CREP_ATMOSPHERE_TABLES_SUM_ADDEND_IMAGE, rgba32f) uniform restrict readonly image3D crep_addend;

void main() {
  ivec3 p = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(p, imageSize(crep_accumulator)))) return;
  imageStore(crep_accumulator, p, vec4(imageLoad(crep_accumulator, p).rgb + imageLoad(crep_addend, p).rgb, 0.0));
}
