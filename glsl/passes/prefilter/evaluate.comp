#version 450 core
// Evaluation pass of prefiltered single scattering (Klehm, Seidel, Eisemann 2014, Sec. 3.3 "Evaluating a
// Ray", Listing 4): one invocation per camera pixel reconstructs the view ray from the camera depth
// buffer and evaluates it with crep_inScatteringSegment (crep/scattering.glsl). Pixel rays, the sky rule
// and the near-plane start are crep::evaluate()'s (crep/prefilter/prefilter.h, "Evaluation"). Output:
// RGB in-scattered radiance, A grey transmittance to the surface. Driven by crep::EvaluatePass. With
// CREP_FROXELS 1 the same evaluation fills a froxel volume (Wronski 2014's frustum-aligned cells), one
// invocation per cell, each ray ending at its cell's sample depth (crep::evaluateFroxels).
#include "crep/bindings.h"
#ifndef CREP_OUTPUT_FORMAT
#define CREP_OUTPUT_FORMAT rgba32f // rgba32f or rgba16f
#endif
#ifndef CREP_LOCAL_SIZE_X
#define CREP_LOCAL_SIZE_X 8
#endif
#ifndef CREP_LOCAL_SIZE_Y
#define CREP_LOCAL_SIZE_Y 8
#endif
#ifndef CREP_EVALUATE_BINDING
#define CREP_EVALUATE_BINDING CREP_EVALUATE_DEFAULT_BINDING // uniform buffer binding of CrepEvaluateBlock
#endif
#ifndef CREP_CAMERA_DEPTH_UNIT
#define CREP_CAMERA_DEPTH_UNIT CREP_CAMERA_DEPTH_DEFAULT_UNIT
#endif
#ifndef CREP_MEMORY_LIMIT
#define CREP_MEMORY_LIMIT 0 // 1: benchmark variant, the same fetches and store without the math
#endif
#ifndef CREP_FROXELS
// 1: fill a froxel volume instead (crep::evaluateFroxels, crep/prefilter/prefilter.h "Froxel volumes"): one
// invocation per cell, the ray through the cell's sample (u, v) up to its sample view depth.
#define CREP_FROXELS 0
#endif
#ifndef CREP_SAMPLE_LIST
// 1: evaluate only the entries of a GPU work list (crep/scatter/gpu_sample_list.h; Yusov 2012, Sec. 6.4 and
// 6.7: epipolar sampling's marched samples and corrections), one invocation per entry in work groups of 64
// dispatched indirectly (a compacted list keeps a real GPU's waves full). The camera-depth unit holds the
// list's coordinates (x, y, d, z); the ray goes through (x, y) to depth d; the output is RGBA32F.
#define CREP_SAMPLE_LIST 0
#endif
#include "crep/scattering.glsl"

layout(std140, binding = CREP_EVALUATE_BINDING) uniform CrepEvaluateBlock { CrepEvaluateParams crep_evaluate; };
#if CREP_FROXELS
#include "crep/froxel.glsl"
// Workgroups of CREP_LOCAL_SIZE_X x CREP_LOCAL_SIZE_Y cells of one slice (a choice for GPUs: those cells map
// to neighbouring rows and columns of the basis, so their fetches share texture cache lines; cells of one
// ray would fetch the same row at columns far apart).
layout(local_size_x = CREP_LOCAL_SIZE_X, local_size_y = CREP_LOCAL_SIZE_Y, local_size_z = 1) in;
// RGBA16F or RGBA32F: a writeonly image needs no format qualifier (GLSL 4.50), so one program serves both.
layout(binding = CREP_EVALUATE_FROXELS_OUT_IMAGE) uniform writeonly restrict image3D crep_froxelsOut;
// Vulkan (and so HLSL root constants, an MSL buffer): push constants; GL: uniform locations.
#ifdef VULKAN
layout(push_constant) uniform CrepEvaluateFroxelsPush {
  vec4 crep_froxelJitter;
  vec2 crep_froxelRange;
};
#else
layout(location = 0) uniform vec4 crep_froxelJitter; // xyz: the sample's offset in cells
layout(location = 1) uniform vec2 crep_froxelRange;  // the volume's (near, far) view depth (FroxelDepthRange)
#endif
#elif CREP_SAMPLE_LIST
#include "crep/sample_list.glsl"
layout(local_size_x = CREP_SAMPLE_LIST_GROUP_SIZE) in;
layout(binding = CREP_CAMERA_DEPTH_UNIT) uniform sampler2D crep_cameraDepth; // the list's (x, y, d, z)
layout(binding = CREP_EVALUATE_SCATTERING_OUT_IMAGE, CREP_OUTPUT_FORMAT) uniform writeonly restrict image2D crep_scatteringOut;
#else
layout(local_size_x = CREP_LOCAL_SIZE_X, local_size_y = CREP_LOCAL_SIZE_Y) in;
layout(binding = CREP_CAMERA_DEPTH_UNIT) uniform sampler2D crep_cameraDepth; // depth-buffer values in [0, 1]
layout(binding = CREP_EVALUATE_SCATTERING_OUT_IMAGE, CREP_OUTPUT_FORMAT) uniform writeonly restrict image2D crep_scatteringOut;
#endif

