#version 450 core
// Ray march of each camera pixel's view ray along its row of a rectified map (crep/epipolar/march.h,
// "Rectified marches"): CREP_MARCH_TREE 1 walks the row's 1D min/max binary tree (Chen et al. 2011;
// Yusov 2012, Algorithm 2 and Sec. 4), 0 tests every texel (brute force). Same rays, sections and
// output as crep::minMaxMarch / crep::bruteForceMarch; float precision.
//
// Resources: params block (binding 0), layout block (crep/layout.glsl, binding 1), camera depth
// (unit 0), rectified map depth (unit 1, texelFetch), min/max nodes (storage buffer 0, tree variant),
// outputs: RGBA32F scattering (image 0), R32F steps (image 1); CREP_SAMPLE_LIST: the list at storage
// buffer CREP_SAMPLE_LIST_BINDING (2). Without a list the dispatch covers the pixel rectangle
// crep_march.region, and with block.z >= 0 only the pixels within block.z pixels of block.xy are written
// (crep::Scattering's epipole block on the epipolar map, Klehm et al. 2014, Fig. 8).
// CREP_LIGHT_TEXTURE 1: a light texture's colour map of the rectified map (crep::lightColorMap,
// LightColorMapPass; texelFetch at texture unit 2): each lit texel's section times its colour
// (crep::bruteForceMarch with lightColors); the tree variant walks a lit node texel by texel (the colours
// differ inside it), so only shadowed nodes are skipped whole.
// CREP_SAMPLE_LIST 1: only the entries of a GPU work list (crep/scatter/gpu_sample_list.h; Yusov 2012,
// Sec. 6.4: epipolar sampling's marched samples), one invocation per entry in work groups of 64 (a wave
// or two on real GPUs, every lane busy: the list is compacted) dispatched indirectly; texture unit 0 holds
// the list's coordinates (x, y, d, z) instead of the camera depth, the ray is crep_screenRay at (x, y) to
// depth d, and the outputs are written at the entry's texel only.
#include "crep/bindings.h"
#include "crep/layout.glsl"
#include "crep/local_light.glsl"
#include "crep/phase.glsl"

#ifndef CREP_MARCH_TREE
#define CREP_MARCH_TREE 1
#endif
#ifndef CREP_LIGHT_TEXTURE
#define CREP_LIGHT_TEXTURE 0
#endif

#ifndef CREP_SAMPLE_LIST
#define CREP_SAMPLE_LIST 0
#endif

#if CREP_SAMPLE_LIST
#include "crep/sample_list.glsl"
layout(local_size_x = CREP_SAMPLE_LIST_GROUP_SIZE) in;
#else
layout(local_size_x = 8, local_size_y = 8) in;
#endif

layout(std140, binding = CREP_MARCH_PARAMS_BINDING) uniform CrepMarchBlock { CrepMarchParams crep_march; };
layout(binding = CREP_MARCH_CAMERA_DEPTH_UNIT) uniform sampler2D cameraDepth; // CREP_SAMPLE_LIST: the list's coordinates (x, y, d, z)
layout(binding = CREP_MARCH_MAP_UNIT) uniform sampler2D rectifiedDepth;
#if CREP_MARCH_TREE
layout(std430, binding = CREP_MARCH_MIN_MAX_BINDING) readonly buffer CrepMinMaxBlock { vec2 crep_minMax[]; };
#endif
#if CREP_LIGHT_TEXTURE
layout(binding = CREP_MARCH_LIGHT_COLORS_UNIT) uniform sampler2D crep_lightColors; // W x H, rgb: each texel's light-ray colour
#endif
layout(binding = CREP_MARCH_SCATTERING_OUT_IMAGE, rgba32f) uniform writeonly image2D scatteringOut;
layout(binding = CREP_MARCH_STEPS_OUT_IMAGE, r32f) uniform writeonly image2D stepsOut;

bool local = false;
CrepLocalLight localLight;
CrepLocalMedium localMedium;
vec3 rayDirection = vec3(0.0);

// The light-dependent factor of the lit section [ta, tb] (crep/scatter/rectified_march.h's rule).
vec3 crep_section(vec3 sigma, float ta, float tb) {
  if (local)
    return crep_localSegment(localLight, localMedium, crep_march.cameraPosition.xyz, rayDirection, ta, tb);
  return crep_transmittanceIntegral(sigma, ta, tb);
}

