// crepuscular: the Earth atmosphere's tables and their look-ups (GLSL twin of crep/atmosphere/atmosphere.h,
// whose top comment states the units, frames, parameterisation and packing; float precision).
//
// Public include (conventions in crep/common.glsl). An engine reads the tables of AtmosphereTablesPass
// (crep/atmosphere/gpu_tables.h) in its own shaders, e.g. the sun's transmittance and the ambient sky
// light of its terrain shading:
//   layout(std140, binding = 0) uniform CrepAtmosphereBlock { CrepAtmosphereParams crep_atmosphere; };
//   vec3 p = crep_atmospherePosition(crep_atmosphere, worldPosition);
//   vec3 sun = crep_sunTransmittance(opticalDepthTexture, crep_atmosphere, p, toSun);
// The block declaration is each shader's own (binding of its choice). Positions are metres around the
// planet centre (0, 0, 0), zenith +y: a float has ~0.5 m resolution at the planet's surface (6.4e6 m), so
// altitudes computed from positions are good to ~0.5 m (the table precomputation avoids that by working
// with offsets from its texel's point, see crep_atmosphereRayPoint).
//
// Samplers: the 4D tables (GL_TEXTURE_3D) and the optical depth and ambient tables (GL_TEXTURE_2D) must be
// read with GL_LINEAR and clamp to edge (AtmosphereTablesPass's textures are set up so).
#ifndef CREP_ATMOSPHERE_GLSL
#define CREP_ATMOSPHERE_GLSL

#include "common.glsl"
#include "phase.glsl"

// gpu::AtmosphereParams (std140): the block CrepAtmosphereBlock { CrepAtmosphereParams crep_atmosphere; }.
struct CrepAtmosphereParams {
  vec4 radii;              // x: R, y: R + H_Atm, z: H_Atm, w: kOccludedDensity
  vec4 rayleighScattering; // rgb: beta_R; w: H_R
  vec4 mieScattering;      // rgb: beta_M; w: H_M
  vec4 mieExtinction;      // rgb: beta_M + mie absorption; w: g
  ivec4 tableSize;         // N_h, N_alpha, N_phi, N_theta
  ivec4 auxSizes;          // optical depth width (altitude), height (zenith); ambient size; orders
  vec4 placement;          // x: metersPerUnit; y: originAltitude; zw: 0
  vec4 multipleScattering; // x: ground albedo; y: Psi_ms texels per side; z: Psi_ms steps; w: 0
};

// (Rayleigh, Mie) densities at altitude h (clamped to >= 0): exp(-h / H) (Bruneton and Neyret 2008, Sec. 2).
vec2 crep_atmosphereDensity(CrepAtmosphereParams a, float h) {
  return exp(-max(h, 0.0) / vec2(a.rayleighScattering.w, a.mieScattering.w));
}

// RGB extinction of the (Rayleigh, Mie) density integrals D: beta_R D.x + beta_Me D.y.
vec3 crep_atmosphereExtinction(CrepAtmosphereParams a, vec2 D) {
  return a.rayleighScattering.rgb * D.x + a.mieExtinction.rgb * D.y;
}

// In-scattering coefficient times phase for scattering cosine cosTheta at densities d (Yusov 2013, Eq. 1's
// integrand without the radiance): beta_R d_R p_R + beta_M d_M p_HG.
vec3 crep_atmosphereScattering(CrepAtmosphereParams a, vec2 d, float cosTheta) {
  return a.rayleighScattering.rgb * (d.x * crep_rayleighPhase(cosTheta)) +
         a.mieScattering.rgb * (d.y * crep_henyeyGreenstein(a.mieExtinction.w, cosTheta));
}

// cos of the horizon's zenith angle at altitude h: -sqrt(h (2R + h)) / (R + h) (Yusov 2013, Eq. 5's c_h).
float crep_cosHorizon(CrepAtmosphereParams a, float h) {
  float R = a.radii.x;
  h = max(h, 0.0);
  return -sqrt(h * (2.0 * R + h)) / (R + h);
}

// crep::horizonBlendWidth: the half-width in cos zenith of the band around the horizon where Eq. 8's
// segment values are blended from a ray just below and one just above it (Bruneton and Neyret 2008's fix):
// the spread of the horizon cosine between the two altitude texels around h, plus 0.004.
float crep_horizonBlendWidth(CrepAtmosphereParams a, float h) {
  int N = a.tableSize.x;
  float H = a.radii.z;
  float u = sqrt(clamp(h / H, 0.0, 1.0)) * float(N - 1);
  int i0 = clamp(int(floor(u)), 0, N - 2);
  float x = float(i0) / float(N - 1), y = float(i0 + 1) / float(N - 1);
  return 2.0 * abs(crep_cosHorizon(a, H * y * y) - crep_cosHorizon(a, H * x * x)) + 0.004;
}