// The pixel ray's rule (crep::pixelRay, crep/scatter/ray.h) for NDC (x, y) and view depth Z: the in-scattering
// from the camera (or the near plane, with the correction) to the ray's point at view depth Z.
vec4 crep_evaluateRay(vec2 ndc, float viewDepth) {
  vec3 forward = crep_evaluate.cameraForward.xyz;
  vec3 dir = normalize(forward + crep_evaluate.cameraCenter.xyz + ndc.x * crep_evaluate.cameraRight.xyz +
                       ndc.y * crep_evaluate.cameraUp.xyz);
  float cosForward = dot(dir, forward);
  float surface = viewDepth / cosForward;
  float start = 0.0;
#if CREP_NEAR_PLANE_CORRECTION
  start = min(crep_evaluate.cameraPosition.w / cosForward, surface);
#endif
  return crep_inScatteringSegment(crep_evaluate.cameraPosition.xyz, dir, start, surface);
}


#if CREP_MEMORY_LIMIT && !CREP_FROXELS
// The fetches of crep_inScatteringSegment (one per layer and region crossed, at the same coordinates) and
// nothing else: their sum is stored so that no fetch is optimized away.
vec4 crep_fetchOnly(vec3 origin, vec3 dir, float start, float surface) {
  CrepEvalRay hit;
  if (!crep_evalMap(origin, dir, surface, hit)) return vec4(0.0);
  int firstRegion = 0;
  float firstU = 0.0;
#if CREP_NEAR_PLANE_CORRECTION
  CrepEvalRay nearPoint;
  if (start > 0.0 && crep_evalMap(origin, dir, start, nearPoint)) {
    firstRegion = min(nearPoint.region, hit.region);
    firstU = nearPoint.u;
  }
#endif
  vec4 sum = vec4(0.0);
#if defined(CREP_VISIBILITY_TABLE_SAMPLES) && !CREP_NEAR_PLANE_CORRECTION
  // The table path: one table fetch per region crossed whole, the basis of the last region.
  vec2 coord = crep_visibilityTableCoord(hit.row, hit.depth);
#if CREP_SCATTERING_PREFIX
  sum += vec4(crep_scatteringPrefixAt(hit.region, coord), 0.0); // one fetch for the regions crossed whole
#else
  for (int r = 0; r < hit.region; ++r) sum += vec4(crep_visibilityTableAt(r, coord));
#endif
  for (int l = 0; l < CREP_EVAL_LAYERS; ++l) sum += crep_filteredBasisAt(hit.region, hit.u, hit.row, l);
  return sum;
#endif
  for (int r = firstRegion; r <= hit.region; ++r) {
    float ub = r == hit.region ? hit.u : 1.0;
    for (int l = 0; l < CREP_EVAL_LAYERS; ++l) sum += crep_filteredBasisAt(r, ub, hit.row, l);
    if (r == firstRegion && firstU > 0.0) // the near-plane correction's second prefix
      for (int l = 0; l < CREP_EVAL_LAYERS; ++l) sum += crep_filteredBasisAt(r, firstU, hit.row, l);
  }
  return sum;
}
#endif

#if CREP_FROXELS
void main() {
  ivec3 cell = ivec3(gl_GlobalInvocationID);
  ivec3 size = crep_evaluate.imageSize.xyz;
  if (any(greaterThanEqual(cell, size))) return;
  vec3 uvw = (vec3(cell) + 0.5 + crep_froxelJitter.xyz) / vec3(size);
  // Beyond the camera's integration far the map has no information: the far plane's value, as the sky's.
  float viewDepth = min(crep_froxelViewDepth(crep_froxelRange, uvw.z), crep_evaluate.cameraDepth.z);
  imageStore(crep_froxelsOut, cell, crep_evaluateRay(2.0 * uvw.xy - 1.0, viewDepth));
}
#else
void main() {
#if CREP_SAMPLE_LIST
  // The entry's texel; its point (x, y) of the W x H camera image (imageSize) and its depth-buffer value:
  // at a pixel centre the same arithmetic as below.
  uint entry = gl_GlobalInvocationID.x;
  if (entry >= crep_listCount()) return;
  ivec2 pixel = crep_listEntry(entry);
  vec4 coordinates = texelFetch(crep_cameraDepth, pixel, 0);
  vec2 ndc = 2.0 * coordinates.xy / vec2(crep_evaluate.imageSize.xy) - 1.0;
  float d = coordinates.z;
#else
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = crep_evaluate.imageSize.xy;
  if (any(greaterThanEqual(pixel, size))) return;
  vec2 ndc = 2.0 * (vec2(pixel) + 0.5) / vec2(size) - 1.0;
  float d = texelFetch(crep_cameraDepth, pixel, 0).r;
#endif
  // Sky (the cleared value, also NaN): integrate to the far distance; beyond the near plane's value: near.
  float viewDepth = crep_cameraViewDepth(d, crep_evaluate.cameraDepth);
#if CREP_MEMORY_LIMIT
  vec3 forward = crep_evaluate.cameraForward.xyz;
  vec3 dir = normalize(forward + crep_evaluate.cameraCenter.xyz + ndc.x * crep_evaluate.cameraRight.xyz +
                       ndc.y * crep_evaluate.cameraUp.xyz);
  float cosForward = dot(dir, forward);
  float surface = viewDepth / cosForward;
  float start = 0.0;
#if CREP_NEAR_PLANE_CORRECTION
  start = min(crep_evaluate.cameraPosition.w / cosForward, surface);
#endif
  imageStore(crep_scatteringOut, pixel, crep_fetchOnly(crep_evaluate.cameraPosition.xyz, dir, start, surface));
#else
  imageStore(crep_scatteringOut, pixel, crep_evaluateRay(ndc, viewDepth));
#endif
}
#endif
