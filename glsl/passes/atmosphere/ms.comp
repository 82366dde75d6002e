#version 450 core
// AtmosphereTablesPass, multiple scattering stage (Hillaire 2020, Sec. 5.5; crep::precomputeAtmosphere's
// Lut method, CPU twin multipleScatteringAt in atmosphere/src/atmosphere.cpp): texel (i, j) of the n x n table
// holds Psi_ms at altitude h = H_Atm (i / (n - 1))^2 and sun zenith cosine c = 2 j / (n - 1) - 1: from the
// point x = (0, R + h, 0), CREP_ATMOSPHERE_SAMPLES Fibonacci directions w, each marched to the ground or the
// top of the atmosphere with CREP_ATMOSPHERE_STEPS midpoint steps, give the second order L2 (the mean of
// the integral of T(x, y) (beta_R d_R p_R + beta_M d_M p_HG)(w . l) T_sun(y), the first scattering with its
// true phase functions where Hillaire takes the isotropic one, plus the sunlit ground's albedo / pi
// bounce) and the transfer f_ms (the mean of the integral of T(x, y) sigma_s(y)); Psi_ms = L2 / (1 - f_ms).
// Positions are offsets from x (altitudes from |x|^2 - R^2 without cancellation, as the 4D passes').
#include "crep/bindings.h"
#include "crep/atmosphere.glsl"

#ifndef CREP_ATMOSPHERE_SAMPLES
#define CREP_ATMOSPHERE_SAMPLES 128
#endif
#ifndef CREP_ATMOSPHERE_STEPS
#define CREP_ATMOSPHERE_STEPS 20
#endif

layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = CREP_ATMOSPHERE_TABLES_PARAMS_BINDING) uniform CrepAtmosphereBlock { CrepAtmosphereParams crep_atmosphere; };
layout(binding = CREP_ATMOSPHERE_TABLES_MS_OPTICAL_DEPTH_UNIT) uniform sampler2D crep_opticalDepth;
layout(binding = CREP_ATMOSPHERE_TABLES_MS_OUTPUT_IMAGE, rgba32f) uniform restrict writeonly image2D crep_output;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  int n = int(crep_atmosphere.multipleScattering.y);
  if (any(greaterThanEqual(p, ivec2(n)))) return;
  float R = crep_atmosphere.radii.x, H = crep_atmosphere.radii.z;
  float u = float(p.x) / float(n - 1);
  float h = H * u * u;
  float mu = -1.0 + 2.0 * float(p.y) / float(n - 1);
  vec3 l = vec3(sqrt(max(0.0, 1.0 - mu * mu)), mu, 0.0);
  float r0 = R + h;
  float hh = h * (2.0 * R + h); // r0^2 - R^2
  float albedo = crep_atmosphere.multipleScattering.x;
  vec3 second = vec3(0.0), transfer = vec3(0.0);
  for (int i = 0; i < CREP_ATMOSPHERE_SAMPLES; ++i) {
    vec3 w = crep_fibonacciSphereDirection(i, CREP_ATMOSPHERE_SAMPLES);
    float c = w.y, b = r0 * c, wl = dot(w, l);
    float disc = b * b - hh;
    bool ground = c < 0.0 && disc >= 0.0;
    float len = ground ? crep_atmosphereGroundDistance(hh, b, disc)
                       : crep_atmosphereTopDistance(crep_atmosphere, h, b);
    float dt = len / float(CREP_ATMOSPHERE_STEPS);
    float phaseR = crep_rayleighPhase(wl), phaseM = crep_henyeyGreenstein(crep_atmosphere.mieExtinction.w, wl);
    vec2 optical = vec2(0.0);
    vec3 lum = vec3(0.0), fms = vec3(0.0);
    for (int k = 0; k < CREP_ATMOSPHERE_STEPS; ++k) {
      float t = (float(k) + 0.5) * dt;
      float rr = hh + t * (2.0 * b + t); // |y|^2 - R^2
      float r = sqrt(R * R + rr);
      float hy = max(rr / (r + R), 0.0);
      vec2 d = crep_atmosphereDensity(crep_atmosphere, hy);
      vec3 T = exp(-crep_atmosphereExtinction(crep_atmosphere, optical + d * (0.5 * dt)));
      optical += d * dt;
      vec3 sigmaS = crep_atmosphere.rayleighScattering.rgb * d.x + crep_atmosphere.mieScattering.rgb * d.y;
      vec3 phased = crep_atmosphere.rayleighScattering.rgb * (d.x * phaseR) +
                    crep_atmosphere.mieScattering.rgb * (d.y * phaseM);
      vec3 sunT = crep_sunTransmittanceAt(crep_opticalDepth, crep_atmosphere, hy, (r0 * mu + t * wl) / r);
      lum += T * phased * sunT * dt;
      fms += T * sigmaS * dt;
    }
    if (ground) {
      float cosSun = (r0 * mu + len * wl) / R;
      if (cosSun > 0.0)
        lum += exp(-crep_atmosphereExtinction(crep_atmosphere, optical)) *
               crep_sunTransmittanceAt(crep_opticalDepth, crep_atmosphere, 0.0, cosSun) *
               (cosSun * albedo * float(CREP_INV_PI));
    }
    second += lum;
    transfer += fms;
  }
  second /= float(CREP_ATMOSPHERE_SAMPLES);
  transfer /= float(CREP_ATMOSPHERE_SAMPLES);
  imageStore(crep_output, p, vec4(second / (vec3(1.0) - transfer), 0.0));
}
