#include <crep/support/image_compare.h>

#include <crep/core/error.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace crep {

namespace {

std::string size(const Image& image) {
  return std::to_string(image.width()) + "x" + std::to_string(image.height());
}

// Returns the number of channels to compare.
int checkComparable(const Image& actual, const Image& reference, int channels) {
  if (actual.empty()) throw InvalidArgument("actual", "empty image", "must not be empty");
  if (reference.empty()) throw InvalidArgument("reference", "empty image", "must not be empty");
  if (actual.width() != reference.width() || actual.height() != reference.height())
    throw InvalidArgument("actual", "size " + size(actual),
                          "must match the reference size " + size(reference));
  if (channels < 0 || channels > 4)
    throw InvalidArgument("CompareOptions.channels", detail::formatValue(channels), "must be in [0, 4]");
  if (channels == 0) {
    if (actual.channels() != reference.channels())
      throw InvalidArgument("actual", std::to_string(actual.channels()) + " channels",
                            "must match the reference's " + std::to_string(reference.channels()) +
                                " channels");
    return actual.channels();
  }
  if (actual.channels() < channels)
    throw InvalidArgument("actual", std::to_string(actual.channels()) + " channels",
                          "must have at least CompareOptions.channels = " + std::to_string(channels));
  if (reference.channels() < channels)
    throw InvalidArgument("reference", std::to_string(reference.channels()) + " channels",
                          "must have at least CompareOptions.channels = " + std::to_string(channels));
  return channels;
}

std::string num(double v) {
  return detail::formatValue(v);
}

std::string shortNum(double v) {
  if (!std::isfinite(v)) return detail::formatValue(v);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

} // namespace

ImageMetrics compareImages(const Image& actual, const Image& reference, const CompareOptions& options) {
  const int channels = checkComparable(actual, reference, options.channels);
  requireNonNegative("CompareOptions.overThreshold", options.overThreshold);
  requireNonNegative("CompareOptions.peak", options.peak);

  ImageMetrics m;
  m.overThreshold = options.overThreshold;
  m.totalSamples = static_cast<long long>(actual.pixelCount()) * channels;
  double sumAbs = 0.0, sumSquared = 0.0, sumReferenceSquared = 0.0, maxReference = 0.0;
  long long over = 0;
  for (int y = 0; y < actual.height(); ++y) {
    for (int x = 0; x < actual.width(); ++x) {
      for (int c = 0; c < channels; ++c) {
        const double a = static_cast<double>(actual.at(x, y, c));
        const double r = static_cast<double>(reference.at(x, y, c));
        m.nanCount += std::isnan(a) ? 1 : 0;
        m.infCount += std::isinf(a) ? 1 : 0;
        m.referenceNanCount += std::isnan(r) ? 1 : 0;
        m.referenceInfCount += std::isinf(r) ? 1 : 0;
        if (!std::isfinite(a) || !std::isfinite(r)) continue;
        const double e = std::abs(a - r);
        ++m.comparedSamples;
        sumAbs += e;
        sumSquared += e * e;
        sumReferenceSquared += r * r;
        maxReference = std::max(maxReference, std::abs(r));
        if (e > options.overThreshold) ++over;
        if (e > m.maxAbsError) {
          m.maxAbsError = e;
          m.worstX = x;
          m.worstY = y;
          m.worstChannel = c;
          m.worstActual = a;
          m.worstReference = r;
        }
      }
    }
  }
  m.peak = options.peak > 0.0 ? options.peak : (maxReference > 0.0 ? maxReference : 1.0);
  if (m.comparedSamples > 0) {
    const double n = static_cast<double>(m.comparedSamples);
    m.meanAbsError = sumAbs / n;
    m.rmse = std::sqrt(sumSquared / n);
    const double rmsReference = std::sqrt(sumReferenceSquared / n);
    m.relativeRmse = rmsReference > 0.0 ? m.rmse / rmsReference : m.rmse;
    m.fractionOver = static_cast<double>(over) / n;
  }
  m.psnr = m.rmse > 0.0 ? 20.0 * std::log10(m.peak / m.rmse) : std::numeric_limits<double>::infinity();
  return m;
}

std::string describe(const ImageMetrics& m) {
  std::string s =
      std::to_string(m.comparedSamples) + "/" + std::to_string(m.totalSamples) + " samples compared: ";
  s += "maxAbs=" + shortNum(m.maxAbsError);
  if (m.worstChannel >= 0)
    s += " at (" + std::to_string(m.worstX) + "," + std::to_string(m.worstY) + ",c" +
         std::to_string(m.worstChannel) + ") [actual " + num(m.worstActual) + ", ref " +
         num(m.worstReference) + "]";
  s += ", meanAbs=" + shortNum(m.meanAbsError) + ", rmse=" + shortNum(m.rmse) +
       ", relRmse=" + shortNum(m.relativeRmse) + ", psnr=" + shortNum(m.psnr) + " dB (peak " +
       shortNum(m.peak) + "), over " + shortNum(m.overThreshold) + ": " + shortNum(m.fractionOver * 100.0) +
       "%";
  s += ", actual NaN/Inf=" + std::to_string(m.nanCount) + "/" + std::to_string(m.infCount);
  if (m.referenceNanCount > 0 || m.referenceInfCount > 0)
    s += ", reference NaN/Inf=" + std::to_string(m.referenceNanCount) + "/" +
         std::to_string(m.referenceInfCount);
  return s;
}

Image differenceImage(const Image& actual, const Image& reference, double amplification) {
  const int channels = checkComparable(actual, reference, 0);
  requirePositive("amplification", amplification);
  Image out(actual.width(), actual.height(), 3);
  for (int y = 0; y < actual.height(); ++y) {
    for (int x = 0; x < actual.width(); ++x) {
      double d[4] = {0.0, 0.0, 0.0, 0.0};
      bool finite = true;
      for (int c = 0; c < channels; ++c) {
        const float a = actual.at(x, y, c), r = reference.at(x, y, c);
        if (!std::isfinite(a) || !std::isfinite(r))
          finite = false;
        else
          d[c] = std::abs(static_cast<double>(a) - static_cast<double>(r)) * amplification;
      }
      double rgb[3] = {d[0], d[1], d[2]};
      if (channels == 1) rgb[1] = rgb[2] = d[0];
      if (channels == 4)
        for (double& v : rgb)
          v = std::max(v, d[3]);
      if (!finite) {
        rgb[0] = 1.0;
        rgb[1] = 0.0;
        rgb[2] = 1.0;
      }
      for (int c = 0; c < 3; ++c) {
        // Keep the result finite even for huge amplifications.
        const double v = std::min(rgb[c], static_cast<double>(std::numeric_limits<float>::max()));
        out.at(x, y, c) = static_cast<float>(v);
      }
    }
  }
  return out;
}

CompareOptions compareOptionsFor(const ImageTolerance& tolerance) {
  CompareOptions options;
  options.overThreshold = tolerance.overThreshold;
  return options;
}

bool withinTolerance(const ImageMetrics& m, const ImageTolerance& t, std::string* whyNot) {
  if (t.maxFractionOver < 1.0 && m.overThreshold != t.overThreshold)
    throw InvalidArgument("ImageTolerance.overThreshold", detail::formatValue(t.overThreshold),
                          "metrics were computed with overThreshold " + detail::formatValue(m.overThreshold) +
                              " (use compareOptionsFor)");
  std::string why;
  const auto fail = [&](const std::string& s) { why += (why.empty() ? "" : "; ") + s; };
  if (!t.allowNonFinite && (m.nanCount > 0 || m.infCount > 0))
    fail("actual has " + std::to_string(m.nanCount) + " NaN and " + std::to_string(m.infCount) +
         " Inf samples");
  if (m.comparedSamples == 0) fail("no finite samples were compared");
  if (!(m.maxAbsError <= t.maxAbsError))
    fail("maxAbsError " + num(m.maxAbsError) + " > " + num(t.maxAbsError));
  if (!(m.meanAbsError <= t.meanAbsError))
    fail("meanAbsError " + num(m.meanAbsError) + " > " + num(t.meanAbsError));
  if (!(m.relativeRmse <= t.relativeRmse))
    fail("relativeRmse " + num(m.relativeRmse) + " > " + num(t.relativeRmse));
  if (!(m.psnr >= t.minPsnr)) fail("psnr " + num(m.psnr) + " dB < " + num(t.minPsnr) + " dB");
  if (!(m.fractionOver <= t.maxFractionOver))
    fail("fraction of samples with error > " + num(t.overThreshold) + " is " + num(m.fractionOver) + " > " +
         num(t.maxFractionOver));
  if (whyNot != nullptr) *whyNot = why;
  return why.empty();
}

} // namespace crep
