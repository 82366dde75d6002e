#version 450 core
// Copies a texture to the render target texel for texel (the viewport must have the source's size),
// optionally sRGB-encoding it (CREP_COPY_SRGB = 1). Draw with passes/fullscreen.vert.
#include "crep/common.glsl"

#ifndef CREP_COPY_SRGB
#define CREP_COPY_SRGB 0
#endif

layout(binding = 0) uniform sampler2D source;
layout(location = 0) out vec4 outColor;

void main() {
  vec4 c = texelFetch(source, ivec2(gl_FragCoord.xy), 0);
#if CREP_COPY_SRGB
  c.rgb = crep_srgbEncode(c.rgb);
#endif
  outColor = c;
}