// Texture coordinate of u in [0, 1] for a dimension of n texels (texel i's centre at u = i / (n - 1)).
float crep_atmosphereTexCoord(float u, int n) { return (0.5 + u * float(n - 1)) / float(n); }

// u_alpha's texture coordinate (Yusov 2013, Eq. 5 and Listing 2) from the half (below the horizon or not)
// and the ratio (c_h - c_alpha) / (c_h + 1) below, (c_alpha - c_h) / (1 - c_h) above.
float crep_atmosphereAlphaCoord(int nAlpha, bool below, float ratio) {
  float t = pow(clamp(ratio, 0.0, 1.0), 0.2);
  float halfN = float(nAlpha / 2);
  float n = float(nAlpha);
  return below ? (0.5 + t * (halfN - 1.0)) / n : (halfN + 0.5 + t * (halfN - 1.0)) / n;
}

// u_phi (Yusov 2013, Eq. 6, Bruneton's form) and u_theta (Eq. 7), each in [0, 1].
float crep_atmosphereSunZenithU(float cosSunZenith) {
  return clamp(0.5 * (atan(max(cosSunZenith, -0.1975) * tan(1.26 * 1.1)) / 1.1 + (1.0 - 0.26)), 0.0, 1.0);
}
float crep_atmosphereSunViewU(float cosSunView) {
  float gamma = acos(clamp(cosSunView, -1.0, 1.0)) * float(CREP_INV_PI);
  float u = gamma >= 0.5 ? 0.5 + 0.5 * pow(2.0 * (gamma - 0.5), 1.5) : 0.5 - 0.5 * pow(2.0 * (0.5 - gamma), 1.5);
  return clamp(u, 0.0, 1.0);
}

// World parameters -> texture coordinates of the 4D table (Yusov 2013, Eq. 4-7, Listing 2;
// crep::atmosphereTableCoords). `previous`: the previous look-up's coordinates of the same ray, negative
// for the first (its y decides the side of the horizon).
vec4 crep_atmosphereTableCoords(CrepAtmosphereParams a, float h, float cosViewZenith, float cosSunZenith,
                                float cosSunView, vec4 previous) {
  float H = a.radii.z;
  h = clamp(h, 0.0, H);
  float cA = clamp(cosViewZenith, -1.0, 1.0);
  float cP = clamp(cosSunZenith, -1.0, 1.0);
  float cT = clamp(cosSunView, -1.0, 1.0);
  float ch = crep_cosHorizon(a, h);
  bool above = previous.y >= 0.5 || (previous.y < 0.0 && cA > ch);
  float ratio = above ? (cA - ch) / (1.0 - ch) : (ch - cA) / (ch + 1.0);
  return vec4(crep_atmosphereTexCoord(sqrt(h / H), a.tableSize.x),
              crep_atmosphereAlphaCoord(a.tableSize.y, !above, ratio),
              crep_atmosphereTexCoord(crep_atmosphereSunZenithU(cP), a.tableSize.z),
              crep_atmosphereTexCoord(crep_atmosphereSunViewU(cT), a.tableSize.w));
}

// Listing 1 (Yusov 2013): the packed 4D table at `coords`, GL trilinear in the packed dimensions (the
// phi coordinate clamped to its slice's texel centres) and linear between the two theta slices; RGBA
// (crep::sampleAtmosphereTableRgba).
vec4 crep_sampleAtmosphereTableRgba(sampler3D table, CrepAtmosphereParams a, vec4 coords) {
  float nPhi = float(a.tableSize.z);
  float nTheta = float(a.tableSize.w);
  float q = coords.w * nTheta - 0.5;
  float q0 = clamp(floor(q), 0.0, nTheta - 1.0);
  float weight = max(q - q0, 0.0);
  float q1 = min(q0 + 1.0, nTheta - 1.0);
  float z0 = clamp((q0 + coords.z) / nTheta, q0 / nTheta + 0.5 / (nPhi * nTheta),
                   (q0 + 1.0) / nTheta - 0.5 / (nPhi * nTheta));
  float z1 = z0 + (q1 - q0) / nTheta;
  vec4 s0 = textureLod(table, vec3(coords.xy, z0), 0.0);
  vec4 s1 = textureLod(table, vec3(coords.xy, z1), 0.0);
  return mix(s0, s1, weight);
}
vec3 crep_sampleAtmosphereTable(sampler3D table, CrepAtmosphereParams a, vec4 coords) {
  return crep_sampleAtmosphereTableRgba(table, a, coords).rgb;
}

