// crepuscular: the blocks of the epipolar sampling stage passes (Yusov 2012, Sec. 6; passes/epipolar_*.comp):
// the frame's sampling parameters and its table of epipolar lines. GLSL twins, member for member, of
// gpu::EpipolarSamplingParams (std140) and gpu::EpipolarSamplingLine (std430) in
// crep/epipolar/gpu_epipolar_sampling.h; the rules and the CPU reference are in
// crep/epipolar/epipolar_sampling.h.
//
// Public include (conventions in crep/common.glsl). Bindings (fixed, those of EpipolarSamplingPass):
//   uniform binding 1   CrepEpipolarSamplingBlock { CrepEpipolarSamplingParams crep_sampling; }
//   storage binding 0   CrepEpipolarLinesBlock { CrepEpipolarLine crep_lines[]; } (readonly)
// Pixel coordinates, origin at the bottom-left. The including pass declares its MarchParams block
// (crep/march.glsl, uniform binding 0) itself if it reads it.
#ifndef CREP_EPIPOLAR_SAMPLING_GLSL
#define CREP_EPIPOLAR_SAMPLING_GLSL
#include "bindings.h"

// gpu::EpipolarSamplingParams.
struct CrepEpipolarSamplingParams {
  vec4 epipole;    // xy epipole (pixels), z arcBegin, w arcLength
  vec4 border;     // x W, y H, z perimeter, w 1 = epipole on screen
  ivec4 counts;    // x slices N, y samples Ns, z initial step S, w downscale F
  ivec4 target;    // xy target size, z depth criterion, w scattering criterion
  vec4 thresholds; // x depth, y scattering, z bilateral
};

// gpu::EpipolarSamplingLine: one line.
struct CrepEpipolarLine {
  vec4 ends;  // xy entry, zw exit
  ivec4 info; // x lastValid (-1: no valid sample), y samples with the denser initial step, z that step
};

layout(std140, binding = CREP_EPIPOLAR_SAMPLING_PARAMS_BINDING) uniform CrepEpipolarSamplingBlock { CrepEpipolarSamplingParams crep_sampling; };
layout(std430, binding = CREP_EPIPOLAR_SAMPLING_LINES_BINDING) readonly buffer CrepEpipolarLinesBlock { CrepEpipolarLine crep_lines[]; };

#endif // CREP_EPIPOLAR_SAMPLING_GLSL
