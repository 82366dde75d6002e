#version 450 core
// Froxel temporal reprojection (Wronski 2014, "Temporal reprojection", "Sample jittering";
// crep::froxelTemporal, rule 5 of crep/postfx/froxel_fog.h), one thread per cell: the unjittered centre's
// world point found in last frame's volume (crep_froxelCoord with the previous camera), the history fetched
// there trilinearly, rejected outside [0, 1]^3 or when not finite, clamped to the min / max of the finite
// current values of the 3 x 3 x 3 neighbourhood, and blended: c + weight (history - c). A non-finite current
// value is replaced by the mean of its finite neighbours (0 when none), so neither a NaN current nor a NaN
// history value ever reaches the output.
// Resources: params block (binding 0), current integrated volume (unit 0, texelFetch), history (unit 1,
// linear sampler, clamp to edge), output (image 0, CREP_FROXEL_FORMAT).
#include "crep/bindings.h"
#include "crep/froxel.glsl"

#ifndef CREP_FROXEL_FORMAT
#define CREP_FROXEL_FORMAT rgba16f
#endif

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

layout(std140, binding = CREP_FROXEL_PARAMS_BINDING) uniform CrepFroxelBlock { CrepFroxelParams crep_froxel; };
layout(binding = CREP_FROXEL_CURRENT_UNIT) uniform sampler3D current;
layout(binding = CREP_FROXEL_HISTORY_UNIT) uniform sampler3D history;
layout(binding = CREP_FROXEL_BLENDED_OUT_IMAGE, CREP_FROXEL_FORMAT) uniform writeonly image3D blendedOut;

bool crep_finite(vec4 v) { return !any(isnan(v)) && !any(isinf(v)); }

void main() {
  ivec3 cell = ivec3(gl_GlobalInvocationID);
  ivec3 size = crep_froxel.grid.xyz;
  if (any(greaterThanEqual(cell, size))) return;
  vec4 lo = vec4(3.0e38), hi = vec4(-3.0e38), sum = vec4(0.0);
  int n = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        ivec3 q = cell + ivec3(dx, dy, dz);
        if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, size))) continue;
        vec4 c = texelFetch(current, q, 0);
        if (!crep_finite(c)) continue;
        lo = min(lo, c);
        hi = max(hi, c);
        sum += c;
        ++n;
      }
  vec4 c = texelFetch(current, cell, 0);
  if (!crep_finite(c)) c = n > 0 ? sum / float(n) : vec4(0.0);
  vec4 result = c;
  float weight = crep_froxel.jitter.w;
  if (crep_froxel.grid.w == 1 && weight > 0.0 && n > 0) {
    vec3 centre = (vec3(cell) + 0.5) / vec3(size);
    vec3 p = crep_froxelWorldPoint(crep_froxel.camera, crep_froxel.range.xy, centre);
    vec3 prev = crep_froxelCoord(crep_froxel.previous, crep_froxel.range.zw, p);
    if (all(greaterThanEqual(prev, vec3(0.0))) && all(lessThanEqual(prev, vec3(1.0)))) {
      vec4 h = textureLod(history, prev, 0.0);
      if (crep_finite(h)) result = c + weight * (clamp(h, lo, hi) - c);
    }
  }
  imageStore(blendedOut, cell, result);
}
