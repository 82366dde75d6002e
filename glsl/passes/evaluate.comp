#version 450 core
// Evaluation pass of prefiltered single scattering (Klehm, Seidel, Eisemann 2014, Sec. 3.3 "Evaluating a
// Ray", Listing 4): one invocation per camera pixel reconstructs the view ray from the camera depth
// buffer and evaluates it with crep_inScatteringSegment (crep/scattering.glsl). Pixel rays, the sky rule
// and the near-plane start are crep::evaluate()'s (crep/prefilter/prefilter.h, "Evaluation"). Output:
// RGB in-scattered radiance, A grey transmittance to the surface. Driven by crep::EvaluatePass.
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
#define CREP_EVALUATE_BINDING 1 // uniform buffer binding of CrepEvaluateBlock
#endif
#ifndef CREP_CAMERA_DEPTH_UNIT
#define CREP_CAMERA_DEPTH_UNIT 1
#endif
#ifndef CREP_MEMORY_LIMIT
#define CREP_MEMORY_LIMIT 0 // 1: benchmark variant, the same fetches and store without the math
#endif
#include "crep/scattering.glsl"

layout(local_size_x = CREP_LOCAL_SIZE_X, local_size_y = CREP_LOCAL_SIZE_Y) in;

layout(binding = CREP_CAMERA_DEPTH_UNIT) uniform sampler2D crep_cameraDepth; // depth-buffer values in [0, 1]
layout(binding = 0, CREP_OUTPUT_FORMAT) uniform writeonly restrict image2D crep_scatteringOut;
layout(std140, binding = CREP_EVALUATE_BINDING) uniform CrepEvaluateBlock { CrepEvaluateParams crep_evaluate; };


#if CREP_MEMORY_LIMIT
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

void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = crep_evaluate.imageSize.xy;
  if (any(greaterThanEqual(pixel, size))) return;
  float zNear = crep_evaluate.cameraPosition.w;
  vec3 forward = crep_evaluate.cameraForward.xyz;
  vec2 ndc = 2.0 * (vec2(pixel) + 0.5) / vec2(size) - 1.0;
  vec3 dir = normalize(forward + crep_evaluate.cameraCenter.xyz + ndc.x * crep_evaluate.cameraRight.xyz +
                       ndc.y * crep_evaluate.cameraUp.xyz);
  float cosForward = dot(dir, forward);
  float d = texelFetch(crep_cameraDepth, pixel, 0).r;
  // Sky (the cleared value, also NaN): integrate to the far distance; beyond the near plane's value: near.
  float viewDepth = crep_cameraViewDepth(d, crep_evaluate.cameraDepth);
  float surface = viewDepth / cosForward;
  float start = 0.0;
#if CREP_NEAR_PLANE_CORRECTION
  start = min(zNear / cosForward, surface);
#endif
#if CREP_MEMORY_LIMIT
  imageStore(crep_scatteringOut, pixel, crep_fetchOnly(crep_evaluate.cameraPosition.xyz, dir, start, surface));
#else
  imageStore(crep_scatteringOut, pixel, crep_inScatteringSegment(crep_evaluate.cameraPosition.xyz, dir, start, surface));
#endif
}
