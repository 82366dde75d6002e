#version 450 core
// Test shader: writes CREP_FILL_VALUE into every texel of an r32f image inside `extent` (texels
// outside it are left untouched). Dispatch ceil(extent / 8) work groups.
#ifndef CREP_FILL_VALUE
#define CREP_FILL_VALUE 1.0
#endif

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, r32f) uniform writeonly image2D target;
layout(location = 0) uniform ivec2 extent;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, extent))) return;
  imageStore(target, p, vec4(CREP_FILL_VALUE));
}
