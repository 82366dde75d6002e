#version 450 core
// The scattering prefix table of the evaluation (crep::EvaluateOptions::scatteringPrefix; the CPU
// reference is crep::scatteringPrefixTable over crep::visibilityTable): for texel row j, depth sample s and
// prefilter region r, S_r = sum_{r' < r} V_r' TI_r' per colour channel, with
//   V_r' = clamp(0.5 + a(z_s) . F_r'(j), 0, 1)  the visibility of region r' crossed whole (F at its last
//          texel: the region's whole weighted average, Klehm et al. 2014 Eq. 9 and Appendix A),
//   TI_r'  the transmittance integral (Eq. 3) over region r' of the view ray of row (j + 0.5) / H and
//          normalized depth s / (Z - 1): a ray from the camera is fixed by its row and depth, so its
//          region boundary distances are too (crep_evalRayAt, crep_evalBoundary).
// A pixel then reads every region it crosses whole with one bilinear fetch (crep_inScatteringSegment with
// CREP_SCATTERING_PREFIX).
// One invocation per (sample, row), looping over the R regions: the invocations of a workgroup share the
// row, so every basis fetch has the same address in all of them (served once by a GPU's texture cache),
// and consecutive invocations write consecutive table texels (coalesced). Staging the row's basis in shared
// memory behind barriers was measured slower on llvmpipe (37 vs 14 ms at 512 rows, 128 samples, 16
// regions; `crep bench`, "evaluation variants"). The transmittance integral of each region comes from the
// carried exp(-sigma t) at its ends (one exp per channel and region instead of crep_transmittanceIntegral's
// two). The ray coefficients a(z_s) come precomputed (in double
// on the CPU, with the ringing filter) from a storage buffer.
// Layouts as the evaluation: the scattering block's projective frame, or CREP_EVAL_LAYOUT.
// CREP_LIGHT_TEXTURE 1 (a basis prefiltered with a light texture, crep/scattering.glsl): V_r' per colour
// channel, cbar_c clamp(0.5 + a(z_s) . F_c, 0, 1) with F_c in layers [c L, (c + 1) L) and cbar at the
// region's last texel (crep::visibilityTable of a textured basis).
// CREP_EXACT_VISIBILITY 1 (crep::VisibilityReconstruction::Exact): V_r' is the exact weighted average of the
// region's depth test at z_s (crep::visibilityTable of an exact basis; sample 0 as the limit from above, z > 0).
// The region's average P = sum_i omega_i [z_i >= z] has the weights omega_i = W_i - W_{i-1} of the cumulative
// weights W (prefilter.comp; W_{n-1} = 1), so a region's whole column of Z samples is one histogram: texel i
// adds omega_i to bin k_i = [z_i > 0] + #{s >= 1 :
// z_i >= s / (Z - 1)}, and V(s) is the sum of the bins above s. A workgroup (one row) builds the histograms of
// CREP_EXACT_CHUNK regions at a time in shared memory, one invocation per region walking its n texels once:
// H (W + 2 R Z) operations per frame instead of H Z W for every sample walking every texel (GPU: shared memory
// instead of Z texel fetches per texel; measured on llvmpipe in docs/MEASUREMENTS.md).
// Driven by crep::EvaluatePass.
#include "crep/bindings.h"
#ifndef CREP_BASES
#define CREP_BASES 32
#endif
#ifndef CREP_VISIBILITY_TABLE_SAMPLES
#define CREP_VISIBILITY_TABLE_SAMPLES 128
#endif
#ifndef CREP_MEMORY_LIMIT
#define CREP_MEMORY_LIMIT 0 // 1: benchmark variant, the same fetches and stores without the math
#endif
#ifndef CREP_TABLE_COEFFICIENTS_BINDING
#define CREP_TABLE_COEFFICIENTS_BINDING CREP_TABLE_COEFFICIENTS_DEFAULT_BINDING
#endif
#include "crep/scattering.glsl"
#if CREP_LIGHT_TEXTURE && CREP_MEMORY_LIMIT
#error "CREP_MEMORY_LIMIT is a variant of the untextured pass"
#endif

#define CREP_PREFIX_LAYERS ((CREP_BASES + 3) / 4)

#ifndef CREP_PREFIX_LOCAL_SIZE
#define CREP_PREFIX_LOCAL_SIZE 64 // samples per workgroup (exact: 128, one workgroup builds a row's histograms)
#endif
layout(local_size_x = CREP_PREFIX_LOCAL_SIZE) in;
layout(binding = CREP_SCATTERING_PREFIX_PREFIX_OUT_IMAGE, rgba32f) uniform writeonly restrict image2D crep_prefixOut; // width R Z, height H
#if CREP_LOCAL_LIGHT && CREP_LOCAL_SECTIONS
// The local section table: region r's unshadowed in-scattering along the sample ray (same layout).
layout(binding = CREP_SCATTERING_PREFIX_SECTION_OUT_IMAGE, rgba32f) uniform writeonly restrict image2D crep_sectionOut;
#endif
// a(z_s) of sample s, layer l at index s * layers + l (Eq. 8 order, zero beyond M).
layout(std430, binding = CREP_TABLE_COEFFICIENTS_BINDING) readonly restrict buffer CrepTableCoefficients {
  vec4 crep_tableA[];
};

