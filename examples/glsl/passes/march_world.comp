#version 450 core
// Reference single scattering (seed 003, Eq. 1) for a directional light: each pixel's view ray is
// marched in world space from the camera to the first surface (or the far plane for sky pixels),
// testing every sample against a standard shadow map. No rectification involved. Midpoint rule
// with CREP_MARCH_STEPS samples; transmittance exp(-sigma_t t) per channel.
#include "crep/common.glsl"
#include "crep/phase.glsl"

#ifndef CREP_MARCH_STEPS
#define CREP_MARCH_STEPS 256
#endif

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0) uniform sampler2D cameraDepth; // depth-buffer values in [0, 1]
layout(binding = 1) uniform sampler2D shadowMap;   // depth-buffer values in [0, 1], nearest
layout(binding = 0, rgba32f) uniform writeonly image2D scatteringOut; // rgb in-scattering, a transmittance

layout(location = 0) uniform mat4 worldFromClip;
layout(location = 1) uniform mat4 shadowClipFromWorld;
layout(location = 2) uniform vec3 cameraPosition;
layout(location = 3) uniform vec3 lightDirection;  // direction the light travels
layout(location = 4) uniform vec3 lightIrradiance;
layout(location = 5) uniform vec3 mieScattering;
layout(location = 6) uniform vec3 rayleighScattering;
layout(location = 7) uniform vec3 extinction;
layout(location = 8) uniform float hgG;
layout(location = 9) uniform ivec2 imageSize;
layout(location = 10) uniform float shadowBias;

float litAt(vec3 p) {
  vec4 clip = shadowClipFromWorld * vec4(p, 1.0);
  vec3 uvz = clip.xyz / clip.w * 0.5 + 0.5;
  if (any(lessThan(uvz.xy, vec2(0.0))) || any(greaterThan(uvz.xy, vec2(1.0)))) return 1.0;
  return texture(shadowMap, uvz.xy).r + shadowBias >= clamp(uvz.z, 0.0, 1.0) ? 1.0 : 0.0;
}

void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, imageSize))) return;
  vec2 uv = (vec2(pixel) + 0.5) / vec2(imageSize);
  float depth = texelFetch(cameraDepth, pixel, 0).r;
  vec4 farH = worldFromClip * vec4(uv * 2.0 - 1.0, 2.0 * min(depth, 1.0) - 1.0, 1.0);
  vec3 hit = farH.xyz / farH.w;
  vec3 ray = hit - cameraPosition;
  float s = length(ray);
  vec3 dir = ray / s;
  // Scattering angle: between the light's travel direction and the direction toward the camera.
  float cosTheta = dot(lightDirection, -dir);
  vec3 sigmaPhase = mieScattering * crep_henyeyGreenstein(hgG, cosTheta) + rayleighScattering * crep_rayleighPhase(cosTheta);
  vec3 sum = vec3(0.0);
  float dt = s / float(CREP_MARCH_STEPS);
  for (int i = 0; i < CREP_MARCH_STEPS; ++i) {
    float t = (float(i) + 0.5) * dt;
    sum += exp(-extinction * t) * litAt(cameraPosition + t * dir);
  }
  vec3 inscatter = sigmaPhase * lightIrradiance * sum * dt;
  vec3 transmittance = exp(-extinction * s);
  imageStore(scatteringOut, pixel, vec4(inscatter, dot(transmittance, vec3(1.0 / 3.0))));
}
