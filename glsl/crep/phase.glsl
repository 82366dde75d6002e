// crepuscular: phase functions of a participating medium.
//
// Public include (see crep/common.glsl): an engine can `#include "crep/phase.glsl"`. Both functions
// are normalized over the sphere (unit: 1/sr) and take cosTheta, the cosine of the angle between the
// direction the light travels and the direction it is scattered into (cosTheta = 1: forward
// scattering). They match crep::henyeyGreenstein() and crep::rayleighPhase() (crep/core/medium.h).
#ifndef CREP_PHASE_GLSL
#define CREP_PHASE_GLSL

#include "common.glsl"

// Henyey-Greenstein: (1 - g^2) / (4 pi (1 + g^2 - 2 g cosTheta)^1.5), g in (-1, 1); g > 0 scatters
// forward.
float crep_henyeyGreenstein(float g, float cosTheta) {
  float g2 = g * g;
  float denom = 1.0 + g2 - 2.0 * g * cosTheta;
  return float(CREP_INV_FOUR_PI) * (1.0 - g2) / (denom * sqrt(denom));
}

// Rayleigh: 3 / (16 pi) (1 + cosTheta^2).
float crep_rayleighPhase(float cosTheta) { return float(3.0 / (16.0 * CREP_PI)) * (1.0 + cosTheta * cosTheta); }

// Isotropic: 1 / (4 pi).
float crep_isotropicPhase() { return float(CREP_INV_FOUR_PI); }

#endif // CREP_PHASE_GLSL
