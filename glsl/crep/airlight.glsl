// crepuscular: the unshadowed in-scattering of a local light along a view-ray section in closed form (Sun,
// Ramamoorthi, Narasimhan and Nayar 2005, Sec. 3, extended): the float counterpart of
// crep::AirlightScattering::segment (crep/scatter/airlight.h, whose header comment is the rule). With xi the
// angle of Sun et al.'s substitution, the section of a constant-intensity piece is
//   S = I (2 / h) [E(ta) - E(tb)],  E(t) = exp(-sigma (t + d)) (sigma_mie N_hg + sigma_rayleigh N_r)(u, xi) K(u, eta)
// per channel, u = sigma h, eta = pi / 2 - xi, N read from the airlight table (crep::makeAirlightTable: RG32F,
// GL_LINEAR, clamp to edge, bound at CREP_AIRLIGHT_UNIT, default 4) and K = crep_airlightScale. GPU: the
// table's coordinates are chosen so that an end costs square roots, one exp and one fetch per channel (no
// inverse trigonometric function). The pieces: the light reaches one interval of the ray (the spot's outer
// cone, the face's sector: convex); a spot's inner cone is one closed-form piece and its falloff band on
// either side keeps crep_localSegment's quadrature (the falloff varies there); a ray through the near
// ball (h <= nearPlane) keeps the quadrature throughout.
//
// Public include (conventions in crep/common.glsl). Choices for GPUs are marked "GPU:".
#ifndef CREP_AIRLIGHT_GLSL
#define CREP_AIRLIGHT_GLSL

#include "bindings.h"
#include "common.glsl"
#include "local_light.glsl"
#include "phase.glsl"

#ifndef CREP_AIRLIGHT_UNIT
#define CREP_AIRLIGHT_UNIT CREP_AIRLIGHT_DEFAULT_UNIT
#endif
layout(binding = CREP_AIRLIGHT_UNIT) uniform sampler2D crep_airlightTable;

// crep::kAirlightUScale and the corner function's a (airlight.cpp).
#define CREP_AIRLIGHT_U_SCALE 1.0
#define CREP_AIRLIGHT_CORNER_A 0.9135

// crep::airlightScale: K(u, eta) = s G(u / s), s = sin(eta) = cos(xi), G(r) = (1 + a r) / (1 + (1 + 2a) r +
// a r^2) (written over r^2 above r = 1 so that r^2 never overflows).
float crep_airlightScale(float u, float s) {
  if (!(s > 0.0)) return 0.0;
  float r = u / s, a = CREP_AIRLIGHT_CORNER_A;
  if (r <= 1.0) return s * (1.0 + a * r) / (1.0 + (1.0 + 2.0 * a) * r + a * r * r);
  float q = 1.0 / r;
  return s * (q * q + a * q) / (q * q + (1.0 + 2.0 * a) * q + a);
}

// The table's row of u (crep::airlightURow: the root y of c y^2 = u (1 - y)).
float crep_airlightRow(float u) {
  float c = CREP_AIRLIGHT_U_SCALE;
  return u > 0.0 ? (u < 1e6 ? 2.0 * u / (u + sqrt(u * u + 4.0 * c * u)) : 1.0) : 0.0;
}

// N of both phase functions at row y and column x (crep::AirlightTable::lookup), texel centres at the grid.
vec2 crep_airlightN(float y, float x) {
  vec2 size = vec2(textureSize(crep_airlightTable, 0));
  return textureLod(crep_airlightTable, (vec2(x, y) * (size - 1.0) + 0.5) / size, 0.0).rg;
}

