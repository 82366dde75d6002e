#version 450 core
// The atmosphere of each camera pixel's view ray (AtmospherePass, crep/atmosphere/gpu_pass.h): the
// sky, aerial perspective and light shafts of crep::atmosphereRay (crep/atmosphere/atmosphere.h; the full
// rule is at the top of atmosphere/src/ray.cpp) in float, with the table look-ups of
// crep/atmosphere.glsl (Yusov 2013, Listings 1-2; Bruneton and Neyret 2008).
//
// CREP_ATMOSPHERE_SHAFTS (crep::AtmosphereShafts):
//   0 None: Eq. 8 (Yusov 2013) with L_M from the camera to the surface (the sky: L_M at the camera);
//   1 (a) Integrated: the min/max tree walk over the pixel's row of the rectified map
//     (crep/minmax_walk.glsl); single scattering integrated with the trapezoid rule over each lit section
//     (touching sections merged, as crep::minMaxLitSections), plus the unshadowed part beyond the far plane
//     for the sky; higher orders unoccluded (Eq. 8 with L_H);
//   2 (b) LitLengthTable: the same walk only accumulates the lit length D_lit and the first lit distance
//     D_start (two floats instead of the integrand's state: fewer registers, no look-ups inside the walk),
//     then Eq. 8 with L1 over [D_start, D_start + D_lit]; higher orders as (a);
//   3 (c) PrefilteredVisibility: the prefiltered texel's visible fraction (crep::prefilteredVisibility)
//     times Eq. 8 with L1; higher orders as (a).
// With CREP_ATMOSPHERE_VOLUME 1 (the default), None, (b) and (c) take L1 from the view tables instead of
// Eq. 8 (the rule at the top of atmosphere/src/ray.cpp): the same shadows, no difference of two large
// look-ups.
// Points along the ray are never formed as float positions (0.5 m resolution at the planet's surface):
// rayPoint() gives the altitude and zenith cosines of C + v t from |C|^2 - R^2 and C.v, C.l, and the
// look-ups, transmittances and sun transmittances (the formulas of crep_lookUpAtmosphere,
// crep_atmosphereTransmittance, crep_sunTransmittance) take those (measured against the double CPU
// reference: transmittance 7e-4 -> 8e-6, (b)'s shadows 2e-2 -> 2e-4 relative).
//
// Resources: march block (crep/march.glsl, uniform binding 0: camera, sun; (c): the proxy medium; info.x
// tree levels, info.y tree row stride, info.z integrationSteps, info.w skySteps), layout block
// (crep/layout.glsl, uniform binding 1, and the epipolar row table at storage binding 1; (a), (b)),
// atmosphere block (uniform binding 2), camera depth (unit 0), rectified depth (unit 1, (a), (b)),
// optical depth table (unit 2), single S_R + S_M.r (unit 3), L_H (unit 4), single S_M (unit 5; not read
// with CREP_ATMOSPHERE_COMBINED_MIE 1), prefiltered radiance (unit 6, (c)), ambient sky light (unit 7),
// the view tables (units 8-11, CREP_ATMOSPHERE_VOLUME),
// min/max nodes (storage binding 0, (a), (b)); outputs: RGBA32F in-scattering + mean transmittance (image 0),
// RGBA32F transmittance (image 1).
#include "crep/bindings.h"
#ifndef CREP_ATMOSPHERE_SHAFTS
#define CREP_ATMOSPHERE_SHAFTS 0
#endif
// CREP_ATMOSPHERE_VOLUME 1 (None, (b), (c)): L1 from the camera's view tables (crep::AtmosphereViewTables,
// Hillaire 2020, Sec. 5.2-5.3): the aerial perspective volume (units 8 Rayleigh, 9 Mie; march block region =
// (W, H, D, steps)) in front of the far plane, the sky-view table (units 10, 11; block = (W, H, steps, 0))
// beyond it; the 4D table's Eq. 8 when the camera is above the atmosphere (cameraShift > 0).
// CREP_ATMOSPHERE_VOLUME_PASS 1: this program computes the volume instead (one invocation per froxel
// column, images 0 and 1: 3D RGBA32F, RGB the integrals, A 0); CREP_ATMOSPHERE_VOLUME_PASS 2 the sky-view
// table (one invocation per texel, images 0 and 1: 2D RGBA32F).
#ifndef CREP_ATMOSPHERE_VOLUME
#define CREP_ATMOSPHERE_VOLUME 0
#endif
#ifndef CREP_ATMOSPHERE_VOLUME_PASS
#define CREP_ATMOSPHERE_VOLUME_PASS 0
#endif
#define CREP_SHAFTS_WALK (CREP_ATMOSPHERE_SHAFTS == 1 || CREP_ATMOSPHERE_SHAFTS == 2)

