// crepuscular: the in-scattering of a view-ray section for a local light, a spot light or one face of a
// point light (Klehm et al. 2014, Eq. 1; Sec. 3.2 "Local Lights": a point light is six perspective
// faces, each lighting the sector of directions whose major axis is its own, and "Angular-dependency for
// Sources": the spot's angular weighting). GLSL counterpart in float of crep::RayScattering::segment for a
// crep::LocalLight (crep/scatter/ray_scattering.h, whose header comment is the rule): for the view ray
// x(t) = origin + t dir (dir unit) and a lit section [ta, tb],
//
//   S(ta, tb) = integral_ta^tb exp(-sigma t) sigma_s p(theta(t)) I(w) exp(-sigma dc) / dc^2 dt
//
// per RGB channel, with w the unit direction from the light to x(t), d = |x(t) - position|, dc = max(d,
// nearPlane), I(w) the intensity times the spot falloff t^2 (3 - 2 t) (crep::spotFalloff) and, for a
// point face, 0 outside the face's sector (crep::PointLight::faceOf), theta the scattering angle
// (cos theta = dot(w, -dir)). The same breakpoints (the near ball, the cone angles, the sector planes),
// the same substitution t = t0 + hq tan gamma (hq = max(h, nearPlane), t0 and h the nearest point of the
// ray's line to the light and its distance), and a cheaper rule on the pieces: parts of at most twice the
// CPU's gammaStep (clamp(min(pi / 32, (1 - |g|) / 2), 1e-3, ...)) with 3-point Gauss-Legendre on each
// (the CPU: gammaStep, 8 points), 8 parts in t inside the near ball. Add the six faces' results for a
// whole point light. The result is the radiance itself (no C factor as for a directional light).
//
// Public include (conventions in crep/common.glsl). Choices for GPUs (float only, no fp64; few
// registers; fixed loop bounds) are marked "GPU:" below. Differences to the CPU reference are float
// rounding and the cheaper rule (crep_localGaussLegendre: at most 1.7e-5 of a ray's sum): the GL test
// (tests/scatter/WorldMarchLocalGLTest.cpp) compares the world march with it.
#ifndef CREP_LOCAL_LIGHT_GLSL
#define CREP_LOCAL_LIGHT_GLSL

#include "common.glsl"
#include "phase.glsl"

// GPU: the loop bound of the Gauss-Legendre parts of one smooth piece. ceil(pi / 2e-3) = 1571 is the most
// the rule can ask for (a piece spans less than pi radians, gammaStep >= 2e-3), so the bound never
// coarsens the rule; the loop ends at the piece's own part count (16 at most for |g| <= 0.8).
#ifndef CREP_LOCAL_MAX_PARTS
#define CREP_LOCAL_MAX_PARTS 1571
#endif

// GPU: the breakpoints of a section: its two ends, 2 near-ball crossings, 2 x 2 cone crossings (inner,
// outer) and 4 sector planes: the 10 inner candidates sit unsorted in three vec4 registers
// (CrepLocalCuts) and the pieces are walked in order by taking the smallest candidate above the current
// end (the CPU collects them in a vector and sorts: the same pieces). No dynamically indexed local array:
// llvmpipe (and many GPUs) keep those in scratch memory, and its mere presence in a shader halved the
// local light's evaluation speed on llvmpipe (measured: table 194 -> 76 ms, per-pixel 524 -> 264 ms at
// 1920x1080 for one spot, the analytic scene).
#define CREP_LOCAL_MAX_PIECES 11

// A local light (crep::LocalLight): a spot light, or face `face` of a point light.
struct CrepLocalLight {
  vec3 position;   // world
  vec3 intensity;  // radiant intensity per channel (on the axis for a spot)
  vec3 axis;       // spot: unit axis (the direction the light points); point face: the face's axis
  float nearPlane; // d is clamped below at it (the light is a ball of that radius)
  float cosInner;  // spot falloff: full intensity for cos(angle to axis) >= cosInner
  float cosOuter;  // spot falloff: none for cos(angle to axis) <= cosOuter
  bool cone;       // the spot falloff applies
  int face;        // point light face 0..5 (+x, -x, +y, -y, +z, -z), -1: every direction
};

