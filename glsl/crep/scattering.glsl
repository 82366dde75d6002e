// crepuscular: prefiltered single scattering on a rectified shadow map (Klehm, Seidel, Eisemann 2014,
// "Filter-based real-time single scattering using rectified shadow maps", JCGT 3(3)), the per-pixel
// half: Fourier coefficients (Eq. 8), the constant-time evaluation of a view ray (Listing 4,
// Appendix A), generalised to prefilter regions exactly as crep::evaluate() (crep/prefilter/prefilter.h,
// "Evaluation") does it, and the weight and basis helpers the prefilter pass shares with it.
//
// Public include (see crep/common.glsl for the conventions). How an engine uses it in its own deferred
// or forward shader:
//
//   #define CREP_SCATTERING_BINDING 3      // uniform buffer binding of CrepScatteringBlock (default 0)
//   #define CREP_FILTERED_BASIS_UNIT 5     // texture unit of the filtered basis (default 0)
//   #include "crep/scattering.glsl"
//   ...
//   vec4 s = crep_inScattering(cameraPosition, viewDirection, surfaceDistance);
//   color = surface * s.a + s.rgb;
//
// C++ side: bind PrefilterPass::filteredBasisTexture() (GL_TEXTURE_2D_ARRAY; GL_LINEAR filtering and
// clamp to edge, as the pass sets them) to the unit and a uniform buffer holding the gpu::ScatteringParams
// of makeScatteringParams() (crep/prefilter/gpu_pass.h) to the binding.
//
// Entry points: crep_inScattering(origin, dir, surfaceDistance), crep_inScatteringAt(worldPosition),
// crep_inScatteringSegment(origin, dir, start, surface). They return vec4(in-scattered radiance,
// grey transmittance to the surface). Scope as crep::evaluate: a directional light and a projective
// rectification (the block holds its frame and split zetas).
//
// Options (#define before the include; every one has a default):
//   CREP_SCATTERING_BINDING, CREP_FILTERED_BASIS_UNIT    resources above
//   CREP_BASES                 M, when known at compile time (loops get constant bounds); must then equal
//                              the filtered basis's M. Without it M comes from the uniform block.
//   CREP_NEAR_PLANE_CORRECTION 1: Sec. 3.1's near-plane correction (crep_inScatteringSegment with start > 0);
//                              also declares the region-weights storage buffer (PrefilterPass::
//                              regionWeightsBuffer()) at CREP_REGION_WEIGHTS_BINDING (default 1).
//   CREP_RINGING_LANCZOS       1: damp the ray coefficients with Lanczos sigma factors (crep::RingingFilter::
//                              Lanczos, fourier.h; not in the paper); default 0 = Eq. 8 as published
//   CREP_FP64                  1: reduce Fourier angles in double (opt-in; default 0: float only, exact
//                              reduction from float pairs, see "Accuracy" below). The former CREP_NO_FP64
//                              is still read: CREP_NO_FP64 0 means CREP_FP64 1.
//   CREP_VISIBILITY_TABLE_SAMPLES  Z: read the visibility of every region a ray crosses whole from the
//                              region visibility table (crep::EvaluateOptions::visibilityTableSamples; built
//                              by EvaluatePass, or glsl/passes/prefilter/visibility_table.comp) bound as a sampler2D
//                              with GL_LINEAR at CREP_VISIBILITY_TABLE_UNIT (default 6); one fetch instead of
//                              M / 4 per such region. Ignored with CREP_NEAR_PLANE_CORRECTION 1.
//   CREP_SCATTERING_PREFIX     1 (with CREP_VISIBILITY_TABLE_SAMPLES): read the regions a ray crosses whole
//                              from the scattering prefix table instead (crep::EvaluateOptions::
//                              scatteringPrefix; built by EvaluatePass, or glsl/passes/prefilter/scattering_prefix.comp)
//                              bound as an RGBA32F sampler2D with GL_LINEAR at CREP_SCATTERING_PREFIX_UNIT
//                              (default 7): one fetch per pixel, whatever the number of regions crossed.
//   CREP_LOCAL_SECTIONS        1 (with CREP_LOCAL_LIGHT and CREP_SCATTERING_PREFIX): the last region's
//                              section from the local section table (RGBA32F, the prefix table's layout,
//                              at CREP_LOCAL_SECTION_UNIT, default 5) times crep_localPartialShare.
//   CREP_LOCAL_LIGHT           1: a local light (spot, or one point-light face) instead of the directional
//                              light of the block: declares CrepLocalLightBlock (gpu::LocalLightParams,
//                              binding CREP_LOCAL_LIGHT_BINDING, default 3) and integrates every region
//                              segment with crep_localSegment (crep/local_light.glsl) times its
//                              visibility; the basis must be prefiltered with the same light. The
//                              projective frame or CREP_EVAL_LAYOUT (an EpipolarLayout built for the
//                              light's position), no near-plane correction. CREP_AIRLIGHT 1 (default) integrates
//                              the sections in closed form (crep_airlightSegment, crep/airlight.glsl: the
//                              airlight table bound at CREP_AIRLIGHT_UNIT, default 4); 0 keeps the quadrature.
//   CREP_LIGHT_TEXTURE         1: a basis prefiltered with a light texture's colour map (crep/prefilter/
//                              prefilter.h, "Light textures"; Klehm et al. 2014, Sec. 3.2): the array holds
//                              three bases (colour c in layers [c L, (c + 1) L), L = ceil(M / 4)) and the
//                              prefix mean colour is bound as a sampler2D (GL_RGBA16F, GL_LINEAR) at
//                              CREP_MEAN_COLOR_UNIT (default 2); each region's visibility is per channel,
//                              V_c = cbar_c clamp(0.5 + a . F_c, 0, 1). Not with CREP_NEAR_PLANE_CORRECTION
//                              nor with the visibility table alone (use the scattering prefix or no table).
//   CREP_SCATTERING_NO_EVALUATION  only the math (no block, no sampler): what the prefilter pass uses.
//   CREP_EVAL_LAYOUT           evaluate on a layout block of crep/layout.glsl instead of the projective
//                              frame of the scattering block: CREP_LAYOUT_PROJECTIVE (0) or
//                              CREP_LAYOUT_EPIPOLAR (1, the fallback of Klehm et al. 2014, Sec. 4.1). Bind
//                              the layout block at CREP_LAYOUT_BINDING and, for the epipolar layout, the
//                              slice table at CREP_SLICES_BINDING (gpu::LayoutBuffers of any layout). The
//                              entry points and the integration rule are the same on both layouts.
#ifndef CREP_SCATTERING_GLSL
#define CREP_SCATTERING_GLSL

#include "bindings.h"
#include "common.glsl"
#include "local_light.glsl"
#include "phase.glsl"
#include "ray.glsl"
#include "scattering_structs.glsl"

