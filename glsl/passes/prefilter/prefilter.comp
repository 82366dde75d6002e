#version 450 core
// Prefilter pass of prefiltered single scattering (Klehm, Seidel, Eisemann 2014, Sec. 3.3): the basis
// transform fused into the weighted prefix filter (Listing 3 + Listing 2), with the normalized storage
// of Appendix A. The rules are crep::prefilter()'s (crep/prefilter/prefilter.h, "Prefilter"):
//   z_i = texelBasisDepth(depth(i, j), m),  F_i = F_{i-1} + m_i (B(z_i) - F_{i-1}),  F_{-1} = 0,
//   stored e_i = 0.5 + 0.5 F_i  (rounded as the RGBA8 rule says when CREP_BASIS_UNORM8 is 1).
// One invocation filters one row j (x), one group of CREP_BASES_PER_INVOCATION bases (y) and one
// prefilter region r (z), left to right over the region's n texels (Table 1's two parallelization
// factors: bases per invocation, regions per row). Driven by crep::PrefilterPass (gpu_pass.h).
// CREP_LIGHT_TEXTURE 1: a light texture's colour map in the weights, one basis per colour channel and the
// prefix mean colour (crep/prefilter/prefilter.h, "Light textures"; Klehm et al. 2014, Sec. 3.2).
#include "crep/bindings.h"
#define CREP_SCATTERING_NO_EVALUATION
#include "crep/scattering.glsl"

#ifndef CREP_BASES_PER_INVOCATION
#define CREP_BASES_PER_INVOCATION 8 // a multiple of 4; the last group of bases may be partial
#endif
#ifndef CREP_BASIS_FORMAT
#define CREP_BASIS_FORMAT rgba8 // image format of the filtered basis: rgba8, rgba16f or rgba32f
#endif
#ifndef CREP_BASIS_UNORM8
#define CREP_BASIS_UNORM8 1 // 1: round to the RGBA8 rule before the store (CREP_BASIS_FORMAT rgba8)
#endif
#ifndef CREP_BASIS_HALF
#define CREP_BASIS_HALF 0 // 1: round to the nearest binary16, ties to even, before the store (rgba16f)
#endif
#ifndef CREP_LOCAL_SIZE_X
#define CREP_LOCAL_SIZE_X 64 // rows per workgroup
#endif
#ifndef CREP_LOCAL_SIZE_Y
#define CREP_LOCAL_SIZE_Y 1 // base groups per workgroup
#endif
#ifndef CREP_MEMORY_LIMIT
#define CREP_MEMORY_LIMIT 0 // 1: benchmark variant, the same map reads and basis writes without the math
#endif
#ifndef CREP_LOCAL_SIZE_Z
#define CREP_LOCAL_SIZE_Z 1 // regions per workgroup
#endif
#ifndef CREP_LOCAL_LIGHT
#define CREP_LOCAL_LIGHT 0 // 1: a local light's factor in the weights (crep::prefilter(map, medium, LocalLight))
#endif
#ifndef CREP_LIGHT_TEXTURE
#define CREP_LIGHT_TEXTURE 0 // 1: a light texture's colour map (crep::prefilter(map, medium, lightColors))
#endif
// CREP_EXACT_VISIBILITY 1 (crep::VisibilityReconstruction::Exact, from crep/scattering.glsl): no basis. Layer 0
// of an RG32F array gets (depth, W_i) per texel, W_i = prod_{k > i} (1 - m_k) the cumulative weight over the
// region's total (with a light texture an RGBA32F array, (depth, W_i of colour 0, 1, 2)): the mix factors on
// the way left to right, turned into W right to left. Layer 1 gets each block of CREP_EXACT_BLOCK texels' (min,
// max) depth at texel (region n + block, row), which lets the evaluation pass a block whose texels all pass or
// all fail the depth test in one step. One group of bases.

#define CREP_GROUP_VEC4S (CREP_BASES_PER_INVOCATION / 4)