#if CREP_MARCH_TREE
// The walk of crep/minmax_walk.glsl (shared with passes/atmosphere/atmosphere.comp) adds each lit node here.
vec3 litSum = vec3(0.0);
vec3 litSigma = vec3(0.0);
float litSurface = 0.0;
void crep_walkLitNode(CrepRowRay r, int i, int next, float ta, float tb) {
#if CREP_LIGHT_TEXTURE
  float a = ta;
  for (int k = i; k < next; ++k) { // the node's texels, each with its own colour
    float b = k + 1 >= next ? tb : clamp(min(crep_rowRayDistance(r, k + 1, crep_march.sizes.zw), litSurface), a, tb);
    litSum += texelFetch(crep_lightColors, ivec2(k, r.texelRow), 0).rgb * crep_section(litSigma, a, b);
    a = b;
  }
#else
  litSum += crep_section(litSigma, ta, tb);
#endif
}
#define CREP_MINMAX_WALK_INPUTS 1
#include "crep/minmax_walk.glsl"
#endif

void main() {
#if CREP_SAMPLE_LIST
  uint entry = gl_GlobalInvocationID.x;
  if (entry >= crep_listCount()) return;
  ivec2 pixel = crep_listEntry(entry); // the texel of the coordinates and outputs
  vec4 coordinates = texelFetch(cameraDepth, pixel, 0);
  vec4 ray = crep_screenRay(crep_march, coordinates.xy, coordinates.z);
#else
  // The dispatch covers crep_march.region (the image, or the bounding box of the disc crep_march.block).
  ivec2 pixel = crep_march.region.xy + ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(ivec2(gl_GlobalInvocationID.xy), crep_march.region.zw)) ||
      any(greaterThanEqual(pixel, crep_march.sizes.xy)))
    return;
  if (crep_march.block.z >= 0.0 && distance(vec2(pixel) + 0.5, crep_march.block.xy) > crep_march.block.z) return;
  vec4 ray = crep_pixelRay(crep_march, pixel, texelFetch(cameraDepth, pixel, 0).r);
#endif
  vec3 dir = ray.xyz;
  float s = ray.w;
  vec3 sigma = crep_march.extinction.rgb;
  float cosTheta = dot(crep_march.lightDirection.xyz, -dir);
  // Directional: S = C * transmittance integral; a local light (lightPosition.w = 1): S = crep_localSegment
  // of each lit section (the same integrand as the CPU's RayScattering) and C = 1.
  local = crep_march.lightPosition.w > 0.5;
  localLight = crep_localLight(crep_march.lightPosition, crep_march.lightAxis, crep_march.lightCone,
                               crep_march.lightIntensity);
  localMedium = CrepLocalMedium(crep_march.mieScattering, crep_march.rayleighScattering.rgb, sigma);
  rayDirection = dir;
  vec3 C = local ? vec3(1.0)
                 : crep_march.lightIrradiance.rgb *
                       (crep_march.mieScattering.rgb * crep_henyeyGreenstein(crep_march.mieScattering.w, cosTheta) +
                        crep_march.rayleighScattering.rgb * crep_rayleighPhase(cosTheta));
  ivec2 mapSize = crep_march.sizes.zw;
  vec3 L = vec3(0.0);
  int steps = 0;
  CrepRowRay r;
  if (!crep_mapRowRay(dir, s, mapSize, r)) {
    L = crep_section(sigma, 0.0, s);
  } else {
#if CREP_MARCH_TREE
    litSigma = sigma;
    litSurface = s;
    steps = crep_minMaxWalk(r, s, mapSize, crep_march.info.x, crep_march.info.y);
    L = litSum;
#else
    int j = r.texelRow, end = r.last + 1;
    float z = r.depth;
    float ta = 0.0;
    for (int i = 0; i < end; ++i) {
      ++steps;
      float tb = i + 1 > r.last ? s : min(crep_rowRayDistance(r, i + 1, mapSize), s);
      tb = max(tb, ta);
#if CREP_LIGHT_TEXTURE
      if (texelFetch(rectifiedDepth, ivec2(i, j), 0).r >= z)
        L += texelFetch(crep_lightColors, ivec2(i, j), 0).rgb * crep_section(sigma, ta, tb);
#else
      if (texelFetch(rectifiedDepth, ivec2(i, j), 0).r >= z) L += crep_section(sigma, ta, tb);
#endif
      ta = tb;
    }
#endif
  }
  imageStore(scatteringOut, pixel, vec4(C * L, exp(-crep_march.extinction.w * s)));
  imageStore(stepsOut, pixel, vec4(float(steps)));
}