#ifndef CREP_NEAR_PLANE_CORRECTION
#define CREP_NEAR_PLANE_CORRECTION 0
#endif
#ifndef CREP_LOCAL_LIGHT
#define CREP_LOCAL_LIGHT 0
#endif
#ifndef CREP_LOCAL_LIGHT_BINDING
#define CREP_LOCAL_LIGHT_BINDING CREP_LOCAL_LIGHT_DEFAULT_BINDING
#endif
#ifndef CREP_LOCAL_SECTIONS
#define CREP_LOCAL_SECTIONS 0
#endif
// A local section's far end when its end boundary is beyond reach (the ray never gets there): far enough
// that nothing is left of the light beyond it, small enough for float arithmetic on it.
#define CREP_LOCAL_SECTION_END 1e29
#ifndef CREP_RINGING_LANCZOS
#define CREP_RINGING_LANCZOS 0
#endif
// 1: crep::VisibilityReconstruction::Exact. Layer 0 of the basis array holds per texel (depth, cumulative
// weight W) in RG32F (with a light texture (depth, W of colour 0, 1, 2) in RGBA32F), layer 1 each block of
// CREP_EXACT_BLOCK texels' (min, max) depth; evaluation walks them (crep_exactPrefix) instead of the series.
#ifndef CREP_EXACT_VISIBILITY
#define CREP_EXACT_VISIBILITY 0
#endif
#define CREP_EXACT_BLOCK 8 // texels per block of the exact reconstruction's (min, max) layer
#ifndef CREP_EXACT_NEAREST
#define CREP_EXACT_NEAREST 0 // 1: crep::Sampling::Nearest of the exact prefix (the nearest texel)
#endif

// ---------------------------------------------------------------------------------------------------
// Fourier basis and coefficients (Eq. 8). Harmonic h = 0, 1, ... is the paper's k = h + 1, with
// c_k = pi (2k - 1) = pi (2h + 1). Bases are packed four per RGBA texel as crep::fourierBasis orders
// them: (B_{2k-1}, B_{2k}, B_{2k+1}, B_{2k+2}) = (sin c_k z, cos c_k z, sin c_{k+1} z, cos c_{k+1} z),
// so layer l holds harmonics 2l and 2l + 1.
//
// Accuracy: the highest harmonic reaches (2h + 1) pi ~ 400 rad for M = 128, where a float angle is only
// good to ~2e-5 rad. Angles are therefore reduced in half turns exactly (x mod 2) and only the reduced value
// is rounded; sin and cos of pi r come from crep_sincospi, whose reduction is exact too. Harmonics inside a
// group advance by the angle-addition recurrence (one sin/cos pair per group).
// Default (chosen for GPUs: consumer parts run fp64 at 1/16 to 1/64 of the float rate, some have none):
// float only. A depth is an unevaluated pair hi + lo (CrepDepth = vec2) that holds m + (1 - 2m) d exactly
// (Dekker's product and Knuth's sum, `precise` so no compiler reassociates or contracts them), and
// (2h + 1) z is formed from a Veltkamp split of hi into two 12-bit halves, whose products by 2h + 1 < 2^12
// are exact, so the reduction mod 2 is exact and one rounding remains. CREP_FP64 1 (opt-in) does the same
// reduction in double instead. Measured against the double CPU prefilter (RGBA32F, llvmpipe; tests/
// prefilter/PrefilterGpuGLTest.cpp): max error of the stored basis 8e-7 for M = 32 and M = 128 with either.
// (The former float path, one rounded product, gave 1.8e-6 / 1.1e-5.)

#if !defined(CREP_FP64) && defined(CREP_NO_FP64)
#define CREP_FP64 (1 - CREP_NO_FP64) // the former switch: CREP_NO_FP64 0 asked for double
#endif
#ifndef CREP_FP64
#define CREP_FP64 0
#endif

#if CREP_FP64
#define CrepDepth double

// x mod 2 in [-1, 1): the angle pi x reduced to one turn (exact in double).
float crep_halfTurns(double x) { return float(x - 2.0LF * floor(x * 0.5LF + 0.5LF)); }
float crep_harmonicTurns(int h, CrepDepth z) { return crep_halfTurns(double(2 * h + 1) * z); }
float crep_stepTurns(CrepDepth z) { return crep_halfTurns(2.0LF * z); }
CrepDepth crep_basisDepth(float depth, float margin) {
  return double(margin) + (1.0LF - 2.0LF * double(margin)) * double(depth);
}
CrepDepth crep_depthConstant(float v) { return double(v); }
#else
#define CrepDepth vec2

// Knuth's TwoSum: a + b = s + e exactly.
vec2 crep_twoSum(float a, float b) {
  precise float s = a + b;
  precise float bb = s - a;
  precise float e = (a - (s - bb)) + (b - bb);
  return vec2(s, e);
}
// Veltkamp's split: a = hi + lo, each with at most 12 significant bits.
vec2 crep_split(float a) {
  precise float c = 4097.0 * a;
  precise float hi = c - (c - a);
  precise float lo = a - hi;
  return vec2(hi, lo);
}
// Dekker's TwoProduct: a b = p + e exactly.
vec2 crep_twoProduct(float a, float b) {
  precise float p = a * b;
  vec2 x = crep_split(a), y = crep_split(b);
  precise float e = ((x.x * y.x - p) + x.x * y.y + x.y * y.x) + x.y * y.y;
  return vec2(p, e);
}
// x mod 2 in [-1, 1) of a float that is a multiple of its own ulp (exact: the result keeps x's grid).
float crep_reduce2(float x) {
  precise float r = x - 2.0 * floor(x * 0.5 + 0.5);
  return r;
}
// (k z) mod 2 for an integer 0 < k < 2^12: exact up to the final rounding.
float crep_scaledTurns(float k, CrepDepth z) {
  vec2 h = crep_split(z.x);
  precise float a = crep_reduce2(k * h.x); // 12 x 12 bits: exact
  precise float b = crep_reduce2(k * h.y); // exact
  precise float r = (a + b) + k * z.y;
  return r;
}
float crep_harmonicTurns(int h, CrepDepth z) { return crep_scaledTurns(float(2 * h + 1), z); }
float crep_stepTurns(CrepDepth z) { return crep_scaledTurns(2.0, z); }
// m + (1 - 2m) d as hi + lo (exact for the float m and d; 1 - 2m is exact for m a multiple of 2^-24).
CrepDepth crep_basisDepth(float depth, float margin) {
  vec2 p = crep_twoProduct(1.0 - 2.0 * margin, depth);
  vec2 s = crep_twoSum(margin, p.x);
  precise float lo = s.y + p.y;
  return crep_twoSum(s.x, lo);
}
CrepDepth crep_depthConstant(float v) { return vec2(v, 0.0); }
#endif

