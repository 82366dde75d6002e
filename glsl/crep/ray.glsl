// crepuscular: the transmittance integral of a view-ray section, shared by the evaluation of the
// prefiltered scattering (crep/scattering.glsl) and the marches (crep/march.glsl). GLSL twin of
// crep/scatter/ray.h (Klehm et al. 2014, Eq. 3 on one section).
//
// Public include (conventions in crep/common.glsl).
#ifndef CREP_RAY_GLSL
#define CREP_RAY_GLSL

#include "common.glsl"

// phi(x) = (1 - exp(-x)) / x for x >= 0, phi(0) = 1 (crep::oneMinusExpOverX): the series below 1/4
// (truncation < 2e-9) keeps the sigma -> 0 limit exact and free of the cancellation of 1 - exp(-x) in float.
// The series alone (for x < 1/4), per component.
vec3 crep_oneMinusExpOverXSeries(vec3 x) {
  return 1.0 - x * (1.0 / 2.0 - x * (1.0 / 6.0 - x * (1.0 / 24.0 - x * (1.0 / 120.0 - x * (1.0 / 720.0 - x / 5040.0)))));
}
float crep_oneMinusExpOverX(float x) {
  if (x < 0.25) return crep_oneMinusExpOverXSeries(vec3(x)).x;
  return (1.0 - exp(-x)) / x;
}

// (exp(-sigma ta) - exp(-sigma tb)) / sigma per channel, = tb - ta for sigma -> 0; 0 when tb <= ta
// (crep::transmittanceIntegral).
vec3 crep_transmittanceIntegral(vec3 sigma, float ta, float tb) {
  float len = tb - ta;
  if (!(len > 0.0)) return vec3(0.0);
  vec3 x = sigma * len;
  return exp(-sigma * ta) * len *
         vec3(crep_oneMinusExpOverX(x.r), crep_oneMinusExpOverX(x.g), crep_oneMinusExpOverX(x.b));
}

#endif // CREP_RAY_GLSL
