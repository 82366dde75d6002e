#version 450 core
// Converts a depth buffer (standard OpenGL perspective) into view-space distances along -Z, texel for
// texel (the viewport must have the depth texture's size), into an R32F target. Draw with
// passes/fullscreen.vert.
#include "crep/common.glsl"

layout(binding = 0) uniform sampler2D depthTexture;
layout(location = 0) uniform float zNear;
layout(location = 1) uniform float zFar;
layout(location = 0) out float outDistance;

void main() {
  float depth = texelFetch(depthTexture, ivec2(gl_FragCoord.xy), 0).r;
  outDistance = crep_linearDepth(depth, zNear, zFar);
}