// (sin(pi x), cos(pi x)) for |x| < 2^22, within a few ulp: exact reduction to r in [-1/4, 1/4] and the
// quadrant, then Taylor polynomials of degree 9 / 10 in r (truncation below 1e-8).
vec2 crep_sincospi(float x) {
  float k = round(2.0 * x);
  float r = x - 0.5 * k;
  float r2 = r * r;
  float s = r * (3.14159265358979 +
                 r2 * (-5.16771278004997 + r2 * (2.55016403987735 + r2 * (-0.599264529320792 + r2 * 0.0821458866111282))));
  float c = 1.0 + r2 * (-4.93480220054468 +
                        r2 * (4.05871212641677 + r2 * (-1.33526276885459 + r2 * (0.235330630358893 + r2 * -0.0258068913900914))));
  int q = int(k) & 3;
  if (q == 0) return vec2(s, c);
  if (q == 1) return vec2(c, -s);
  if (q == 2) return vec2(-s, -c);
  return vec2(-c, s);
}

// (sin, cos) of c_k z for harmonic h (k = h + 1): the start of a recurrence.
vec2 crep_harmonic(int h, CrepDepth z) { return crep_sincospi(crep_harmonicTurns(h, z)); }

// (sin, cos) of the recurrence step 2 pi z between consecutive harmonics.
vec2 crep_harmonicStep(CrepDepth z) { return crep_sincospi(crep_stepTurns(z)); }

// Angle addition: (sin, cos) of a + b from those of a and b.
vec2 crep_rotate(vec2 a, vec2 b) { return vec2(a.x * b.y + a.y * b.x, a.y * b.y - a.x * b.x); }

// The depth fed to B for a stored map depth (crep::texelBasisDepth, fourier.h): the exact end values 0
// (caster clamped in front) and 1 (nothing) stay, the rest moves into [m, 1 - m].
CrepDepth crep_texelBasisDepth(float depth, float margin) {
  if (depth >= 1.0) return crep_depthConstant(1.0);
  if (depth <= 0.0) return crep_depthConstant(0.0);
  return crep_basisDepth(depth, margin);
}

// The depth fed to a for a view ray (crep::rayBasisDepth): m + (1 - 2m) clamp(depth, 0, 1).
CrepDepth crep_rayBasisDepth(float depth, float margin) { return crep_basisDepth(clamp(depth, 0.0, 1.0), margin); }

// Eq. 8 coefficients of harmonics h and h + 1 in basis order: (a_{2k-1}, a_{2k}, a_{2k+1}, a_{2k+2}) =
// (2 cos / c_k, -2 sin / c_k, 2 cos / c_{k+1}, -2 sin / c_{k+1}) from their (sin, cos).
vec4 crep_coefficients4(int h, vec2 first, vec2 second) {
  float g0 = 2.0 / (float(CREP_PI) * float(2 * h + 1));
  float g1 = 2.0 / (float(CREP_PI) * float(2 * h + 3));
  return vec4(g0 * first.y, -g0 * first.x, g1 * second.y, -g1 * second.x);
}

// Lanczos sigma factor sin(x) / x, x = pi (2h + 1) / M, of harmonic h (crep::ringingFactor).
float crep_lanczosFactor(int h, int bases) {
  float x = float(2 * h + 1) / float(bases);
  return crep_sincospi(x).x / (float(CREP_PI) * x);
}

// ---------------------------------------------------------------------------------------------------
// Weights (crep/prefilter/weights.h; Eq. 11 and its variants). s is the scalar weight extinction.

// exp(x) - 1 without cancellation near 0 (series below 1/4, truncation < 1e-8 relative).
float crep_expm1(float x) {
  if (abs(x) < 0.25)
    return x * (1.0 + x * (1.0 / 2.0 + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x * (1.0 / 120.0 + x / 720.0)))));
  return exp(x) - 1.0;
}

// The weight mode's distance tau from the region's start at fractional texel position x = u n (see
// gpu::RegionWeights); a negative value stands for +infinity.
float crep_regionDistance(CrepRegionWeights w, int mode, int n, float x) {
  if (w.valid == 0) return -1.0;
  if (mode == CREP_WEIGHTS_EXACT) {
    float u = x / float(n);
    float den = w.c + w.d * u;
    return den > 0.0 ? u * w.scale / den : -1.0;
  }
  if (mode == CREP_WEIGHTS_CONSTANT_STEP) return x * w.scale;
  if (mode == CREP_WEIGHTS_CONSTANT_RATIO) return w.c == 0.0 ? x * w.scale : w.scale * crep_expm1(x * w.c);
  return x;
}

// Listing 2's mix factor of texel i of an n-texel region (crep::regionMixFactors): w_i / sum_{j<=i} w_j
// with w_i = exp(-s tau_i) - exp(-s tau_{i+1}), written with phi so that s = 0 is the length-weighted
// mean. Texel lengths come without the cancellation of tau_{i+1} - tau_i.
float crep_mixFactor(CrepRegionWeights w, int mode, float s, int i, int n) {
  if (mode == CREP_WEIGHTS_AVERAGE_VISIBILITY) return 1.0 / float(i + 1);
  if (i == 0) return 1.0;
  if (w.valid == 0) return 0.0;
  float t0, t1, dt;
  if (mode == CREP_WEIGHTS_EXACT) {
    float u0 = float(i) / float(n), u1 = float(i + 1) / float(n);
    float den0 = w.c + w.d * u0, den1 = w.c + w.d * u1;
    if (!(den0 > 0.0) || !(den1 > 0.0)) return 0.0; // beyond a spot light's horizon
    t0 = u0 * w.scale / den0;
    t1 = u1 * w.scale / den1;
    dt = w.scale * w.c / (float(n) * den0 * den1);
  } else if (mode == CREP_WEIGHTS_CONSTANT_STEP) {
    t0 = float(i) * w.scale;
    t1 = float(i + 1) * w.scale;
    dt = w.scale;
  } else { // CREP_WEIGHTS_CONSTANT_RATIO: tau_i = D0 (r^i - 1) / (r - 1), step D0 r^i
    if (w.c == 0.0) {
      t0 = float(i) * w.scale;
      t1 = float(i + 1) * w.scale;
      dt = w.scale;
    } else {
      t0 = w.scale * crep_expm1(float(i) * w.c);
      t1 = w.scale * crep_expm1(float(i + 1) * w.c);
      dt = w.d * exp(float(i) * w.c);
    }
  }
  float num = exp(-s * t0) * crep_oneMinusExpOverX(s * dt) * dt;
  float den = crep_oneMinusExpOverX(s * t1) * t1;
  if (!(den > 0.0)) return 1.0 / float(i + 1);
  float m = num / den;
  return m >= 0.0 ? min(m, 1.0) : 0.0; // also sends NaN (float overflow far out) to 0
}

// The local light of a gpu::LocalLightParams block as crep_localSegment takes it (crep/local_light.glsl).
CrepLocalLight crep_localLightOf(CrepLocalLightParams L) {
  CrepLocalLight l;
  l.position = L.position.xyz;
  l.intensity = L.intensity.rgb;
  l.axis = L.axis.xyz;
  l.nearPlane = L.position.w;
  l.cosInner = L.cone.x;
  l.cosOuter = L.cone.y;
  l.cone = L.cone.z != 0.0;
  l.face = int(L.axis.w);
  return l;
}

