// CPU reference of tone mapping, auto exposure and light adaptation (crep/postfx/tone_mapping.h), in
// double precision. The float GPU twin of the curves is glsl/crep/tone_mapping.glsl.
#include <crep/core/error.h>
#include <crep/postfx/tone_mapping.h>

#include <algorithm>
#include <cmath>

namespace crep {

namespace {

struct OperatorName {
  ToneMapOperator op;
  const char* name;
};
constexpr std::array<OperatorName, 7> kNames = {{{ToneMapOperator::Exponential, "exp"},
                                                 {ToneMapOperator::Reinhard, "reinhard"},
                                                 {ToneMapOperator::ModifiedReinhard, "reinhard-mod"},
                                                 {ToneMapOperator::Uncharted2, "uncharted2"},
                                                 {ToneMapOperator::FilmicALU, "filmic-alu"},
                                                 {ToneMapOperator::Logarithmic, "log"},
                                                 {ToneMapOperator::AdaptiveLogarithmic, "adaptive-log"}}};

/// Throws InvalidArgument naming owner.field unless value is finite and in [lo, hi] (lo excluded when
/// `openLow`).
void requireRange(const std::string& owner, const char* field, double value, double lo, double hi,
                  bool openLow, const char* requirement) {
  const bool ok = std::isfinite(value) && (openLow ? value > lo : value >= lo) && value <= hi;
  if (!ok) throw InvalidArgument(owner + "." + field, detail::formatValue(value), requirement);
}

/// Hable 2010, "Uncharted 2: HDR Lighting": the filmic curve (toe, linear section, shoulder) as a ratio of
/// quadratics shifted so that h(0) = 0.
double hableCurve(double y) {
  const double A = kUncharted2A, B = kUncharted2B, C = kUncharted2C, D = kUncharted2D, E = kUncharted2E,
               F = kUncharted2F;
  return (y * (A * y + C * B) + D * E) / (y * (A * y + B) + D * F) - E / F;
}

bool finitePixel(const Image& image, int x, int y) {
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(image.at(x, y, c))) return false;
  return true;
}

glm::dvec3 pixelRgb(const Image& image, int x, int y) {
  return glm::max(glm::dvec3(image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)), glm::dvec3(0.0));
}

void requireColourImage(const Image& image, const char* parameter) {
  if (image.empty() || image.channels() < 3)
    throw InvalidArgument(parameter, std::to_string(image.channels()) + " channels",
                          "must be a non-empty image of 3 or 4 channels");
}

} // namespace

const char* toneMapOperatorName(ToneMapOperator op) {
  for (const OperatorName& n : kNames)
    if (n.op == op) return n.name;
  return "?";
}

std::optional<ToneMapOperator> findToneMapOperator(std::string_view name) {
  for (const OperatorName& n : kNames)
    if (name == n.name) return n.op;
  return std::nullopt;
}

std::string toneMapOperatorNames() {
  std::string list;
  for (const OperatorName& n : kNames)
    list += (list.empty() ? "" : ", ") + std::string(n.name);
  return list;
}

ToneMapOperator parseToneMapOperator(std::string_view name, const std::string& parameter) {
  if (const auto op = findToneMapOperator(name)) return *op;
  throw InvalidArgument(parameter, "'" + std::string(name) + "'", "must be one of " + toneMapOperatorNames());
}

void validate(const ToneMapOptions& o, const std::string& owner) {
  if (!findToneMapOperator(toneMapOperatorName(o.op)))
    throw InvalidArgument(owner + ".op", detail::formatValue(static_cast<int>(o.op)),
                          "must be a ToneMapOperator");
  requireRange(owner, "middleGrey", o.middleGrey, 0.0, 1e3, true, "must be finite and in (0, 1000]");
  requireRange(owner, "whitePoint", o.whitePoint, 1e-3, 1e6, false, "must be finite and in [0.001, 1e6]");
  requireRange(owner, "saturation", o.saturation, 0.0, 8.0, false, "must be finite and in [0, 8]");
  requireRange(owner, "exposure", o.exposure, 0.0, 1e30, true, "must be finite and in (0, 1e30]");
  requireRange(owner, "adaptationTau", o.adaptationTau, 0.0, 1e30, false, "must be finite and >= 0");
}

// ITU-R BT.709 luminance weights (the primaries of linear sRGB).
double luminance(const glm::dvec3& rgb) {
  return 0.2126 * rgb.r + 0.7152 * rgb.g + 0.0722 * rgb.b;
}

std::optional<double> LuminanceStats::logAverage() const {
  if (count == 0) return std::nullopt;
  return std::exp(logSum / static_cast<double>(count));
}

// Reinhard et al. 2002, Eq. 1: the sum of log(delta + Y) over the finite pixels.
LuminanceStats luminanceStats(const Image& image) {
  requireColourImage(image, "luminanceStats.image");
  LuminanceStats s;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      if (!finitePixel(image, x, y)) continue;
      s.logSum += std::log(kLogAverageDelta + luminance(pixelRgb(image, x, y)));
      ++s.count;
    }
  return s;
}