// (The shader library includes each file once, where it first appears, whatever the #if around it: the
// includes below are unconditional or appear once.)
#include "crep/march.glsl"
#if CREP_SHAFTS_WALK
#include "crep/layout.glsl"
#endif
#include "crep/atmosphere.glsl"
#include "crep/phase.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(std140, binding = CREP_ATMOSPHERE_MARCH_BINDING) uniform CrepMarchBlock { CrepMarchParams crep_march; };
layout(std140, binding = CREP_ATMOSPHERE_PARAMS_BINDING) uniform CrepAtmosphereBlock { CrepAtmosphereParams crep_atmosphere; };
layout(binding = CREP_ATMOSPHERE_CAMERA_DEPTH_UNIT) uniform sampler2D cameraDepth;
layout(binding = CREP_ATMOSPHERE_OPTICAL_DEPTH_TABLE_UNIT) uniform sampler2D opticalDepthTable;
layout(binding = CREP_ATMOSPHERE_SINGLE_TABLE_UNIT) uniform sampler3D singleTable;
layout(binding = CREP_ATMOSPHERE_HIGHER_ORDERS_TABLE_UNIT) uniform sampler3D higherOrdersTable;
layout(binding = CREP_ATMOSPHERE_SINGLE_MIE_TABLE_UNIT) uniform sampler3D singleMieTable; // not read with CREP_ATMOSPHERE_COMBINED_MIE 1
layout(binding = CREP_ATMOSPHERE_AMBIENT_TABLE_UNIT) uniform sampler2D ambientTable;   // E_sky: the ground beyond the scene
#if CREP_SHAFTS_WALK
layout(binding = CREP_ATMOSPHERE_RECTIFIED_DEPTH_UNIT) uniform sampler2D rectifiedDepth;
layout(std430, binding = CREP_ATMOSPHERE_MIN_MAX_BINDING) readonly buffer CrepMinMaxBlock { vec2 crep_minMax[]; };
#endif
#if CREP_ATMOSPHERE_SHAFTS == 3
layout(binding = CREP_ATMOSPHERE_PREFILTERED_UNIT) uniform sampler2D prefiltered;
#endif
#if CREP_ATMOSPHERE_VOLUME_PASS == 1
layout(binding = CREP_ATMOSPHERE_VOLUME_RAYLEIGH_OUT_IMAGE, rgba32f) uniform writeonly image3D volumeRayleighOut;
layout(binding = CREP_ATMOSPHERE_VOLUME_MIE_OUT_IMAGE, rgba32f) uniform writeonly image3D volumeMieOut;
#elif CREP_ATMOSPHERE_VOLUME_PASS == 2
layout(binding = CREP_ATMOSPHERE_SKY_RAYLEIGH_OUT_IMAGE, rgba32f) uniform writeonly image2D skyRayleighOut;
layout(binding = CREP_ATMOSPHERE_SKY_MIE_OUT_IMAGE, rgba32f) uniform writeonly image2D skyMieOut;
#else
layout(binding = CREP_ATMOSPHERE_INSCATTERING_OUT_IMAGE, rgba32f) uniform writeonly image2D inscatteringOut;
layout(binding = CREP_ATMOSPHERE_TRANSMITTANCE_OUT_IMAGE, rgba32f) uniform writeonly image2D transmittanceOut;
#endif
#if CREP_ATMOSPHERE_VOLUME
layout(binding = CREP_ATMOSPHERE_VOLUME_RAYLEIGH_UNIT) uniform sampler3D volumeRayleigh;
layout(binding = CREP_ATMOSPHERE_VOLUME_MIE_UNIT) uniform sampler3D volumeMie;
layout(binding = CREP_ATMOSPHERE_SKY_RAYLEIGH_UNIT) uniform sampler2D skyRayleigh;
layout(binding = CREP_ATMOSPHERE_SKY_MIE_UNIT) uniform sampler2D skyMie;
#endif

// The ray of this invocation, in metres around the planet centre (atmosphere.h's table frame).
vec3 rayC = vec3(0.0);    // the (restrained) camera position C
vec3 rayV = vec3(0.0);    // unit view direction v
vec3 rayL = vec3(0.0);    // unit direction towards the sun l
float metres = 1.0;       // metres per world unit
float cameraShift = 0.0;  // metres C was moved along v into the atmosphere (Yusov's restrained camera)
float surfaceM = 0.0;     // s_m: the surface (or far plane) distance from C, metres
vec3 rayleighPhaseBeta = vec3(0.0), miePhaseBeta = vec3(0.0); // beta_R p_R(c_theta), beta_M p_HG(c_theta)

