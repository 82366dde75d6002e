#version 450 core
// Froxel accumulation (Wronski 2014, "Solving scattering equation": a front-to-back scan of every column;
// crep::froxelAccumulate, rule 3 of crep/postfx/froxel_fog.h), one thread per (x, y) column, in place: the
// lighting volume (RGB in-scattering per world unit, A grey extinction) becomes the integrated volume (RGB
// in-scattered radiance from the camera to the sample point, A grey transmittance). The integrand is
// piecewise constant (cell 0 on [0, t_0], the two cells' values on either half of [t_{z-1}, t_z]); each
// piece is integrated exactly with per-channel extinction (A (sigma_c / sbar)). Each thread reads slice z
// before writing it and keeps slice z - 1 in registers, so the in-place update needs no barrier; the
// threads of a workgroup walk neighbouring columns in lock step, so every step of the loop reads and
// writes one contiguous 8 x 8 tile of a slice (coalesced on a GPU).
// Resources: params block (binding 0), the volume (image 0, CREP_FROXEL_FORMAT, read and written).
#include "crep/bindings.h"
#include "crep/froxel.glsl"
#include "crep/ray.glsl"

#ifndef CREP_FROXEL_FORMAT
#define CREP_FROXEL_FORMAT rgba16f
#endif

layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = CREP_FROXEL_PARAMS_BINDING) uniform CrepFroxelBlock { CrepFroxelParams crep_froxel; };
layout(binding = CREP_FROXEL_VOLUME_IMAGE, CREP_FROXEL_FORMAT) uniform restrict image3D volume;

vec3 crep_L;
float crep_tau;

// Adds the piece [ta, tb] of a cell with value `cell` (rule 3).
void crep_piece(vec4 cell, vec3 k, float ta, float tb) {
  float len = tb - ta;
  if (!(len > 0.0)) return;
  crep_L += exp(-k * crep_tau) * cell.rgb * crep_transmittanceIntegral(k * cell.a, 0.0, len);
  crep_tau += cell.a * len;
}

void main() {
  ivec2 column = ivec2(gl_GlobalInvocationID.xy);
  ivec3 size = crep_froxel.grid.xyz;
  if (any(greaterThanEqual(column, size.xy))) return;
  vec3 k = crep_froxel.extinction.rgb / crep_froxel.extinction.w;
  vec2 uv = (vec2(column) + 0.5 + crep_froxel.jitter.xy) / vec2(size.xy);
  vec3 ray = crep_froxelRay(crep_froxel.camera, uv);
  float cosForward = dot(ray, crep_froxel.camera.forward.xyz);
  crep_L = vec3(0.0);
  crep_tau = 0.0;
  vec4 previous = vec4(0.0);
  float tPrevious = 0.0;
  for (int z = 0; z < size.z; ++z) {
    vec4 cell = imageLoad(volume, ivec3(column, z));
    float w = (float(z) + 0.5 + crep_froxel.jitter.z) / float(size.z);
    float t = crep_froxelViewDepth(crep_froxel.range.xy, w) / cosForward;
    if (z == 0) {
      crep_piece(cell, k, 0.0, t);
    } else {
      float mid = 0.5 * (tPrevious + t);
      crep_piece(previous, k, tPrevious, mid);
      crep_piece(cell, k, mid, t);
    }
    imageStore(volume, ivec3(column, z), vec4(crep_L, exp(-crep_tau)));
    previous = cell;
    tPrevious = t;
  }
}
