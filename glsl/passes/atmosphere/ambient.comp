#version 450 core
// AtmosphereTablesPass, ambient sky light stage (Yusov 2013, Eq. 3 and Listing 6): texel i of N holds
// E_sky at c_phi = -1 + 2 i / (N - 1) for a point 20 m above the ground: the sum over the
// CREP_ATMOSPHERE_SAMPLES (kAmbientSampleFactor * sphereSamples) Fibonacci directions (lower ones mirrored) of
// L_M(C, w, l) (w . zenith), times 2 pi / samples; L_M = L1 (the phase-free single tables with their phase
// functions at w . l) + L_H.
#include "crep/bindings.h"
#include "crep/atmosphere.glsl"

#ifndef CREP_ATMOSPHERE_SAMPLES
#define CREP_ATMOSPHERE_SAMPLES 128
#endif

layout(local_size_x = 64) in;

layout(std140, binding = CREP_ATMOSPHERE_TABLES_PARAMS_BINDING) uniform CrepAtmosphereBlock { CrepAtmosphereParams crep_atmosphere; };
layout(binding = CREP_ATMOSPHERE_TABLES_AMBIENT_SINGLE_UNIT) uniform sampler3D crep_single;
layout(binding = CREP_ATMOSPHERE_TABLES_AMBIENT_SINGLE_MIE_UNIT) uniform sampler3D crep_singleMie;
layout(binding = CREP_ATMOSPHERE_TABLES_AMBIENT_HIGHER_ORDERS_UNIT) uniform sampler3D crep_higherOrders;
layout(binding = CREP_ATMOSPHERE_TABLES_AMBIENT_OUTPUT_IMAGE, rgba32f) uniform restrict writeonly image2D crep_ambient;

void main() {
  int i = int(gl_GlobalInvocationID.x);
  int n = crep_atmosphere.auxSizes.z;
  if (i >= n) return;
  float c = -1.0 + 2.0 * float(i) / float(n - 1);
  vec3 sun = vec3(sqrt(max(0.0, 1.0 - c * c)), c, 0.0);
  const float h = 20.0;
  vec3 sum = vec3(0.0);
  for (int k = 0; k < CREP_ATMOSPHERE_SAMPLES; ++k) {
    vec3 w = crep_fibonacciSphereDirection(k, CREP_ATMOSPHERE_SAMPLES);
    w.y = abs(w.y);
    float wl = dot(w, sun);
    vec4 coords = crep_atmosphereTableCoords(crep_atmosphere, h, w.y, c, wl, vec4(-1.0));
    vec3 multiple = crep_sampleSingleScattering(crep_single, crep_singleMie, crep_atmosphere, coords, wl) +
                    crep_sampleAtmosphereTable(crep_higherOrders, crep_atmosphere, coords);
    sum += multiple * w.y;
  }
  imageStore(crep_ambient, ivec2(i, 0), vec4(sum * float(CREP_TWO_PI / float(CREP_ATMOSPHERE_SAMPLES)), 0.0));
}