// The point C + v t without forming it: a float position has 0.5 m resolution at the planet's surface
// (which moves u_h of a low point by a few 1e-4 texel and tilts a short segment's direction); here
// |P|^2 - R^2 = (|C|^2 - R^2) + t (2 C.v + t) keeps the altitude to millimetres.
float rayRR = 0.0;                           // |C|^2 - R^2, from the camera's world position
float rayCV = 0.0, rayCL = 0.0, rayVL = 0.0; // C.v, C.l, v.l
struct RayPoint {
  float h;   // altitude
  float r;   // |P|
  float cosView, cosSun; // cos zenith of v and of l at P
};
RayPoint rayPoint(float t) {
  float R = crep_atmosphere.radii.x;
  float rr = rayRR + t * (2.0 * rayCV + t);
  float r = sqrt(R * R + rr);
  return RayPoint(rr / (r + R), r, (rayCV + t) / r, (rayCL + t * rayVL) / r);
}

// crep_lookUpAtmosphere at C + v t. `coords`: as crep_lookUpAtmosphere's.
vec3 lookUpAt(sampler3D table, float t, inout vec4 coords) {
  RayPoint p = rayPoint(t);
  coords = crep_atmosphereTableCoords(crep_atmosphere, p.h, p.cosView, p.cosSun, rayVL, coords);
  return crep_sampleAtmosphereTable(table, crep_atmosphere, coords);
}

// crep_atmosphereTransmittance from C to C + v t (its rule: D(C, v) - D(P, v), or D(P, -v) - D(C, -v)
// when the ray hits the ground); 1 at t = 0.
vec3 transmittanceTo(float t) {
  if (!(t > 0.0)) return vec3(1.0);
  RayPoint a = rayPoint(0.0), b = rayPoint(t);
  vec2 D;
  if (!crep_atmosphereHitsGround(crep_atmosphere, a.h, a.cosView)) {
    D = crep_densityToTop(opticalDepthTable, crep_atmosphere, a.h, a.cosView) -
        crep_densityToTop(opticalDepthTable, crep_atmosphere, b.h, b.cosView);
  } else {
    D = crep_densityToTop(opticalDepthTable, crep_atmosphere, b.h, -b.cosView) -
        crep_densityToTop(opticalDepthTable, crep_atmosphere, a.h, -a.cosView);
  }
  return exp(-crep_atmosphereExtinction(crep_atmosphere, max(D, vec2(0.0))));
}

// crep::atmosphereRay's segment transmittance T(C -> C + v t) for Eq. 8 and a surface's output: the
// trapezoid rule with CREP_SEGMENT_STEPS steps of the densities along the segment (the optical depth
// table's difference of two large values steps by several percent near the horizon); 1 at t = 0.
#define CREP_SEGMENT_STEPS 16
// The (Rayleigh, Mie) density integrals of that segment (0 at t <= 0).
vec2 segmentDensity(float t) {
  if (!(t > 0.0)) return vec2(0.0);
  float dt = t / float(CREP_SEGMENT_STEPS);
  vec2 sum = 0.5 * (crep_atmosphereDensity(crep_atmosphere, rayPoint(0.0).h) +
                    crep_atmosphereDensity(crep_atmosphere, rayPoint(t).h));
  for (int k = 1; k < CREP_SEGMENT_STEPS; ++k)
    sum += crep_atmosphereDensity(crep_atmosphere, rayPoint(float(k) * dt).h);
  return sum * dt;
}
vec3 segmentTransmittance(float t) {
  if (!(t > 0.0)) return vec3(1.0);
  return exp(-crep_atmosphereExtinction(crep_atmosphere, segmentDensity(t)));
}

// A table at C + v t, with the ray's look-up coordinates (Listing 2: every look-up on the first's side).
vec3 lookUp(sampler3D table, float t, vec4 first) {
  vec4 coords = first;
  return lookUpAt(table, t, coords);
}

// L1 at C + v t: the phase-free single tables with the current ray's phase functions (rayVL;
// crep_sampleSingleScattering). `coords`: as crep_lookUpAtmosphere's.
vec3 singleAt(float t, inout vec4 coords) {
  RayPoint p = rayPoint(t);
  coords = crep_atmosphereTableCoords(crep_atmosphere, p.h, p.cosView, p.cosSun, rayVL, coords);
  return crep_sampleSingleScattering(singleTable, singleMieTable, crep_atmosphere, coords, rayVL);
}
vec3 singleLookUp(float t, vec4 first) {
  vec4 coords = first;
  return singleAt(t, coords);
}

