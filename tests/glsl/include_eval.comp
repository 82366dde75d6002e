#version 450 core
// Test fixture: evaluates the public includes for comparison with their CPU counterparts
// (ShaderCompileGLTest.cpp).
#include "crep/phase.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Inputs { vec4 inputs[]; };   // g, cosTheta, depth, linear
layout(std430, binding = 1) writeonly buffer Outputs { vec4 outputs[]; }; // HG, Rayleigh, distance, sRGB
layout(location = 0) uniform uint count;
layout(location = 1) uniform vec2 nearFar;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  vec4 v = inputs[i];
  outputs[i] = vec4(crep_henyeyGreenstein(v.x, v.y), crep_rayleighPhase(v.y), crep_linearDepth(v.z, nearFar.x, nearFar.y),
                    crep_srgbEncode(vec3(v.w)).x);
}
