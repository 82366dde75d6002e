#version 450 core
// Epipolar sampling, stage 3: refinement (Yusov 2012, Sec. 6.2; the in-scattering criterion of Yusov
// 2013; rules and CPU reference: crep::refineSamples in crep/epipolar/epipolar_sampling.h). One work group
// of Ns threads per line (CREP_SAMPLES, local_size_x): thread k flags the break between samples k and
// k + 1 (depth and / or unshadowed in-scattering discontinuity), the flags are packed 32 per uint in
// shared memory, and each sample finds its interpolation sources by scanning the packed words inside its
// section [a, b] (findMSB to the left, findLSB to the right: at most S / 32 + 1 words, not S samples).
// A sample that is initial (k % S == 0 with S the line's step at k, k == lastValid) or next to a break is marched: sources (k, k),
// appended to the sample list (crep/sample_list.glsl); the others get (left, right), both marched.
// Invalid samples (k > lastValid): (-1, -1).
//
// Real GPUs: Ns / 32 words of shared flags instead of Ns booleans (Yusov's packing: few bank accesses,
// a word per 32 samples); the z and U of the line are staged once in shared memory, one read per thread.
//
// Resources: EpipolarSamplingParams (uniform 1), line table (storage 0), sample list (storage 2),
// coordinates RGBA32F (image 0, read), U R32F (image 1, read), sources RG32I (image 2, written).
#include "crep/bindings.h"
#include "crep/sample_list.glsl"
#include "crep/epipolar_sampling.glsl"

#ifndef CREP_SAMPLES
#define CREP_SAMPLES 256
#endif
#define CREP_FLAG_WORDS (CREP_SAMPLES / 32)

layout(local_size_x = CREP_SAMPLES) in;

layout(binding = CREP_EPIPOLAR_SAMPLING_COORDINATES_IN_IMAGE, rgba32f) uniform readonly image2D coordinatesIn;
layout(binding = CREP_EPIPOLAR_SAMPLING_UNSHADOWED_IN_IMAGE, r32f) uniform readonly image2D unshadowedIn;
layout(binding = CREP_EPIPOLAR_SAMPLING_SOURCES_OUT_IMAGE, rg32i) uniform writeonly iimage2D sourcesOut;

shared uint flags[CREP_FLAG_WORDS]; // bit j: a break between samples j and j + 1
shared float lineZ[CREP_SAMPLES], lineU[CREP_SAMPLES];

// Mask of bits lo..hi (0 <= lo <= hi <= 31) of a word.
uint crep_bitRange(int lo, int hi) {
  uint upper = hi == 31 ? 0xFFFFFFFFu : (1u << uint(hi + 1)) - 1u;
  return upper & (0xFFFFFFFFu << uint(lo));
}

// The largest j in [lo, hi] with a break flag, or -1.
int crep_lastBreak(int lo, int hi) {
  for (int w = hi >> 5; w >= (lo >> 5); --w) {
    uint bits = flags[w] & crep_bitRange(w == (lo >> 5) ? lo & 31 : 0, w == (hi >> 5) ? hi & 31 : 31);
    if (bits != 0u) return w * 32 + findMSB(bits);
  }
  return -1;
}

// The smallest j in [lo, hi] with a break flag, or -1.
int crep_firstBreak(int lo, int hi) {
  for (int w = lo >> 5; w <= (hi >> 5); ++w) {
    uint bits = flags[w] & crep_bitRange(w == (lo >> 5) ? lo & 31 : 0, w == (hi >> 5) ? hi & 31 : 31);
    if (bits != 0u) return w * 32 + findLSB(bits);
  }
  return -1;
}

void main() {
  int k = int(gl_LocalInvocationID.x), i = int(gl_WorkGroupID.x);
  int lastValid = crep_lines[i].info.x;
  if (k < CREP_FLAG_WORDS) flags[k] = 0u;
  bool valid = k <= lastValid;
  lineZ[k] = valid ? imageLoad(coordinatesIn, ivec2(k, i)).w : 0.0;
  lineU[k] = valid ? imageLoad(unshadowedIn, ivec2(k, i)).r : 0.0;
  barrier(); // flags cleared, z and U staged

  if (k + 1 <= lastValid) {
    float za = lineZ[k], zb = lineZ[k + 1], ua = lineU[k], ub = lineU[k + 1];
    bool brk = (crep_sampling.target.z != 0 && abs(za - zb) > crep_sampling.thresholds.x * min(za, zb)) ||
               (crep_sampling.target.w != 0 && abs(ua - ub) > crep_sampling.thresholds.y * max(ua, ub));
    if (brk) atomicOr(flags[k >> 5], 1u << uint(k & 31));
  }
  barrier(); // flags complete

  if (!valid) {
    imageStore(sourcesOut, ivec2(k, i), ivec4(-1, -1, 0, 0));
    return;
  }
  // The initial step: S, or the denser step on the samples nearest the epipole (info.y samples, step info.z).
  int S = k < crep_lines[i].info.y ? crep_lines[i].info.z : crep_sampling.counts.z;
  int a = (k / S) * S, b = min(a + S, lastValid);
  int left = k, right = k;
  if (k > a) {
    int j = crep_lastBreak(a, k - 1); // break between j and j + 1
    left = j < 0 ? a : j + 1;
  }
  if (k < b) {
    int j = crep_firstBreak(k, b - 1);
    right = j < 0 ? b : j;
  }
  bool marched = k % S == 0 || k == lastValid || left == k || right == k;
  imageStore(sourcesOut, ivec2(k, i), marched ? ivec4(k, k, 0, 0) : ivec4(left, right, 0, 0));
  if (marched) crep_listAppend(uvec2(k, i));
}