#if CREP_ATMOSPHERE_VOLUME_PASS || CREP_ATMOSPHERE_SHAFTS == 1
// crep's ViewMarch (atmosphere/src/ray.cpp): the trapezoid rule of the phase-free integrands
// (beta_R d_R, beta_M d_M) T(C->P) T_sun(P) along the current ray from t0, T(C->P) the densities marched
// from C (`optical0` those of [0, t0]). viewStep(t, wPrevious, w): to t, adding (wPrevious f(t_prev) +
// w f(t)) / 2; viewCubic(tb, n): n steps in u to tb in t = ta + (tb - ta) u^3.
vec3 vmRayleigh = vec3(0.0), vmMie = vec3(0.0), vmFR = vec3(0.0), vmFM = vec3(0.0);
vec2 vmDensity = vec2(0.0), vmOptical = vec2(0.0);
float vmT = 0.0;
void viewIntegrand(RayPoint p, vec2 d) {
  vec3 w = exp(-crep_atmosphereExtinction(crep_atmosphere, vmOptical)) *
           crep_sunTransmittanceAt(opticalDepthTable, crep_atmosphere, p.h, p.cosSun);
  vmFR = crep_atmosphere.rayleighScattering.rgb * d.x * w;
  vmFM = crep_atmosphere.mieScattering.rgb * d.y * w;
}
void viewBegin(float t0, vec2 optical0) {
  RayPoint p = rayPoint(t0);
  vmRayleigh = vec3(0.0);
  vmMie = vec3(0.0);
  vmOptical = optical0;
  vmT = t0;
  vmDensity = crep_atmosphereDensity(crep_atmosphere, p.h);
  viewIntegrand(p, vmDensity);
}
void viewStep(float t, float wPrevious, float w) {
  RayPoint p = rayPoint(t);
  vec2 d = crep_atmosphereDensity(crep_atmosphere, p.h);
  vmOptical += 0.5 * (vmDensity + d) * (t - vmT);
  vec3 fR = vmFR, fM = vmFM;
  viewIntegrand(p, d);
  vmRayleigh += 0.5 * (wPrevious * fR + w * vmFR);
  vmMie += 0.5 * (wPrevious * fM + w * vmFM);
  vmT = t;
  vmDensity = d;
}
void viewCubic(float tb, int n) {
  float ta = vmT, len = tb - ta, du = 1.0 / float(n), w = du * 3.0 * len; // du dt/du = w u^2
  for (int k = 1; k <= n; ++k) {
    float u = float(k) * du, u0 = u - du;
    viewStep(ta + len * u * u * u, w * u0 * u0, w * u * u);
  }
}
#endif

#if CREP_ATMOSPHERE_SHAFTS == 1
// (a)'s unshadowed rest of a sky ray, [ta, tb] (crep::atmosphereRay's rule): viewCubic's n steps of the
// integrand of trapezoid() below, T(C->P) the segment's densities to ta, then marched.
vec3 skyQuadrature(float ta, float tb, int n) {
  if (!(tb > ta)) return vec3(0.0);
  viewBegin(ta, segmentDensity(ta));
  viewCubic(tb, n);
  return vmRayleigh * crep_rayleighPhase(rayVL) + vmMie * crep_henyeyGreenstein(crep_atmosphere.mieExtinction.w, rayVL);
}

// The trapezoid rule with n steps over [ta, tb] metres of the single scattering integrand (beta_R d_R p_R +
// beta_M d_M p_HG) T(C->P) T_sun(P): T(C->P) from the densities along the ray (CREP_SEGMENT_STEPS to ta,
// then the section's own steps), not the optical depth table's difference (crep::atmosphereRay's rule).
vec3 trapezoid(float ta, float tb, int n) {
  float h = (tb - ta) / float(n);
  vec2 optical = segmentDensity(ta); // C -> the section
  vec2 previous = vec2(0.0);
  vec3 sum = vec3(0.0);
  for (int k = 0; k <= n; ++k) {
    RayPoint p = rayPoint(ta + float(k) * h);
    vec2 d = crep_atmosphereDensity(crep_atmosphere, p.h);
    if (k > 0) optical += 0.5 * (previous + d) * h;
    previous = d;
    vec3 f = (rayleighPhaseBeta * d.x + miePhaseBeta * d.y) *
             exp(-crep_atmosphereExtinction(crep_atmosphere, optical)) *
             crep_sunTransmittanceAt(opticalDepthTable, crep_atmosphere, p.h, p.cosSun);
    sum += (k == 0 || k == n) ? 0.5 * f : f;
  }
  return sum * h;
}

vec3 singleSum = vec3(0.0);
float pendingA = -1.0, pendingB = -1.0; // the lit section being merged (world units from the camera)
float sectionEnd = 0.0;                 // s_E (surface) or s_F (sky), metres

// One lit section [ta, tb] (world units from the camera) clipped to [0, sectionEnd] metres:
// min(integrationSteps, max(1, ceil(integrationSteps (tb - ta) / s_m))) trapezoid steps.
void integrateSection(float ta, float tb) {
  float a = clamp(ta * metres - cameraShift, 0.0, sectionEnd), b = clamp(tb * metres - cameraShift, 0.0, sectionEnd);
  if (!(b > a)) return;
  int steps = crep_march.info.z;
  int n = clamp(int(ceil(float(steps) * (b - a) / surfaceM)), 1, steps);
  singleSum += trapezoid(a, b, n);
}

