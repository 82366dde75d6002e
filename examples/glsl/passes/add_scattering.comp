#version 450 core
// The crep tool's sum of lights (Klehm et al. 2014, Sec. 3.2: the contributions of the lights add): RGB
// in-scattered radiance of `addend` added to `sum`; A (the grey transmittance to the surface, the same for
// every light) is kept. Both RGBA32F, the camera image's size.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba32f) uniform restrict image2D sum;
layout(binding = 1, rgba32f) uniform readonly restrict image2D addend;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, imageSize(sum)))) return;
  vec4 s = imageLoad(sum, p);
  s.rgb += imageLoad(addend, p).rgb;
  imageStore(sum, p, s);
}