// E at u = t - t0 per channel (t = t0 + u). The table's column and K come from the geometry with square
// roots alone: with d + u and d - u (formed without cancellation, their product h^2), sin^2 xi = (d + u) / 2d,
// cos^2 xi = (d - u) / 2d and x = (d + u)^1/4 / ((d + u)^1/4 + (d - u)^1/4) (crep::airlightXiColumn). GPU:
// a grey medium (one extinction) reads the table once; the branch is uniform over the dispatch.
vec3 crep_airlightEnd(CrepLocalMedium m, CrepLocalRay r, float u) {
  float h2 = r.h * r.h, d = sqrt(h2 + u * u);
  float dp = u >= 0.0 ? d + u : h2 / (d - u), dm = u >= 0.0 ? h2 / (d + u) : d - u;
  float qp = sqrt(sqrt(dp)), qm = sqrt(sqrt(dm));
  float x = qp / (qp + qm), s = sqrt(dm / (2.0 * d)); // s = cos xi = sin eta
  vec3 decay = exp(-m.extinction * (r.t0 + u + d));
  if (m.extinction.r == m.extinction.g && m.extinction.g == m.extinction.b) {
    float uu = m.extinction.r * r.h;
    vec2 N = crep_airlightN(crep_airlightRow(uu), x);
    return decay * (m.mie.rgb * N.x + m.rayleigh * N.y) * crep_airlightScale(uu, s);
  }
  vec3 E;
  for (int c = 0; c < 3; ++c) {
    float uu = m.extinction[c] * r.h;
    vec2 N = crep_airlightN(crep_airlightRow(uu), x);
    E[c] = decay[c] * (m.mie[c] * N.x + m.rayleigh[c] * N.y) * crep_airlightScale(uu, s);
  }
  return E;
}

// crep_localSegment's quadrature on a piece [u1, u2] outside the near ball (parts of at most gammaStep in
// gamma, 3-point Gauss-Legendre): the spot's falloff band.
vec3 crep_airlightBand(CrepLocalLight l, CrepLocalMedium m, CrepLocalRay r, float u1, float u2) {
  if (!(u2 > u1)) return vec3(0.0);
  float xa = atan(u1 / r.hq), xb = atan(u2 / r.hq);
  int parts = clamp(int(ceil((xb - xa) / r.gammaStep)), 1, CREP_LOCAL_MAX_PARTS);
  vec3 total = vec3(0.0);
  for (int k = 0; k < CREP_LOCAL_MAX_PARTS; ++k) {
    if (k >= parts) break;
    total += crep_localGaussLegendre(l, m, r, xa + (xb - xa) * float(k) / float(parts),
                                     xa + (xb - xa) * float(k + 1) / float(parts), true);
  }
  return total;
}

// S(ta, tb) per channel (see the top); 0 when tb <= ta. A ray that passes through the light's near ball
// keeps crep_localSegment's quadrature.
vec3 crep_airlightSegment(CrepLocalLight l, CrepLocalMedium m, vec3 origin, vec3 dir, float ta, float tb) {
  if (!(tb > ta)) return vec3(0.0);
  CrepLocalRay r = crep_localRay(l, m, origin, dir);
  if (!(r.h > l.nearPlane)) return crep_localSegment(l, m, origin, dir, ta, tb);
  vec2 lit = crep_localReachU(l, r, ta - r.t0, tb - r.t0);
  if (!(lit.x < lit.y)) return vec3(0.0);
  vec3 I = l.intensity * (2.0 / r.h);
  if (!l.cone) return I * (crep_airlightEnd(m, r, lit.x) - crep_airlightEnd(m, r, lit.y));
  // A spot: closed form inside the inner cone, the quadrature on the falloff band on either side.
  vec2 inner = crep_coneInterval(r, l.axis, l.cosInner, lit.x, lit.y);
  if (!(inner.x < inner.y)) return crep_airlightBand(l, m, r, lit.x, lit.y);
  return crep_airlightBand(l, m, r, lit.x, inner.x) +
         I * (crep_airlightEnd(m, r, inner.x) - crep_airlightEnd(m, r, inner.y)) +
         crep_airlightBand(l, m, r, inner.y, lit.y);
}

#endif // CREP_AIRLIGHT_GLSL
