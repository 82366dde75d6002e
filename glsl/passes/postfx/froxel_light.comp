#version 450 core
// Froxel lighting (Wronski 2014, "Density estimation and volume lighting"; crep::froxelLighting, rule 2 of
// crep/postfx/froxel_fog.h), one thread per cell: at the cell's (jittered) sample point, the density rho
// (height fog, value noise), the sun's in-scattering sigma_s phase E times the ESM visibility plus the
// isotropic ambient L_amb sigma_s, all times rho; A = rho sbar. Non-finite values are stored as 0.
// Resources: params block (binding 0), ESM (unit 0, texelFetch: the bilinear weights are computed here in
// full float precision, where a GPU's texture unit would round them to 8 bits), output volume (image 0,
// CREP_FROXEL_FORMAT).
#include "crep/bindings.h"
#include "crep/common.glsl"
#include "crep/froxel.glsl"
#include "crep/phase.glsl"

#ifndef CREP_FROXEL_FORMAT
#define CREP_FROXEL_FORMAT rgba16f
#endif

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(std140, binding = CREP_FROXEL_PARAMS_BINDING) uniform CrepFroxelBlock { CrepFroxelParams crep_froxel; };
layout(binding = CREP_FROXEL_ESM_UNIT) uniform sampler2D esm;
layout(binding = CREP_FROXEL_LIGHTING_OUT_IMAGE, CREP_FROXEL_FORMAT) uniform writeonly image3D lightingOut;

// crep::esmVisibility: clamp(exp(c (z + bias - d_r)), 0, 1) with z the bilinear mean of exp(c z_i) taken
// in log space around the largest texel; lit outside the map.
float crep_esmVisibility(vec3 p) {
  vec4 q = crep_froxel.lightClipFromWorld * vec4(p, 1.0);
  if (!(q.w > 0.0)) return 1.0;
  vec3 uvd = q.xyz / q.w * 0.5 + 0.5;
  if (!(uvd.x >= 0.0 && uvd.x <= 1.0 && uvd.y >= 0.0 && uvd.y <= 1.0)) return 1.0;
  ivec2 size = crep_froxel.sizes.zw;
  vec2 f = uvd.xy * vec2(size) - 0.5;
  vec2 f0 = floor(f), a = f - f0;
  ivec2 i0 = ivec2(f0);
  vec4 z = vec4(texelFetch(esm, clamp(i0, ivec2(0), size - 1), 0).r,
                texelFetch(esm, clamp(i0 + ivec2(1, 0), ivec2(0), size - 1), 0).r,
                texelFetch(esm, clamp(i0 + ivec2(0, 1), ivec2(0), size - 1), 0).r,
                texelFetch(esm, clamp(i0 + ivec2(1, 1), ivec2(0), size - 1), 0).r);
  vec4 w = vec4((1.0 - a.x) * (1.0 - a.y), a.x * (1.0 - a.y), (1.0 - a.x) * a.y, a.x * a.y);
  float m = -3.0e38;
  for (int i = 0; i < 4; ++i)
    if (w[i] > 0.0) m = max(m, z[i]);
  float c = crep_froxel.esm.x;
  float occluder = m + log(dot(w, exp(c * min(z - m, vec4(0.0))))) / c; // zero-weight texels may exceed m
  float receiver = clamp(uvd.z, 0.0, 1.0);
  return clamp(exp(c * (occluder + crep_froxel.esm.y - receiver)), 0.0, 1.0);
}

// crep::froxelDensity: exponential height fog times value noise.
float crep_froxelDensity(vec3 p) {
  vec4 d = crep_froxel.density;
  float rho = 1.0;
  if (d.y > 0.0) rho *= exp(clamp(-(p.y - d.x) / d.y, -60.0, 20.0));
  if (d.z > 0.0) rho *= 1.0 + d.z * (2.0 * crep_froxelValueNoise(d.w * (p + crep_froxel.noiseOffset.xyz)) - 1.0);
  return rho;
}

void main() {
  ivec3 cell = ivec3(gl_GlobalInvocationID);
  ivec3 size = crep_froxel.grid.xyz;
  if (any(greaterThanEqual(cell, size))) return;
  vec3 uvw = (vec3(cell) + 0.5 + crep_froxel.jitter.xyz) / vec3(size);
  vec3 p = crep_froxelWorldPoint(crep_froxel.camera, crep_froxel.range.xy, uvw);
  vec3 v = crep_froxelRay(crep_froxel.camera, uvw.xy);
  float cosTheta = dot(crep_froxel.lightDirection.xyz, -v);
  vec3 sigmaPhase = crep_froxel.mieScattering.rgb * crep_henyeyGreenstein(crep_froxel.mieScattering.w, cosTheta) +
                    crep_froxel.rayleighScattering.rgb * crep_rayleighPhase(cosTheta);
  vec3 sigmaS = crep_froxel.mieScattering.rgb + crep_froxel.rayleighScattering.rgb;
  float vis = crep_froxel.esm.z > 0.5 ? crep_esmVisibility(p) : 1.0;
  float rho = crep_froxelDensity(p);
  vec4 value = vec4(rho * (crep_froxel.lightIrradiance.rgb * sigmaPhase * vis + crep_froxel.ambient.rgb * sigmaS),
                    rho * crep_froxel.extinction.w);
  if (any(isnan(value)) || any(isinf(value))) value = vec4(0.0);
  imageStore(lightingOut, cell, value);
}