#if CREP_EXACT_VISIBILITY
#define CREP_EXACT_BINS (CREP_VISIBILITY_TABLE_SAMPLES + 1)
#if CREP_LIGHT_TEXTURE
#define CREP_EXACT_COLORS 3
#else
#define CREP_EXACT_COLORS 1
#endif
// Regions per pass through shared memory: 16, fewer where the bins of 16 would pass 32 KB (GL's minimum of
// shared memory; EvaluatePass allows Z <= 2047 with the exact reconstruction, one region's bins of every
// colour).
#define CREP_EXACT_FIT (8192 / (CREP_EXACT_COLORS * CREP_EXACT_BINS))
#define CREP_EXACT_CHUNK (CREP_EXACT_FIT > 16 ? 16 : CREP_EXACT_FIT < 1 ? 1 : CREP_EXACT_FIT)
// Bin k of colour c of the chunk's region q at (c * CREP_EXACT_CHUNK + q) * CREP_EXACT_BINS + k: 8.3 KB at the
// default Z = 128, or 24.8 KB with a light texture.
shared float crep_exactBins[CREP_EXACT_COLORS * CREP_EXACT_CHUNK * CREP_EXACT_BINS];

// Fills the bins of regions [first, first + CREP_EXACT_CHUNK) of row j (invocation `lane` of the workgroup's
// gl_WorkGroupSize.x), then turns them into sums from the top: bin k = V(k - 1). Call from uniform control
// flow: it has barriers.
void crep_exactFillChunk(int first, int j, int R, int n, uint lane) {
  const int Z = CREP_VISIBILITY_TABLE_SAMPLES;
  barrier(); // the previous chunk's readers are done
  for (uint q = lane; q < uint(CREP_EXACT_CHUNK); q += gl_WorkGroupSize.x) {
    int r = first + int(q);
    for (int c = 0; c < CREP_EXACT_COLORS; ++c)
      for (int k = 0; k < CREP_EXACT_BINS; ++k) crep_exactBins[(c * CREP_EXACT_CHUNK + int(q)) * CREP_EXACT_BINS + k] = 0.0;
    if (r >= R) continue;
    vec3 previous = vec3(0.0);
    for (int i = 0; i < n; ++i) {
      vec4 t = texelFetch(crep_filteredBasis, ivec3(r * n + i, j, 0), 0);
      // k = [z > 0] + #{s in [1, Z - 1] : z >= s / (Z - 1)}, the floor corrected against the same division.
      int k = 0;
      if (t.r > 0.0) {
        int c = clamp(int(floor(t.r * float(Z - 1))), 0, Z - 1);
        if (c < Z - 1 && t.r >= float(c + 1) / float(Z - 1)) ++c;
        if (c >= 1 && t.r < float(c) / float(Z - 1)) --c;
        k = 1 + c;
      }
#if CREP_LIGHT_TEXTURE
      vec3 W = t.gba;
#else
      vec3 W = vec3(t.g); // RG32F: one colour
#endif
      vec3 omega = W - previous;
      previous = W;
      for (int c = 0; c < CREP_EXACT_COLORS; ++c) crep_exactBins[(c * CREP_EXACT_CHUNK + int(q)) * CREP_EXACT_BINS + k] += omega[c];
    }
    for (int c = 0; c < CREP_EXACT_COLORS; ++c) {
      float sum = 0.0;
      for (int k = CREP_EXACT_BINS - 1; k >= 0; --k) {
        int b = (c * CREP_EXACT_CHUNK + int(q)) * CREP_EXACT_BINS + k;
        sum += crep_exactBins[b];
        crep_exactBins[b] = sum;
      }
    }
  }
  barrier();
}
#endif

