#version 450 core
// AtmosphereTablesPass, J_n stage (Yusov 2013, Eq. 1, n >= 2): each texel of the 4D table sums over the
// CREP_ATMOSPHERE_SAMPLES directions w of the Fibonacci sphere (beta_R d_R(h) p_R(w . v) + beta_M d_M(h)
// p_HG(w . v)) L_(n-1)(C, w, l) times 4 pi / samples, L_(n-1) looked up (Listing 1) at the texel's point with
// fresh coordinates. CREP_ATMOSPHERE_FIRST_ORDER 1 (n = 2): L1 from the phase-free single tables with its
// phase functions at w . l (crep_sampleSingleScattering), plus the ground's first bounce of the sunlight for
// the directions that hit the ground (crep::precomputeAtmosphere's groundBounce; optical depth at unit 2).
#include "crep/bindings.h"
#include "crep/atmosphere.glsl"

#ifndef CREP_ATMOSPHERE_SAMPLES
#define CREP_ATMOSPHERE_SAMPLES 128
#endif

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(std140, binding = CREP_ATMOSPHERE_TABLES_PARAMS_BINDING) uniform CrepAtmosphereBlock { CrepAtmosphereParams crep_atmosphere; };
#ifndef CREP_ATMOSPHERE_FIRST_ORDER
#define CREP_ATMOSPHERE_FIRST_ORDER 0
#endif
layout(binding = CREP_ATMOSPHERE_TABLES_SCATTERED_PREVIOUS_ORDER_UNIT) uniform sampler3D crep_previousOrder; // n = 2: the single table
#if CREP_ATMOSPHERE_FIRST_ORDER
layout(binding = CREP_ATMOSPHERE_TABLES_SCATTERED_SINGLE_MIE_UNIT) uniform sampler3D crep_singleMie;
layout(binding = CREP_ATMOSPHERE_TABLES_SCATTERED_OPTICAL_DEPTH_UNIT) uniform sampler2D crep_opticalDepth;

// T(C->g) (albedo / pi) T_sun(g) max(0, n_g . l) for a direction w from altitude h that hits the ground at g.
vec3 groundBounce(float h, vec3 w, vec3 sun, float wl) {
  float albedo = crep_atmosphere.multipleScattering.x;
  if (!(albedo > 0.0) || !(w.y < 0.0)) return vec3(0.0);
  float R = crep_atmosphere.radii.x, r0 = R + h, hh = h * (2.0 * R + h), b = r0 * w.y;
  float disc = b * b - hh;
  if (disc < 0.0) return vec3(0.0);
  float t = crep_atmosphereGroundDistance(hh, b, disc);
  float mu = (b + t) / R, cosSun = (r0 * sun.y + t * wl) / R;
  if (!(cosSun > 0.0)) return vec3(0.0);
  vec2 D = max(crep_densityToTop(crep_opticalDepth, crep_atmosphere, 0.0, -mu) -
                   crep_densityToTop(crep_opticalDepth, crep_atmosphere, h, -w.y),
               vec2(0.0));
  return exp(-crep_atmosphereExtinction(crep_atmosphere, D)) *
         crep_sunTransmittanceAt(crep_opticalDepth, crep_atmosphere, 0.0, cosSun) *
         (cosSun * albedo * float(CREP_INV_PI));
}
#endif
layout(binding = CREP_ATMOSPHERE_TABLES_SCATTERED_OUTPUT_IMAGE, rgba32f) uniform restrict writeonly image3D crep_output;

void main() {
  ivec3 p = ivec3(gl_GlobalInvocationID);
  ivec4 n = crep_atmosphere.tableSize;
  if (any(greaterThanEqual(p, ivec3(n.x, n.y, n.z * n.w)))) return;
  CrepAtmosphereTexelRay ray = crep_atmosphereTexelRay(crep_atmosphere, ivec4(p.xy, p.z % n.z, p.z / n.z));
  vec2 dens = crep_atmosphereDensity(crep_atmosphere, ray.h);
  vec3 sum = vec3(0.0);
  for (int i = 0; i < CREP_ATMOSPHERE_SAMPLES; ++i) {
    vec3 w = crep_fibonacciSphereDirection(i, CREP_ATMOSPHERE_SAMPLES);
    float wl = dot(w, ray.sun);
    vec4 coords = crep_atmosphereTableCoords(crep_atmosphere, ray.h, w.y, ray.sun.y, wl, vec4(-1.0));
#if CREP_ATMOSPHERE_FIRST_ORDER
    vec3 radiance = crep_sampleSingleScattering(crep_previousOrder, crep_singleMie, crep_atmosphere, coords, wl) +
                    groundBounce(ray.h, w, ray.sun, wl);
#else
    vec3 radiance = crep_sampleAtmosphereTable(crep_previousOrder, crep_atmosphere, coords);
#endif
    sum += crep_atmosphereScattering(crep_atmosphere, dens, dot(w, ray.view)) * radiance;
  }
  imageStore(crep_output, p, vec4(sum * float(CREP_FOUR_PI / float(CREP_ATMOSPHERE_SAMPLES)), 0.0));
}
