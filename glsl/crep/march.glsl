// crepuscular: the frame block of the march and resampling passes and the camera pixel rays they march
// (GLSL twin of gpu::MarchParams in crep/scatter/gpu_world_march.h; the rays of crep/scatter/ray.h).
//
// Public include (conventions in crep/common.glsl).
#ifndef CREP_MARCH_GLSL
#define CREP_MARCH_GLSL

#include "common.glsl"
#include "ray.glsl"

// gpu::MarchParams (std140): the frame attributes of the march and resampling passes.
struct CrepMarchParams {
  vec4 cameraPosition;     // xyz world; w near
  vec4 cameraForward;      // xyz unit view direction; w far
  vec4 cameraRight;        // xyz right * tan(fovY / 2) * aspect; w 0
  vec4 cameraUp;           // xyz up * tan(fovY / 2); w 0
  vec4 lightDirection;     // xyz direction the light travels; w 0
  vec4 lightIrradiance;    // rgb; w 0
  vec4 mieScattering;      // rgb; w Henyey-Greenstein g
  vec4 rayleighScattering; // rgb; w 0
  vec4 extinction;         // rgb sigma_t; w grey extinction (mean of rgb)
  ivec4 sizes;             // march: xy camera image, zw map; world march: zw shadow map; resampling: xy shadow map, zw map
  ivec4 info;              // march: x tree levels L, y tree row stride; world march: x steps N, y refinements
  vec4 bias;               // world march: x shadow bias (depth-buffer units); yzw 0
  vec4 block;              // world and rectified marches: xy centre (pixels), z radius (pixels, < 0: every pixel), w 0
  ivec4 region;            // world and rectified marches: xy first pixel of the dispatch, zw its size
  mat4 lightClipFromWorld; // world march / resampling: the standard shadow map's matrix
  vec4 cameraCenter;       // xyz the image centre's offset from forward (off-centre projections); w 0
  vec4 cameraDepth;        // x near, y projection far (0 = infinite), z integration far, w 1 = reversed-Z
  // The world march's local light (zeros: directional; crep/local_light.glsl, crep_localLight reads them).
  vec4 lightPosition;      // xyz world; w 1 = local light (spot or point face), 0 = directional
  vec4 lightAxis;          // xyz unit spot axis or point-face axis; w point face index, or -1
  vec4 lightCone;          // x cosInner, y cosOuter, z near plane, w 1 = the spot falloff applies
  vec4 lightIntensity;     // rgb radiant intensity (on the axis for a spot); w 0
};

// The view ray through the continuous position `position` (pixel coordinates, origin bottom-left, pixel
// centres at + 0.5) of the w x h camera image m.sizes.xy, ending at the surface of depth-buffer value
// `depth` (crep::screenRay, crep/scatter/ray.h: sky rays end at the far plane). xyz = unit direction,
// w = distance.
vec4 crep_screenRay(CrepMarchParams m, vec2 position, float depth) {
  vec2 ndc = 2.0 * position / vec2(m.sizes.xy) - 1.0;
  vec3 dir = normalize(m.cameraForward.xyz + m.cameraCenter.xyz + ndc.x * m.cameraRight.xyz + ndc.y * m.cameraUp.xyz);
  float viewDepth = crep_cameraViewDepth(depth, m.cameraDepth);
  return vec4(dir, viewDepth / dot(dir, m.cameraForward.xyz));
}

// The view ray of pixel p of a w x h camera image and its surface distance (crep/scatter/ray.h: sky
// pixels end at the far plane): crep_screenRay at the pixel centre (the same arithmetic, so a work list
// entry at a pixel centre gets this ray bit for bit). xyz = unit direction, w = distance.
vec4 crep_pixelRay(CrepMarchParams m, ivec2 p, float depth) {
  return crep_screenRay(m, vec2(p) + 0.5, depth);
}

#endif // CREP_MARCH_GLSL