// Single scattering is stored without its phase functions (crep/atmosphere/atmosphere.h): the single table
// holds S_R in RGB and S_M's red in A, the single Mie table S_M in RGB. With
// CREP_ATMOSPHERE_COMBINED_MIE 1 (AtmospherePrecomputeOptions::combinedMie) there is no single Mie table
// and S_M is rebuilt from the single table's texel by Bruneton's 2017 rule (crep::combinedMieScattering).
#ifndef CREP_ATMOSPHERE_COMBINED_MIE
#define CREP_ATMOSPHERE_COMBINED_MIE 0
#endif
vec3 crep_combinedMieScattering(CrepAtmosphereParams a, vec4 single) {
  if (!(single.r > 0.0) || !(a.mieScattering.r > 0.0)) return vec3(0.0);
  return single.rgb * (single.a / single.r) * (a.rayleighScattering.r / a.mieScattering.r) *
         (a.mieScattering.rgb / a.rayleighScattering.rgb);
}
// L1 at `coords` for the scattering cosine c = v . l (crep::sampleSingleScattering): S_R p_R(c) + S_M p_HG(c).
// `singleMie` is not read with CREP_ATMOSPHERE_COMBINED_MIE 1 (bind any 3D texture there).
vec3 crep_sampleSingleScattering(sampler3D single, sampler3D singleMie, CrepAtmosphereParams a, vec4 coords,
                                 float cosSunView) {
  vec4 s = crep_sampleAtmosphereTableRgba(single, a, coords);
#if CREP_ATMOSPHERE_COMBINED_MIE
  vec3 mie = crep_combinedMieScattering(a, s);
#else
  vec3 mie = crep_sampleAtmosphereTable(singleMie, a, coords);
#endif
  float c = clamp(cosSunView, -1.0, 1.0);
  return s.rgb * crep_rayleighPhase(c) + mie * crep_henyeyGreenstein(a.mieExtinction.w, c);
}

// Listing 1 end to end (crep::lookUpAtmosphere): the table's value at `position` (metres, planet centre at
// the origin) looking along unit `view` with the sun towards unit `toSun`. `coords`: the previous
// look-up's coordinates of the same ray in (negative for the first), this one's out.
vec3 crep_lookUpAtmosphere(sampler3D table, CrepAtmosphereParams a, vec3 position, vec3 view, vec3 toSun,
                           inout vec4 coords) {
  float r = length(position);
  vec3 zenith = position / r;
  coords = crep_atmosphereTableCoords(a, r - a.radii.x, dot(zenith, view), dot(zenith, toSun), dot(view, toSun),
                                      coords);
  return crep_sampleAtmosphereTable(table, a, coords);
}

// Texture coordinates at altitude h and cos zenith c of a 2D table of size.x altitudes (u = sqrt(h / H_Atm))
// by size.y cosines (linear in [-1, 1]): the optical depth table's and Psi_ms's rule (atmosphere.h).
vec2 crep_heightCosineCoords(CrepAtmosphereParams a, float h, float cosZenith, ivec2 size) {
  return vec2(crep_atmosphereTexCoord(sqrt(clamp(h / a.radii.z, 0.0, 1.0)), size.x),
              crep_atmosphereTexCoord((clamp(cosZenith, -1.0, 1.0) + 1.0) * 0.5, size.y));
}

// Texture coordinates of the optical depth table at altitude h and cos zenith c (atmosphere.h's rule).
vec2 crep_opticalDepthCoords(CrepAtmosphereParams a, float h, float cosZenith) {
  return crep_heightCosineCoords(a, h, cosZenith, a.auxSizes.xy);
}

// (Rayleigh, Mie) density integrals from altitude h along cos zenith c to the top of the atmosphere
// (Yusov 2013's net density table, bilinear; crep::lookUpDensityToTop).
vec2 crep_densityToTop(sampler2D opticalDepth, CrepAtmosphereParams a, float h, float cosZenith) {
  return textureLod(opticalDepth, crep_opticalDepthCoords(a, h, cosZenith), 0.0).rg;
}