void crep_walkLitNode(CrepRowRay r, int i, int next, float ta, float tb) {
  if (!(tb > ta)) return;
  if (pendingB == ta) { // touching the previous lit node: one section (crep::minMaxLitSections)
    pendingB = tb;
    return;
  }
  if (pendingB > pendingA) integrateSection(pendingA, pendingB);
  pendingA = ta;
  pendingB = tb;
}
#elif CREP_ATMOSPHERE_SHAFTS == 2
float litLength = 0.0;   // D_lit, world units
float firstLit = -1.0;   // D_start, world units (-1: no lit section yet)
void crep_walkLitNode(CrepRowRay r, int i, int next, float ta, float tb) {
  if (!(tb > ta)) return;
  if (firstLit < 0.0) firstLit = ta;
  litLength += tb - ta;
}
#endif
#if CREP_SHAFTS_WALK
#define CREP_MINMAX_WALK_INPUTS 1
#include "crep/minmax_walk.glsl"
#endif

float visibility = 1.0; // (c): the prefiltered visible fraction of the ray

// Everything but (a)'s integrated single scattering, for the current ray (rayV, rayCV, rayVL): Eq. 8 with
// L_M (None), or the unoccluded higher orders (Eq. 8 with L_H) plus (b)'s or (c)'s single scattering. The
// first look-up (at C) fixes the side of the horizon of every later one (Listing 2).
bool useVolume = false; // CREP_ATMOSPHERE_VOLUME with the camera in the atmosphere
vec3 tablePart(bool sky, float tE) {
  vec4 first = vec4(-1.0);
  vec3 TE = segmentTransmittance(tE);
#if CREP_ATMOSPHERE_VOLUME
  if (useVolume) { // L_H only: the view tables have L1
    vec3 higherC = lookUpAt(higherOrdersTable, 0.0, first);
    return sky ? higherC : higherC - TE * lookUp(higherOrdersTable, tE, first);
  }
#endif
#if CREP_ATMOSPHERE_SHAFTS == 0
  // L_M = L1 + L_H (the same coordinates).
  vec3 multipleC = singleAt(0.0, first) + lookUp(higherOrdersTable, 0.0, first);
  if (sky) return multipleC;
  vec3 multipleE = singleLookUp(tE, first) + lookUp(higherOrdersTable, tE, first);
  return multipleC - TE * multipleE; // Eq. 8
#else
  vec3 higherC = lookUpAt(higherOrdersTable, 0.0, first);
  vec3 part = sky ? higherC : higherC - TE * lookUp(higherOrdersTable, tE, first); // unoccluded, Eq. 8
#if CREP_ATMOSPHERE_SHAFTS == 2
  if (litLength > 0.0) { // Eq. 8 with L1 over [D_start, D_start + D_lit], clipped to [0, s_E] (sky s_F)
    float start = firstLit * metres - cameraShift;
    float t1 = clamp(start, 0.0, tE);
    float t2 = clamp(start + litLength * metres, t1, tE);
    part += max(segmentTransmittance(t1) * singleLookUp(t1, first) -
                    segmentTransmittance(t2) * singleLookUp(t2, first),
                vec3(0.0));
  }
  if (sky) part += TE * singleLookUp(tE, first); // unshadowed beyond the far plane
#elif CREP_ATMOSPHERE_SHAFTS == 3
  vec3 singleC = singleLookUp(0.0, first);
  vec3 singleE = TE * singleLookUp(tE, first);
  part += visibility * (singleC - singleE);
  if (sky) part += singleE;
#endif
  return part;
#endif
}

// The ray state above for the camera's ray along unit world direction v (C not yet restrained).
void beginRay(vec3 v) {
  rayV = v;
  rayL = -crep_march.lightDirection.xyz;
  metres = crep_atmosphere.placement.x;
  vec3 C0 = crep_atmospherePosition(crep_atmosphere, crep_march.cameraPosition.xyz);
  rayC = C0;
  vec3 w = crep_march.cameraPosition.xyz * metres;
  float yAlt = w.y + crep_atmosphere.placement.y; // the camera's altitude
  rayRR = w.x * w.x + w.z * w.z + yAlt * (yAlt + 2.0 * crep_atmosphere.radii.x);
  rayCV = dot(C0, rayV);
  rayCL = dot(C0, rayL);
  rayVL = dot(rayV, rayL);
}

// crep::AtmosphereViewTables' sky-view frame at the camera: the zenith, the sun's horizontal direction, the
// third axis, the horizon's elevation e_h.
struct SkyFrame {
  vec3 zenith, sunAzimuth, side;
  float horizon;
};
SkyFrame skyFrame() {
  SkyFrame f;
  f.zenith = normalize(rayC);
  vec3 across = rayL - dot(rayL, f.zenith) * f.zenith;
  vec3 other = abs(f.zenith.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 0.0, 1.0);
  f.sunAzimuth = length(across) > 1e-6 ? normalize(across) : normalize(cross(f.zenith, other));
  f.side = cross(f.zenith, f.sunAzimuth);
  float R = crep_atmosphere.radii.x, r = sqrt(R * R + rayRR);
  f.horizon = asin(clamp(crep_cosHorizon(crep_atmosphere, max(rayRR / (r + R), 0.0)), -1.0, 1.0));
  return f;
}


