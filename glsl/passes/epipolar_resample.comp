#version 450 core
// Point resampling of a standard shadow map into a rectified map with blocker clamping (Klehm et al. 2014,
// Sec. 4.1; rules in crep/epipolar/resample.h), for the epipolar fallback layout (CREP_LAYOUT 1) or a
// projective layout (CREP_LAYOUT 0). One invocation per texel of the rectified map.
//
// Resources: params block (binding 0: sizes.xy standard map, sizes.zw rectified map, lightClipFromWorld),
// layout block (binding 1) and slices (storage buffer 1, epipolar), standard shadow map (unit 0,
// texelFetch), output: R32F rectified map (image 0), worldFromLightClip (location 0).
#include "crep/epipolar.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = 0) uniform CrepMarchBlock { CrepMarchParams crep_march; };
layout(binding = 0) uniform sampler2D shadowMap;
layout(binding = 0, r32f) uniform writeonly image2D rectifiedOut;
layout(location = 0) uniform mat4 worldFromLightClip;

void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 mapSize = crep_march.sizes.zw, shadowSize = crep_march.sizes.xy;
  if (any(greaterThanEqual(texel, mapSize))) return;
  vec2 cr = (vec2(texel) + 0.5) / vec2(mapSize);
  CrepLightRay ray = crep_layoutLightRay(cr.x, cr.y);
  vec4 q = crep_march.lightClipFromWorld * vec4(ray.origin, 1.0);
  vec2 ndc = q.xy / q.w;
  float depth = 1.0;
  if (all(greaterThanEqual(ndc, vec2(-1.0))) && all(lessThanEqual(ndc, vec2(1.0)))) {
    ivec2 s = min(ivec2((ndc + 1.0) * 0.5 * vec2(shadowSize)), shadowSize - 1);
    float d = texelFetch(shadowMap, s, 0).r;
    if (d < 1.0) { // also false for NaN: an empty texel
      vec4 h = worldFromLightClip * vec4(ndc, 2.0 * d - 1.0, 1.0);
      vec4 p;
      if (crep_layoutToRectified(h.xyz / h.w, p)) depth = clamp(p.z, 0.0, 1.0);
    }
  }
  imageStore(rectifiedOut, texel, vec4(depth));
}