// The grey light-side factor of the prefilter's weights at `point` of a view ray of direction v
// (crep::LocalLight::weightFactor; Klehm et al. 2014, Sec. 3.2 "Angular-dependency for Sources").
float crep_localWeightFactor(CrepLocalLightParams L, vec3 point, vec3 v) {
  if (L.cone.w == 2.0) return 1.0; // crep::LocalLightWeights::None
  vec3 p = point - L.position.xyz;
  float d = length(p);
  vec3 w = d > 0.0 ? p / d : v;
  float dc = max(d, L.position.w);
  float mu = dot(w, -v);
  vec3 phase = L.mieScattering.rgb * crep_henyeyGreenstein(L.mieScattering.w, mu) +
               L.rayleighScattering.rgb * crep_rayleighPhase(mu);
  vec3 I = crep_localIntensityToward(crep_localLightOf(L), w);
  if (L.cone.w == 1.0) return (I.r + I.g + I.b) / 3.0; // crep::LocalLightWeights::Angular
  return (phase.r + phase.g + phase.b) * (I.r + I.g + I.b) / 9.0 * exp(-L.origin.w * dc) / (dc * dc);
}

// The weight total of the first u n texels divided by s (crep::regionWeightTotal): tau phi(s tau).
float crep_regionWeightTotal(CrepRegionWeights w, int mode, float s, int n, float u) {
  if (mode == CREP_WEIGHTS_AVERAGE_VISIBILITY) return u * float(n);
  float tau = crep_regionDistance(w, mode, n, u * float(n));
  if (tau < 0.0) return s > 0.0 ? 1.0 / s : 3.0e38;
  return tau * crep_oneMinusExpOverX(s * tau);
}

#ifndef CREP_SCATTERING_NO_EVALUATION
// ---------------------------------------------------------------------------------------------------
// Evaluation (Listing 4 + Appendix A, regions as in crep::evaluate).

#ifndef CREP_SCATTERING_BINDING
#define CREP_SCATTERING_BINDING CREP_SCATTERING_DEFAULT_BINDING
#endif
#ifndef CREP_FILTERED_BASIS_UNIT
#define CREP_FILTERED_BASIS_UNIT CREP_FILTERED_BASIS_DEFAULT_UNIT
#endif
#ifndef CREP_REGION_WEIGHTS_BINDING
#define CREP_REGION_WEIGHTS_BINDING CREP_REGION_WEIGHTS_DEFAULT_BINDING
#endif

layout(std140, binding = CREP_SCATTERING_BINDING) uniform CrepScatteringBlock { CrepScatteringParams crep_scattering; };
layout(binding = CREP_FILTERED_BASIS_UNIT) uniform sampler2DArray crep_filteredBasis;
#ifndef CREP_LIGHT_TEXTURE
#define CREP_LIGHT_TEXTURE 0
#endif
#if CREP_LIGHT_TEXTURE
#ifndef CREP_MEAN_COLOR_UNIT
#define CREP_MEAN_COLOR_UNIT CREP_MEAN_COLOR_DEFAULT_UNIT
#endif
layout(binding = CREP_MEAN_COLOR_UNIT) uniform sampler2D crep_meanColor; // cbar, rgb
#if CREP_NEAR_PLANE_CORRECTION
#error "CREP_LIGHT_TEXTURE: the near-plane correction is not supported with a light texture"
#endif
#if defined(CREP_VISIBILITY_TABLE_SAMPLES) && !CREP_SCATTERING_PREFIX
#error "CREP_LIGHT_TEXTURE: use the scattering prefix table (CREP_SCATTERING_PREFIX 1) or no table"
#endif
#endif
#ifdef CREP_VISIBILITY_TABLE_SAMPLES
#ifndef CREP_VISIBILITY_TABLE_UNIT
#define CREP_VISIBILITY_TABLE_UNIT CREP_VISIBILITY_TABLE_DEFAULT_UNIT
#endif
layout(binding = CREP_VISIBILITY_TABLE_UNIT) uniform sampler2D crep_visibilityTable;
#ifndef CREP_SCATTERING_PREFIX
#define CREP_SCATTERING_PREFIX 0
#endif
#if CREP_SCATTERING_PREFIX
#ifndef CREP_SCATTERING_PREFIX_UNIT
#define CREP_SCATTERING_PREFIX_UNIT CREP_SCATTERING_PREFIX_DEFAULT_UNIT
#endif
layout(binding = CREP_SCATTERING_PREFIX_UNIT) uniform sampler2D crep_scatteringPrefix;
#if CREP_LOCAL_LIGHT && CREP_LOCAL_SECTIONS
#ifndef CREP_LOCAL_SECTION_UNIT
#define CREP_LOCAL_SECTION_UNIT CREP_LOCAL_SECTION_DEFAULT_UNIT
#endif
layout(binding = CREP_LOCAL_SECTION_UNIT) uniform sampler2D crep_localSections;
#endif
#endif
#endif
#if CREP_NEAR_PLANE_CORRECTION
layout(std430, binding = CREP_REGION_WEIGHTS_BINDING) readonly buffer CrepRegionWeightsBlock {
  CrepRegionWeights crep_regionWeights[];
};
#endif

#ifdef CREP_BASES
#define CREP_EVAL_LAYERS ((CREP_BASES + 3) / 4)
#define CREP_EVAL_HALF (CREP_BASES / 2)
#define CREP_EVAL_MAX_LAYERS ((CREP_BASES + 3) / 4)
#else
#define CREP_EVAL_LAYERS crep_scattering.basisInfo.y
#define CREP_EVAL_HALF (crep_scattering.basisInfo.x / 2)
#define CREP_EVAL_MAX_LAYERS 32
#endif

#ifdef CREP_EVAL_LAYOUT
#define CREP_LAYOUT CREP_EVAL_LAYOUT
#include "layout.glsl"
#endif

#if CREP_LOCAL_LIGHT
#ifdef VULKAN
// Vulkan: the same block as a read-only storage buffer (std430 = std140 for its vec4 members). Mesa 22.3's
// lavapipe faults when it inlines this block's values (used in branches) as a uniform block next to a
// layout block (docs/BACKENDS.md, "Vulkan backend").
#ifndef CREP_LOCAL_LIGHT_STORAGE_BINDING
#define CREP_LOCAL_LIGHT_STORAGE_BINDING CREP_LOCAL_LIGHT_STORAGE_DEFAULT_BINDING
#endif
layout(std430, binding = CREP_LOCAL_LIGHT_STORAGE_BINDING) readonly buffer CrepLocalLightBlock { CrepLocalLightParams crep_localParams; };
#else
layout(std140, binding = CREP_LOCAL_LIGHT_BINDING) uniform CrepLocalLightBlock { CrepLocalLightParams crep_localParams; };
#endif
#ifndef CREP_AIRLIGHT
#define CREP_AIRLIGHT 1
#endif
#if CREP_AIRLIGHT
#include "airlight.glsl"
#endif

