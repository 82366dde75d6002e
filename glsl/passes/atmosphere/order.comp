#version 450 core
// AtmosphereTablesPass, L_n stage (Yusov 2013, Eq. 2 and Listing 5, n >= 2): each texel integrates
// T(C -> P) J_n(P, v, l) by the trapezoid rule with CREP_ATMOSPHERE_STEPS steps along its ray (ending as in
// the single scattering stage); the camera's density integral is accumulated by the trapezoid rule, the
// look-ups into J_n keep the texel's side of the horizon (Listing 2); the first one (at C) is at the texel's
// own coordinates.
#include "crep/bindings.h"
#include "crep/atmosphere.glsl"

#ifndef CREP_ATMOSPHERE_STEPS
#define CREP_ATMOSPHERE_STEPS 64
#endif

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(std140, binding = CREP_ATMOSPHERE_TABLES_PARAMS_BINDING) uniform CrepAtmosphereBlock { CrepAtmosphereParams crep_atmosphere; };
layout(binding = CREP_ATMOSPHERE_TABLES_ORDER_SCATTERED_UNIT) uniform sampler3D crep_scattered;
layout(binding = CREP_ATMOSPHERE_TABLES_ORDER_OUTPUT_IMAGE, rgba32f) uniform restrict writeonly image3D crep_output;

void main() {
  ivec3 p = ivec3(gl_GlobalInvocationID);
  ivec4 n = crep_atmosphere.tableSize;
  if (any(greaterThanEqual(p, ivec3(n.x, n.y, n.z * n.w)))) return;
  CrepAtmosphereTexelRay ray = crep_atmosphereTexelRay(crep_atmosphere, ivec4(p.xy, p.z % n.z, p.z / n.z));
  float dt = ray.end / float(CREP_ATMOSPHERE_STEPS);
  vec2 camera = vec2(0.0);
  vec2 previousDensity = vec2(0.0);
  vec3 sum = vec3(0.0);
  for (int k = 0; k <= CREP_ATMOSPHERE_STEPS; ++k) {
    CrepAtmosphereRayPoint q = crep_atmosphereRayPoint(crep_atmosphere, ray, dt * float(k));
    vec2 dens = crep_atmosphereDensity(crep_atmosphere, q.h);
    if (k > 0) camera += 0.5 * (previousDensity + dens) * dt;
    previousDensity = dens;
    vec3 cameraT = exp(-crep_atmosphereExtinction(crep_atmosphere, camera));
    // The first sample (at C) reads J_n at the texel's own coordinates.
    vec3 f = cameraT * crep_sampleAtmosphereTable(crep_scattered, crep_atmosphere, k == 0 ? ray.coords : q.coords);
    sum += (k == 0 || k == CREP_ATMOSPHERE_STEPS) ? 0.5 * f : f;
  }
  imageStore(crep_output, p, vec4(sum * dt, 0.0));
}
