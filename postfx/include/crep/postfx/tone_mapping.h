// Tone mapping: HDR linear RGB (radiance, any scale) -> display-referred linear RGB in [0, 1], with
// exposure set by hand or from the image's log-average luminance, and temporal light adaptation. The
// list of operators and knobs is the one of Yusov's Outdoor Light Scattering demo ("Tone mapping" and
// "Tone mapping controls"); each curve follows the paper that demo cites (named at each function). This
// header is the CPU reference, in double precision; ToneMapPass (crep/postfx/gpu_tone_mapping.h) runs the
// same rule on the GPU in float, its curves in glsl/crep/tone_mapping.glsl (a public include: an engine
// calls crep_toneMapColor in its own shaders).
//
// The rule for one pixel, rgb (linear, the caller's units):
//   1. A pixel with a non-finite channel (NaN, +-Inf) is written black: a broken pixel never looks
//      plausible (the PNG writer of crep::support has the same rule). Negative channels count as 0.
//   2. Exposure: scale = middleGrey / La with La the (adapted) log-average luminance when autoExposure
//      (Reinhard et al. 2002, Eq. 2: the key maps the scene's average to middle grey), else the manual
//      `exposure`. Scaled values are capped at kMaxScaledValue (every curve has saturated far below it;
//      the cap keeps the float GPU twin free of overflow).
//   3. The operator:
//      - luminance operators (Exponential, Reinhard, ModifiedReinhard, Logarithmic, AdaptiveLogarithmic)
//        map the scaled luminance L = scale * Y(rgb) (Y: Rec. 709 weights) to Ld, and the colour is
//        rebuilt with the saturation rule  out = (rgb / Y)^s * Ld  (per channel; s = `saturation`: 1
//        keeps the pixel's chromaticity, 0 gives grey, s > 1 saturates further; Y = 0 gives black);
//      - colour operators (Uncharted2, FilmicALU) map each scaled channel with their curve (they ignore
//        `saturation`, as in Yusov's demo).
//   4. Each channel is clamped to [0, 1] (the curves that pass 1 above the white point "burn out", as
//      Reinhard et al. 2002 intend for the modified operator). The result is linear; display encoding
//      (srgbEncode) is a separate step, as PNG writers and framebuffers with an SRGB8 format apply
//      it themselves.
//   Alpha is not tone-mapped: toneMapImage writes 1, as the GPU pass does.
//
// Log-average luminance (Reinhard et al. 2002, Eq. 1): La = exp(mean over pixels of log(delta + Y)),
// delta = kLogAverageDelta. Pixels with a non-finite channel are SKIPPED (counted neither in the sum nor
// in the count), negative channels count as 0. An image without a finite pixel has no log-average: the
// exposure then keeps its previous adapted value (1 for the first frame).
//
// Temporal light adaptation: the luminance the eye is adapted to follows the frame's log-average with
// a first-order (exponential) lag, the model of Pattanaik et al. 2000, Time-dependent visual adaptation
// for fast realistic image display, which Yusov's demo simulates (its Light adaptation checkbox):
//   La(t + dt) = La(t) + (Lt - La(t)) (1 - exp(-dt / tau)),
// exact for a target Lt held constant over dt, so the result after a time T does not depend on how T is
// cut into frames. After tau seconds, exp(-1) of the initial gap remains.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <glm/glm.hpp>

#include <crep/core/image.h>