// The block's light and medium as crep_localSegment takes them.
CrepLocalLight crep_blockLocalLight() { return crep_localLightOf(crep_localParams); }
CrepLocalMedium crep_blockLocalMedium() {
  return CrepLocalMedium(crep_localParams.mieScattering, crep_localParams.rayleighScattering.rgb,
                         crep_scattering.extinction.rgb);
}
#endif

// The light-dependent factor of a lit section [ta, tb] of the ray origin + t dir: the transmittance
// integral of Eq. 3 for the directional light (the caller multiplies by C), or with CREP_LOCAL_LIGHT the
// local light's own in-scattering of the section (crep_localSegment; crep::evaluate(..., LocalLight)).
vec3 crep_sectionIntegral(vec3 origin, vec3 dir, vec3 sigma, float ta, float tb) {
#if CREP_LOCAL_LIGHT
  if (!(tb < 1e30)) return vec3(0.0); // beyond a region boundary the ray never reaches
#if CREP_AIRLIGHT
  return crep_airlightSegment(crep_blockLocalLight(), crep_blockLocalMedium(), origin, dir, ta, tb);
#else
  return crep_localSegment(crep_blockLocalLight(), crep_blockLocalMedium(), origin, dir, ta, tb);
#endif
#else
  return crep_transmittanceIntegral(sigma, ta, tb);
#endif
}

// A world point in the rectified map (crep::Rectification::toRectified): slopes y = Y / X, z = Z / X,
// normalized row and depth, split k and the column within it.
struct CrepRectPoint {
  float y, z;
  float row, depth;
  int split;
  float splitColumn;
};

// `offset` = point - frame origin (world). False where the rectification cannot map it (X <= 0).
bool crep_toRectified(vec3 offset, out CrepRectPoint p) {
  float X = dot(crep_scattering.frameAxisX.xyz, offset);
  p = CrepRectPoint(0.0, 0.0, 0.0, 0.0, 0, 0.0);
  if (!(X > 0.0)) return false;
  float Y = dot(crep_scattering.frameAxisY.xyz, offset), Z = dot(crep_scattering.frameAxisZ.xyz, offset);
  p.y = Y / X;
  p.z = Z / X;
  p.row = (p.y - crep_scattering.slopes.x) * crep_scattering.slopes.y;
  p.depth = (p.z - crep_scattering.slopes.z) * crep_scattering.slopes.w;
  float zeta = (1.0 + crep_scattering.frameAxisX.w * Z) / X;
  int K = crep_scattering.mapSize.w;
  int k = 0;
  while (k < K - 1 && zeta < crep_scattering.splitZeta[k].y) ++k;
  vec2 range = crep_scattering.splitZeta[k].xy;
  p.split = k;
  p.splitColumn = (range.x - zeta) / (range.x - range.y);
  return true;
}

// The prefilter region r = k P + q of a mapped point and its column u in [0, 1] inside it.
void crep_regionPoint(CrepRectPoint p, out int region, out float u) {
  int K = crep_scattering.mapSize.w, P = crep_scattering.basisInfo.z;
  int k = clamp(p.split, 0, K - 1);
  float uk = clamp(p.splitColumn, 0.0, 1.0);
  int q = min(int(floor(uk * float(P))), P - 1);
  region = k * P + q;
  u = clamp(uk * float(P) - float(q), 0.0, 1.0);
}

// World distance along the view ray of slopes (y, z) to the boundary column b / R of the prefilter
// regions (crep::Rectification::rayDistance); 3e38 where the ray never gets there.
float crep_boundaryDistance(float y, float z, int b) {
  int K = crep_scattering.mapSize.w, P = crep_scattering.basisInfo.z;
  int k = b / P;
  float u = float(b - k * P) / float(P);
  if (k >= K) {
    k = K - 1;
    u = 1.0;
  }
  vec2 range = crep_scattering.splitZeta[k].xy;
  float den = range.x + u * (range.y - range.x) - crep_scattering.frameAxisX.w * z;
  return den > 0.0 ? sqrt(1.0 + y * y + z * z) / den : 3.0e38;
}

// A view ray mapped for the evaluation: its normalized row and depth z_r, the prefilter region and column
// of its end, and what crep_evalBoundary needs (the projective frame's slopes, or a layout's row ray).
struct CrepEvalRay {
  float row, depth;
  int region;
  float u;
  vec4 data;     // projective frame: (y, z, 0, 0)
#ifdef CREP_EVAL_LAYOUT
  CrepRowRay rr; // layout: the row ray of crep/layout.glsl
#endif
};

// Maps the point origin + t dir (t = surface) of a ray from the camera; false where the layout cannot.
bool crep_evalMap(vec3 origin, vec3 dir, float t, out CrepEvalRay e) {
#ifdef CREP_EVAL_LAYOUT
  e = CrepEvalRay(0.0, 0.0, 0, 0.0, vec4(0.0), CrepRowRay(0.0, 0.0, 0, 0, vec4(0.0)));
  vec4 p; // (row, column, depth, layout region) of the end point, from the ray's own mapping
  if (!(t > 0.0) || !crep_mapRowRayPoint(dir, t, crep_scattering.mapSize.xy, e.rr, p)) return false;
  CrepRectPoint hit = CrepRectPoint(0.0, 0.0, p.x, p.z, int(p.w), p.y * float(crep_scattering.mapSize.w) - p.w);
  crep_regionPoint(hit, e.region, e.u);
  e.row = p.x;
  e.depth = p.z;
  return true;
#else
  e = CrepEvalRay(0.0, 0.0, 0, 0.0, vec4(0.0));
  CrepRectPoint hit;
  if (!crep_toRectified(origin - crep_scattering.frameOrigin.xyz + t * dir, hit)) return false;
  crep_regionPoint(hit, e.region, e.u);
  e.row = hit.row;
  e.depth = hit.depth;
  e.data = vec4(hit.y, hit.z, 0.0, 0.0);
  return true;
#endif
}

// The ray of normalized row and depth (every point of a ray from the camera has the same row and depth):
// what crep_evalBoundary needs, as crep_evalMap gives it for a ray there. Region and column are not set.
CrepEvalRay crep_evalRayAt(float row, float depth) {
#ifdef CREP_EVAL_LAYOUT
  return CrepEvalRay(row, depth, 0, 0.0, vec4(0.0), crep_rowRayAt(row, depth, crep_scattering.mapSize.xy));
#else
  // The slopes of the scattering block's frame (inverse of crep_toRectified's row and depth).
  float y = crep_scattering.slopes.x + row / crep_scattering.slopes.y;
  float z = crep_scattering.slopes.z + depth / crep_scattering.slopes.w;
  return CrepEvalRay(row, depth, 0, 0.0, vec4(y, z, 0.0, 0.0));
#endif
}