// Transmittance to the sun from altitude h with the sun at zenith cosine c.
vec3 crep_sunTransmittanceAt(sampler2D opticalDepth, CrepAtmosphereParams a, float h, float cosSunZenith) {
  return exp(-crep_atmosphereExtinction(a, crep_densityToTop(opticalDepth, a, h, cosSunZenith)));
}

// Transmittance from `position` (metres) to the sun along unit `toSun` (crep::sunTransmittance).
vec3 crep_sunTransmittance(sampler2D opticalDepth, CrepAtmosphereParams a, vec3 position, vec3 toSun) {
  float r = length(position);
  return crep_sunTransmittanceAt(opticalDepth, a, r - a.radii.x, dot(position / r, toSun));
}

// Distances along a ray from altitude h (hh = h (2R + h) = |x|^2 - R^2, b = |x| times the ray's cos zenith,
// disc = b^2 - hh) to the ground (the near root of |x + t v| = R, written without cancellation; the tangent
// point at disc = 0) and to the top of the atmosphere (the far root of |x + t v| = R + H_Atm).
float crep_atmosphereGroundDistance(float hh, float b, float disc) { return hh / (-b + sqrt(max(disc, 0.0))); }
float crep_atmosphereTopDistance(CrepAtmosphereParams a, float h, float b) {
  float R = a.radii.x, H = a.radii.z;
  float cc = (H - h) * (2.0 * R + H + h); // (R + H)^2 - |x|^2
  float d = sqrt(b * b + cc);
  return b >= 0.0 ? cc / (b + d) : d - b;
}

// Ray-sphere intersection (sphere of `radius` at the origin, unit `dir`): the (near, far) distances along
// the ray (negative when behind the origin), or (-1, -1) when the line misses the sphere. The constant
// term is (|o| - radius)(|o| + radius), which keeps a point near the sphere precise in float.
vec2 crep_raySphere(vec3 origin, vec3 dir, float radius) {
  float b = dot(origin, dir);
  float lo = length(origin);
  float c = (lo - radius) * (lo + radius);
  float disc = b * b - c;
  if (disc < 0.0) return vec2(-1.0);
  float s = sqrt(disc);
  // Stable roots: q = -(b + sign(b) s), roots q and c / q.
  float q = b >= 0.0 ? -(b + s) : -b + s;
  float t0 = q;
  float t1 = q != 0.0 ? c / q : 0.0;
  return vec2(min(t0, t1), max(t0, t1));
}

// True when the ray from altitude h (metres) with cos zenith c hits the ground: c < 0 and
// (R + h)^2 (c^2 - 1) + R^2 >= 0, computed as (R + h)^2 c^2 - h (2R + h) >= 0.
bool crep_atmosphereHitsGround(CrepAtmosphereParams a, float h, float cosZenith) {
  float R = a.radii.x;
  h = max(h, 0.0);
  float r = R + h;
  return cosZenith < 0.0 && r * r * cosZenith * cosZenith - h * (2.0 * R + h) >= 0.0;
}

// RGB transmittance between points pa and pb (metres; crep::atmosphereTransmittance): through the optical
// depth table, D(a, v) - D(b, v) when the ray from pa through pb does not hit the ground, else
// D(b, -v) - D(a, -v); differences clamped to >= 0.
vec3 crep_atmosphereTransmittance(sampler2D opticalDepth, CrepAtmosphereParams a, vec3 pa, vec3 pb) {
  vec3 v = normalize(pb - pa);
  float ra = length(pa);
  float rb = length(pb);
  float ha = ra - a.radii.x;
  float hb = rb - a.radii.x;
  float ca = dot(pa, v) / ra;
  float cb = dot(pb, v) / rb;
  vec2 D;
  if (!crep_atmosphereHitsGround(a, ha, ca)) {
    D = crep_densityToTop(opticalDepth, a, ha, ca) - crep_densityToTop(opticalDepth, a, hb, cb);
  } else {
    D = crep_densityToTop(opticalDepth, a, hb, -cb) - crep_densityToTop(opticalDepth, a, ha, -ca);
  }
  return exp(-crep_atmosphereExtinction(a, max(D, vec2(0.0))));
}

