// Numerical comparison of two float images (tests, tools, regression checks). Definitions of every
// metric (non-finite samples, peak, worst sample): support/README.md, "crep/support/image_compare.h".
#pragma once

#include <crep/core/image.h>

#include <limits>
#include <string>

namespace crep {

struct ImageMetrics {
  double maxAbsError = 0.0;
  double meanAbsError = 0.0;
  double rmse = 0.0;
  double relativeRmse = 0.0;
  double psnr = std::numeric_limits<double>::infinity();
  double peak = 1.0;          ///< peak used for psnr
  double overThreshold = 0.0; ///< threshold used for fractionOver
  double fractionOver = 0.0;
  long long nanCount = 0, infCount = 0;                   ///< in actual
  long long referenceNanCount = 0, referenceInfCount = 0; ///< in reference
  int worstX = -1, worstY = -1, worstChannel = -1;
  double worstActual = 0.0, worstReference = 0.0; ///< values at the worst sample
  long long comparedSamples = 0;
  long long totalSamples = 0; ///< width * height * compared channels
};

struct CompareOptions {
  double overThreshold = 0.0; ///< for fractionOver; finite and >= 0
  double peak = 0.0;          ///< 0 = max |reference|; otherwise finite and > 0
  int channels = 0;           ///< 0 = all (channel counts must match); else the first n (both need >= n)
};

/// Throws InvalidArgument ("actual" / "reference": empty, size, channels) or for bad options. O(samples).
ImageMetrics compareImages(const Image& actual, const Image& reference, const CompareOptions& options = {});

/// One line, e.g. "1 of 4 samples differ > 0: maxAbs=0.5 at (1,0,c0) [actual 1.5, ref 1], ...".
std::string describe(const ImageMetrics& metrics);

/// 3-channel |actual - reference| * amplification (finite, > 0) for viewing; NaN / Inf pixels magenta.
Image differenceImage(const Image& actual, const Image& reference, double amplification);

struct ImageTolerance {
  double maxAbsError = std::numeric_limits<double>::infinity();
  double meanAbsError = std::numeric_limits<double>::infinity();
  double relativeRmse = std::numeric_limits<double>::infinity();
  double minPsnr = -std::numeric_limits<double>::infinity();
  double maxFractionOver = 1.0;
  double overThreshold = 0.0;  ///< threshold for maxFractionOver (use compareOptionsFor)
  bool allowNonFinite = false; ///< otherwise any NaN/Inf in actual fails
};

/// CompareOptions whose overThreshold matches the tolerance.
CompareOptions compareOptionsFor(const ImageTolerance& tolerance);

/// True when every (inclusive) bound holds, actual is finite unless allowNonFinite and a sample was
/// compared; else false and the failed bounds in `whyNot`. InvalidArgument ("ImageTolerance.overThreshold").
bool withinTolerance(const ImageMetrics& metrics, const ImageTolerance& tolerance,
                     std::string* whyNot = nullptr);

} // namespace crep
