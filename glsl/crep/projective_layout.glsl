// crepuscular: the projective layout of crep/layout.glsl (Klehm et al. 2014, Sec. 4.2; crep::ProjectiveLayout).
// Included by crep/layout.glsl (include that one); it includes what it needs itself.
#ifndef CREP_PROJECTIVE_LAYOUT_GLSL
#define CREP_PROJECTIVE_LAYOUT_GLSL

#include "layout_common.glsl"

#if CREP_LAYOUT == CREP_LAYOUT_PROJECTIVE
// ---------------------------------------------------------------------------------------------------
// Projective layout (rectify.h "The math"): frame coordinates X, Y, Z of p - origin; slopes y = Y / X,
// z = Z / X; zeta = (1 + rho Z) / X; split k covers zeta in [zetaEnd_k, zetaBegin_k].

// gpu::ProjectiveLayoutParams (std140).
struct CrepProjectiveLayoutParams {
  vec4 origin;  // xyz camera position; w rho (0: directional)
  vec4 axisX;   // xyz; w 0
  vec4 axisY;   // xyz; w 0
  vec4 axisZ;   // xyz; w 0
  vec4 slopes;  // row slope min, row slope max, depth slope min, depth slope max
  ivec4 counts; // x regions (splits) K
  vec4 splitZeta[CREP_MAX_LAYOUT_REGIONS]; // x zetaBegin, y zetaEnd
};

layout(std140, binding = CREP_LAYOUT_BINDING) uniform CrepProjectiveLayoutBlock {
  CrepProjectiveLayoutParams crep_projective;
};

bool crep_layoutToRectified(vec3 world, out vec4 p) {
  vec3 offset = world - crep_projective.origin.xyz;
  float X = dot(crep_projective.axisX.xyz, offset);
  p = vec4(0.0);
  if (!(X > 0.0)) return false;
  float Y = dot(crep_projective.axisY.xyz, offset), Z = dot(crep_projective.axisZ.xyz, offset);
  vec4 s = crep_projective.slopes;
  float zeta = (1.0 + crep_projective.origin.w * Z) / X;
  int K = crep_projective.counts.x;
  int k = 0;
  while (k < K - 1 && zeta < crep_projective.splitZeta[k].y) ++k;
  vec2 range = crep_projective.splitZeta[k].xy;
  float u = (range.x - zeta) / (range.x - range.y);
  p = vec4((Y / X - s.x) / (s.y - s.x), (float(k) + u) / float(K), (Z / X - s.z) / (s.w - s.z), float(k));
  return true;
}

// zeta of a normalized column (the end splits extrapolate), as crep::Rectification does.
float crep_projectiveZeta(float column) {
  int K = crep_projective.counts.x;
  float scaled = column * float(K);
  int k = clamp(int(floor(scaled)), 0, K - 1);
  vec2 range = crep_projective.splitZeta[k].xy;
  return range.x + (scaled - float(k)) * (range.y - range.x);
}

// crep::Rectification::lightRay: a directional light (rho = 0): the point of the light ray with Z = 0 and
// the light direction; a spot light or point-light face (rho > 0): the light position L = origin - axisZ /
// rho and the unit direction axisX + y axisY + (zeta / rho) axisZ of the ray's points L + X (...), X >= 0.
CrepLightRay crep_layoutLightRay(float column, float row) {
  vec4 s = crep_projective.slopes;
  float y = s.x + row * (s.y - s.x);
  float zeta = crep_projectiveZeta(column);
  float rho = crep_projective.origin.w;
  if (rho > 0.0)
    return CrepLightRay(crep_projective.origin.xyz - crep_projective.axisZ.xyz / rho,
                        normalize(crep_projective.axisX.xyz + y * crep_projective.axisY.xyz +
                                  (zeta / rho) * crep_projective.axisZ.xyz));
  float X = 1.0 / zeta;
  return CrepLightRay(crep_projective.origin.xyz + X * (crep_projective.axisX.xyz + y * crep_projective.axisY.xyz),
                      crep_projective.axisZ.xyz);
}

// The row ray of a normalized row and depth (every point of a ray from the camera shares them): its texel
// row, depth clamped to [0, 1] and the distance data of crep_rowRayDistance, the slopes at that depth:
// s(zeta) = sqrt(1 + y^2 + z^2) / (zeta - rho z). `last` is left 0.
CrepRowRay crep_rowRayAt(float row, float depth, ivec2 mapSize) {
  CrepRowRay r = CrepRowRay(row, clamp(depth, 0.0, 1.0), clamp(int(floor(row * float(mapSize.y))), 0, mapSize.y - 1),
                            0, vec4(0.0));
  vec4 s = crep_projective.slopes;
  float y = s.x + row * (s.y - s.x), z = s.z + r.depth * (s.w - s.z);
  r.dist = vec4(sqrt(1.0 + y * y + z * z), crep_projective.origin.w * z, 0.0, 0.0);
  return r;
}

// The unit direction of the view ray of a normalized row and depth.
vec3 crep_layoutViewDirection(float row, float depth) {
  vec4 s = crep_projective.slopes;
  float y = s.x + row * (s.y - s.x), z = s.z + clamp(depth, 0.0, 1.0) * (s.w - s.z);
  return normalize(crep_projective.axisX.xyz + y * crep_projective.axisY.xyz + z * crep_projective.axisZ.xyz);
}

bool crep_mapRowRayPoint(vec3 dir, float surface, ivec2 mapSize, out CrepRowRay r, out vec4 p) {
  r = CrepRowRay(0.0, 0.0, 0, 0, vec4(0.0));
  if (!crep_layoutToRectified(crep_projective.origin.xyz + surface * dir, p)) return false;
  int K = crep_projective.counts.x, n = mapSize.x / K;
  int k = int(p.w);
  r = crep_rowRayAt(p.x, p.z, mapSize);
  r.last = crep_lastTexel(k, p.y * float(K) - float(k), K, n);
  return true;
}

float crep_rowRayDistance(CrepRowRay r, int i, ivec2 mapSize) {
  int K = crep_projective.counts.x, n = mapSize.x / K;
  int k = i / n, q = i - k * n;
  if (k >= K) {
    k = K - 1;
    q = n;
  }
  vec2 range = crep_projective.splitZeta[k].xy;
  float den = range.x + (float(q) / float(n)) * (range.y - range.x) - r.dist.y;
  return den > 0.0 ? r.dist.x / den : CREP_NEVER;
}
#endif // CREP_LAYOUT_PROJECTIVE

#endif // CREP_PROJECTIVE_LAYOUT_GLSL
