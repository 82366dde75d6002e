#version 450 core
// Test evaluator of a work list (crep/scatter/gpu_sample_list.h; tests/epipolar/EpipolarSamplingGLTest.cpp):
// writes for each entry a smooth function of its coordinates texel (x, y, d, z):
// (0.01 x, 0.01 y, 0.05 z, 1). Dispatched indirectly (gpu::dispatchSampleList).
#include "crep/sample_list.glsl"

layout(local_size_x = 64) in;
layout(binding = 0, rgba32f) uniform readonly image2D coordinatesIn;
layout(binding = 1, rgba32f) uniform writeonly image2D valuesOut;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= crep_listCount()) return;
  ivec2 t = crep_listEntry(i);
  vec4 c = imageLoad(coordinatesIn, t);
  imageStore(valuesOut, t, vec4(0.01 * c.x, 0.01 * c.y, 0.05 * c.w, 1.0));
}