namespace crep {

/// The operators of Yusov's demo (names in toneMapOperatorName()).
enum class ToneMapOperator {
  Exponential,        ///< "exp": Ld = 1 - exp(-L)
  Reinhard,           ///< "reinhard": Reinhard et al. 2002, Eq. 3
  ModifiedReinhard,   ///< "reinhard-mod": Reinhard et al. 2002, Eq. 4 (white point)
  Uncharted2,         ///< "uncharted2": Hable 2010 filmic curve, white W = whitePoint
  FilmicALU,          ///< "filmic-alu": Hejl and Burgess-Dawson's curve (Hable 2010), gamma removed
  Logarithmic,        ///< "log": Drago et al. 2003, Sec. 3: log(1 + L) / log(1 + Lmax)
  AdaptiveLogarithmic ///< "adaptive-log": Drago et al. 2003, Sec. 3 (adaptive base), b = 0.85
};

/// Every operator, in the order of the enum (the order of `crep render --tonemap all`).
inline constexpr std::array<ToneMapOperator, 7> kToneMapOperators = {
    ToneMapOperator::Exponential,        ToneMapOperator::Reinhard,  ToneMapOperator::ModifiedReinhard,
    ToneMapOperator::Uncharted2,         ToneMapOperator::FilmicALU, ToneMapOperator::Logarithmic,
    ToneMapOperator::AdaptiveLogarithmic};

/// "exp", "reinhard", "reinhard-mod", "uncharted2", "filmic-alu", "log", "adaptive-log".
const char* toneMapOperatorName(ToneMapOperator op);
/// The operator of a name of toneMapOperatorName() (exact, case-sensitive), or nothing.
std::optional<ToneMapOperator> findToneMapOperator(std::string_view name);
/// The names joined by ", " (for usage messages).
std::string toneMapOperatorNames();
/// findToneMapOperator(), or InvalidArgument naming `parameter` whose requirement lists the names.
ToneMapOperator parseToneMapOperator(std::string_view name, const std::string& parameter);

/// Reinhard et al. 2002, Eq. 1: the small delta added to the luminance before its logarithm, so that a
/// black pixel does not send the log-average to zero. Also the smallest possible log-average.
inline constexpr double kLogAverageDelta = 1e-4;
/// Cap of scaled luminances and channels (step 2 of the rule above).
inline constexpr double kMaxScaledValue = 1e15;
/// Hable 2010's curve constants (shoulder strength A, linear strength B, linear angle C, toe strength D,
/// toe numerator E, toe denominator F) and the exposure bias his example applies before the curve.
inline constexpr double kUncharted2A = 0.15, kUncharted2B = 0.50, kUncharted2C = 0.10, kUncharted2D = 0.20,
                        kUncharted2E = 0.02, kUncharted2F = 0.30, kUncharted2ExposureBias = 2.0;
/// Drago et al. 2003, Sec. 3: the bias power b of the adaptive logarithmic operator (0.85 is the
/// value the paper recommends).
inline constexpr double kDragoBias = 0.85;

struct ToneMapOptions {
  ToneMapOperator op = ToneMapOperator::Uncharted2;
  /// The key a (Reinhard et al. 2002, Sec. 3.1): the value the log-average maps to with autoExposure.
  /// In (0, 1e3]. 0.18 is Reinhard's "normal key" and the demo's default.
  double middleGrey = 0.18;
  /// The white point, in scaled units (after exposure): the smallest scaled luminance shown as white by
  /// ModifiedReinhard (L_white), Logarithmic and AdaptiveLogarithmic (L_max), and Uncharted2's linear
  /// white W (applied after its exposure bias of 2). In [1e-3, 1e6] (W^2 stays a normal float). Default
  /// 3: about 4 stops above middle grey.
  double whitePoint = 3.0;
  /// The saturation power s of the luminance operators' colour rule, in [0, 8] (above 8, (rgb / Y)^s of a
  /// pure primary, up to 13.9^s, would leave the float range on the GPU).
  double saturation = 1.0;
  /// Exposure from the log-average luminance (with light adaptation) instead of `exposure`.
  bool autoExposure = true;
  /// The manual scale applied to the input when autoExposure is false; finite and > 0.
  double exposure = 1.0;
  /// Time constant tau (seconds) of light adaptation, finite and >= 0 (0: no lag, the frame's own
  /// log-average).
  double adaptationTau = 0.5;
};

/// Throws InvalidArgument naming the field (`owner` + ".middleGrey", e.g. "ToneMapOptions.middleGrey" or
/// "ToneMapPass::CreateInfo.options.whitePoint") for a value outside the ranges documented above.
void validate(const ToneMapOptions& options, const std::string& owner = "ToneMapOptions");

/// Rec. 709 relative luminance (the primaries of linear RGB in srgbEncode's standard) Y = 0.2126 R + 0.7152 G
/// + 0.0722 B (ITU-R BT.709, item 3.2).
double luminance(const glm::dvec3& rgb);

/// Sum of log(kLogAverageDelta + Y) over the finite pixels of an image, and their count.
struct LuminanceStats {
  double logSum = 0.0;
  std::uint64_t count = 0;
  /// exp(logSum / count) (Reinhard et al. 2002, Eq. 1), or nothing when count is 0.
  std::optional<double> logAverage() const;
};
/// The log-average luminance statistics of an image of 3 or 4 channels (alpha ignored); pixels with a
/// non-finite channel are skipped, negative channels count as 0. InvalidArgument ("image") otherwise.
LuminanceStats luminanceStats(const Image& image);

/// Temporal light adaptation (Pattanaik et al. 2000 exponential lag, as simulated by Yusov's demo): the
/// adapted luminance after dt seconds toward `target`: adapted + (target - adapted)(1 - exp(-dt / tau)).
/// tau = 0 returns target. InvalidArgument for dt or tau not finite and >= 0 ("dt", "tau").
double adaptLuminance(double adapted, double target, double dt, double tau);

/// The exposure scale: middleGrey / adaptedLuminance with autoExposure (Reinhard et al. 2002, Eq. 2),
/// else options.exposure.
double exposureScale(const ToneMapOptions& options, double adaptedLuminance);

/// One curve on a scaled value x >= 0 (a luminance for the luminance operators, a channel for the colour
/// operators), before the clamp to [0, 1] of step 4.
double toneMapCurve(ToneMapOperator op, double x, const ToneMapOptions& options);

/// Steps 1-4 of the rule for one pixel: linear display RGB in [0, 1].
glm::dvec3 toneMapColor(const glm::dvec3& rgb, double scale, const ToneMapOptions& options);

/// Tone-maps an image of 3 or 4 channels with a given exposure scale (exposureScale()); RGBA output
/// (alpha 1), the input's size.
Image toneMapImage(const Image& hdr, double scale, const ToneMapOptions& options);

/// Light adaptation over a sequence of frames: the CPU reference of ToneMapPass's state.
class LightAdaptation {
public:
  /// Feeds one frame's statistics: with no previous state (first frame, after reset()) the adapted
  /// luminance becomes the frame's log-average; otherwise adaptLuminance() toward it over dt seconds.
  /// A frame without a finite pixel leaves the state as it is. Returns the adapted luminance (1 before
  /// any finite frame).
  double update(const LuminanceStats& frame, double dt, double tau);
  void reset() { adapted_.reset(); }
  double adapted() const { return adapted_.value_or(1.0); }

private:
  std::optional<double> adapted_;
};

/// The standard RGB encoding of a linear value (IEC 61966-2-1 OETF): 12.92 x for x <= 0.0031308, else
/// 1.055 x^(1/2.4) - 0.055; x clamped to [0, 1] first (NaN -> 0). A separate step from the tone mapping.
double srgbEncode(double linear);

} // namespace crep
