// crepuscular: the epipolar layout of crep/layout.glsl (Klehm et al. 2014, Sec. 4.1; crep::EpipolarLayout).
// Included by crep/layout.glsl (include that one); it includes what it needs itself.
#ifndef CREP_EPIPOLAR_LAYOUT_GLSL
#define CREP_EPIPOLAR_LAYOUT_GLSL

#include "layout_common.glsl"

#if CREP_LAYOUT == CREP_LAYOUT_EPIPOLAR
// ---------------------------------------------------------------------------------------------------
// Epipolar layout (crep/epipolar/epipolar.h): m = direction toward the light, for a point q = p - camera:
// a = q.m, b = |q - a m|, psi = atan(b, a); the slice is the half-plane of q around the light axis, named
// by the border position sigma (pixels, Yusov's order) of its exit point; row = (sigma - arcBegin) /
// arcLength; column = b / bMax_j, depth = (psi - psiMin_j) / (psiMax_j - psiMin_j) with the bounds of
// texel row j = floor(row H).
// A local light at L (origin.w = D = |L - camera| > 0; crep/epipolar/epipolar.h "Local lights"): m = (L -
// camera) / D, the light rays leave L at angle theta = atan(b, D - a) from the direction toward the camera;
// column = region k of theta / thetaMax_j (bounds.x), inside it theta = mu + atan((2 u - 1) tan h) (mu the
// region's mid angle, h its half width), distances t = D sin(theta) / sin(psi + theta).

// gpu::EpipolarLayoutParams (std140).
struct CrepEpipolarLayoutParams {
  vec4 origin;      // xyz camera position, w D (local light) or 0
  vec4 towardLight; // xyz m
  vec4 imageX;      // xyz right / tanX
  vec4 imageY;      // xyz up / tanY
  vec4 forward;     // xyz
  vec4 cameraTan;   // x tanX, y tanY
  vec4 border;      // x width, y height (pixels), z perimeter
  vec4 arc;         // x arcBegin, y arcLength, z 1 = exit at the larger psi
  ivec4 counts;     // x slices H, y regions K
  vec4 regionFractions[CREP_MAX_LAYOUT_REGIONS / 4 + 1]; // f_k in element k / 4, component k % 4
};

// gpu::EpipolarSlice (std430).
struct CrepEpipolarSlice {
  vec4 bounds; // x bMax (local light: thetaMax), y g(psiMin), z g(psiMax) (g: the depth warp)
};

layout(std140, binding = CREP_LAYOUT_BINDING) uniform CrepEpipolarLayoutBlock {
  CrepEpipolarLayoutParams crep_epipolar;
};
layout(std430, binding = CREP_SLICES_BINDING) readonly buffer CrepEpipolarSlicesBlock {
  CrepEpipolarSlice crep_slices[];
};

// Homogeneous image point of a direction: NDC = xy / z where z > 0.
vec3 crep_epipolarImage(vec3 w) {
  return vec3(dot(w, crep_epipolar.imageX.xyz), dot(w, crep_epipolar.imageY.xyz), dot(w, crep_epipolar.forward.xyz));
}

// [lo, hi] intersected with {psi : A cos psi + B sin psi <= 0} (a half-circle centred at atan(B, A) + pi).
void crep_clipHalfCircle(float A, float B, inout float lo, inout float hi) {
  if (A == 0.0 && B == 0.0) return;
  float mid = 0.5 * (lo + hi);
  float centre = atan(B, A) + float(CREP_PI);
  centre -= float(CREP_TWO_PI) * round((centre - mid) / float(CREP_TWO_PI));
  lo = max(lo, centre - 0.5 * float(CREP_PI));
  hi = min(hi, centre + 0.5 * float(CREP_PI));
}

// Border position (pixels) of an NDC point on the border: left top->bottom, bottom left->right, right
// bottom->top, top right->left, starting at the top-left corner.
float crep_epipolarBorderSigma(vec2 ndc) {
  float w = crep_epipolar.border.x, h = crep_epipolar.border.y;
  vec2 p = clamp(ndc, -1.0, 1.0);
  if (abs(p.x) >= abs(p.y)) return p.x < 0.0 ? 0.5 * (1.0 - p.y) * h : h + w + 0.5 * (p.y + 1.0) * h;
  return p.y < 0.0 ? h + 0.5 * (p.x + 1.0) * w : 2.0 * h + w + 0.5 * (1.0 - p.x) * w;
}