// Psi_ms at altitude h and sun zenith cosine c (Hillaire 2020, Sec. 5.5; bilinear, texel (i, j) at
// u = sqrt(h / H_Atm) = i / (n - 1), c = 2 j / (n - 1) - 1; crep::lookUpMultipleScatteringLut).
vec3 crep_multipleScatteringLut(sampler2D lut, CrepAtmosphereParams a, float h, float cosSunZenith) {
  int n = int(a.multipleScattering.y);
  return textureLod(lut, crep_heightCosineCoords(a, h, cosSunZenith, ivec2(n)), 0.0).rgb;
}

// E_sky at the cos of the sun's zenith angle (linear in the 1D table; crep::lookUpAmbientSkyLight).
vec3 crep_ambientSkyLight(sampler2D ambient, CrepAtmosphereParams a, float cosSunZenith) {
  float u = crep_atmosphereTexCoord((clamp(cosSunZenith, -1.0, 1.0) + 1.0) * 0.5, a.auxSizes.z);
  return textureLod(ambient, vec2(u, 0.5), 0.0).rgb;
}

// World point -> metres around the planet centre (crep::atmospherePosition): the planet centre is at
// (0, -(R + originAltitude) / metersPerUnit, 0) in world units.
vec3 crep_atmospherePosition(CrepAtmosphereParams a, vec3 world) {
  float m = a.placement.x;
  return vec3(world.x * m, world.y * m + (a.radii.x + a.placement.y), world.z * m);
}

// Direction i of the n-direction Fibonacci sphere (crep::fibonacciSphereDirection): y = 1 - (2 i + 1) / n,
// angle = i pi (3 - sqrt(5)) = 2 pi frac(i (3 - sqrt(5)) / 2), the fraction in 32-bit fixed point.
vec3 crep_fibonacciSphereDirection(int i, int n) {
  float y = 1.0 - float(2 * i + 1) / float(n);
  float r = sqrt(max(0.0, 1.0 - y * y));
  float angle = float(CREP_TWO_PI) * (float(uint(i) * 1640531527u) * (1.0 / 4294967296.0));
  return vec3(r * cos(angle), y, r * sin(angle));
}

// ---------------------------------------------------------------------------------------------------------
// The tables' precomputation (AtmosphereTablesPass's shaders). A table texel's point C = (0, R + h, 0)
// and its ray C + t v are handled through offsets from C so that altitudes and the horizon cosines keep
// float precision (a position alone has 0.5 m).

// The view and sun directions of the table's point for (c_alpha, c_phi, c_theta) (crep::atmosphereDirections).
void crep_atmosphereDirections(float cosViewZenith, float cosSunZenith, float cosSunView, out vec3 view,
                               out vec3 sun) {
  float s = sqrt(max(0.0, 1.0 - cosViewZenith * cosViewZenith));
  view = vec3(s, cosViewZenith, 0.0);
  float lx = s < 1e-6 ? 0.0 : (cosSunView - cosViewZenith * cosSunZenith) / s;
  float lz = sqrt(max(0.0, 1.0 - lx * lx - cosSunZenith * cosSunZenith));
  sun = normalize(vec3(lx, cosSunZenith, lz));
}

// One ray of a table texel: from C at altitude h along v (cos zenith c), and its side of the horizon.
struct CrepAtmosphereTexelRay {
  float h;       // altitude of C
  float c;       // cos zenith of v
  float disc;    // (R + h)^2 c^2 - h (2R + h): the ground sphere's discriminant, constant along the line
  bool below;    // the lower half of u_alpha (ends on the ground)
  float end;     // distance to the ray's end (ground or top of the atmosphere)
  vec3 view;     // v
  vec3 sun;      // l
  float cosSunView; // v . l
  vec4 coords;   // the texel's own texture coordinates (the `previous` of the look-ups along the ray)
};