// The medium of crep::Medium as the integrand sees it: mie = (rgb sigma_s of the Henyey-Greenstein part,
// w g), rayleigh = rgb sigma_s of the Rayleigh part, extinction = rgb sigma_t.
struct CrepLocalMedium {
  vec4 mie;
  vec3 rayleigh;
  vec3 extinction;
};

// The light of the packed vectors of gpu::MarchParams (crep/march.glsl: lightPosition, lightAxis,
// lightCone, lightIntensity).
CrepLocalLight crep_localLight(vec4 position, vec4 axis, vec4 cone, vec4 intensity) {
  CrepLocalLight l;
  l.position = position.xyz;
  l.intensity = intensity.rgb;
  l.axis = axis.xyz;
  l.nearPlane = cone.z;
  l.cosInner = cone.x;
  l.cosOuter = cone.y;
  l.cone = cone.w > 0.5;
  l.face = int(round(axis.w));
  return l;
}

// crep::PointLight::faceOf: the face whose sector holds w (ties go to the lower axis, then to +).
int crep_pointFaceOf(vec3 w) {
  vec3 a = abs(w);
  int major = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
  return 2 * major + (w[major] >= 0.0 ? 0 : 1);
}

// crep::spotFalloff: s = t^2 (3 - 2 t), t = clamp((cosAngle - cosOuter) / (cosInner - cosOuter), 0, 1).
float crep_spotFalloff(float cosAngle, float cosInner, float cosOuter) {
  float t = clamp((cosAngle - cosOuter) / (cosInner - cosOuter), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

// crep::LocalLight::intensityToward: the radiant intensity toward unit direction w.
vec3 crep_localIntensityToward(CrepLocalLight l, vec3 w) {
  if (l.face >= 0 && crep_pointFaceOf(w) != l.face) return vec3(0.0);
  if (l.cone) return l.intensity * crep_spotFalloff(dot(w, l.axis), l.cosInner, l.cosOuter);
  return l.intensity;
}

// The ray as the integrand sees it. GPU: positions are relative to the nearest point of the ray's line
// to the light, x(t) - position = perp + u dir with u = t - t0 (perp orthogonal to dir, |perp| = h), so
// d, w and cos theta carry no cancellation of two large float vectors (the CPU forms x(t) - position in
// double).
struct CrepLocalRay {
  vec3 perp; // nearest point of the line minus the light position
  vec3 dir;  // unit
  float t0;  // parameter of the nearest point
  float h;   // |perp|
  float hq;  // max(h, nearPlane): the substitution's scale
  float gammaStep;
};

CrepLocalRay crep_localRay(CrepLocalLight l, CrepLocalMedium m, vec3 origin, vec3 dir) {
  CrepLocalRay r;
  vec3 p = origin - l.position;
  r.dir = dir;
  r.t0 = -dot(p, dir);
  r.perp = p + r.t0 * dir;
  r.h = length(r.perp);
  r.hq = max(r.h, l.nearPlane);
  // GPU: twice the CPU's step (see crep_localGaussLegendre).
  r.gammaStep = 2.0 * max(min(float(CREP_PI / 32.0), 0.5 * (1.0 - abs(m.mie.w))), 1e-3);
  return r;
}

// exp(-sigma t) sigma_s p(theta) I(w) exp(-sigma dc) at u = t - t0, without the 1 / dc^2 (the caller's
// Jacobian holds it).
vec3 crep_localDensityNumerator(CrepLocalLight l, CrepLocalMedium m, CrepLocalRay r, float u) {
  float d = sqrt(r.h * r.h + u * u);
  vec3 w = d > 0.0 ? (r.perp + u * r.dir) / d : r.dir;
  float cosTheta = d > 0.0 ? -u / d : -1.0; // dot(w, -dir): perp is orthogonal to dir
  float dc = max(d, l.nearPlane);
  vec3 phase =
      m.mie.rgb * crep_henyeyGreenstein(m.mie.w, cosTheta) + m.rayleigh * crep_rayleighPhase(cosTheta);
  return exp(-m.extinction * (r.t0 + u + dc)) * phase * crep_localIntensityToward(l, w);
}

// crep::RayScattering::density at u = t - t0.
vec3 crep_localDensity(CrepLocalLight l, CrepLocalMedium m, CrepLocalRay r, float u) {
  float dc = max(sqrt(r.h * r.h + u * u), l.nearPlane);
  return crep_localDensityNumerator(l, m, r, u) / (dc * dc);
}

// The integrand in gamma: density(t(gamma)) dt / dgamma, t = t0 + hq tan gamma. GPU: the Jacobian
// hq / (cos^2 gamma dc^2) is evaluated as hq / max(h^2 cos^2 + hq^2 sin^2, near^2 cos^2) (the same value:
// cos^2 d^2 = h^2 cos^2 + (hq sin)^2), which stays finite and accurate in float as gamma nears +-pi/2.
vec3 crep_localIntegrandInGamma(CrepLocalLight l, CrepLocalMedium m, CrepLocalRay r, float gamma) {
  float s = sin(gamma), c = cos(gamma);
  float u = r.hq * s / c;
  float cc = c * c;
  float jacobian = r.hq / max(r.h * r.h * cc + r.hq * r.hq * s * s, l.nearPlane * l.nearPlane * cc);
  return crep_localDensityNumerator(l, m, r, u) * jacobian;
}

// The integrand at x of a piece: in gamma (inGamma; crep_localIntegrandInGamma) or in u = t - t0
// (crep_localDensity). GPU: one evaluation with the variable chosen by selects, not two functions behind a
// branch: lanes of a SIMD group (GPU warps, llvmpipe's vectors) that differ in the kind of their piece
// would otherwise run both.
vec3 crep_localIntegrand(CrepLocalLight l, CrepLocalMedium m, CrepLocalRay r, float x, bool inGamma) {
  float s = sin(x), c = cos(x);
  float u = inGamma ? r.hq * s / c : x;
  float cc = c * c, near2 = l.nearPlane * l.nearPlane;
  float jacobian = inGamma ? r.hq / max(r.h * r.h * cc + r.hq * r.hq * s * s, near2 * cc)
                           : 1.0 / max(r.h * r.h + u * u, near2);
  return crep_localDensityNumerator(l, m, r, u) * jacobian;
}

// 3-point Gauss-Legendre on [a, b], in gamma (inGamma) or in u = t - t0. GPU: 3 points on parts of twice
// the CPU's gammaStep instead of its 8 points on parts of gammaStep (crep::RayScattering::segment): 3.6x
// fewer integrand evaluations on a 16-region view ray (20.6 parts x 3 against 28 x 8, rays of the
// scattering prefix table), for a quadrature error that stays below float resolution in practice:
// measured against the CPU rule in double over 3000 random rays (16 segments each, g in [0, 0.8],
// sigma in [0.003, 0.3], lengths up to 100), worst relative error of a ray's sum 1.7e-5, RMS 3.2e-7 (8
// points: 1e-9; 2 points on these parts: 2.2e-4).
vec3 crep_localGaussLegendre(CrepLocalLight l, CrepLocalMedium m, CrepLocalRay r, float a, float b,
                             bool inGamma) {
  const float node = 0.7745966692414834, wEnd = 0.5555555555555556, wMid = 0.8888888888888889;
  float mid = 0.5 * (a + b), dx = 0.5 * (b - a) * node;
  vec3 sum = wEnd * (crep_localIntegrand(l, m, r, mid - dx, inGamma) + crep_localIntegrand(l, m, r, mid + dx, inGamma)) +
             wMid * crep_localIntegrand(l, m, r, mid, inGamma);
  return sum * (0.5 * (b - a));
}

// The inner breakpoints of a section, unsorted: a candidate outside (lo, hi) is stored as hi (no cut).
struct CrepLocalCuts {
  vec4 c0, c1, c2; // near ball (2), inner cone (2); outer cone (2), unused (2); sector planes (4)
};

// The cone crossings of cos(angle to the axis) = cosAngle on the forward nappe, in u: (bp + a u)^2 =
// c2 (h^2 + u^2) with bp + a u >= 0 (the CPU's quadratic in t, shifted by t0; the stable root pair). Either
// root is `none` when it is not a cut.
vec2 crep_localConeCuts(float a, float bp, float h2, float cosAngle, float none) {
  float c2 = cosAngle * cosAngle;
  float qa = a * a - c2, qb = 2.0 * a * bp, qc = bp * bp - c2 * h2;
  float scale = max(abs(qa), max(abs(qb), abs(qc)));
  vec2 roots = vec2(none);
  if (!(scale > 0.0)) return roots;
  if (abs(qa) <= 1e-7 * scale) { // GPU: the float counterpart of the CPU's 1e-14
    if (qb != 0.0) roots.x = -qc / qb;
  } else {
    float disc = qb * qb - 4.0 * qa * qc;
    if (disc < 0.0) return vec2(none);
    float q = -0.5 * (qb + (qb >= 0.0 ? 1.0 : -1.0) * sqrt(disc));
    roots.x = q / qa;
    if (q != 0.0) roots.y = qc / q;
  }
  return mix(vec2(none), roots, greaterThanEqual(vec2(bp) + a * roots, vec2(0.0)));
}

// The inner breakpoints of the section [lo, hi] (in u = t - t0) into smooth pieces: the near ball's
// crossings, the cone angles' (inner, outer) and the sector planes' (crep::RayScattering::breakpoints).
CrepLocalCuts crep_localCuts(CrepLocalLight l, CrepLocalRay r, float lo, float hi) {
  CrepLocalCuts k = CrepLocalCuts(vec4(hi), vec4(hi), vec4(hi));
  float near2 = l.nearPlane * l.nearPlane, h2 = r.h * r.h;
  // The near ball: |perp + u dir| = near at u = +-sqrt(near^2 - h^2).
  if (h2 < near2) {
    float e = sqrt(near2 - h2);
    k.c0.xy = vec2(-e, e);
  }
  if (l.cone) {
    float a = dot(r.dir, l.axis), bp = dot(r.perp, l.axis);
    k.c0.zw = crep_localConeCuts(a, bp, h2, l.cosInner, hi);
    k.c1.xy = crep_localConeCuts(a, bp, h2, l.cosOuter, hi);
  }
  if (l.face >= 0) {
    int major = l.face / 2;
    int j0 = major == 0 ? 1 : 0, j1 = major == 2 ? 1 : 2; // the two other axes
    vec4 slope = vec4(r.dir[major]) - vec4(r.dir[j0], -r.dir[j0], r.dir[j1], -r.dir[j1]);
    vec4 offset = vec4(r.perp[major]) - vec4(r.perp[j0], -r.perp[j0], r.perp[j1], -r.perp[j1]);
    k.c2 = mix(vec4(hi), -offset / slope, notEqual(slope, vec4(0.0)));
  }
  k.c0 = mix(vec4(hi), k.c0, bvec4(uvec4(greaterThan(k.c0, vec4(lo))) & uvec4(lessThan(k.c0, vec4(hi)))));
  k.c1 = mix(vec4(hi), k.c1, bvec4(uvec4(greaterThan(k.c1, vec4(lo))) & uvec4(lessThan(k.c1, vec4(hi)))));
  k.c2 = mix(vec4(hi), k.c2, bvec4(uvec4(greaterThan(k.c2, vec4(lo))) & uvec4(lessThan(k.c2, vec4(hi)))));
  return k;
}

// The smallest breakpoint above u (hi when none is).
float crep_localNextCut(CrepLocalCuts k, float u, float hi) {
  vec4 m = min(mix(vec4(hi), k.c0, greaterThan(k.c0, vec4(u))),
               min(mix(vec4(hi), k.c1, greaterThan(k.c1, vec4(u))), mix(vec4(hi), k.c2, greaterThan(k.c2, vec4(u)))));
  return min(min(m.x, m.y), min(m.z, m.w));
}

// The interval of u in [lo, hi] where the angle to the axis is below acos(cosAngle) on the cone's forward
// nappe (the cone is convex for angles below 90 degrees, so a line meets it in one interval):
// vec2(first, last), first > last when empty. Straight-line code: the roots of crep_localConeCuts' quadratic,
// no sorted array. GPU: no dynamically indexed local array (on llvmpipe and many GPUs those live in scratch
// memory).
vec2 crep_coneInterval(CrepLocalRay r, vec3 axis, float cosAngle, float lo, float hi) {
  float a = dot(r.dir, axis), bp = dot(r.perp, axis), h2 = r.h * r.h;
  float c2 = cosAngle * cosAngle;
  float qa = a * a - c2, qb = 2.0 * a * bp, qc = bp * bp - c2 * h2;
  float scale = max(abs(qa), max(abs(qb), abs(qc)));
  float r0 = hi, r1 = hi;
  int count = 0;
  if (scale > 0.0) {
    float x0 = lo - 1.0, x1 = lo - 1.0; // not roots
    if (abs(qa) <= 1e-7 * scale) {
      if (qb != 0.0) x0 = -qc / qb;
    } else {
      float disc = qb * qb - 4.0 * qa * qc;
      if (disc >= 0.0) {
        float q = -0.5 * (qb + (qb >= 0.0 ? 1.0 : -1.0) * sqrt(disc));
        x0 = q / qa;
        if (q != 0.0) x1 = qc / q;
      }
    }
    bool v0 = x0 > lo && x0 < hi && bp + a * x0 >= 0.0, v1 = x1 > lo && x1 < hi && bp + a * x1 >= 0.0;
    if (v0 && v1) {
      r0 = min(x0, x1);
      r1 = max(x0, x1);
      count = 2;
    } else if (v0 || v1) {
      r0 = v0 ? x0 : x1;
      count = 1;
    }
  }
  // Inside at lo: dot(p, axis) > cosAngle |p| at the point, scaled so that a far lo never overflows.
  float k = 1.0 / (1.0 + abs(lo));
  vec3 p = r.perp * k + r.dir * (lo * k);
  bool inside = dot(p, axis) > cosAngle * length(p);
  if (inside) return vec2(lo, count >= 1 ? r0 : hi);
  if (count == 0) return vec2(1.0, 0.0);
  return vec2(r0, count >= 2 ? r1 : hi);
}

// The interval of u in [lo, hi] inside point face `face`'s sector (crep::PointLight::faceOf): four half-spaces
// through the light, s p_major >= |p_j| for the two other axes j, clipped one by one.
vec2 crep_sectorInterval(CrepLocalRay r, int face, float lo, float hi) {
  int major = face / 2;
  float s = face % 2 == 0 ? 1.0 : -1.0;
  vec2 range = vec2(lo, hi);
  for (int j = 0; j < 3; ++j) {
    if (j == major) continue;
    for (int k = 0; k < 2; ++k) {
      float sgn = k == 0 ? 1.0 : -1.0;
      float f0 = s * r.perp[major] - sgn * r.perp[j], f1 = s * r.dir[major] - sgn * r.dir[j]; // f0 + u f1 >= 0
      if (f1 > 0.0) range.x = max(range.x, -f0 / f1);
      else if (f1 < 0.0) range.y = min(range.y, -f0 / f1);
      else if (f0 < 0.0) range = vec2(1.0, 0.0);
    }
  }
  return range.x <= range.y ? range : vec2(1.0, 0.0);
}

// The part of [lo, hi] (in u = t - t0) the light reaches outside its near ball: the spot's outer cone, the
// face's sector, or all of it.
vec2 crep_localReachU(CrepLocalLight l, CrepLocalRay r, float lo, float hi) {
  if (l.cone) return crep_coneInterval(r, l.axis, l.cosOuter, lo, hi);
  if (l.face >= 0) return crep_sectorInterval(r, l.face, lo, hi);
  return vec2(lo, hi);
}

// The part [first, last] of [ta, tb] (in t) the light reaches: the spot's outer cone, the face's sector;
// first > last when it reaches none of it, so S(ta, tb) = 0 and a caller can skip the work. A ray through
// the near ball counts as reached throughout.
vec2 crep_localReach(CrepLocalLight l, CrepLocalRay r, float ta, float tb) {
  if (!(tb > ta)) return vec2(1.0, 0.0);
  if (!(r.h > l.nearPlane)) return vec2(ta, tb);
  vec2 u = crep_localReachU(l, r, ta - r.t0, tb - r.t0);
  return u.x <= u.y ? u + r.t0 : vec2(1.0, 0.0);
}

// The share of S(ta, tEnd) that [ta, tb] holds (ta <= tb <= tEnd), per channel, by the trapezoid rule in
// gamma on the part the light reaches (crep::RayScattering::partialShare): the evaluation's last region
// takes its section from the table of its sample rays times this share of its own ray (one integrand at
// each of three points instead of a quadrature of the region). Exact for an integrand constant in gamma
// (the 1 / d^2 peak is the substitution's); 1 when the light reaches the region's ray only before tb.
vec3 crep_localPartialShare(CrepLocalLight l, CrepLocalMedium m, vec3 origin, vec3 dir, float ta, float tb,
                            float tEnd) {
  CrepLocalRay r = crep_localRay(l, m, origin, dir);
  vec2 lit = r.h > l.nearPlane ? crep_localReachU(l, r, ta - r.t0, tEnd - r.t0) : vec2(ta, tEnd) - r.t0;
  if (!(lit.x < lit.y)) return vec3(0.0);
  // Inside the part the light reaches a point face's sector holds by construction: its ends lie on the
  // sector's planes, where a sector test in float could fall on either side.
  if (r.h > l.nearPlane) l.face = -1;
  float ub = clamp(tb - r.t0, lit.x, lit.y);
  // GPU: gamma kept 1e-6 inside +-pi / 2: float(pi / 2) exceeds pi / 2, and its cosine's sign flips t(gamma)
  // to the far other end of the line (a section ending at CREP_LOCAL_SECTION_END reaches it).
  const float gmax = float(CREP_PI / 2.0) - 1e-6;
  float ga = clamp(atan(lit.x / r.hq), -gmax, gmax), gb = clamp(atan(ub / r.hq), -gmax, gmax),
        ge = clamp(atan(lit.y / r.hq), -gmax, gmax);
  vec3 fa = crep_localIntegrand(l, m, r, ga, true), fb = crep_localIntegrand(l, m, r, gb, true),
       fe = crep_localIntegrand(l, m, r, ge, true);
  vec3 fab = crep_localIntegrand(l, m, r, 0.5 * (ga + gb), true), fbe = crep_localIntegrand(l, m, r, 0.5 * (gb + ge), true);
  vec3 part = (gb - ga) * (fa + 4.0 * fab + fb), rest = (ge - gb) * (fb + 4.0 * fbe + fe);
  vec3 whole = part + rest;
  return mix(vec3((gb - ga) / max(ge - ga, 1e-30)), part / max(whole, vec3(1e-37)), greaterThan(whole, vec3(0.0)));
}

// S(ta, tb) per channel for the view ray origin + t dir (dir unit); 0 when tb <= ta. The float
// counterpart of crep::RayScattering::segment (see the top). GPU: the ray's constants (CrepLocalRay) are recomputed per
// call (a dot product and a length) rather than held by the caller across its march (few registers).
vec3 crep_localSegment(CrepLocalLight l, CrepLocalMedium m, vec3 origin, vec3 dir, float ta, float tb) {
  if (!(tb > ta)) return vec3(0.0);
  CrepLocalRay r = crep_localRay(l, m, origin, dir);
  float lo = ta - r.t0, hi = tb - r.t0;
  CrepLocalCuts cuts = crep_localCuts(l, r, lo, hi);
  float near2 = l.nearPlane * l.nearPlane, h2 = r.h * r.h;

  vec3 total = vec3(0.0);
  float u1 = lo;
  for (int i = 0; i < CREP_LOCAL_MAX_PIECES; ++i) {
    if (!(u1 < hi)) break;
    float u2 = crep_localNextCut(cuts, u1, hi);
    // A piece inside the near ball: 8 equal parts in u; outside: parts of at most gammaStep in gamma. GPU:
    // one loop for both kinds (lanes on pieces of different kinds share it).
    float um = 0.5 * (u1 + u2);
    bool inGamma = !(h2 + um * um < near2);
    float xa = inGamma ? atan(u1 / r.hq) : u1, xb = inGamma ? atan(u2 / r.hq) : u2;
    int parts = inGamma ? clamp(int(ceil((xb - xa) / r.gammaStep)), 1, CREP_LOCAL_MAX_PARTS) : 8;
    for (int k = 0; k < CREP_LOCAL_MAX_PARTS; ++k) {
      if (k >= parts) break;
      total += crep_localGaussLegendre(l, m, r, xa + (xb - xa) * float(k) / float(parts),
                                       xa + (xb - xa) * float(k + 1) / float(parts), inGamma);
    }
    u1 = u2;
  }
  return total;
}

#endif // CREP_LOCAL_LIGHT_GLSL
