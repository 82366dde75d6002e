#version 450 core
// Epipolar sampling, stage 4: interpolation of the samples that were not marched (Yusov 2012, Sec. 6.5;
// rule and CPU reference: crep::interpolateSamples in crep/epipolar/epipolar_sampling.h). One thread per
// texel of the Ns x N sample texture, in place: a sample with sources (left, right), left < right, gets
// (1 - w) L_left + w L_right, w = (k - left) / (right - left); invalid samples 0; marched samples (the
// evaluator's values) are left untouched. Sources are always marched samples, which this pass never
// writes, so the in-place reads and writes do not overlap.
//
// Resources: sources RG32I (image 0, read), samples RGBA32F (image 1, read and written).
#include "crep/bindings.h"
layout(local_size_x = 64, local_size_y = 1) in;

layout(binding = CREP_EPIPOLAR_SAMPLING_SOURCES_IN_IMAGE, rg32i) uniform readonly iimage2D sourcesIn;
layout(binding = CREP_EPIPOLAR_SAMPLING_SAMPLES_IMAGE, rgba32f) uniform image2D samples;

void main() {
  ivec2 t = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(t, imageSize(samples)))) return;
  ivec2 s = imageLoad(sourcesIn, t).xy;
  if (s.x < 0) {
    imageStore(samples, t, vec4(0.0));
    return;
  }
  if (s.x == s.y) return; // marched
  float w = float(t.x - s.x) / float(s.y - s.x);
  vec4 a = imageLoad(samples, ivec2(s.x, t.y)), b = imageLoad(samples, ivec2(s.y, t.y));
  imageStore(samples, t, (1.0 - w) * a + w * b);
}