vec2 crep_epipolarBorderPoint(float sigma) {
  float w = crep_epipolar.border.x, h = crep_epipolar.border.y, P = crep_epipolar.border.z;
  float s = mod(sigma, P);
  if (s < h) return vec2(-1.0, 1.0 - 2.0 * s / h);
  s -= h;
  if (s < w) return vec2(-1.0 + 2.0 * s / w, -1.0);
  s -= w;
  if (s < h) return vec2(1.0, -1.0 + 2.0 * s / h);
  s -= h;
  return vec2(1.0 - 2.0 * min(s, w) / w, 1.0);
}

float crep_epipolarRowOfSigma(float sigma) {
  float P = crep_epipolar.border.z, begin = crep_epipolar.arc.x, len = crep_epipolar.arc.y;
  float d = sigma - begin;
  if (len >= P) return mod(d, P) / P;
  float gap = P - len;
  return clamp((mod(d + 0.5 * gap, P) - 0.5 * gap) / len, 0.0, 1.0);
}

// The exit border position of the half-plane with unit direction n (orthogonal to m); false when no
// part of it is on screen. psiRange receives its visible psi interval.
bool crep_epipolarExitSigma(vec3 n, out float sigma, out vec2 psiRange) {
  vec3 hm = crep_epipolarImage(crep_epipolar.towardLight.xyz), hn = crep_epipolarImage(n);
  float lo = 0.0, hi = float(CREP_PI);
  crep_clipHalfCircle(hm.x - hm.z, hn.x - hn.z, lo, hi);
  crep_clipHalfCircle(-hm.x - hm.z, -hn.x - hn.z, lo, hi);
  crep_clipHalfCircle(hm.y - hm.z, hn.y - hn.z, lo, hi);
  crep_clipHalfCircle(-hm.y - hm.z, -hn.y - hn.z, lo, hi);
  psiRange = vec2(lo, hi);
  sigma = 0.0;
  if (!(lo <= hi)) return false;
  float psiExit = crep_epipolar.arc.z > 0.5 ? hi : lo;
  vec3 H = cos(psiExit) * hm + sin(psiExit) * hn;
  if (!(H.z > 0.0)) return false;
  sigma = crep_epipolarBorderSigma(H.xy / H.z);
  return true;
}

// Region boundary f_k (b / bMax) and the piecewise-linear column <-> b / bMax mapping.
float crep_epipolarFraction(int k) { return crep_epipolar.regionFractions[k >> 2][k & 3]; }

float crep_epipolarColumnFraction(float column) {
  int K = crep_epipolar.counts.y;
  int k = clamp(int(floor(column * float(K))), 0, K - 1);
  float f0 = crep_epipolarFraction(k), f1 = crep_epipolarFraction(k + 1);
  return f0 + (column * float(K) - float(k)) * (f1 - f0);
}

// Region k and the column u in it of b / bMax.
void crep_epipolarFractionRegion(float fraction, out int k, out float u) {
  int K = crep_epipolar.counts.y;
  k = 0;
  while (k < K - 1 && fraction >= crep_epipolarFraction(k + 1)) ++k;
  float f0 = crep_epipolarFraction(k), f1 = crep_epipolarFraction(k + 1);
  u = (fraction - f0) / (f1 - f0);
}

// The depth warp g(psi) = log((psi + e) / (pi - psi + e)), e = arc.w (psi itself when e = 0), and its
// inverse: depth is linear in g between the slice's bounds.
float crep_epipolarWarp(float psi) {
  float e = crep_epipolar.arc.w;
  return e > 0.0 ? log((psi + e) / (3.14159265 - psi + e)) : psi;
}
float crep_epipolarUnwarp(float g) {
  float e = crep_epipolar.arc.w;
  if (!(e > 0.0)) return g;
  float r = exp(g);
  return clamp((r * (3.14159265 + e) - e) / (1.0 + r), 0.0, 3.14159265);
}