// The texel (ih, ia, ip, it) of the 4D table: its parameters (crep::atmosphereTexelParams: the inverse of
// Yusov 2013, Eq. 4-7 at texel centres), directions, and ray end (the lower half ends on the ground, the
// upper half at the top of the atmosphere).
CrepAtmosphereTexelRay crep_atmosphereTexelRay(CrepAtmosphereParams a, ivec4 texel) {
  CrepAtmosphereTexelRay ray;
  float R = a.radii.x;
  float H = a.radii.z;
  ivec4 n = a.tableSize;
  float uh = float(texel.x) / float(n.x - 1);
  float h = H * uh * uh;
  float r0 = R + h;
  float hh = h * (2.0 * R + h); // r0^2 - R^2
  float ch = -sqrt(hh) / r0;
  int halfN = n.y / 2;
  ray.below = texel.y < halfN;
  int k = ray.below ? texel.y : texel.y - halfN;
  float t = float(k) / float(halfN - 1);
  float s = t * t * t * t * t;
  float c;
  if (ray.below) {
    // c = c_h - s (c_h + 1); disc = r0^2 (c - c_h)(c + c_h), both factors negative.
    float ch1 = R * R / (r0 * (r0 + sqrt(hh))); // 1 + c_h without cancellation
    c = ch - s * ch1;
    ray.disc = r0 * r0 * (s * ch1) * (s * ch1 - 2.0 * ch);
  } else {
    c = ch + s * (1.0 - ch);
    ray.disc = r0 * r0 * (s * (1.0 - ch)) * (2.0 * ch + s * (1.0 - ch));
  }
  // The last texel of each half is exactly straight down / up (as in double): v's horizontal part is 0
  // there, and l is then decided by c_phi alone (crep_atmosphereDirections' degenerate case), which a
  // float rounding of c away from -1 / 1 would not reproduce.
  if (k == halfN - 1) c = ray.below ? -1.0 : 1.0;
  float uPhi = float(texel.z) / float(n.z - 1);
  float cPhi = tan((2.0 * uPhi - 0.74) * 1.1) / tan(1.26 * 1.1);
  float uTheta = float(texel.w) / float(n.w - 1);
  // Eq. 7's inverse: gamma from u_theta, c_theta = cos(pi gamma).
  float gamma = uTheta >= 0.5 ? 0.5 + 0.5 * pow(2.0 * (uTheta - 0.5), 1.0 / 1.5)
                              : 0.5 - 0.5 * pow(2.0 * (0.5 - uTheta), 1.0 / 1.5);
  float cTheta = cos(float(CREP_PI) * gamma);
  ray.h = h;
  ray.c = c;
  crep_atmosphereDirections(c, cPhi, cTheta, ray.view, ray.sun);
  ray.cosSunView = dot(ray.view, ray.sun); // the texel's c_theta unless l was renormalized
  float b = r0 * c;
  ray.end = ray.below ? crep_atmosphereGroundDistance(hh, b, ray.disc) : crep_atmosphereTopDistance(a, h, b);
  ray.end = max(ray.end, 0.0);
  ray.coords = (vec4(texel) + 0.5) / vec4(n);
  return ray;
}

// A point C + t v of a texel's ray: its altitude, cos zenith of v and of the sun, and its table coordinates
// on the ray's side of the horizon (the look-up's `previous` is the texel's own coordinates).
struct CrepAtmosphereRayPoint {
  float h;
  float cosViewZenith;
  float cosSunZenith;
  vec4 coords;
};

CrepAtmosphereRayPoint crep_atmosphereRayPoint(CrepAtmosphereParams a, CrepAtmosphereTexelRay ray, float t) {
  CrepAtmosphereRayPoint p;
  float R = a.radii.x;
  float r0 = R + ray.h;
  float X = r0 * ray.c + t;                                              // dot(P, v)
  float rr = ray.h * (2.0 * R + ray.h) + t * (2.0 * r0 * ray.c + t);      // |P|^2 - R^2
  float r = sqrt(R * R + rr);
  float S = sqrt(max(rr, 0.0));
  p.h = clamp(rr / (r + R), 0.0, a.radii.z);
  p.cosViewZenith = X / r;
  p.cosSunZenith = (r0 * ray.sun.y + t * ray.cosSunView) / r;
  // c_alpha - c_h = (X + S) / r, or -disc / (r (S - X)) when X < 0 (no cancellation); ratios of Eq. 5.
  float num = X >= 0.0 ? X + S : -ray.disc / (S - X); // r (c_alpha - c_h)
  float ratio = ray.below ? -num * (r + S) / (R * R) : num / (r + S);
  float hc = p.h;
  float cP = clamp(p.cosSunZenith, -1.0, 1.0);
  p.coords = vec4(crep_atmosphereTexCoord(sqrt(hc / a.radii.z), a.tableSize.x),
                  crep_atmosphereAlphaCoord(a.tableSize.y, ray.below, ratio),
                  crep_atmosphereTexCoord(crep_atmosphereSunZenithU(cP), a.tableSize.z),
                  crep_atmosphereTexCoord(crep_atmosphereSunViewU(ray.cosSunView), a.tableSize.w));
  return p;
}

#endif // CREP_ATMOSPHERE_GLSL
