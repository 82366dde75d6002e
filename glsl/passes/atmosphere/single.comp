#version 450 core
// AtmosphereTablesPass, single scattering stage (Yusov 2013, Listing 3 without the phase functions;
// crep/atmosphere/atmosphere.h's contract): each texel of the 4D table (packed 3D: x h, y alpha, z theta * N_phi
// + phi) integrates S_R = beta_R d_R T(C -> P) T(P -> sun) and S_M = beta_M d_M T(C -> P) T(P -> sun) (the
// single table: RGB S_R, A S_M's red; the single Mie table, unless CREP_ATMOSPHERE_COMBINED_MIE: RGB S_M)
// (with CREP_ATMOSPHERE_MS_LUT 1 also L_H = T(C -> P) sigma_s(P) Psi_ms(P), Hillaire 2020, Sec. 5.5, into the
// higher orders table) by the trapezoid rule with CREP_ATMOSPHERE_STEPS
// steps from its point C to the ground (lower alpha half) or the top of the atmosphere (upper half); the
// camera's density integral is accumulated by the trapezoid rule over the steps so far (Listing 5's way),
// the sun's transmittance comes from the optical depth table.
#include "crep/bindings.h"
#include "crep/atmosphere.glsl"

#ifndef CREP_ATMOSPHERE_STEPS
#define CREP_ATMOSPHERE_STEPS 100
#endif

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(std140, binding = CREP_ATMOSPHERE_TABLES_PARAMS_BINDING) uniform CrepAtmosphereBlock { CrepAtmosphereParams crep_atmosphere; };
layout(binding = CREP_ATMOSPHERE_TABLES_SINGLE_OPTICAL_DEPTH_UNIT) uniform sampler2D crep_opticalDepth;
layout(binding = CREP_ATMOSPHERE_TABLES_SINGLE_OUTPUT_IMAGE, rgba32f) uniform restrict writeonly image3D crep_output;
#if !CREP_ATMOSPHERE_COMBINED_MIE
layout(binding = CREP_ATMOSPHERE_TABLES_SINGLE_OUTPUT_MIE_IMAGE, rgba32f) uniform restrict writeonly image3D crep_outputMie;
#endif
#ifndef CREP_ATMOSPHERE_MS_LUT
#define CREP_ATMOSPHERE_MS_LUT 0
#endif
#if CREP_ATMOSPHERE_MS_LUT
layout(binding = CREP_ATMOSPHERE_TABLES_SINGLE_MS_LUT_UNIT) uniform sampler2D crep_msLut; // Psi_ms
layout(binding = CREP_ATMOSPHERE_TABLES_SINGLE_OUTPUT_HIGHER_IMAGE, rgba32f) uniform restrict writeonly image3D crep_outputHigher;
#endif

void main() {
  ivec3 p = ivec3(gl_GlobalInvocationID);
  ivec4 n = crep_atmosphere.tableSize;
  if (any(greaterThanEqual(p, ivec3(n.x, n.y, n.z * n.w)))) return;
  CrepAtmosphereTexelRay ray = crep_atmosphereTexelRay(crep_atmosphere, ivec4(p.xy, p.z % n.z, p.z / n.z));
  float dt = ray.end / float(CREP_ATMOSPHERE_STEPS);
  vec2 camera = vec2(0.0);
  vec2 previousDensity = vec2(0.0);
  vec3 sumR = vec3(0.0), sumM = vec3(0.0), sumH = vec3(0.0);
  for (int k = 0; k <= CREP_ATMOSPHERE_STEPS; ++k) {
    CrepAtmosphereRayPoint q = crep_atmosphereRayPoint(crep_atmosphere, ray, dt * float(k));
    vec2 dens = crep_atmosphereDensity(crep_atmosphere, q.h);
    if (k > 0) camera += 0.5 * (previousDensity + dens) * dt;
    previousDensity = dens;
    vec3 cameraT = exp(-crep_atmosphereExtinction(crep_atmosphere, camera));
    vec3 sunT = crep_sunTransmittanceAt(crep_opticalDepth, crep_atmosphere, q.h, q.cosSunZenith);
    vec3 tt = cameraT * sunT;
    float weight = (k == 0 || k == CREP_ATMOSPHERE_STEPS) ? 0.5 : 1.0;
    sumR += weight * (crep_atmosphere.rayleighScattering.rgb * dens.x) * tt;
    sumM += weight * (crep_atmosphere.mieScattering.rgb * dens.y) * tt;
#if CREP_ATMOSPHERE_MS_LUT
    vec3 sigmaS = crep_atmosphere.rayleighScattering.rgb * dens.x + crep_atmosphere.mieScattering.rgb * dens.y;
    sumH += weight * cameraT * sigmaS *
            crep_multipleScatteringLut(crep_msLut, crep_atmosphere, q.h, q.cosSunZenith);
#endif
  }
  imageStore(crep_output, p, vec4(sumR * dt, sumM.r * dt));
#if !CREP_ATMOSPHERE_COMBINED_MIE
  imageStore(crep_outputMie, p, vec4(sumM * dt, 0.0));
#endif
#if CREP_ATMOSPHERE_MS_LUT
  imageStore(crep_outputHigher, p, vec4(sumH * dt, 0.0));
#endif
}
