// Tone mapping: HDR linear RGB -> display-referred linear RGB in [0, 1], manual or auto exposure (Reinhard
// et al. 2002), light adaptation (Pattanaik et al. 2000), the operators of Yusov's outdoor demo. CPU
// reference in double (ToneMapPass on the GPU). The rule: postfx/README.md, "crep/postfx/tone_mapping.h".
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

/// Reinhard et al. 2002, Eq. 1: delta added to the luminance before its logarithm; the smallest log-average.
inline constexpr double kLogAverageDelta = 1e-4;
/// Cap of scaled luminances and channels (step 2 of the rule above).
inline constexpr double kMaxScaledValue = 1e15;
/// Hable 2010's curve constants A-F and the exposure bias applied before the curve.
inline constexpr double kUncharted2A = 0.15, kUncharted2B = 0.50, kUncharted2C = 0.10, kUncharted2D = 0.20,
                        kUncharted2E = 0.02, kUncharted2F = 0.30, kUncharted2ExposureBias = 2.0;
/// Drago et al. 2003, Sec. 3: the bias power b of the adaptive logarithmic operator.
inline constexpr double kDragoBias = 0.85;

struct ToneMapOptions {
  ToneMapOperator op = ToneMapOperator::Uncharted2;
  /// The key a (Reinhard et al. 2002, Sec. 3.1), in (0, 1e3]: what the log-average maps to (autoExposure).
  double middleGrey = 0.18;
  /// The white point in scaled units, in [1e-3, 1e6]: L_white, L_max or Uncharted2's W (README).
  double whitePoint = 3.0;
  /// The saturation power s of the luminance operators' colour rule, in [0, 8].
  double saturation = 1.0;
  /// Exposure from the log-average luminance (with light adaptation) instead of `exposure`.
  bool autoExposure = true;
  /// The manual scale applied to the input when autoExposure is false; finite and > 0.
  double exposure = 1.0;
  /// Time constant tau of light adaptation, seconds, finite and >= 0 (0: no lag).
  double adaptationTau = 0.5;
};

/// Throws InvalidArgument naming `owner` + ".field" for a value outside the ranges above.
void validate(const ToneMapOptions& options, const std::string& owner = "ToneMapOptions");

/// Rec. 709 relative luminance Y = 0.2126 R + 0.7152 G + 0.0722 B (ITU-R BT.709, item 3.2).
double luminance(const glm::dvec3& rgb);

/// Sum of log(kLogAverageDelta + Y) over the finite pixels of an image, and their count.
struct LuminanceStats {
  double logSum = 0.0;
  std::uint64_t count = 0;
  /// exp(logSum / count) (Reinhard et al. 2002, Eq. 1), or nothing when count is 0.
  std::optional<double> logAverage() const;
};
/// The log-average statistics of a 3- or 4-channel image (non-finite pixels skipped; InvalidArgument
/// "image" otherwise). O(pixels).
LuminanceStats luminanceStats(const Image& image);

/// Pattanaik et al. 2000: adapted + (target - adapted)(1 - exp(-dt / tau)), dt and tau in seconds (tau 0:
/// target). InvalidArgument ("dt", "tau") unless both are finite and >= 0.
double adaptLuminance(double adapted, double target, double dt, double tau);

/// The exposure scale: middleGrey / adaptedLuminance with autoExposure (Reinhard et al. 2002, Eq. 2),
/// else options.exposure.
double exposureScale(const ToneMapOptions& options, double adaptedLuminance);

/// One curve on a scaled value x >= 0 (luminance or channel), before the clamp to [0, 1] (step 4).
double toneMapCurve(ToneMapOperator op, double x, const ToneMapOptions& options);

/// Steps 1-4 of the rule (README) for one pixel: linear display RGB in [0, 1].
glm::dvec3 toneMapColor(const glm::dvec3& rgb, double scale, const ToneMapOptions& options);

/// Tone-maps a 3- or 4-channel image with an exposure scale (exposureScale()): RGBA, alpha 1. O(pixels).
Image toneMapImage(const Image& hdr, double scale, const ToneMapOptions& options);

/// Light adaptation over a sequence of frames: the CPU reference of ToneMapPass's state.
class LightAdaptation {
public:
  /// Feeds one frame's statistics (the first frame sets the state; README); returns the adapted luminance.
  double update(const LuminanceStats& frame, double dt, double tau);
  void reset() { adapted_.reset(); }
  double adapted() const { return adapted_.value_or(1.0); }

private:
  std::optional<double> adapted_;
};

/// The standard RGB OETF (IEC 61966-2-1) of a linear value clamped to [0, 1] (NaN -> 0): a separate step.
double srgbEncode(double linear);

} // namespace crep