#if CREP_ATMOSPHERE_VOLUME_PASS == 1
// The aerial perspective volume: column (i, j) from the camera to the far plane, slice k at view depth
// far (k / (D - 1))^2, `steps` trapezoid steps per slice.
void main() {
  ivec3 size = crep_march.region.xyz;
  int steps = crep_march.region.w;
  ivec2 column = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(column, size.xy))) return;
  vec2 position = (vec2(column) + 0.5) / vec2(size.xy) * vec2(crep_march.sizes.xy);
  beginRay(crep_screenRay(crep_march, position, 0.5).xyz);
  float end = crep_march.cameraDepth.z / dot(rayV, crep_march.cameraForward.xyz) * metres;
  viewBegin(0.0, vec2(0.0));
  imageStore(volumeRayleighOut, ivec3(column, 0), vec4(0.0));
  imageStore(volumeMieOut, ivec3(column, 0), vec4(0.0));
  float t = 0.0;
  for (int k = 1; k < size.z; ++k) {
    float u = float(k) / float(size.z - 1);
    float tb = end * u * u, dt = (tb - t) / float(steps);
    for (int i = 1; i <= steps; ++i)
      viewStep(t + dt * float(i), dt, dt);
    t = tb;
    imageStore(volumeRayleighOut, ivec3(column, k), vec4(vmRayleigh, 0.0));
    imageStore(volumeMieOut, ivec3(column, k), vec4(vmMie, 0.0));
  }
}
#elif CREP_ATMOSPHERE_VOLUME_PASS == 2
// The sky-view table: texel (i, j)'s whole ray, t = t_end u^3; the lower half ends on the ground (from
// |C|^2 - R^2 and C.v, as main()), the upper half at the top, decided by the half.
void main() {
  ivec2 size = ivec2(crep_march.block.xy);
  int n = int(crep_march.block.z);
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(texel, size))) return;
  beginRay(vec3(0.0, 1.0, 0.0));
  SkyFrame f = skyFrame();
  int halfRows = size.y / 2;
  bool above = texel.y >= halfRows;
  float s = float(above ? texel.y - halfRows : texel.y) / float(halfRows - 1);
  float pi = float(CREP_PI);
  float e = above ? f.horizon + s * s * (0.5 * pi - f.horizon) : f.horizon - s * s * (f.horizon + 0.5 * pi);
  float phi = pi * float(texel.x) / float(size.x - 1);
  beginRay(cos(e) * (cos(phi) * f.sunAzimuth + sin(phi) * f.side) + sin(e) * f.zenith);
  // C.v and, below the horizon, the ground's near root from the elevations (a float C.v leaves b^2 - c
  // metres^2 off near the tangent): b = r sin e, b^2 - c = (R - r cos e)(R + r cos e) with
  // R - r cos e = r (cos e_h - cos e) = -2 r sin((e_h + e) / 2) sin((e_h - e) / 2).
  float R = crep_atmosphere.radii.x, r = sqrt(R * R + rayRR);
  rayCV = r * sin(e);
  float end = 0.0;
  if (!above) {
    float disc = max(-2.0 * r * sin(0.5 * (f.horizon + e)) * sin(0.5 * (f.horizon - e)) * (R + r * cos(e)), 0.0);
    end = rayRR / (sqrt(disc) - rayCV);
  } else {
    end = max(crep_raySphere(rayC, rayV, crep_atmosphere.radii.y).y, 0.0);
  }
  viewBegin(0.0, vec2(0.0));
  viewCubic(end, n);
  imageStore(skyRayleighOut, texel, vec4(vmRayleigh, 0.0));
  imageStore(skyMieOut, texel, vec4(vmMie, 0.0));
}
#else
#if CREP_ATMOSPHERE_VOLUME
// L1 of this pixel's ray from C to C + v t (metres): crep::sampleAerialPerspective (hardware trilinear).
vec2 pixelScreen = vec2(0.0);
vec3 volumeSingle(float t) {
  if (!(t > 0.0)) return vec3(0.0);
  float z = t / metres * dot(rayV, crep_march.cameraForward.xyz);
  float D = float(crep_march.region.z);
  float slice = sqrt(clamp(z / crep_march.cameraDepth.z, 0.0, 1.0)) * (D - 1.0);
  float c = rayVL;
  vec3 coords = vec3(pixelScreen, (slice + 0.5) / D);
  return texture(volumeRayleigh, coords).rgb * crep_rayleighPhase(c) +
         texture(volumeMie, coords).rgb * crep_henyeyGreenstein(crep_atmosphere.mieExtinction.w, c);
}
// L1 of this pixel's whole ray: crep::sampleSkyView (hardware bilinear within the ray's half).
vec3 skyViewSingle() {
  SkyFrame f = skyFrame();
  vec2 size = crep_march.block.xy;
  float halfRows = 0.5 * size.y, pi = float(CREP_PI);
  // atan2, not asin / acos: well conditioned at every angle (acos of a cosine near 1 loses half the digits).
  float cz = dot(rayV, f.zenith);
  vec3 level = rayV - cz * f.zenith;
  float e = atan(cz, length(level));
  float across = dot(level, f.side), along = dot(level, f.sunAzimuth);
  float phi = across != 0.0 || along != 0.0 ? abs(atan(across, along)) : 0.0;
  float x = clamp(phi / pi, 0.0, 1.0) * (size.x - 1.0);
  float y = e >= f.horizon
                ? halfRows + sqrt(clamp((e - f.horizon) / (0.5 * pi - f.horizon), 0.0, 1.0)) * (halfRows - 1.0)
                : sqrt(clamp((f.horizon - e) / (f.horizon + 0.5 * pi), 0.0, 1.0)) * (halfRows - 1.0);
  vec2 coords = (vec2(x, y) + 0.5) / size;
  float c = rayVL;
  return texture(skyRayleigh, coords).rgb * crep_rayleighPhase(c) +
         texture(skyMie, coords).rgb * crep_henyeyGreenstein(crep_atmosphere.mieExtinction.w, c);
}
#endif

