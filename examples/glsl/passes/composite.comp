#version 450 core
// Composite for the crep tool: surface radiance attenuated by the per-channel transmittance to the
// surface (exp(-sigma_t s), Eq. 1's T) plus the in-scattered radiance of any method.
#ifndef CREP_LOCAL_SIZE
#define CREP_LOCAL_SIZE 8
#endif
layout(local_size_x = CREP_LOCAL_SIZE, local_size_y = CREP_LOCAL_SIZE) in;

layout(binding = 0) uniform sampler2D cameraDepth;  // depth-buffer values in [0, 1]
layout(binding = 1) uniform sampler2D surfaceColor; // lit surfaces
layout(binding = 2) uniform sampler2D scattering;   // rgb in-scattering
layout(binding = 0, rgba32f) uniform writeonly image2D compositeOut;

layout(location = 0) uniform mat4 worldFromClip;
layout(location = 1) uniform vec3 cameraPosition;
layout(location = 2) uniform vec3 extinction;
layout(location = 3) uniform ivec2 imageSize;

void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, imageSize))) return;
  vec2 uv = (vec2(pixel) + 0.5) / vec2(imageSize);
  float depth = texelFetch(cameraDepth, pixel, 0).r;
  vec4 h = worldFromClip * vec4(uv * 2.0 - 1.0, 2.0 * min(depth, 1.0) - 1.0, 1.0);
  float s = length(h.xyz / h.w - cameraPosition);
  vec3 surface = texelFetch(surfaceColor, pixel, 0).rgb;
  vec3 inscatter = texelFetch(scattering, pixel, 0).rgb;
  imageStore(compositeOut, pixel, vec4(surface * exp(-extinction * s) + inscatter, 1.0));
}
