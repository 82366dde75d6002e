#version 450 core
// Point resampling of a standard shadow map into a rectified map with blocker clamping (Klehm et al. 2014,
// Sec. 4.1; rules in crep/epipolar/resample.h), for the epipolar fallback layout (CREP_LAYOUT 1) or a
// projective layout (CREP_LAYOUT 0) of a directional light, spot light or point-light face. One invocation
// per texel of the rectified map.
//
// Resources: params block (binding 0: sizes.xy standard map, sizes.zw rectified map, lightClipFromWorld),
// layout block (binding 1) and slices (storage buffer 1, epipolar), standard shadow map (unit 0,
// texelFetch), output: R32F rectified map (image 0), worldFromLightClip (location 0), projectedDistance
// (location 1): 0 for a directional light (the ray origin is projected: an orthographic map), else the
// distance along the local light's ray of the projected point (its origin is the light, the perspective
// map's centre of projection).
#include "crep/epipolar.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = 0) uniform CrepMarchBlock { CrepMarchParams crep_march; };
layout(binding = 0) uniform sampler2D shadowMap;
layout(binding = 0, r32f) uniform writeonly image2D rectifiedOut;
layout(location = 0) uniform mat4 worldFromLightClip;
layout(location = 1) uniform float projectedDistance;

void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 mapSize = crep_march.sizes.zw, shadowSize = crep_march.sizes.xy;
  if (any(greaterThanEqual(texel, mapSize))) return;
  vec2 cr = (vec2(texel) + 0.5) / vec2(mapSize);
  CrepLightRay ray = crep_layoutLightRay(cr.x, cr.y);
  vec4 q = crep_march.lightClipFromWorld * vec4(ray.origin + projectedDistance * ray.direction, 1.0);
  vec2 ndc = q.xy / q.w;
  float depth = 1.0;
  bool inFront = projectedDistance == 0.0 || q.w > 0.0; // a local light's ray behind its map: no information
  if (inFront && all(greaterThanEqual(ndc, vec2(-1.0))) && all(lessThanEqual(ndc, vec2(1.0)))) {
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
