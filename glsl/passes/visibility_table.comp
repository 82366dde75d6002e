#version 450 core
// The region visibility table of the evaluation (crep::EvaluateOptions::visibilityTableSamples; the CPU
// reference is crep::visibilityTable): for texel row j, prefilter region r and depth sample s,
// V = clamp(0.5 + a(z_s) . F_r(j), 0, 1), F_r(j) the decoded filtered basis at the region's last texel (the
// region's whole weighted average, Klehm et al. 2014 Eq. 9 and Appendix A) and z_s the ray basis depth of
// the normalized depth s / (Z - 1). A region a ray crosses whole then costs one bilinear fetch (row,
// depth) in crep_inScatteringSegment instead of M / 4. One invocation per (sample, row, region): each
// fetches its region's M / 4 texels (neighbouring invocations share them through the texture cache).
// Driven by crep::EvaluatePass.
#ifndef CREP_BASES
#define CREP_BASES 32
#endif
#ifndef CREP_TABLE_SAMPLES
#define CREP_TABLE_SAMPLES 128
#endif
#ifndef CREP_RINGING_LANCZOS
#define CREP_RINGING_LANCZOS 0
#endif
#ifndef CREP_MEMORY_LIMIT
#define CREP_MEMORY_LIMIT 0 // 1: benchmark variant, the same fetches and store without the math (writes 1)
#endif
#define CREP_SCATTERING_NO_EVALUATION
#include "crep/scattering.glsl"

layout(local_size_x = 64) in;
layout(binding = 0) uniform sampler2DArray crep_basis;                    // the filtered basis (stored e)
layout(binding = 0, r32f) uniform writeonly restrict image2D crep_tableOut; // width R Z, height H
layout(location = 0) uniform ivec4 crep_tableSize;                        // x H, y R, z n (texels per region)
layout(location = 1) uniform float crep_tableMargin;                      // m of fourier.h

void main() {
  int s = int(gl_GlobalInvocationID.x), j = int(gl_GlobalInvocationID.y), r = int(gl_GlobalInvocationID.z);
  if (s >= CREP_TABLE_SAMPLES || j >= crep_tableSize.x || r >= crep_tableSize.y) return;
  const int layers = (CREP_BASES + 3) / 4, harmonics = CREP_BASES / 2;
  int x = r * crep_tableSize.z + crep_tableSize.z - 1;
#if CREP_MEMORY_LIMIT
  vec4 sum = vec4(0.0);
  for (int l = 0; l < layers; ++l) sum += texelFetch(crep_basis, ivec3(x, j, l), 0);
  imageStore(crep_tableOut, ivec2(r * CREP_TABLE_SAMPLES + s, j), vec4(sum.x > 1e30 ? 0.0 : 1.0));
  return;
#endif
  CrepDepth z = crep_rayBasisDepth(float(s) / float(CREP_TABLE_SAMPLES - 1), crep_tableMargin);
  vec2 stepSC = crep_harmonicStep(z);
  vec2 sc = crep_harmonic(0, z);
  float dotF = 0.0;
  for (int l = 0; l < layers; ++l) {
    vec2 next = crep_rotate(sc, stepSC);
    vec4 a = crep_coefficients4(2 * l, sc, next);
#if CREP_RINGING_LANCZOS
    a *= vec4(vec2(crep_lanczosFactor(2 * l, CREP_BASES)), vec2(crep_lanczosFactor(2 * l + 1, CREP_BASES)));
#endif
    if (2 * l + 1 >= harmonics) a.zw = vec2(0.0); // M % 4 == 2: the last layer holds one harmonic
    dotF += dot(a, 2.0 * texelFetch(crep_basis, ivec3(x, j, l), 0) - 1.0);
    sc = crep_rotate(next, stepSC);
  }
  imageStore(crep_tableOut, ivec2(r * CREP_TABLE_SAMPLES + s, j), vec4(clamp(0.5 + dotF, 0.0, 1.0)));
}
