#version 450 core
// Froxel apply (Wronski 2014, "Applying effect": one 3D lookup per pixel; crep::froxelApply, rule 4 of
// crep/postfx/froxel_fog.h): the pixel's view depth Z from the camera depth (at the image border, outside
// the outermost sample columns, the depth on that column's ray at the pixel's distance), uvw = (pixel
// centre, slice coordinate of Z) shifted by the volume's sample offset, one trilinear fetch (clamp to edge, so beyond the
// last sample the last value); in front of slice 0's sample (view depth Z_0) the value there blended with
// the camera's (RGB 0, A 1) by Z / Z_0. Output RGBA: RGB in-scattered radiance, A the volume's grey
// transmittance. A NaN camera depth is the sky (crep_cameraViewDepth).
// Resources: params block (binding 0), camera depth (unit 0, texelFetch), integrated volume (unit 1,
// linear sampler, clamp to edge), output RGBA32F (image 0).
#include "crep/bindings.h"
#include "crep/common.glsl"
#include "crep/froxel.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = CREP_FROXEL_PARAMS_BINDING) uniform CrepFroxelBlock { CrepFroxelParams crep_froxel; };
layout(binding = CREP_FROXEL_CAMERA_DEPTH_UNIT) uniform sampler2D cameraDepth;
layout(binding = CREP_FROXEL_INTEGRATED_UNIT) uniform sampler3D integrated;
layout(binding = CREP_FROXEL_SCATTERING_OUT_IMAGE, rgba32f) uniform writeonly image2D scatteringOut;

void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 image = crep_froxel.sizes.xy;
  if (any(greaterThanEqual(pixel, image))) return;
  vec3 size = vec3(crep_froxel.grid.xyz);
  float Z = crep_cameraViewDepth(texelFetch(cameraDepth, pixel, 0).r, crep_froxel.cameraDepth);
  vec2 uv = (vec2(pixel) + 0.5) / vec2(image);
  // At the image border the fetch reads the outermost column (clamp to edge): take the depth on that
  // column's ray at the pixel's own distance.
  vec2 offset = crep_froxel.jitter.xy / size.xy;
  vec2 column = clamp(uv - offset, 0.5 / size.xy, 1.0 - 0.5 / size.xy) + offset;
  if (column != uv) {
    vec3 fwd = crep_froxel.camera.forward.xyz;
    Z *= dot(crep_froxelRay(crep_froxel.camera, column), fwd) / dot(crep_froxelRay(crep_froxel.camera, uv), fwd);
  }
  vec3 tex = vec3(uv, crep_froxelSliceCoord(crep_froxel.range.xy, Z)) - crep_froxel.jitter.xyz / size;
  float firstTex = 0.5 / size.z;
  vec4 value;
  if (tex.z < firstTex) {
    float Z0 = crep_froxelViewDepth(crep_froxel.range.xy, (0.5 + crep_froxel.jitter.z) / size.z);
    float f = Z / Z0;
    value = f * textureLod(integrated, vec3(tex.xy, firstTex), 0.0) + (1.0 - f) * vec4(0.0, 0.0, 0.0, 1.0);
  } else {
    value = textureLod(integrated, tex, 0.0);
  }
  imageStore(scatteringOut, pixel, value);
}