// The unit direction of a ray of crep_evalRayAt.
vec3 crep_evalRayDirection(CrepEvalRay e) {
#ifdef CREP_EVAL_LAYOUT
  return crep_layoutViewDirection(e.row, e.depth);
#else
  return normalize(crep_scattering.frameAxisX.xyz + e.data.x * crep_scattering.frameAxisY.xyz +
                   e.data.y * crep_scattering.frameAxisZ.xyz);
#endif
}

// World distance along the mapped ray to the boundary column b / R of the prefilter regions.
float crep_evalBoundary(CrepEvalRay e, int b) {
#ifdef CREP_EVAL_LAYOUT
  int n = crep_scattering.mapSize.x / crep_scattering.mapSize.z; // texels per prefilter region
  return crep_rowRayDistance(e.rr, b * n, crep_scattering.mapSize.xy);
#else
  return crep_boundaryDistance(e.data.x, e.data.y, b);
#endif
}

// The decoded filtered basis F = 2 e - 1 of one layer at prefix boundary u of region r and normalized
// row (crep::evaluate's sampling rule: texel x = clamp(u n - 1, 0, n - 1) of the region, y = clamp(row H
// - 0.5, 0, H - 1)). The sampler's GL_LINEAR / GL_NEAREST does the filtering; x never leaves the region.
vec4 crep_filteredBasisAt(int region, float u, float row, int layer) {
  int W = crep_scattering.mapSize.x, H = crep_scattering.mapSize.y, n = W / crep_scattering.mapSize.z;
  float x = clamp(u * float(n) - 1.0, 0.0, float(n - 1));
  float y = clamp(row * float(H) - 0.5, 0.0, float(H - 1));
  vec3 coord = vec3((float(region * n) + x + 0.5) / float(W), (y + 0.5) / float(H), float(layer));
  return 2.0 * textureLod(crep_filteredBasis, coord, 0.0) - 1.0;
}

#if CREP_EXACT_VISIBILITY
#if CREP_LIGHT_TEXTURE
#define CrepExactWeight vec3
#define crep_exactWeightOf(t) (t).gba
#else
#define CrepExactWeight float // one colour: scalar arithmetic (GPU: fewer registers and instructions)
#define crep_exactWeightOf(t) (t).g
#endif
// crep::VisibilityReconstruction::Exact: P_x = sum_{i <= x} [z_i >= z] (W_i - W_{i-1}) / W_x over region r's
// texels in row y up to x1 (region-local; crep::evaluate's rule), P at x0 <= x1 into atX0. The blocks before
// x0's block come from layer 1: a block whose depths all pass (min >= z) adds its weight W_end - W_before in one
// step, one that all fail adds nothing; only a block that straddles z (a shadow edge, or the receiver's own
// texels near the ray's end) is walked texel by texel. GPU: about (x0 / 8) * 2 + 8 fetches instead of x0, and
// lanes that end far apart in a region diverge over a few blocks, not over n texels.
float crep_exactRatio(float lit, float W) { return W > 0.0 ? lit / W : 0.0; }
vec3 crep_exactRatio(vec3 lit, vec3 W) { return mix(vec3(0.0), lit / max(W, vec3(1e-30)), greaterThan(W, vec3(0.0))); }

vec3 crep_exactRunningPrefix(int region, int y, int x0, int x1, float z, out vec3 atX0) {
  int n = crep_scattering.mapSize.x / crep_scattering.mapSize.z, base = region * n;
  CrepExactWeight lit = CrepExactWeight(0.0), previous = CrepExactWeight(0.0);
  int firstTexel = (x0 / CREP_EXACT_BLOCK) * CREP_EXACT_BLOCK;
  for (int b = 0; b * CREP_EXACT_BLOCK < firstTexel; ++b) {
    vec2 range = texelFetch(crep_filteredBasis, ivec3(base + b, y, 1), 0).rg;
    int last = b * CREP_EXACT_BLOCK + CREP_EXACT_BLOCK - 1;
    if (z <= range.x || z > range.y) {
      CrepExactWeight W = crep_exactWeightOf(texelFetch(crep_filteredBasis, ivec3(base + last, y, 0), 0));
      if (z <= range.x) lit += W - previous;
      previous = W;
    } else {
      for (int k = b * CREP_EXACT_BLOCK; k <= last; ++k) {
        vec4 t = texelFetch(crep_filteredBasis, ivec3(base + k, y, 0), 0);
        CrepExactWeight W = crep_exactWeightOf(t);
        lit += step(z, t.r) * (W - previous);
        previous = W;
      }
    }
  }
  for (int k = firstTexel; k <= x0; ++k) {
    vec4 t = texelFetch(crep_filteredBasis, ivec3(base + k, y, 0), 0);
    CrepExactWeight W = crep_exactWeightOf(t);
    lit += step(z, t.r) * (W - previous);
    previous = W;
  }
  atX0 = vec3(crep_exactRatio(lit, previous));
  if (x1 > x0) {
    vec4 t = texelFetch(crep_filteredBasis, ivec3(base + x1, y, 0), 0);
    CrepExactWeight W = crep_exactWeightOf(t);
    lit += step(z, t.r) * (W - previous);
    previous = W;
  }
  return vec3(crep_exactRatio(lit, previous));
}

// The exact prefix visibility of region r at boundary u for the ray depth z, in the ray's own (nearest) row,
// linear along the row at crep_filteredBasisAt's positions (or the nearest texel); per colour channel.
vec3 crep_exactPrefix(int region, float u, float row, float z) {
  int H = crep_scattering.mapSize.y, n = crep_scattering.mapSize.x / crep_scattering.mapSize.z;
  float x = clamp(u * float(n) - 1.0, 0.0, float(n - 1));
  int y = clamp(int(floor(row * float(H))), 0, H - 1);
  vec3 P0;
#if CREP_EXACT_NEAREST
  int xi = int(floor(x + 0.5));
  return crep_exactRunningPrefix(region, y, xi, xi, z, P0);
#else
  int x0 = int(floor(x)), x1 = min(x0 + 1, n - 1);
  vec3 P1 = crep_exactRunningPrefix(region, y, x0, x1, z, P0);
  return mix(P0, P1, x - float(x0));
#endif
}
#endif

#if CREP_LIGHT_TEXTURE
// The prefix mean colour cbar at the same sample position as crep_filteredBasisAt.
vec3 crep_meanColorAt(int region, float u, float row) {
  int W = crep_scattering.mapSize.x, H = crep_scattering.mapSize.y, n = W / crep_scattering.mapSize.z;
  float x = clamp(u * float(n) - 1.0, 0.0, float(n - 1));
  float y = clamp(row * float(H) - 0.5, 0.0, float(H - 1));
  return textureLod(crep_meanColor, vec2((float(region * n) + x + 0.5) / float(W), (y + 0.5) / float(H)), 0.0).rgb;
}

