#version 450 core
// Checkerboard min/max depth downsample of the reduced-resolution evaluation (crep::downsampleDepth,
// crep/pipeline/reduced_resolution.h): low pixel (i, j) takes the minimum of its f x f block of depth-buffer
// values where i + j is even, the maximum where it is odd. Driven by crep::DepthAwareResamplePass.
#include "crep/bindings.h"
#ifndef CREP_FACTOR
#define CREP_FACTOR 2
#endif
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = CREP_DEPTH_DOWNSAMPLE_FULL_DEPTH_UNIT) uniform sampler2D crep_fullDepth;
layout(binding = CREP_DEPTH_DOWNSAMPLE_LOW_DEPTH_IMAGE, r32f) uniform writeonly restrict image2D crep_lowDepth;
// Vulkan (and so HLSL root constants, an MSL buffer): push constants; GL: uniform locations.
#ifdef VULKAN
layout(push_constant) uniform CrepDepthDownsamplePush { ivec2 crep_lowSize; };
#else
layout(location = 0) uniform ivec2 crep_lowSize;
#endif

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, crep_lowSize))) return;
  bool nearest = ((p.x + p.y) & 1) == 0;
  float d = nearest ? 3.0e38 : -3.0e38;
  for (int j = 0; j < CREP_FACTOR; ++j)
    for (int i = 0; i < CREP_FACTOR; ++i) {
      float v = texelFetch(crep_fullDepth, p * CREP_FACTOR + ivec2(i, j), 0).r;
      d = nearest ? min(d, v) : max(d, v);
    }
  imageStore(crep_lowDepth, p, vec4(d));
}