layout(local_size_x = CREP_LOCAL_SIZE_X, local_size_y = CREP_LOCAL_SIZE_Y, local_size_z = CREP_LOCAL_SIZE_Z) in;

layout(binding = CREP_PREFILTER_RECTIFIED_DEPTH_UNIT) uniform sampler2D crep_rectifiedDepth; // W x H depth-buffer values in [0, 1]
#if CREP_EXACT_VISIBILITY // read back by the pass that writes it (the right-to-left sweep)
layout(binding = CREP_PREFILTER_FILTERED_BASIS_OUT_IMAGE, CREP_BASIS_FORMAT) uniform restrict image2DArray crep_filteredBasisOut;
#else
layout(binding = CREP_PREFILTER_FILTERED_BASIS_OUT_IMAGE, CREP_BASIS_FORMAT) uniform writeonly restrict image2DArray crep_filteredBasisOut;
#endif
layout(std140, binding = CREP_PREFILTER_PARAMS_BINDING) uniform CrepPrefilterBlock { CrepPrefilterParams crep_prefilter; };
layout(std430, binding = CREP_PREFILTER_REGION_WEIGHTS_BINDING) readonly restrict buffer CrepRegionWeightsBlock { CrepRegionWeights crep_regionWeights[]; };
#if CREP_LIGHT_TEXTURE
// Light textures (crep/prefilter/prefilter.h, "Light textures"): the colour map (W x H, rgb) in, the prefix
// mean colour cbar out (RGBA16F, A = 1); the basis array holds 3 ceil(M / 4) layers, colour c from layer c L.
layout(binding = CREP_PREFILTER_LIGHT_COLORS_UNIT) uniform sampler2D crep_lightColors;
layout(binding = CREP_PREFILTER_MEAN_COLOR_OUT_IMAGE, rgba32f) uniform writeonly restrict image2D crep_meanColorOut;
#endif
#if CREP_LOCAL_LIGHT
layout(std140, binding = CREP_PREFILTER_LOCAL_LIGHT_BINDING) uniform CrepLocalLightBlock { CrepLocalLightParams crep_localParams; };
layout(std430, binding = CREP_PREFILTER_REGION_RAYS_BINDING) readonly restrict buffer CrepRegionRaysBlock { vec4 crep_regionRays[]; };

// The light-side factor at distance tau from the region's start along its reference ray (crep_regionDistance;
// 0 beyond the horizon, tau < 0).
float crep_lightFactorAt(vec4 ray, float tau) {
  if (tau < 0.0 || ray.w < 0.0) return 0.0;
  return crep_localWeightFactor(crep_localParams, crep_localParams.origin.xyz + (ray.w + tau) * ray.xyz, ray.xyz);
}
#endif

// The stored value e = 0.5 + 0.5 F, rounded by crep::storeFiltered's rule of the format, so that the
// store itself is exact (the GL leaves the rounding of float -> unorm / half conversions open; Mesa
// llvmpipe truncates to half).
// The nearest binary16 value (ties to even; crep::roundToHalf for values below 65504): binary16 keeps 11
// significant bits (quantum 2^(exponent - 11)), and a fixed quantum 2^-24 below 2^-14.
vec4 crep_roundToHalf(vec4 e) {
  ivec4 exponent;
  frexp(e, exponent);
  vec4 quantum = ldexp(vec4(1.0), max(exponent - 11, ivec4(-24)));
  return roundEven(e / quantum) * quantum;
}

vec4 crep_encodeFiltered(vec4 F) {
  vec4 e = 0.5 + 0.5 * F;
#if CREP_BASIS_UNORM8
  e = floor(clamp(e, 0.0, 1.0) * 255.0 + 0.5) / 255.0; // round half up
#elif CREP_BASIS_HALF
  e = crep_roundToHalf(e);
#endif
  return e;
}

