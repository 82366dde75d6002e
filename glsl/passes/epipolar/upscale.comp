#version 450 core
// Epipolar sampling, stage 6: the bilateral upscale of the (W / F) x (H / F) target to the full-resolution
// output (Yusov 2012, Sec. 6.8; rule and CPU reference: crep::upscaleSamples in
// crep/epipolar/epipolar_sampling.h). One thread per full-resolution pixel q: the bilinear neighbours of
// u = (q + 0.5) / F - 0.5 in the target (clamped so that both are inside it), each weight times a
// bilateral depth test against the target pixel's view depth. Total weight <= 1e-4: q is appended to the
// full-resolution correction list with its coordinates (q + 0.5, d, z_q); its output is not written.
//
// Real GPUs: 4 image loads of the target and its coordinates; float only.
//
// Resources: MarchParams (uniform 0), EpipolarSamplingParams (uniform 1), correction list (storage 2),
// camera depth (texture unit 0), target RGBA32F (image 0, read), target coordinates RGBA32F (image 1,
// read), output RGBA32F (image 2, written), full-resolution coordinates RGBA32F (image 3, written).
#include "crep/bindings.h"
#include "crep/march.glsl"
#include "crep/sample_list.glsl"
#include "crep/epipolar_sampling.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = CREP_EPIPOLAR_SAMPLING_MARCH_BINDING) uniform CrepMarchBlock { CrepMarchParams crep_march; };
layout(binding = CREP_EPIPOLAR_SAMPLING_CAMERA_DEPTH_UNIT) uniform sampler2D cameraDepth;
layout(binding = CREP_EPIPOLAR_SAMPLING_TARGET_IN_IMAGE, rgba32f) uniform readonly image2D targetIn;
layout(binding = CREP_EPIPOLAR_SAMPLING_TARGET_COORDINATES_IN_IMAGE, rgba32f) uniform readonly image2D targetCoordinatesIn;
layout(binding = CREP_EPIPOLAR_SAMPLING_OUTPUT_IMAGE, rgba32f) uniform writeonly image2D output_;
layout(binding = CREP_EPIPOLAR_SAMPLING_FULL_COORDINATES_OUT_IMAGE, rgba32f) uniform writeonly image2D fullCoordinatesOut;

void main() {
  ivec2 q = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(q, ivec2(crep_sampling.border.xy)))) return;
  ivec2 size = crep_sampling.target.xy;
  float d = texelFetch(cameraDepth, q, 0).r;
  float zq = crep_cameraViewDepth(d, crep_march.cameraDepth);
  vec2 u = clamp((vec2(q) + 0.5) / float(crep_sampling.counts.w) - 0.5, vec2(0.0), vec2(size - 1));
  ivec2 i0 = max(min(ivec2(floor(u)), size - 2), ivec2(0)); // an axis of one texel: i0 = 0, g = 0
  vec2 g = u - vec2(i0);
  vec4 sum = vec4(0.0);
  float total = 0.0;
  for (int n = 0; n < 4; ++n) {
    ivec2 o = ivec2(n & 1, n >> 1);
    ivec2 t = min(i0 + o, size - 1);
    float w = (o.x == 1 ? g.x : 1.0 - g.x) * (o.y == 1 ? g.y : 1.0 - g.y);
    float z = imageLoad(targetCoordinatesIn, t).w;
    if (!(w > 0.0) || !(abs(z - zq) <= crep_sampling.thresholds.z * zq)) continue;
    sum += w * imageLoad(targetIn, t);
    total += w;
  }
  if (total <= 1e-4) {
    imageStore(fullCoordinatesOut, q, vec4(vec2(q) + 0.5, d, zq));
    crep_listAppend(uvec2(q));
    return;
  }
  imageStore(output_, q, sum / total);
}