void main() {
  ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(pixel, crep_march.sizes.xy))) return;
  float depth = texelFetch(cameraDepth, pixel, 0).r;
  bool sky = !(depth < 1.0); // the sky test of crep::atmosphereImage (NaN: the sky)
  vec4 ray = crep_pixelRay(crep_march, pixel, depth);
  float s = ray.w;
  beginRay(ray.xyz);
  float Rg = crep_atmosphere.radii.x, Rt = crep_atmosphere.radii.y;
  vec3 C0 = rayC;
  if (length(C0) > Rt) { // above the top: start where the ray enters the atmosphere
    vec2 top = crep_raySphere(C0, rayV, Rt);
    if (!(top.y > 0.0)) { // misses the atmosphere: nothing in-scattered, everything transmitted
      imageStore(inscatteringOut, pixel, vec4(0.0, 0.0, 0.0, 1.0));
      imageStore(transmittanceOut, pixel, vec4(1.0));
      return;
    }
    cameraShift = max(top.x, 0.0);
    rayC = C0 + cameraShift * rayV;
    rayRR += cameraShift * (2.0 * rayCV + cameraShift);
    rayCV += cameraShift;
    rayCL += cameraShift * rayVL;
  }
#if CREP_ATMOSPHERE_VOLUME
  useVolume = cameraShift == 0.0;
  pixelScreen = (vec2(pixel) + 0.5) / vec2(crep_march.sizes.xy);
#endif
  surfaceM = max(s * metres - cameraShift, 0.0);
  float exitTop = max(crep_raySphere(rayC, rayV, Rt).y, 0.0);
  // The ground's near root from |C|^2 - R^2 and C.v (rayRR, rayCV): a float ray-sphere test with |C|^2 ~ 4e13
  // m^2 moves it by metres, and a look-up at a point metres above the ground reads a fraction of the next
  // altitude texel. t0 = -b - sqrt(b^2 - c) = c / (-b + sqrt(b^2 - c)) for b = C.v < 0, c = |C|^2 - R^2 > 0.
  float discGround = rayCV * rayCV - rayRR;
  bool hitsGround = rayCV < 0.0 && rayRR > 0.0 && discGround >= 0.0;
  float groundT = hitsGround ? rayRR / (sqrt(discGround) - rayCV) : 0.0;
  float rayEnd = hitsGround ? min(groundT, exitTop) : exitTop;   // t_X: the ray's end X
  float tE = sky ? min(surfaceM, rayEnd) : min(surfaceM, exitTop); // s_F (sky: the far plane) or s_E

  float cosTheta = dot(rayV, rayL);
  rayleighPhaseBeta = crep_atmosphere.rayleighScattering.rgb * crep_rayleighPhase(cosTheta);
  miePhaseBeta = crep_atmosphere.mieScattering.rgb * crep_henyeyGreenstein(crep_atmosphere.mieExtinction.w, cosTheta);

  vec3 single = vec3(0.0);
#if CREP_SHAFTS_WALK
  ivec2 mapSize = crep_march.sizes.zw;
  CrepRowRay r;
  bool mapped = crep_mapRowRay(rayV, s, mapSize, r);
#endif
#if CREP_ATMOSPHERE_SHAFTS == 1
  sectionEnd = tE;
  if (!mapped) {
    integrateSection(0.0, s);
  } else {
    crep_minMaxWalk(r, s, mapSize, crep_march.info.x, crep_march.info.y);
    if (pendingB > pendingA) integrateSection(pendingA, pendingB);
  }
  single = singleSum;
  if (sky && rayEnd > tE) single += skyQuadrature(tE, rayEnd, max(crep_march.info.w, 1)); // unshadowed