// Light textures: the region's visibility per colour channel at prefix boundary u, V_c = cbar_c clamp(0.5 +
// a . F_c, 0, 1) (crep::evaluate of a textured basis), F_c in layers [c L, (c + 1) L).
vec3 crep_texturedVisibility(vec4 a[CREP_EVAL_MAX_LAYERS], int region, float u, float row, float depth) {
#if CREP_EXACT_VISIBILITY
  return clamp(crep_exactPrefix(region, u, row, clamp(depth, 0.0, 1.0)), 0.0, 1.0) * crep_meanColorAt(region, u, row);
#endif
  vec3 V;
  for (int c = 0; c < 3; ++c) {
    float dotF = 0.0;
    for (int l = 0; l < CREP_EVAL_LAYERS; ++l)
      dotF += dot(a[l], crep_filteredBasisAt(region, u, row, c * CREP_EVAL_LAYERS + l));
    V[c] = clamp(0.5 + dotF, 0.0, 1.0);
  }
  return V * crep_meanColorAt(region, u, row);
}
#endif

#ifdef CREP_VISIBILITY_TABLE_SAMPLES
// The region visibility table (crep::evaluate's rule): GL_LINEAR in the texel row, y = clamp(row H - 0.5,
// 0, H - 1) as for the basis, and in the depth sample d (Z - 1) inside the region's Z samples. The
// coordinate is per ray (x: the sample inside a region, y: the row), the region adds r Z texels.
vec2 crep_visibilityTableCoord(float row, float depth) {
  int H = crep_scattering.mapSize.y;
  return vec2(clamp(depth, 0.0, 1.0) * float(CREP_VISIBILITY_TABLE_SAMPLES - 1) + 0.5,
              (clamp(row * float(H) - 0.5, 0.0, float(H - 1)) + 0.5) / float(H));
}
float crep_visibilityTableAt(int r, vec2 coord) {
  int Z = CREP_VISIBILITY_TABLE_SAMPLES, RZ = crep_scattering.mapSize.z * Z;
  return textureLod(crep_visibilityTable, vec2((float(r * Z) + coord.x) / float(RZ), coord.y), 0.0).r;
}
#if CREP_SCATTERING_PREFIX
// The scattering prefix table at region r (same texel layout and filtering as the visibility table).
vec3 crep_scatteringPrefixAt(int r, vec2 coord) {
  int Z = CREP_VISIBILITY_TABLE_SAMPLES, RZ = crep_scattering.mapSize.z * Z;
  return textureLod(crep_scatteringPrefix, vec2((float(r * Z) + coord.x) / float(RZ), coord.y), 0.0).rgb;
}
#if CREP_LOCAL_LIGHT && CREP_LOCAL_SECTIONS
// The local light's section table (built with the prefix table): region r's unshadowed in-scattering along
// the sample rays, up to its end boundary or CREP_LOCAL_SECTION_END (same layout and filtering).
vec3 crep_localSectionAt(int r, vec2 coord) {
  int Z = CREP_VISIBILITY_TABLE_SAMPLES, RZ = crep_scattering.mapSize.z * Z;
  return textureLod(crep_localSections, vec2((float(r * Z) + coord.x) / float(RZ), coord.y), 0.0).rgb;
}
#endif
#endif
#endif

// C of Eq. 1 for a view direction (unit, from the camera): irradiance * sigma_s * phase, per channel.
vec3 crep_scatteringConstant(vec3 viewDirection) {
  float cosTheta = dot(crep_scattering.lightDirection.xyz, -viewDirection);
  return crep_scattering.lightIrradiance.rgb *
         (crep_scattering.mieScattering.rgb * crep_henyeyGreenstein(crep_scattering.mieScattering.w, cosTheta) +
          crep_scattering.rayleighScattering.rgb * crep_rayleighPhase(cosTheta));
}

