#version 450 core
// Composite of `crep render --method atmosphere`: lit surfaces times the atmosphere's RGB transmittance to
// them plus its in-scattered radiance (sky pixels: the surface colour is 0, so the sky's radiance alone).
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0) uniform sampler2D surfaceColor;  // lit surfaces (0 for the sky)
layout(binding = 1) uniform sampler2D inscattering;  // rgb in-scattered radiance
layout(binding = 2) uniform sampler2D transmittance; // rgb transmittance to the surface
layout(binding = 0, rgba32f) uniform writeonly image2D compositeOut;

layout(location = 0) uniform ivec2 imageSize;

void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, imageSize))) return;
  vec3 surface = texelFetch(surfaceColor, pixel, 0).rgb;
  vec3 L = texelFetch(inscattering, pixel, 0).rgb;
  vec3 T = texelFetch(transmittance, pixel, 0).rgb;
  imageStore(compositeOut, pixel, vec4(surface * T + L, 1.0));
}