// Local light: the mid angle and tan of the half width of region k of a slice with thetaMax.
vec2 crep_epipolarRegionAngles(int k, float thetaMax) {
  float t0 = crep_epipolarFraction(k) * thetaMax, t1 = crep_epipolarFraction(k + 1) * thetaMax;
  return vec2(0.5 * (t0 + t1), tan(0.5 * (t1 - t0)));
}

// Local light: theta at column u of region k, and region k and u of theta.
float crep_epipolarRegionTheta(int k, float u, float thetaMax) {
  vec2 angles = crep_epipolarRegionAngles(k, thetaMax);
  return angles.x + atan((2.0 * u - 1.0) * angles.y);
}
void crep_epipolarThetaRegion(float theta, float thetaMax, out int k, out float u) {
  crep_epipolarFractionRegion(theta / thetaMax, k, u);
  vec2 angles = crep_epipolarRegionAngles(k, thetaMax);
  u = 0.5 * (tan(theta - angles.x) / angles.y + 1.0);
}

int crep_epipolarSliceIndex(float row) {
  int H = crep_epipolar.counts.x;
  return clamp(int(floor(row * float(H))), 0, H - 1);
}

// Unit direction of the slice at a normalized row, orthogonal to m.
vec3 crep_epipolarSliceDirection(float row) {
  vec2 p = crep_epipolarBorderPoint(crep_epipolar.arc.x + row * crep_epipolar.arc.y);
  vec2 t = crep_epipolar.cameraTan.xy;
  // imageX * tanX = right, imageY * tanY = up: the view ray through NDC p is forward + p.x tanX right + ...
  vec3 w = normalize(crep_epipolar.forward.xyz + (p.x * t.x * t.x) * crep_epipolar.imageX.xyz +
                     (p.y * t.y * t.y) * crep_epipolar.imageY.xyz);
  vec3 m = crep_epipolar.towardLight.xyz;
  return normalize(w - dot(w, m) * m);
}

bool crep_layoutToRectified(vec3 world, out vec4 p) {
  p = vec4(0.0);
  vec3 m = crep_epipolar.towardLight.xyz;
  vec3 q = world - crep_epipolar.origin.xyz;
  float a = dot(q, m);
  vec3 perp = q - a * m;
  float b = length(perp);
  if (!(b > 0.0)) return false;
  float sigma;
  vec2 range;
  if (!crep_epipolarExitSigma(perp / b, sigma, range)) return false;
  float row = crep_epipolarRowOfSigma(sigma);
  vec4 s = crep_slices[crep_epipolarSliceIndex(row)].bounds;
  int k;
  float u;
  float D = crep_epipolar.origin.w;
  if (D > 0.0)
    crep_epipolarThetaRegion(atan(b, D - a), s.x, k, u);
  else
    crep_epipolarFractionRegion(b / s.x, k, u);
  p = vec4(row, (float(k) + u) / float(crep_epipolar.counts.y), (crep_epipolarWarp(atan(b, a)) - s.y) / (s.z - s.y), float(k));
  return true;
}

CrepLightRay crep_layoutLightRay(float column, float row) {
  vec4 s = crep_slices[crep_epipolarSliceIndex(row)].bounds;
  float D = crep_epipolar.origin.w;
  vec3 m = crep_epipolar.towardLight.xyz;
  if (D > 0.0) { // local light: from L at theta to the direction toward the camera
    int K = crep_epipolar.counts.y;
    int k = clamp(int(floor(column * float(K))), 0, K - 1);
    float theta = crep_epipolarRegionTheta(k, column * float(K) - float(k), s.x);
    return CrepLightRay(crep_epipolar.origin.xyz + D * m, -cos(theta) * m + sin(theta) * crep_epipolarSliceDirection(row));
  }
  return CrepLightRay(crep_epipolar.origin.xyz + crep_epipolarColumnFraction(column) * s.x *
                                                     crep_epipolarSliceDirection(row),
                      -crep_epipolar.towardLight.xyz);
}

