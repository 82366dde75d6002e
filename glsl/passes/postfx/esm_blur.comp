#version 450 core
// Exponential shadow map, step 2 (Wronski 2014: a separable box filter in two passes; crep::buildEsm, rule
// 1 of crep/postfx/froxel_fog.h): the mean of the 2r + 1 texels along `crep_direction` (0: x, 1: y),
// clamped to the edge, of exp(c z) of the stored log-space depths z, evaluated in log space around the
// window's largest z.
// Resources: params block (binding 0), input ESM (unit 0, texelFetch), output R32F (image 0).
#include "crep/bindings.h"
#include "crep/froxel.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = CREP_ESM_FROXEL_BINDING) uniform CrepFroxelBlock { CrepFroxelParams crep_froxel; };
// Vulkan (and so HLSL root constants, an MSL buffer): push constants; GL: uniform locations.
#ifdef VULKAN
layout(push_constant) uniform CrepEsmBlurPush { int crep_direction; };
#else
layout(location = 0) uniform int crep_direction;
#endif
layout(binding = CREP_ESM_IN_UNIT) uniform sampler2D esmIn;
layout(binding = CREP_ESM_OUT_IMAGE, r32f) uniform writeonly image2D esmOut;

void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = crep_froxel.sizes.zw;
  if (any(greaterThanEqual(texel, size))) return;
  int r = crep_froxel.info.y;
  ivec2 axis = crep_direction == 0 ? ivec2(1, 0) : ivec2(0, 1);
  float c = crep_froxel.esm.x;
  float m = -3.0e38;
  for (int k = -r; k <= r; ++k)
    m = max(m, texelFetch(esmIn, clamp(texel + k * axis, ivec2(0), size - 1), 0).r);
  float sum = 0.0;
  for (int k = -r; k <= r; ++k)
    sum += exp(c * (texelFetch(esmIn, clamp(texel + k * axis, ivec2(0), size - 1), 0).r - m));
  imageStore(esmOut, texel, vec4(m + log(sum / float(2 * r + 1)) / c));
}