// In-scattered radiance along the ray origin + t dir, t in [start, surface] (world units; dir unit),
// and the grey transmittance to the surface: vec4(L.rgb, exp(-mean(sigma_t) surface)).
// The visibility of each prefilter region the ray crosses is clamp(0.5 + a(z_r) . F, 0, 1) with F the
// region's normalized filtered basis at the ray's end in it (Appendix A), weighted by the ray's own
// transmittance integral over that region (Eq. 3, 11). start > 0 needs CREP_NEAR_PLANE_CORRECTION.
vec4 crep_inScatteringSegment(vec3 origin, vec3 dir, float start, float surface) {
  vec3 sigma = crep_scattering.extinction.rgb;
  float transmittance = exp(-dot(sigma, vec3(1.0 / 3.0)) * surface);
#if CREP_LOCAL_LIGHT
  vec3 C = vec3(1.0); // the local light's factors are in each section's integral
  // A ray the light never reaches (outside the spot's outer cone or the face's sector all along): nothing
  // to fetch. GPU: neighbouring pixels mostly agree, so whole groups skip the basis.
  vec2 reach = crep_localReach(crep_blockLocalLight(),
                               crep_localRay(crep_blockLocalLight(), crep_blockLocalMedium(), origin, dir), start, surface);
  if (!(reach.x <= reach.y)) return vec4(0.0, 0.0, 0.0, transmittance);
#else
  vec3 C = crep_scatteringConstant(dir);
#endif
  CrepEvalRay hit;
  if (!crep_evalMap(origin, dir, surface, hit))
    return vec4(C * crep_sectionIntegral(origin, dir, sigma, start, surface), transmittance);
  int lastRegion = hit.region, firstRegion = 0;
  float lastU = hit.u, firstU = 0.0;
#if CREP_NEAR_PLANE_CORRECTION
  if (start > 0.0) {
    CrepEvalRay nearPoint;
    if (!crep_evalMap(origin, dir, start, nearPoint))
      return vec4(C * crep_sectionIntegral(origin, dir, sigma, start, surface), transmittance);
    firstRegion = nearPoint.region;
    firstU = nearPoint.u;
    if (firstRegion > lastRegion || (firstRegion == lastRegion && firstU > lastU)) {
      firstRegion = lastRegion;
      firstU = lastU;
    }
  }
#else
  start = 0.0;
#endif

  // Eq. 8 coefficients of the ray, by recurrence from one reduced sin/cos pair.
  vec4 a[CREP_EVAL_MAX_LAYERS];
#if !CREP_EXACT_VISIBILITY // the exact prefix needs no coefficients
  float margin = crep_scattering.depthMargin.x;
  CrepDepth zr = crep_rayBasisDepth(hit.depth, margin);
  vec2 stepSC = crep_harmonicStep(zr);
  vec2 sc = crep_harmonic(0, zr);
  for (int l = 0; l < CREP_EVAL_LAYERS; ++l) {
    vec2 next = crep_rotate(sc, stepSC);
    a[l] = crep_coefficients4(2 * l, sc, next);
#if CREP_RINGING_LANCZOS
    a[l] *= vec4(vec2(crep_lanczosFactor(2 * l, 2 * CREP_EVAL_HALF)), vec2(crep_lanczosFactor(2 * l + 1, 2 * CREP_EVAL_HALF)));
#endif
    if (2 * l + 1 >= CREP_EVAL_HALF) a[l].zw = vec2(0.0); // M % 4 == 2: the last layer holds one harmonic
    sc = crep_rotate(next, stepSC);
  }
#endif

  vec3 L = vec3(0.0);
  float ta = start;
#if CREP_NEAR_PLANE_CORRECTION
  int R = crep_scattering.mapSize.z, n = crep_scattering.mapSize.x / R;
  int nearestRow = clamp(int(floor(hit.row * float(crep_scattering.mapSize.y))), 0, crep_scattering.mapSize.y - 1);
  int mode = crep_scattering.basisInfo.w;
  float s = crep_scattering.extinction.w;
#endif
#if defined(CREP_VISIBILITY_TABLE_SAMPLES) && !CREP_NEAR_PLANE_CORRECTION
  // The regions crossed whole from the table (crep::evaluate's rule: bilinear in the texel row and the
  // depth sample d (Z - 1)), then the last region from the basis. Two loops, no branch inside: neighbouring
  // pixels that end in different regions run the same instructions (SIMD lanes, GPU warps).
  {
    vec2 coord = crep_visibilityTableCoord(hit.row, hit.depth);
#if CREP_SCATTERING_PREFIX
    // Every region before the last in one fetch (crep::EvaluateOptions::scatteringPrefix); the last region
    // starts at the ray's own boundary distance. Constant cost per pixel: M / 4 + 1 fetches.
    L = crep_scatteringPrefixAt(lastRegion, coord);
    if (lastRegion > 0) ta = clamp(crep_evalBoundary(hit, lastRegion), ta, surface);
#else
    for (int r = 0; r < lastRegion; ++r) {
      float tb = clamp(crep_evalBoundary(hit, r + 1), ta, surface);
      float V = crep_visibilityTableAt(r, coord);
      L += V * crep_sectionIntegral(origin, dir, sigma, ta, tb);
      ta = tb;
    }
#endif
#if CREP_SCATTERING_PREFIX && CREP_LOCAL_LIGHT && CREP_LOCAL_SECTIONS
    // The last region's section: its sample rays' section from the table times the share of it that this
    // ray's [ta, surface] holds (crep_localPartialShare), instead of a quadrature per pixel.
    float tEnd = min(max(crep_evalBoundary(hit, lastRegion + 1), surface), CREP_LOCAL_SECTION_END);
    vec3 lastSection = crep_localSectionAt(lastRegion, coord) *
                       crep_localPartialShare(crep_blockLocalLight(), crep_blockLocalMedium(), origin, dir, ta,
                                              surface, tEnd);
#else
    vec3 lastSection = crep_sectionIntegral(origin, dir, sigma, ta, surface);
#endif
#if CREP_LIGHT_TEXTURE
    L += crep_texturedVisibility(a, lastRegion, lastU, hit.row, hit.depth) * lastSection;
#else
#if CREP_EXACT_VISIBILITY
    L += clamp(crep_exactPrefix(lastRegion, lastU, hit.row, clamp(hit.depth, 0.0, 1.0)).x, 0.0, 1.0) * lastSection;
#else
    float dotF = 0.0;
    for (int l = 0; l < CREP_EVAL_LAYERS; ++l) dotF += dot(a[l], crep_filteredBasisAt(lastRegion, lastU, hit.row, l));
    L += clamp(0.5 + dotF, 0.0, 1.0) * lastSection;
#endif
#endif
    return vec4(C * L, transmittance);
  }
#endif
  for (int r = firstRegion; r <= lastRegion; ++r) {
    float ua = r == firstRegion ? firstU : 0.0;
    float ub = r == lastRegion ? lastU : 1.0;
    float tb = r == lastRegion ? surface : crep_evalBoundary(hit, r + 1);
    tb = clamp(tb, ta, surface);
    float dotF = 0.0;
    bool plain = true;
#if CREP_NEAR_PLANE_CORRECTION
    if (ua > 0.0) {
      // The prefix difference of one region, each prefix restored by its own weight total.
      CrepRegionWeights w = crep_regionWeights[nearestRow * R + r];
      float wa = crep_regionWeightTotal(w, mode, s, n, ua), wb = crep_regionWeightTotal(w, mode, s, n, ub);
      if (wb - wa > 1e-12 * wb) {
        plain = false;
#if CREP_EXACT_VISIBILITY
        float z = clamp(hit.depth, 0.0, 1.0);
        dotF = (wb * crep_exactPrefix(r, ub, hit.row, z).x - wa * crep_exactPrefix(r, ua, hit.row, z).x) / (wb - wa) - 0.5;
#else
        for (int l = 0; l < CREP_EVAL_LAYERS; ++l)
          dotF += dot(a[l], wb * crep_filteredBasisAt(r, ub, hit.row, l) - wa * crep_filteredBasisAt(r, ua, hit.row, l));
        dotF /= wb - wa;
#endif
      }
    }
#endif
#if CREP_LIGHT_TEXTURE
    L += C * crep_texturedVisibility(a, r, ub, hit.row, hit.depth) * crep_sectionIntegral(origin, dir, sigma, ta, tb);
#else
#if CREP_EXACT_VISIBILITY
    if (plain) dotF = crep_exactPrefix(r, ub, hit.row, clamp(hit.depth, 0.0, 1.0)).x - 0.5;
#else
    if (plain)
      for (int l = 0; l < CREP_EVAL_LAYERS; ++l) dotF += dot(a[l], crep_filteredBasisAt(r, ub, hit.row, l));
#endif
    float V = clamp(0.5 + dotF, 0.0, 1.0);
    L += C * V * crep_sectionIntegral(origin, dir, sigma, ta, tb);
#endif
    ta = tb;
  }
  return vec4(L, transmittance);
}

// In-scattering from the camera (origin) to the surface at distance `surface` along `dir` (unit):
// vec4(radiance, grey transmittance). Sky pixels: pass the far-plane distance (the map has no
// information beyond it); composite as surface * result.a + result.rgb.
vec4 crep_inScattering(vec3 origin, vec3 dir, float surface) { return crep_inScatteringSegment(origin, dir, 0.0, surface); }

// The same for a world-space surface point seen from the rectification's camera.
vec4 crep_inScatteringAt(vec3 worldPosition) {
  vec3 d = worldPosition - crep_scattering.frameOrigin.xyz;
  float t = length(d);
  return crep_inScattering(crep_scattering.frameOrigin.xyz, t > 0.0 ? d / t : crep_scattering.frameAxisX.xyz, t);
}

#endif // CREP_SCATTERING_NO_EVALUATION
#endif // CREP_SCATTERING_GLSL
