#version 450 core
// World-space reference march against a standard shadow map (crep/scatter/world_march.h; Klehm et al.
// 2014, Eq. 1 and 3, Yusov 2012, Eq. 15-16): N equal sections from the camera to the
// surface, visibility at their ends, bisection of every section whose ends differ, exact transmittance
// integral of every lit part. Same rules as crep::worldSpaceMarch; float precision.
//
// Light: directional (crep_march.lightPosition.w = 0: each lit part C * transmittance integral) or local,
// a spot or one point-light face (lightPosition.w = 1: each lit part crep_localSegment of
// crep/local_light.glsl, the output RGB the radiance itself), as the two crep::worldSpaceMarch overloads.
//
// The dispatch covers the pixel rectangle crep_march.region (origin xy, size zw); with block.z >= 0 only
// the pixels within block.z pixels of block.xy (pixel centres) are written: the epipole block of Klehm
// et al. 2014, Fig. 8. Resources: params block (binding 0), camera depth (unit 0), shadow map (unit 1, texelFetch),
// outputs: RGBA32F scattering (image 0), R32F steps (image 1).
// CREP_LIGHT_TEXTURE 1: a light texture (crep/scatter/light_texture.h) at texture unit 2 with its block
// (CrepLightTextureParams) at uniform binding 1; each lit part times the texture's colour at its midpoint
// (crep::worldSpaceMarch with a LightTexture).
#include "crep/bindings.h"
#include "crep/local_light.glsl"
#include "crep/march.glsl"
#include "crep/phase.glsl"

#ifndef CREP_LIGHT_TEXTURE
#define CREP_LIGHT_TEXTURE 0
#endif
#if CREP_LIGHT_TEXTURE
#include "crep/light_texture.glsl"
layout(std140, binding = CREP_MARCH_LIGHT_TEXTURE_BINDING) uniform CrepLightTextureBlock { CrepLightTextureParams crep_lightTextureParams; };
layout(binding = CREP_MARCH_LIGHT_TEXTURE_UNIT) uniform sampler2D crep_lightTexture;
#endif

layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = CREP_MARCH_PARAMS_BINDING) uniform CrepMarchBlock { CrepMarchParams crep_march; };
layout(binding = CREP_MARCH_CAMERA_DEPTH_UNIT) uniform sampler2D cameraDepth;
layout(binding = CREP_MARCH_MAP_UNIT) uniform sampler2D shadowMap;
layout(binding = CREP_MARCH_SCATTERING_OUT_IMAGE, rgba32f) uniform writeonly image2D scatteringOut;
layout(binding = CREP_MARCH_STEPS_OUT_IMAGE, r32f) uniform writeonly image2D stepsOut;

int crep_lookups = 0;

// crep::standardShadowLit: nearest texel, outside the map lit, behind a perspective light's eye plane
// (clip w <= 0) lit, NaN texels lit (documented GPU rule).
bool crep_lit(vec3 p) {
  ++crep_lookups;
  vec4 q = crep_march.lightClipFromWorld * vec4(p, 1.0);
  if (!(q.w > 0.0)) return true;
  vec3 uvd = q.xyz / q.w * 0.5 + 0.5;
  if (!(uvd.x >= 0.0 && uvd.x <= 1.0 && uvd.y >= 0.0 && uvd.y <= 1.0)) return true;
  ivec2 size = crep_march.sizes.zw;
  ivec2 texel = min(ivec2(uvd.xy * vec2(size)), size - 1);
  float stored = texelFetch(shadowMap, texel, 0).r;
  return !(clamp(uvd.z, 0.0, 1.0) > stored + crep_march.bias.x);
}

// The lit part [ta, tb] of the ray: the transmittance integral (directional, times C in main) or the
// local light's in-scattering.
vec3 crep_section(bool local, CrepLocalLight light, CrepLocalMedium medium, vec3 origin, vec3 dir, float ta, float tb) {
  vec3 v = local ? crep_localSegment(light, medium, origin, dir, ta, tb)
                 : crep_transmittanceIntegral(medium.extinction, ta, tb);
#if CREP_LIGHT_TEXTURE
  v *= crep_lightTextureColor(crep_lightTexture, crep_lightTextureParams, origin + (0.5 * (ta + tb)) * dir);
#endif
  return v;
}

void main() {
  ivec2 pixel = crep_march.region.xy + ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(ivec2(gl_GlobalInvocationID.xy), crep_march.region.zw)) ||
      any(greaterThanEqual(pixel, crep_march.sizes.xy)) || any(lessThan(pixel, ivec2(0))))
    return;
  if (crep_march.block.z >= 0.0 && distance(vec2(pixel) + 0.5, crep_march.block.xy) > crep_march.block.z) return;
  vec4 ray = crep_pixelRay(crep_march, pixel, texelFetch(cameraDepth, pixel, 0).r);
  vec3 dir = ray.xyz, origin = crep_march.cameraPosition.xyz;
  float s = ray.w;
  vec3 sigma = crep_march.extinction.rgb;
  bool local = crep_march.lightPosition.w > 0.5;
  CrepLocalLight light = crep_localLight(crep_march.lightPosition, crep_march.lightAxis, crep_march.lightCone,
                                         crep_march.lightIntensity);
  CrepLocalMedium medium = CrepLocalMedium(crep_march.mieScattering, crep_march.rayleighScattering.rgb, sigma);
  float cosTheta = dot(crep_march.lightDirection.xyz, -dir);
  // Directional: S = C * transmittance integral; local: S = crep_localSegment and C = 1.
  vec3 C = local ? vec3(1.0)
                 : crep_march.lightIrradiance.rgb *
                       (crep_march.mieScattering.rgb * crep_henyeyGreenstein(crep_march.mieScattering.w, cosTheta) +
                        crep_march.rayleighScattering.rgb * crep_rayleighPhase(cosTheta));
  int N = crep_march.info.x, refinements = crep_march.info.y;
  vec3 L = vec3(0.0);
  float ta = 0.0;
  bool va = crep_lit(origin);
  for (int k = 1; k <= N; ++k) {
    float tb = k == N ? s : s * float(k) / float(N);
    bool vb = crep_lit(origin + tb * dir);
    if (va == vb) {
      if (va) L += crep_section(local, light, medium, origin, dir, ta, tb);
    } else {
      float lo = ta, hi = tb;
      for (int r = 0; r < refinements; ++r) {
        float mid = 0.5 * (lo + hi);
        if (crep_lit(origin + mid * dir) == va)
          lo = mid;
        else
          hi = mid;
      }
      float change = 0.5 * (lo + hi);
      if (va) L += crep_section(local, light, medium, origin, dir, ta, change);
      if (vb) L += crep_section(local, light, medium, origin, dir, change, tb);
    }
    ta = tb;
    va = vb;
  }
  imageStore(scatteringOut, pixel, vec4(C * L, exp(-crep_march.extinction.w * s)));
  imageStore(stepsOut, pixel, vec4(float(crep_lookups)));
}
