#version 450 core
// Epipolar sampling, stage 2: the samples of every epipolar line (Yusov 2012, Sec. 6.1; rules and CPU
// reference: crep::epipolarSamples in crep/epipolar/epipolar_sampling.h). One thread per texel (k, i) of
// the Ns x N coordinate texture: sample k of line i at p_k = entry + (exit - entry) k / (Ns - 1), its
// depth-buffer value at the pixel containing p_k (point sampling: never a depth between two surfaces),
// view depth, and U = the luminance of the unshadowed in-scattering of its ray (Yusov 2013's refinement
// criterion). Invalid samples (k > lastValid): (-1, -1, -1, -1) and U = 0.
//
// Real GPUs: threads along x are consecutive samples of one line, so the depth fetches of a wave follow
// the line through the depth texture (coherent reads); float only (no fp64).
//
// Resources: MarchParams (uniform 0), EpipolarSamplingParams (uniform 1), line table (storage 0), camera
// depth (texture unit 0, texelFetch), outputs: coordinates RGBA32F (image 0), U R32F (image 1).
#include "crep/bindings.h"
#include "crep/radial_blur.glsl"
#include "crep/epipolar_sampling.glsl"

layout(local_size_x = 64, local_size_y = 1) in;

layout(std140, binding = CREP_EPIPOLAR_SAMPLING_MARCH_BINDING) uniform CrepMarchBlock { CrepMarchParams crep_march; };
layout(binding = CREP_EPIPOLAR_SAMPLING_CAMERA_DEPTH_UNIT) uniform sampler2D cameraDepth;
layout(binding = CREP_EPIPOLAR_SAMPLING_COORDINATES_OUT_IMAGE, rgba32f) uniform writeonly image2D coordinatesOut;
layout(binding = CREP_EPIPOLAR_SAMPLING_UNSHADOWED_OUT_IMAGE, r32f) uniform writeonly image2D unshadowedOut;

void main() {
  ivec2 t = ivec2(gl_GlobalInvocationID.xy); // (k, i)
  int Ns = crep_sampling.counts.y;
  if (t.x >= Ns || t.y >= crep_sampling.counts.x) return;
  CrepEpipolarLine line = crep_lines[t.y];
  if (t.x > line.info.x) {
    imageStore(coordinatesOut, t, vec4(-1.0));
    imageStore(unshadowedOut, t, vec4(0.0));
    return;
  }
  vec2 size = crep_sampling.border.xy;
  vec2 p = mix(line.ends.xy, line.ends.zw, float(t.x) / float(Ns - 1));
  ivec2 q = clamp(min(ivec2(floor(p)), ivec2(size) - 1), ivec2(0), ivec2(size) - 1);
  float d = texelFetch(cameraDepth, q, 0).r;
  float z = crep_cameraViewDepth(d, crep_march.cameraDepth);
  // The ray through the continuous position p (crep::screenRay on the CPU): the ray an evaluator of the
  // work list gets for this texel.
  vec3 L = crep_radialUnshadowed(crep_march, crep_screenRay(crep_march, p, d));
  imageStore(coordinatesOut, t, vec4(p, d, z));
  imageStore(unshadowedOut, t, vec4(crep_luminance(L)));
}
