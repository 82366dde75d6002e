#version 450 core
// Depth-aware (joint bilateral) upsample of the reduced-resolution evaluation (crep::depthAwareUpsample,
// crep/pipeline/reduced_resolution.h): the four low pixels of the bilinear footprint, weights bilinear /
// (e + |Z - Z_k| / Z) with view-space depths Z. Driven by crep::DepthAwareResamplePass.
#include "crep/bindings.h"
#ifndef CREP_FACTOR
#define CREP_FACTOR 2
#endif
#include "crep/common.glsl"
#ifndef CREP_DEPTH_EPSILON
#define CREP_DEPTH_EPSILON 0.01
#endif
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = CREP_DEPTH_UPSAMPLE_LOW_UNIT) uniform sampler2D crep_low;       // RGBA32F, low size
layout(binding = CREP_DEPTH_UPSAMPLE_LOW_DEPTH_UNIT) uniform sampler2D crep_lowDepth;  // R32F, low size
layout(binding = CREP_DEPTH_UPSAMPLE_FULL_DEPTH_UNIT) uniform sampler2D crep_fullDepth; // full size
layout(binding = CREP_DEPTH_UPSAMPLE_OUTPUT_IMAGE, rgba32f) uniform writeonly restrict image2D crep_output;
// Vulkan (and so HLSL root constants, an MSL buffer): push constants; GL: uniform locations.
#ifdef VULKAN
layout(push_constant) uniform CrepDepthUpsamplePush {
  ivec4 crep_sizes;
  vec4 crep_cameraDepthMap;
};
#else
layout(location = 0) uniform ivec4 crep_sizes;        // full width, height, low width, height
layout(location = 1) uniform vec4 crep_cameraDepthMap; // crep_cameraViewDepth's map of the camera
#endif


void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, crep_sizes.xy))) return;
  ivec2 lowSize = crep_sizes.zw;
  float Z = crep_cameraViewDepth(texelFetch(crep_fullDepth, p, 0).r, crep_cameraDepthMap);
  vec2 u = (vec2(p) + 0.5) / float(CREP_FACTOR) - 0.5;
  ivec2 i0 = ivec2(floor(u));
  vec2 f = u - vec2(i0);
  vec4 sum = vec4(0.0);
  float total = 0.0;
  for (int k = 0; k < 4; ++k) {
    ivec2 o = ivec2(k & 1, k >> 1);
    ivec2 q = clamp(i0 + o, ivec2(0), lowSize - 1);
    float b = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
    float Zk = crep_cameraViewDepth(texelFetch(crep_lowDepth, q, 0).r, crep_cameraDepthMap);
    float w = b / (CREP_DEPTH_EPSILON + abs(Z - Zk) / Z);
    sum += w * texelFetch(crep_low, q, 0);
    total += w;
  }
  imageStore(crep_output, p, total > 0.0 ? sum / total : texelFetch(crep_low, clamp(i0, ivec2(0), lowSize - 1), 0));
}
