#version 450 core
// AtmosphereTablesPass, single scattering stage (Yusov 2013, Listing 3 without the phase functions;
// crep/postfx/atmosphere.h's contract): each texel of the 4D table (packed 3D: x h, y alpha, z theta * N_phi
// + phi) integrates S_R = beta_R d_R T(C -> P) T(P -> sun) and S_M = beta_M d_M T(C -> P) T(P -> sun) (the
// single table: RGB S_R, A S_M's red; the single Mie table, unless CREP_ATMOSPHERE_COMBINED_MIE: RGB S_M)
// by the trapezoid rule with CREP_ATMOSPHERE_STEPS
// steps from its point C to the ground (lower alpha half) or the top of the atmosphere (upper half); the
// camera's density integral is accumulated by the trapezoid rule over the steps so far (Listing 5's way),
// the sun's transmittance comes from the optical depth table.
#include "crep/atmosphere.glsl"

#ifndef CREP_ATMOSPHERE_STEPS
#define CREP_ATMOSPHERE_STEPS 100
#endif

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(std140, binding = 0) uniform CrepAtmosphereBlock { CrepAtmosphereParams crep_atmosphere; };
layout(binding = 0) uniform sampler2D crep_opticalDepth;
layout(binding = 0, rgba32f) uniform restrict writeonly image3D crep_output;
#if !CREP_ATMOSPHERE_COMBINED_MIE
layout(binding = 1, rgba32f) uniform restrict writeonly image3D crep_outputMie;
#endif

void main() {
  ivec3 p = ivec3(gl_GlobalInvocationID);
  ivec4 n = crep_atmosphere.tableSize;
  if (any(greaterThanEqual(p, ivec3(n.x, n.y, n.z * n.w)))) return;
  CrepAtmosphereTexelRay ray = crep_atmosphereTexelRay(crep_atmosphere, ivec4(p.xy, p.z % n.z, p.z / n.z));
  float dt = ray.end / float(CREP_ATMOSPHERE_STEPS);
  vec2 camera = vec2(0.0);
  vec2 previousDensity = vec2(0.0);
  vec3 sumR = vec3(0.0), sumM = vec3(0.0);
  for (int k = 0; k <= CREP_ATMOSPHERE_STEPS; ++k) {
    CrepAtmosphereRayPoint q = crep_atmosphereRayPoint(crep_atmosphere, ray, dt * float(k));
    vec2 dens = crep_atmosphereDensity(crep_atmosphere, q.h);
    if (k > 0) camera += 0.5 * (previousDensity + dens) * dt;
    previousDensity = dens;
    vec3 cameraT = exp(-crep_atmosphereExtinction(crep_atmosphere, camera));
    vec2 toSun = crep_densityToTop(crep_opticalDepth, crep_atmosphere, q.h, q.cosSunZenith);
    vec3 sunT = exp(-crep_atmosphereExtinction(crep_atmosphere, toSun));
    vec3 tt = cameraT * sunT;
    float weight = (k == 0 || k == CREP_ATMOSPHERE_STEPS) ? 0.5 : 1.0;
    sumR += weight * (crep_atmosphere.rayleighScattering.rgb * dens.x) * tt;
    sumM += weight * (crep_atmosphere.mieScattering.rgb * dens.y) * tt;
  }
  imageStore(crep_output, p, vec4(sumR * dt, sumM.r * dt));
#if !CREP_ATMOSPHERE_COMBINED_MIE
  imageStore(crep_outputMie, p, vec4(sumM * dt, 0.0));
#endif
}
