#version 450 core
// ToneMapPass, the tone-mapping pass (crep/postfx/gpu_tone_mapping.h; rule and CPU reference in
// crep/postfx/tone_mapping.h, crep::toneMapColor): HDR input -> linear display RGB in [0, 1] (or its sRGB
// encoding with CREP_TONE_MAP_SRGB), alpha 1. The exposure is the state buffer's (auto exposure) or the
// block's manual one. Variants: CREP_TONE_MAP_OPERATOR (compile-time constant: the operator's branch is
// all that remains), CREP_TONE_MAP_FORMAT (the output image's format qualifier, rgba8 or rgba32f).
#include "crep/bindings.h"
#include "crep/tone_mapping.glsl"

#ifndef CREP_TONE_MAP_OPERATOR
#define CREP_TONE_MAP_OPERATOR CREP_TONE_MAP_UNCHARTED2
#endif
#ifndef CREP_TONE_MAP_FORMAT
#define CREP_TONE_MAP_FORMAT rgba32f
#endif
#ifndef CREP_TONE_MAP_SRGB
#define CREP_TONE_MAP_SRGB 0
#endif

layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = CREP_TONE_MAP_PARAMS_BINDING) uniform CrepToneMapBlock { CrepToneMapParams crep_toneMap; };
layout(std430, binding = CREP_TONE_MAP_STATE_BINDING) restrict readonly buffer CrepToneMapStateBlock { CrepToneMapState crep_state; };
layout(binding = CREP_TONE_MAP_HDR_UNIT) uniform sampler2D crep_hdr;
layout(binding = CREP_TONE_MAP_DISPLAY_IMAGE, CREP_TONE_MAP_FORMAT) uniform restrict writeonly image2D crep_display;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, crep_toneMap.sizes.xy))) return;
  float scale = crep_toneMap.flags.x != 0 ? crep_state.exposureScale : crep_toneMap.curve.w;
  vec3 rgb = crep_toneMapColor(texelFetch(crep_hdr, p, 0).rgb, scale, CREP_TONE_MAP_OPERATOR,
                               crep_toneMap.curve.y, crep_toneMap.curve.z);
#if CREP_TONE_MAP_SRGB
  rgb = crep_srgbEncode(rgb);
#endif
  imageStore(crep_display, p, vec4(rgb, 1.0));
}
