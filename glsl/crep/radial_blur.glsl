// crepuscular: the block of the radial blur passes (GLSL twin of gpu::RadialBlurParams in
// crep/postfx/gpu_radial_blur.h; rules in crep/postfx/radial_blur.h, after Mitchell 2007, GPU Gems 3
// ch. 13), the sky rule of its occlusion pre-pass and the unshadowed in-scattering of a pixel ray.
//
// Public include (conventions in crep/common.glsl).
#ifndef CREP_RADIAL_BLUR_GLSL
#define CREP_RADIAL_BLUR_GLSL

#include "common.glsl"
#include "march.glsl"
#include "phase.glsl"

// gpu::RadialBlurParams (std140).
struct CrepRadialBlurParams {
  vec4 light; // xy the sun's screen position (texture coordinates), z fade, w exposure * weight / (n + 1)
  vec4 shape; // x decay, y density / n, zw 0
  ivec4 info; // x samples n, y sourceScale k, zw source size (texels)
};

// The cleared depth value of a camera (crep::Camera::surfaceViewDepth's sky rule): t = 1 - depth, or depth
// for reversed-Z (cameraDepth.w = 1, the map of crep_cameraViewDepth), not > 0; NaN counts as sky.
bool crep_radialIsSky(float depth, vec4 cameraDepth) {
  float t = cameraDepth.w > 0.5 ? depth : 1.0 - depth;
  return !(t > 0.0);
}

// The unshadowed in-scattering of a pixel ray (xyz unit direction, w distance; crep_pixelRay) from the
// camera: C of the ray times the transmittance integral over [0, w] (the closed form of
// crep::unshadowedScattering, Klehm et al. 2014, Eq. 1 with V = 1 and Eq. 3; Mitchell 2007, Eq. 1).
vec3 crep_radialUnshadowed(CrepMarchParams m, vec4 ray) {
  float cosTheta = dot(m.lightDirection.xyz, -ray.xyz);
  vec3 C = m.lightIrradiance.rgb * (m.mieScattering.rgb * crep_henyeyGreenstein(m.mieScattering.w, cosTheta) +
                                    m.rayleighScattering.rgb * crep_rayleighPhase(cosTheta));
  return C * crep_transmittanceIntegral(m.extinction.rgb, 0.0, ray.w);
}

#endif // CREP_RADIAL_BLUR_GLSL
