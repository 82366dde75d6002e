#version 450 core
// AtmosphereTablesPass, optical depth stage (crep/atmosphere/gpu_tables.h; CPU reference
// crep::precomputeAtmosphere): texel (i, j) of the opticalDepthHeight x opticalDepthZenith table holds the
// (Rayleigh, Mie) density integrals from altitude h = H_Atm (i / (W - 1))^2 along cos zenith
// c = -1 + 2 j / (H - 1) to the top of the atmosphere (Yusov 2013's net density table), by the trapezoid
// rule with CREP_ATMOSPHERE_STEPS steps, or kOccludedDensity in both channels when the ray hits the ground.
#include "crep/bindings.h"
#include "crep/atmosphere.glsl"

#ifndef CREP_ATMOSPHERE_STEPS
#define CREP_ATMOSPHERE_STEPS 256
#endif

layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = CREP_ATMOSPHERE_TABLES_PARAMS_BINDING) uniform CrepAtmosphereBlock { CrepAtmosphereParams crep_atmosphere; };
layout(binding = CREP_ATMOSPHERE_TABLES_OPTICAL_DEPTH_OUTPUT_IMAGE, rg32f) uniform restrict writeonly image2D crep_opticalDepth;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = crep_atmosphere.auxSizes.xy;
  if (any(greaterThanEqual(p, size))) return;
  float R = crep_atmosphere.radii.x;
  float H = crep_atmosphere.radii.z;
  float u = float(p.x) / float(size.x - 1);
  float h = H * u * u;
  float c = -1.0 + 2.0 * float(p.y) / float(size.y - 1);
  if (crep_atmosphereHitsGround(crep_atmosphere, h, c)) {
    imageStore(crep_opticalDepth, p, vec4(vec2(crep_atmosphere.radii.w), 0.0, 0.0));
    return;
  }
  // Far root of |C + t v| = R + H_Atm without cancellation.
  float r0 = R + h;
  float b = r0 * c;
  float cc = (H - h) * (2.0 * R + H + h);
  float d = sqrt(b * b + cc);
  float len = max(b >= 0.0 ? cc / (b + d) : d - b, 0.0);
  float dt = len / float(CREP_ATMOSPHERE_STEPS);
  float hh = h * (2.0 * R + h);
  vec2 sum = vec2(0.0);
  for (int k = 0; k <= CREP_ATMOSPHERE_STEPS; ++k) {
    float t = dt * float(k);
    float rr = hh + t * (2.0 * b + t); // |P|^2 - R^2
    float alt = rr / (sqrt(R * R + rr) + R);
    vec2 dens = crep_atmosphereDensity(crep_atmosphere, alt);
    sum += (k == 0 || k == CREP_ATMOSPHERE_STEPS) ? 0.5 * dens : dens;
  }
  imageStore(crep_opticalDepth, p, vec4(sum * dt, 0.0, 0.0));
}