// Pattanaik et al. 2000's exponential adaptation: the exact step of dLa/dt = (Lt - La) / tau.
double adaptLuminance(double adapted, double target, double dt, double tau) {
  requireNonNegative("adaptLuminance.dt", dt);
  requireNonNegative("adaptLuminance.tau", tau);
  if (tau == 0.0) return target;
  return adapted + (target - adapted) * -std::expm1(-dt / tau);
}

// Reinhard et al. 2002, Eq. 2: a / L_avg.
double exposureScale(const ToneMapOptions& options, double adaptedLuminance) {
  return options.autoExposure ? options.middleGrey / adaptedLuminance : options.exposure;
}

double toneMapCurve(ToneMapOperator op, double x, const ToneMapOptions& o) {
  const double W = o.whitePoint;
  switch (op) {
  case ToneMapOperator::Exponential: // Yusov's demo, "Exp": 1 - exp(-L)
    return -std::expm1(-x);
  case ToneMapOperator::Reinhard: // Reinhard et al. 2002, Eq. 3
    return x / (1.0 + x);
  case ToneMapOperator::ModifiedReinhard: // Reinhard et al. 2002, Eq. 4: white at L_white
    return x / (1.0 + x) * (1.0 + x / (W * W));
  case ToneMapOperator::Uncharted2: // Hable 2010: h(bias x) / h(W)
    return hableCurve(kUncharted2ExposureBias * x) / hableCurve(W);
  case ToneMapOperator::FilmicALU: { // Hejl and Burgess-Dawson (Hable 2010): the curve's 1/2.2 undone
    const double y = std::max(0.0, x - 0.004);
    const double g = y * (6.2 * y + 0.5) / (y * (6.2 * y + 1.7) + 0.06);
    return std::pow(g, 2.2);
  }
  case ToneMapOperator::Logarithmic: // Drago et al. 2003, Sec. 3: log(1 + L) / log(1 + L_max)
    return std::log1p(x) / std::log1p(W);
  case ToneMapOperator::AdaptiveLogarithmic: { // Drago et al. 2003, Sec. 3, with L_dmax 0.01 = 1
    const double p = std::log(kDragoBias) / std::log(0.5);
    return std::log1p(x) / std::log(2.0 + 8.0 * std::pow(x / W, p)) / std::log10(1.0 + W);
  }
  }
  return 0.0;
}

// Steps 1-4 of the header's rule; the luminance operators' colour is (rgb / Y)^s Ld.
glm::dvec3 toneMapColor(const glm::dvec3& input, double scale, const ToneMapOptions& o) {
  if (!std::isfinite(input.r) || !std::isfinite(input.g) || !std::isfinite(input.b)) return glm::dvec3(0.0);
  const glm::dvec3 rgb = glm::max(input, glm::dvec3(0.0));
  glm::dvec3 out(0.0);
  if (o.op == ToneMapOperator::Uncharted2 || o.op == ToneMapOperator::FilmicALU) {
    for (int c = 0; c < 3; ++c)
      out[c] = toneMapCurve(o.op, std::min(scale * rgb[c], kMaxScaledValue), o);
  } else {
    const double Y = luminance(rgb);
    if (!(Y > 0.0)) return glm::dvec3(0.0);
    const double Ld = toneMapCurve(o.op, std::min(scale * Y, kMaxScaledValue), o);
    for (int c = 0; c < 3; ++c)
      out[c] = (o.saturation == 0.0 ? 1.0 : std::pow(rgb[c] / Y, o.saturation)) * Ld;
  }
  return glm::clamp(out, glm::dvec3(0.0), glm::dvec3(1.0));
}

Image toneMapImage(const Image& hdr, double scale, const ToneMapOptions& options) {
  requireColourImage(hdr, "toneMapImage.hdr");
  validate(options);
  requirePositive("toneMapImage.scale", scale);
  Image out(hdr.width(), hdr.height(), 4, 1.0f);
  for (int y = 0; y < hdr.height(); ++y)
    for (int x = 0; x < hdr.width(); ++x) {
      const glm::dvec3 in(hdr.at(x, y, 0), hdr.at(x, y, 1), hdr.at(x, y, 2));
      const glm::dvec3 v = toneMapColor(in, scale, options);
      for (int c = 0; c < 3; ++c)
        out.at(x, y, c) = static_cast<float>(v[c]);
    }
  return out;
}

double LightAdaptation::update(const LuminanceStats& frame, double dt, double tau) {
  requireNonNegative("LightAdaptation::update.dt", dt);
  requireNonNegative("LightAdaptation::update.tau", tau);
  const std::optional<double> target = frame.logAverage();
  if (!target) return adapted();
  adapted_ = adapted_ ? adaptLuminance(*adapted_, *target, dt, tau) : *target;
  return *adapted_;
}

// IEC 61966-2-1 sRGB OETF.
double srgbEncode(double linear) {
  const double x = linear > 0.0 ? std::min(linear, 1.0) : 0.0;
  return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

} // namespace crep
