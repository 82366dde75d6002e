#version 450 core
// The colour map of a rectified map for a light texture (crep::lightColorMap, crep/scatter/light_texture.h;
// Klehm et al. 2014, Sec. 3.2 coloured light textures): texel (i, j) gets the texture's colour at its light
// ray, the ray of map position ((i + 0.5) / W, (j + 0.5) / H), sampled at its point origin + direction.
// Layouts (crep/layout.glsl, CREP_LAYOUT): the projective one, for the sun (crep_layoutLightRay) or a
// local light (the ray from the light through the frame point of the column and row, crep::Rectification::
// lightRay: axisX + y axisY + (zeta / rho) axisZ), and the epipolar one (the sun). Texels without a light
// ray (beyond the far end of a directional map: zeta <= 0) get 0. Output: RGBA32F (A = 1).
// Driven by crep::LightColorMapPass.
#include "crep/bindings.h"
#include "crep/layout.glsl"
#include "crep/light_texture.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = CREP_LIGHT_COLORS_LIGHT_TEXTURE_UNIT) uniform sampler2D crep_lightTexture;
layout(binding = CREP_LIGHT_COLORS_COLORS_OUT_IMAGE, rgba32f) uniform writeonly restrict image2D crep_colorsOut;
layout(std140, binding = CREP_LIGHT_COLORS_LIGHT_TEXTURE_BINDING) uniform CrepLightTextureBlock { CrepLightTextureParams crep_lightTextureParams; };

void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = crep_lightTextureParams.size.zw;
  if (any(greaterThanEqual(texel, size))) return;
  float column = (float(texel.x) + 0.5) / float(size.x), row = (float(texel.y) + 0.5) / float(size.y);
  vec3 color = vec3(0.0);
#if CREP_LAYOUT == CREP_LAYOUT_PROJECTIVE
  float zeta = crep_projectiveZeta(column);
  if (crep_lightTextureParams.lightPosition.w > 0.5) {
    vec4 s = crep_projective.slopes;
    float y = s.x + row * (s.y - s.x);
    vec3 dir = normalize(crep_projective.axisX.xyz + y * crep_projective.axisY.xyz +
                         (zeta / crep_projective.origin.w) * crep_projective.axisZ.xyz);
    color = crep_lightTextureColor(crep_lightTexture, crep_lightTextureParams,
                                   crep_lightTextureParams.lightPosition.xyz + dir);
  } else if (zeta > 0.0) {
    CrepLightRay ray = crep_layoutLightRay(column, row);
    color = crep_lightTextureColor(crep_lightTexture, crep_lightTextureParams, ray.origin + ray.direction);
  }
#else
  CrepLightRay ray = crep_layoutLightRay(column, row);
  color = crep_lightTextureColor(crep_lightTexture, crep_lightTextureParams, ray.origin + ray.direction);
#endif
  imageStore(crep_colorsOut, texel, vec4(color, 1.0));
}
