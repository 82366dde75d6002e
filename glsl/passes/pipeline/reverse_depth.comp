#version 450 core
// A reversed-Z map of the engine (crep::ShadowPassPlanOptions::reversedZ) turned back into the depth-buffer
// values every pass reads: out = 1 - map, texel for texel, into an R32F image of the map's size.
#include "crep/bindings.h"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = CREP_REVERSE_DEPTH_MAP_UNIT) uniform sampler2D crep_reversedMap;
layout(binding = CREP_REVERSE_DEPTH_OUT_IMAGE, r32f) uniform writeonly restrict image2D crep_depthOut;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, imageSize(crep_depthOut)))) return;
  imageStore(crep_depthOut, p, vec4(1.0 - texelFetch(crep_reversedMap, p, 0).r));
}