void main() {
  int row = int(gl_GlobalInvocationID.x), group = int(gl_GlobalInvocationID.y), region = int(gl_GlobalInvocationID.z);
  int H = crep_prefilter.mapSize.y, R = crep_prefilter.mapSize.z, n = crep_prefilter.mapSize.w;
  int M = crep_prefilter.basisInfo.x, layers = (M + 3) / 4;
  int groups = (layers + CREP_GROUP_VEC4S - 1) / CREP_GROUP_VEC4S;
  if (row >= H || group >= groups || region >= R) return;

  int mode = crep_prefilter.basisInfo.z;
  float s = crep_prefilter.weights.x, margin = crep_prefilter.weights.y;
  CrepRegionWeights w = crep_regionWeights[row * R + region];
  int firstHarmonic = group * (CREP_BASES_PER_INVOCATION / 2);
  int firstLayer = group * CREP_GROUP_VEC4S;

#if CREP_LIGHT_TEXTURE
#define CREP_COLOR_BASES 3
  vec3 cbar = vec3(0.0);
#else
#define CREP_COLOR_BASES 1
#endif
  // F[c * CREP_GROUP_VEC4S + v]: colour channel c's basis (one basis without a light texture).
  vec4 F[CREP_COLOR_BASES * CREP_GROUP_VEC4S];
  for (int v = 0; v < CREP_COLOR_BASES * CREP_GROUP_VEC4S; ++v) F[v] = vec4(0.0);
#if CREP_LOCAL_LIGHT
  // Sec. 3.2 "Angular-dependency for Sources": w_i = gbar_i (exp(-s tau_i) - exp(-s tau_{i+1})), gbar_i the
  // light-side factor by Simpson's rule over the texel, m_i = w_i / sum_{j<=i} w_j (crep::regionMixFactors
  // with light samples; Exact weights). The running sum lives in the loop: one texel's set-up per step.
  vec4 ray = crep_regionRays[row * R + region];
  // The left boundary's distance and factor carry over from the texel before (one distance and two
  // factors per texel).
  float tauLeft = crep_regionDistance(w, CREP_WEIGHTS_EXACT, n, 0.0);
  float gLeft = crep_lightFactorAt(ray, tauLeft), weightSum = 0.0;
#endif

#if CREP_EXACT_VISIBILITY
  vec2 blockRange = vec2(1e30, -1e30); // the current block's (min, max) depth
#endif
  for (int i = 0; i < n; ++i) {
    int x = region * n + i;
    // Listing 3: the basis of the texel's depth (Eq. 8), computed here instead of read from a texture.
#if CREP_MEMORY_LIMIT
    // Benchmark variant: the same read and the same writes, no basis and no weights.
    float depth = texelFetch(crep_rectifiedDepth, ivec2(x, row), 0).r;
    for (int v = 0; v < CREP_GROUP_VEC4S; ++v) {
      int layer = firstLayer + v;
      if (layer >= layers) break;
      imageStore(crep_filteredBasisOut, ivec3(x, row, layer), vec4(depth));
    }
    continue;
#endif
    float texelDepth = texelFetch(crep_rectifiedDepth, ivec2(x, row), 0).r;
#if !CREP_EXACT_VISIBILITY
    CrepDepth z = crep_texelBasisDepth(texelDepth, margin);
    vec2 stepSC = crep_harmonicStep(z);
    vec2 sc = crep_harmonic(firstHarmonic, z);
#endif
    // Listing 2: the normalized weighted prefix.
#if CREP_LOCAL_LIGHT
    float tauRight = crep_regionDistance(w, CREP_WEIGHTS_EXACT, n, float(i + 1));
    float gMid = crep_lightFactorAt(ray, crep_regionDistance(w, CREP_WEIGHTS_EXACT, n, float(i) + 0.5));
    float gRight = crep_lightFactorAt(ray, tauRight);
    float wi = 0.0;
    if (tauLeft >= 0.0 && tauRight >= 0.0) {
      float dt = tauRight - tauLeft;
      float g = (gLeft + 4.0 * gMid + gRight) / 6.0;
      wi = g * exp(-s * tauLeft) * crep_oneMinusExpOverX(s * dt) * dt;
      if (!(wi > 0.0) || isinf(wi)) wi = 0.0;
    }
    gLeft = gRight;
    tauLeft = tauRight;
    weightSum += wi;
    float m = weightSum > 0.0 ? clamp(wi / weightSum, 0.0, 1.0) : 1.0 / float(i + 1);
#else
    float m = crep_mixFactor(w, mode, s, i, n);
#endif
#if CREP_LIGHT_TEXTURE
    // The weights w_i c_i per channel as mix factors m_i c_i / cbar_i, cbar the same prefix filter of the
    // colours (crep::prefilter with lightColors); m_i where cbar_i = 0 (no weighted light yet).
    vec3 ci = texelFetch(crep_lightColors, ivec2(x, row), 0).rgb;
    cbar += m * (ci - cbar);
    vec3 mc = vec3(m);
    for (int c = 0; c < 3; ++c)
      if (cbar[c] > 0.0) mc[c] = clamp(m * (ci[c] / cbar[c]), 0.0, 1.0);
    if (group == 0) imageStore(crep_meanColorOut, ivec2(x, row), vec4(cbar, 1.0));
#endif
#if CREP_EXACT_VISIBILITY
#if CREP_LIGHT_TEXTURE
    imageStore(crep_filteredBasisOut, ivec3(x, row, 0), vec4(texelDepth, mc));
#else
    imageStore(crep_filteredBasisOut, ivec3(x, row, 0), vec4(texelDepth, m, 0.0, 0.0));
#endif
    blockRange = vec2(min(blockRange.x, texelDepth), max(blockRange.y, texelDepth));
    if (i % CREP_EXACT_BLOCK == CREP_EXACT_BLOCK - 1 || i == n - 1) {
      imageStore(crep_filteredBasisOut, ivec3(region * n + i / CREP_EXACT_BLOCK, row, 1), vec4(blockRange, 0.0, 0.0));
      blockRange = vec2(1e30, -1e30);
    }
#else
    for (int v = 0; v < CREP_GROUP_VEC4S; ++v) {
      int layer = firstLayer + v;
      if (layer >= layers) break;
      vec2 second = crep_rotate(sc, stepSC);
      // M % 4 == 2: the last layer holds one harmonic; its other channels stay F = 0 (stored 0.5).
      vec4 B = 2 * layer + 1 < M / 2 ? vec4(sc, second) : vec4(sc, 0.0, 0.0);
#if CREP_LIGHT_TEXTURE
      for (int c = 0; c < 3; ++c) {
        F[c * CREP_GROUP_VEC4S + v] += mc[c] * (B - F[c * CREP_GROUP_VEC4S + v]);
        imageStore(crep_filteredBasisOut, ivec3(x, row, c * layers + layer), crep_encodeFiltered(F[c * CREP_GROUP_VEC4S + v]));
      }
#else
      F[v] += m * (B - F[v]);
      imageStore(crep_filteredBasisOut, ivec3(x, row, layer), crep_encodeFiltered(F[v]));
#endif
      sc = crep_rotate(second, stepSC);
    }
#endif
  }
#if CREP_EXACT_VISIBILITY
  // Right to left: W_i = prod_{k > i} (1 - m_k) in place of m_i (crep::prefilter's cumulative weights).
  vec3 carry = vec3(1.0);
  for (int i = n - 1; i >= 0; --i) {
    ivec3 texel = ivec3(region * n + i, row, 0);
    vec4 t = imageLoad(crep_filteredBasisOut, texel);
#if CREP_LIGHT_TEXTURE
    imageStore(crep_filteredBasisOut, texel, vec4(t.r, carry));
    carry *= 1.0 - t.gba;
#else
    imageStore(crep_filteredBasisOut, texel, vec4(t.r, carry.x, 0.0, 0.0));
    carry.x *= 1.0 - t.g;
#endif
  }
#endif
}
