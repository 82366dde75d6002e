#version 450 core
// The region visibility table of the evaluation (crep::EvaluateOptions::visibilityTableSamples; the CPU
// reference is crep::visibilityTable): for texel row j, prefilter region r and depth sample s,
// V = clamp(0.5 + a(z_s) . F_r(j), 0, 1), F_r(j) the decoded filtered basis at the region's last texel (the
// region's whole weighted average, Klehm et al. 2014 Eq. 9 and Appendix A) and z_s the ray basis depth of
// the normalized depth s / (Z - 1). A region a ray crosses whole then costs one bilinear fetch (row,
// depth) in crep_inScatteringSegment instead of M / 4.
// One invocation per (row, region): it fetches the region's M / 4 texels once and writes its Z samples
// (consecutive texels of the table); the ray coefficients a(z_s) of every sample come precomputed (in
// double on the CPU, with the ringing filter) from a storage buffer shared by all invocations: H R (M / 4
// fetches + Z M multiply-adds) in all. Used only with EvaluateOptions::scatteringPrefix = false (the
// default builds the scattering prefix table, passes/prefilter/scattering_prefix.comp, which includes this step).
// CREP_EXACT_VISIBILITY 1 (crep::VisibilityReconstruction::Exact): layer 0 holds (depth, cumulative weight W)
// per texel; V = sum_i [z_i >= z_s] (W_i - W_{i-1}) over the region (W_{n-1} = 1), z_s = s / (Z - 1) (z > 0 for
// s = 0).
// Driven by crep::EvaluatePass.
#include "crep/bindings.h"
#ifndef CREP_BASES
#define CREP_BASES 32
#endif
#ifndef CREP_TABLE_SAMPLES
#define CREP_TABLE_SAMPLES 128
#endif
#ifndef CREP_EXACT_VISIBILITY
#define CREP_EXACT_VISIBILITY 0
#endif
#ifndef CREP_MEMORY_LIMIT
#define CREP_MEMORY_LIMIT 0 // 1: benchmark variant, the same fetches and stores without the math (writes 1)
#endif
#define CREP_TABLE_LAYERS ((CREP_BASES + 3) / 4)

layout(local_size_x = 64) in;
layout(binding = CREP_VISIBILITY_TABLE_BASIS_UNIT) uniform sampler2DArray crep_basis;                    // the filtered basis (stored e)
layout(binding = CREP_VISIBILITY_TABLE_TABLE_OUT_IMAGE, r32f) uniform writeonly restrict image2D crep_tableOut; // width R Z, height H
// a(z_s) of sample s, layer l at index s * layers + l (Eq. 8 order, zero beyond M).
layout(std430, binding = CREP_VISIBILITY_TABLE_TABLE_COEFFICIENTS_BINDING) readonly restrict buffer CrepTableCoefficients { vec4 crep_tableA[]; };
// Vulkan (and so HLSL root constants, an MSL buffer): push constants; GL: uniform locations.
#ifdef VULKAN
layout(push_constant) uniform CrepVisibilityTablePush { ivec4 crep_tableSize; };
#else
layout(location = 0) uniform ivec4 crep_tableSize; // x H, y R, z n (texels per region)
#endif

void main() {
  int j = int(gl_GlobalInvocationID.x), r = int(gl_GlobalInvocationID.y);
  if (j >= crep_tableSize.x || r >= crep_tableSize.y) return;
  int x = r * crep_tableSize.z + crep_tableSize.z - 1;
#if CREP_EXACT_VISIBILITY
  int n = crep_tableSize.z;
  for (int s = 0; s < CREP_TABLE_SAMPLES; ++s) {
    float zs = float(s) / float(CREP_TABLE_SAMPLES - 1), lit = 0.0, previous = 0.0;
    for (int k = 0; k < n; ++k) {
      vec4 t = texelFetch(crep_basis, ivec3(r * n + k, j, 0), 0);
      if (s == 0 ? t.r > 0.0 : t.r >= zs) lit += t.g - previous;
      previous = t.g;
    }
    imageStore(crep_tableOut, ivec2(r * CREP_TABLE_SAMPLES + s, j), vec4(previous > 0.0 ? lit / previous : 0.0));
  }
  return;
#endif
  vec4 F[CREP_TABLE_LAYERS];
  for (int l = 0; l < CREP_TABLE_LAYERS; ++l) F[l] = 2.0 * texelFetch(crep_basis, ivec3(x, j, l), 0) - 1.0;
#if CREP_MEMORY_LIMIT
  vec4 sum = vec4(0.0);
  for (int l = 0; l < CREP_TABLE_LAYERS; ++l) sum += F[l];
  for (int s = 0; s < CREP_TABLE_SAMPLES; ++s)
    imageStore(crep_tableOut, ivec2(r * CREP_TABLE_SAMPLES + s, j), vec4(sum.x > 1e30 ? 0.0 : 1.0));
#else
  for (int s = 0; s < CREP_TABLE_SAMPLES; ++s) {
    float dotF = 0.0;
    for (int l = 0; l < CREP_TABLE_LAYERS; ++l) dotF += dot(crep_tableA[s * CREP_TABLE_LAYERS + l], F[l]);
    imageStore(crep_tableOut, ivec2(r * CREP_TABLE_SAMPLES + s, j), vec4(clamp(0.5 + dotF, 0.0, 1.0)));
  }
#endif
}