#elif CREP_ATMOSPHERE_SHAFTS == 2
  if (!mapped) {
    if (s > 0.0) {
      firstLit = 0.0;
      litLength = s;
    }
  } else {
    crep_minMaxWalk(r, s, mapSize, crep_march.info.x, crep_march.info.y);
  }
#elif CREP_ATMOSPHERE_SHAFTS == 3
  // crep::prefilteredVisibility: Rec. 709 luminance of the shadowed texel over the unshadowed closed form.
  vec3 shadowed = texelFetch(prefiltered, pixel, 0).rgb;
  float g = crep_march.mieScattering.w;
  float c = dot(crep_march.lightDirection.xyz, -rayV);
  vec3 constant = crep_march.lightIrradiance.rgb *
                  (crep_march.mieScattering.rgb * crep_henyeyGreenstein(g, c) +
                   crep_march.rayleighScattering.rgb * crep_rayleighPhase(c));
  vec3 unshadowed = constant * crep_transmittanceIntegral(crep_march.extinction.rgb, 0.0, s);
  const vec3 rec709 = vec3(0.2126, 0.7152, 0.0722);
  float den = dot(rec709, unshadowed);
  visibility = den > 0.0 ? clamp(dot(rec709, shadowed) / den, 0.0, 1.0) : 1.0;
#endif
  // The table-based part; near the horizon the blend of a ray just below and one just above it
  // (crep::horizonBlendWidth), as crep::atmosphereRay.
  vec3 L;
  float rC = sqrt(Rg * Rg + rayRR), cz = rayCV / rC;
  float hC = rayRR / (rC + Rg);
  float ch = crep_cosHorizon(crep_atmosphere, hC), eps = crep_horizonBlendWidth(crep_atmosphere, hC);
  vec3 n = normalize(rayC);
  vec3 across = rayV - cz * n;
  if (abs(cz - ch) < eps && length(across) > 1e-6) {
    vec3 u = normalize(across);
    vec3 v0 = rayV;
    float cv0 = rayCV, vl0 = rayVL;
    float w = (cz - ch + eps) / (2.0 * eps);
    L = vec3(0.0);
    for (int side = 0; side < 2; ++side) {
      float c2 = side == 0 ? ch - eps : ch + eps;
      rayV = c2 * n + sqrt(max(0.0, 1.0 - c2 * c2)) * u;
      rayCV = rC * c2;
      rayVL = dot(rayV, rayL);
      L += (side == 0 ? 1.0 - w : w) * tablePart(sky, tE);
    }
    rayV = v0;
    rayCV = cv0;
    rayVL = vl0;
  } else {
    L = tablePart(sky, tE);
  }
#if CREP_ATMOSPHERE_VOLUME
  if (useVolume) { // L1: the volume in front of the far plane, the sky-view table's whole ray beyond it
    vec3 toEnd = volumeSingle(tE);
#if CREP_ATMOSPHERE_SHAFTS == 0
    L += toEnd;
#elif CREP_ATMOSPHERE_SHAFTS == 2
    if (litLength > 0.0) {
      float t1 = clamp(firstLit * metres, 0.0, tE);
      float t2 = clamp(firstLit * metres + litLength * metres, t1, tE);
      L += max(volumeSingle(t2) - volumeSingle(t1), vec3(0.0));
    }
#elif CREP_ATMOSPHERE_SHAFTS == 3
    L += visibility * toEnd;
#endif
    if (sky) L += max(skyViewSingle() - toEnd, vec3(0.0));
  }
#endif
  L += single;
  // A sky pixel whose ray ends on the ground beyond the scene: the ground's Lambertian reflection of the sun
  // and the sky light seen through the air (crep::atmosphereRay's rule).
  float albedo = crep_atmosphere.multipleScattering.x;
  if (sky && hitsGround && albedo > 0.0) {
    RayPoint X = rayPoint(rayEnd);
    vec3 direct = X.cosSun > 0.0
                      ? crep_sunTransmittanceAt(opticalDepthTable, crep_atmosphere, X.h, X.cosSun) * X.cosSun
                      : vec3(0.0);
    L += segmentTransmittance(rayEnd) * (albedo * float(CREP_INV_PI)) *
         (direct + crep_ambientSkyLight(ambientTable, crep_atmosphere, X.cosSun));
  }
  vec3 T = sky ? (hitsGround ? vec3(0.0) : transmittanceTo(rayEnd)) : segmentTransmittance(tE);
  vec3 inscattering = crep_march.lightIrradiance.rgb * L;
  imageStore(inscatteringOut, pixel, vec4(inscattering, (T.r + T.g + T.b) / 3.0));
  imageStore(transmittanceOut, pixel, vec4(T, 1.0));
}
#endif // CREP_ATMOSPHERE_VOLUME_PASS
