#version 450 core
// ToneMapPass, reduction pass 2 of 2 and light adaptation (crep/postfx/gpu_tone_mapping.h): one workgroup
// adds the partial sums of luminance_reduce.comp, takes the log-average exp(sum / count) (Reinhard et al.
// 2002, Eq. 1) and moves the adapted luminance toward it: La += (Lt - La)(1 - exp(-dt / tau))
// (Pattanaik et al. 2000's exponential lag, as in Yusov's demo; the factor comes from the CPU in double).
// Reset or the first frame: La = Lt. A frame without a finite pixel keeps La. Then the exposure scale
// middleGrey / La (Reinhard et al. 2002, Eq. 2). Nothing is read back to the CPU.
#include "crep/bindings.h"
#include "crep/tone_mapping.glsl"

#define CREP_ADAPT_THREADS 256
layout(local_size_x = CREP_ADAPT_THREADS) in;

layout(std140, binding = CREP_TONE_MAP_PARAMS_BINDING) uniform CrepToneMapBlock { CrepToneMapParams crep_toneMap; };
layout(std430, binding = CREP_TONE_MAP_LUMINANCE_PARTIALS_BINDING) restrict readonly buffer CrepLuminancePartials { CrepLuminancePartial crep_partials[]; };
layout(std430, binding = CREP_TONE_MAP_STATE_BINDING) restrict buffer CrepToneMapStateBlock { CrepToneMapState crep_state; };

shared float crep_sharedLogSum[CREP_ADAPT_THREADS];
shared uint crep_sharedCount[CREP_ADAPT_THREADS];

void main() {
  uint t = gl_LocalInvocationIndex;
  uint n = uint(crep_toneMap.flags.z);
  float logSum = 0.0;
  uint count = 0u;
  for (uint i = t; i < n; i += CREP_ADAPT_THREADS) {
    logSum += crep_partials[i].logSum;
    count += crep_partials[i].count;
  }
  crep_sharedLogSum[t] = logSum;
  crep_sharedCount[t] = count;
  barrier();
  for (uint stride = CREP_ADAPT_THREADS / 2; stride > 0u; stride >>= 1) {
    if (t < stride) {
      crep_sharedLogSum[t] += crep_sharedLogSum[t + stride];
      crep_sharedCount[t] += crep_sharedCount[t + stride];
    }
    barrier();
  }
  if (t != 0u) return;
  bool fresh = crep_toneMap.flags.y != 0 || crep_state.valid == 0;
  float adapted = fresh ? 1.0 : crep_state.adaptedLuminance;
  float target = adapted;
  int valid = fresh ? 0 : 1;
  if (crep_sharedCount[0] > 0u) {
    target = exp(crep_sharedLogSum[0] / float(crep_sharedCount[0]));
    adapted = valid == 0 ? target : adapted + (target - adapted) * crep_toneMap.adaptation.x;
    valid = 1;
  }
  crep_state.adaptedLuminance = adapted;
  crep_state.targetLuminance = target;
  crep_state.exposureScale = crep_toneMap.curve.x / adapted;
  crep_state.valid = valid;
}
