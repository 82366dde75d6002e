#version 450 core
// Adds one light's in-scattering to the frame's output (crep::Scattering with local lights): RGB radiance
// adds, A (the grey transmittance to the surface, the same for every light) is kept. Both RGBA32F, the
// output's size.
#include "crep/bindings.h"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = CREP_ACCUMULATE_ACCUMULATED_IMAGE, rgba32f) uniform restrict image2D crep_accumulated;
layout(binding = CREP_ACCUMULATE_ADDEND_IMAGE, rgba32f) uniform readonly restrict image2D crep_addend;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, imageSize(crep_accumulated)))) return;
  vec4 sum = imageLoad(crep_accumulated, p);
  sum.rgb += imageLoad(crep_addend, p).rgb;
  imageStore(crep_accumulated, p, sum);
}