// The row ray of a normalized row and depth (every point of a ray from the camera shares them) in texel row
// `texelRow` with slice bounds `s`: depth clamped to [0, 1] and the distance data of crep_rowRayDistance,
// T = (b / bMax) bMax / sin(psi) with psi at that depth (a local light: sin(psi), cos(psi), thetaMax). `last`
// is left 0.
CrepRowRay crep_epipolarRowRay(float row, float depth, int texelRow, vec4 s) {
  CrepRowRay r = CrepRowRay(row, clamp(depth, 0.0, 1.0), texelRow, 0, vec4(0.0));
  float psi = crep_epipolarUnwarp(s.y + r.depth * (s.z - s.y));
  if (crep_epipolar.origin.w > 0.0)
    r.dist = vec4(sin(psi), cos(psi), s.x, 0.0);
  else
    r.dist = vec4(s.x / max(sin(psi), 1e-30), 0.0, 0.0, 0.0);
  return r;
}

// The unit direction of the view ray of a normalized row and depth.
vec3 crep_layoutViewDirection(float row, float depth) {
  vec4 s = crep_slices[crep_epipolarSliceIndex(row)].bounds;
  float psi = crep_epipolarUnwarp(s.y + clamp(depth, 0.0, 1.0) * (s.z - s.y));
  return cos(psi) * crep_epipolar.towardLight.xyz + sin(psi) * crep_epipolarSliceDirection(row);
}

CrepRowRay crep_rowRayAt(float row, float depth, ivec2 mapSize) {
  int j = clamp(int(floor(row * float(mapSize.y))), 0, mapSize.y - 1);
  return crep_epipolarRowRay(row, depth, j, crep_slices[j].bounds);
}

// The end point (camera + surface dir) has the ray's slice, psi and b = surface sin(psi): the exit border
// position (four atan) is found once for the ray and its end point.
bool crep_mapRowRayPoint(vec3 dir, float surface, ivec2 mapSize, out CrepRowRay r, out vec4 p) {
  r = CrepRowRay(0.0, 0.0, 0, 0, vec4(0.0));
  p = vec4(0.0);
  vec3 m = crep_epipolar.towardLight.xyz;
  float a = dot(dir, m);
  vec3 perp = dir - a * m;
  float sinPsi = length(perp);
  if (!(sinPsi > 0.0)) return false;
  float sigma;
  vec2 range;
  if (!crep_epipolarExitSigma(perp / sinPsi, sigma, range)) return false;
  float row = crep_epipolarRowOfSigma(sigma);
  int j = clamp(int(floor(row * float(mapSize.y))), 0, mapSize.y - 1);
  vec4 s = crep_slices[j].bounds;
  float depth = (crep_epipolarWarp(atan(sinPsi, a)) - s.y) / (s.z - s.y);
  r = crep_epipolarRowRay(row, depth, j, s);
  int K = crep_epipolar.counts.y, n = mapSize.x / K;
  int k;
  float u;
  float D = crep_epipolar.origin.w;
  if (D > 0.0)
    crep_epipolarThetaRegion(atan(surface * sinPsi, D - surface * a), s.x, k, u);
  else
    crep_epipolarFractionRegion(surface * sinPsi / s.x, k, u);
  r.last = crep_lastTexel(k, u, K, n);
  p = vec4(row, (float(k) + u) / float(K), depth, float(k));
  return true;
}

float crep_rowRayDistance(CrepRowRay r, int i, ivec2 mapSize) {
  int K = crep_epipolar.counts.y, n = mapSize.x / K;
  int k = i / n, q = i - k * n;
  float D = crep_epipolar.origin.w;
  if (D > 0.0) { // local light: the law of sines in the triangle (camera, light, point)
    float theta = k >= K ? r.dist.z : crep_epipolarRegionTheta(k, float(q) / float(n), r.dist.z);
    float den = r.dist.x * cos(theta) + r.dist.y * sin(theta);
    return den > 0.0 ? D * sin(theta) / den : CREP_NEVER;
  }
  if (k >= K) return r.dist.x;
  float f0 = crep_epipolarFraction(k), f1 = crep_epipolarFraction(k + 1);
  return (f0 + (f1 - f0) * float(q) / float(n)) * r.dist.x;
}
#endif // CREP_LAYOUT_EPIPOLAR

#endif // CREP_EPIPOLAR_LAYOUT_GLSL