void main() {
  const int Z = CREP_VISIBILITY_TABLE_SAMPLES, L = CREP_PREFIX_LAYERS;
  int s = int(gl_GlobalInvocationID.x), j = int(gl_GlobalInvocationID.y);
  int H = crep_scattering.mapSize.y, R = crep_scattering.mapSize.z, n = crep_scattering.mapSize.x / R;
#if CREP_EXACT_VISIBILITY
  // Every invocation reaches the barriers of crep_exactFillChunk; those beyond Z compute nothing else.
  bool inTable = s < Z;
  s = min(s, Z - 1);
#else
  if (s >= Z) return;
  bool inTable = true;
#endif
  vec4 a[L];
#if !CREP_EXACT_VISIBILITY
  for (int l = 0; l < L; ++l) a[l] = crep_tableA[s * L + l];
#endif
  CrepEvalRay ray = crep_evalRayAt((float(j) + 0.5) / float(H), float(s) / float(Z - 1));
  vec3 sigma = crep_scattering.extinction.rgb;
  vec3 sum = vec3(0.0), Ea = vec3(1.0);
  float ta = 0.0;
#if CREP_LOCAL_LIGHT
  // The sample ray, and the part of it the light reaches (crep_localReach): regions outside it add nothing,
  // so their basis is not fetched. GPU: the regions a spot's cone misses are most of a row's.
  vec3 dir = crep_evalRayDirection(ray);
  vec2 reach = crep_localReach(crep_blockLocalLight(), crep_localRay(crep_blockLocalLight(), crep_blockLocalMedium(),
                                                                     crep_scattering.frameOrigin.xyz, dir),
                               0.0, min(crep_evalBoundary(ray, R), 1e30));
#endif
  for (int r = 0; r < R; ++r) {
#if CREP_EXACT_VISIBILITY
    if (r % CREP_EXACT_CHUNK == 0) crep_exactFillChunk(r, j, R, n, gl_LocalInvocationID.x);
#endif
    if (inTable) imageStore(crep_prefixOut, ivec2(r * Z + s, j), vec4(sum, 0.0));
    float tb = max(ta, crep_evalBoundary(ray, r + 1));
#if CREP_LOCAL_LIGHT
    if (!(tb > reach.x && ta < reach.y)) {
#if CREP_LOCAL_SECTIONS
      if (inTable) imageStore(crep_sectionOut, ivec2(r * Z + s, j), vec4(0.0));
#endif
      ta = tb;
      continue;
    }
#endif
#if CREP_EXACT_VISIBILITY
    int q = r % CREP_EXACT_CHUNK;
#if CREP_LIGHT_TEXTURE
    vec3 V;
    for (int c = 0; c < 3; ++c) V[c] = crep_exactBins[(c * CREP_EXACT_CHUNK + q) * CREP_EXACT_BINS + s + 1];
    V *= texelFetch(crep_meanColor, ivec2(r * n + n - 1, j), 0).rgb;
#else
    vec3 V = vec3(crep_exactBins[q * CREP_EXACT_BINS + s + 1]);
#endif
#elif CREP_LIGHT_TEXTURE
    vec3 V;
    for (int c = 0; c < 3; ++c) {
      float dotC = 0.0;
      for (int l = 0; l < L; ++l)
        dotC += dot(a[l], 2.0 * texelFetch(crep_filteredBasis, ivec3(r * n + n - 1, j, c * L + l), 0) - 1.0);
      V[c] = clamp(0.5 + dotC, 0.0, 1.0);
    }
    V *= texelFetch(crep_meanColor, ivec2(r * n + n - 1, j), 0).rgb;
#else
    float dotF = 0.0;
    for (int l = 0; l < L; ++l) dotF += dot(a[l], 2.0 * texelFetch(crep_filteredBasis, ivec3(r * n + n - 1, j, l), 0) - 1.0);
    vec3 V = vec3(clamp(0.5 + dotF, 0.0, 1.0));
#endif
#if CREP_MEMORY_LIMIT
    sum += vec3(dotF > 1e30 ? 0.0 : 1.0); // counts the regions (memory-limit test), keeps the reads
#else
#if CREP_LOCAL_LIGHT
    // The local light's in-scattering of the region along the sample ray (crep::scatteringPrefixTable for a
    // LocalLight).
#if CREP_LOCAL_SECTIONS
    vec3 section = crep_sectionIntegral(crep_scattering.frameOrigin.xyz, dir, sigma, ta, min(tb, CREP_LOCAL_SECTION_END));
    if (inTable) imageStore(crep_sectionOut, ivec2(r * Z + s, j), vec4(section, 0.0));
    sum += V * (tb < 1e30 ? section : vec3(0.0));
#else
    sum += V * crep_sectionIntegral(crep_scattering.frameOrigin.xyz, dir, sigma, ta, tb);
#endif
    ta = tb;
    continue;
#endif
    vec3 Eb = exp(-sigma * tb);
    // (Ea - Eb) / sigma, and below sigma (tb - ta) = 1/4 (where that difference cancels) Ea (tb - ta)
    // phi(x) by the series of crep_oneMinusExpOverX: both relative errors stay near float rounding.
    float len = tb - ta;
    vec3 x = sigma * len;
    vec3 integral = mix((Ea - Eb) / sigma, Ea * len * crep_oneMinusExpOverXSeries(x), lessThan(x, vec3(0.25)));
    sum += V * integral;
    Ea = Eb;
    ta = tb;
#endif
  }
}
