// crepuscular: tone-mapping operators, the log-average luminance and the blocks of ToneMapPass
// (GLSL twin of crep/postfx/tone_mapping.h, whose header states the rule; float precision).
//
// Public include (conventions in crep/common.glsl). An engine tone-maps in its own shader with
//   vec3 display = crep_toneMapColor(hdr, scale, CREP_TONE_MAP_REINHARD, whitePoint, saturation);
// (linear, in [0, 1]; crep_srgbEncode of crep/common.glsl for an 8-bit target), scale = middleGrey / adapted luminance, which
// ToneMapPass keeps on the GPU in its state buffer (CrepToneMapState.exposureScale).
#ifndef CREP_TONE_MAPPING_GLSL
#define CREP_TONE_MAPPING_GLSL

#include "common.glsl"

// The operators (crep::ToneMapOperator, same order).
#define CREP_TONE_MAP_EXP 0
#define CREP_TONE_MAP_REINHARD 1
#define CREP_TONE_MAP_REINHARD_MOD 2
#define CREP_TONE_MAP_UNCHARTED2 3
#define CREP_TONE_MAP_FILMIC_ALU 4
#define CREP_TONE_MAP_LOG 5
#define CREP_TONE_MAP_ADAPTIVE_LOG 6

// crep::kLogAverageDelta and crep::kMaxScaledValue.
#define CREP_LOG_AVERAGE_DELTA 1e-4
#define CREP_MAX_SCALED_VALUE 1e15

// gpu::ToneMapParams (std140): ToneMapPass's per-frame block.
struct CrepToneMapParams {
  vec4 curve;      // x middleGrey, y whitePoint, z saturation, w manual exposure
  vec4 adaptation; // x 1 - exp(-dt / tau) (computed in double on the CPU), yzw 0
  ivec4 flags;     // x 1 = auto exposure, y 1 = reset the adaptation, z partial sums of the reduction, w 0
  ivec4 sizes;     // xy input size (pixels), zw workgroups of the reduction
};

// gpu::LuminancePartial (std430): one workgroup's part of the log-average.
struct CrepLuminancePartial {
  float logSum; // sum of log(delta + Y) over its finite pixels
  uint count;   // its finite pixels
};

// gpu::ToneMapState (std430): the adaptation state ToneMapPass keeps on the GPU.
struct CrepToneMapState {
  float adaptedLuminance; // La, what the exposure follows
  float targetLuminance;  // the last frame's log-average (or La when it had no finite pixel)
  float exposureScale;    // middleGrey / La
  int valid;              // 0 until a frame with a finite pixel has been reduced
};

// True when every channel is finite (NaN and +-Inf are not).
bool crep_finiteRgb(vec3 rgb) {
  return !any(isnan(rgb)) && !any(isinf(rgb));
}

// log(1 + x) and exp(x) - 1 without the cancellation of the direct forms for small x (Goldberg 1991 /
// Kahan's rewriting: the rounding of 1 + x cancels in the ratio). Float counterparts of std::log1p/expm1.
float crep_log1p(float x) {
  float u = 1.0 + x;
  return u == 1.0 ? x : log(u) * (x / (u - 1.0));
}
float crep_expm1(float x) {
  float u = exp(x);
  if (u == 1.0) return x;
  float um1 = u - 1.0;
  return um1 == -1.0 ? -1.0 : um1 * (x / log(u));
}

// Hable 2010's filmic curve h(y) (crep::kUncharted2A..F): toe, linear part, shoulder; h(0) = 0.
float crep_hableCurve(float y) {
  const float A = 0.15, B = 0.50, C = 0.10, D = 0.20, E = 0.02, F = 0.30;
  return (y * (A * y + C * B) + D * E) / (y * (A * y + B) + D * F) - E / F;
}

// One operator's curve on a scaled value x >= 0 (crep::toneMapCurve), before the clamp to [0, 1].
float crep_toneMapCurve(int op, float x, float whitePoint) {
  float W = whitePoint;
  if (op == CREP_TONE_MAP_EXP) return -crep_expm1(-x);                           // Yusov's demo, "Exp"
  if (op == CREP_TONE_MAP_REINHARD) return x / (1.0 + x);                         // Reinhard et al. 2002, Eq. 3
  if (op == CREP_TONE_MAP_REINHARD_MOD) return x / (1.0 + x) * (1.0 + x / (W * W)); // Eq. 4
  if (op == CREP_TONE_MAP_UNCHARTED2) return crep_hableCurve(2.0 * x) / crep_hableCurve(W); // Hable 2010, bias 2
  if (op == CREP_TONE_MAP_FILMIC_ALU) {
    // Hejl and Burgess-Dawson (Hable 2010); the curve has the display gamma 1/2.2 built in: undone.
    float y = max(0.0, x - 0.004);
    float g = y * (6.2 * y + 0.5) / (y * (6.2 * y + 1.7) + 0.06);
    return g > 0.0 ? pow(g, 2.2) : 0.0;
  }
  if (op == CREP_TONE_MAP_LOG) return crep_log1p(x) / crep_log1p(W); // Drago et al. 2003, Sec. 3
  // CREP_TONE_MAP_ADAPTIVE_LOG: Drago et al. 2003, Sec. 3, bias 0.85: exponent log(0.85) / log(0.5).
  const float p = 0.23446525363702297;
  float biased = x > 0.0 ? pow(x / W, p) : 0.0;
  return crep_log1p(x) / log(2.0 + 8.0 * biased) / log(1.0 + W) * log(10.0);
}

// One pixel (crep::toneMapColor): non-finite -> black, negative channels -> 0, exposure `scale`, the
// operator (luminance operators: colour (rgb / Y)^saturation Ld, Y = crep_luminance of crep/common.glsl,
// the Rec. 709 weights of crep::luminance), clamped to [0, 1]. Linear output.
vec3 crep_toneMapColor(vec3 rgb, float scale, int op, float whitePoint, float saturation) {
  if (!crep_finiteRgb(rgb)) return vec3(0.0);
  rgb = max(rgb, vec3(0.0));
  vec3 result;
  if (op == CREP_TONE_MAP_UNCHARTED2 || op == CREP_TONE_MAP_FILMIC_ALU) {
    vec3 x = min(scale * rgb, vec3(CREP_MAX_SCALED_VALUE));
    result = vec3(crep_toneMapCurve(op, x.r, whitePoint), crep_toneMapCurve(op, x.g, whitePoint),
                  crep_toneMapCurve(op, x.b, whitePoint));
  } else {
    float Y = crep_luminance(rgb);
    // Below the smallest normal float the ratio rgb / Y is unreliable (denormals may be flushed).
    if (!(Y >= 1.17549435e-38)) return vec3(0.0);
    float Ld = crep_toneMapCurve(op, min(scale * Y, CREP_MAX_SCALED_VALUE), whitePoint);
    vec3 ratio = rgb / Y;
    // pow(0, s) is undefined in GLSL for s <= 0: s = 0 is grey (ratio^0 = 1), zero channels stay 0.
    vec3 colour = saturation == 0.0 ? vec3(1.0)
                                    : mix(vec3(0.0), pow(max(ratio, vec3(1e-30)), vec3(saturation)),
                                          greaterThan(ratio, vec3(0.0)));
    result = colour * Ld;
  }
  return clamp(result, vec3(0.0), vec3(1.0));
}

#endif // CREP_TONE_MAPPING_GLSL
