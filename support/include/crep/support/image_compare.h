// Numerical comparison of two float images (tests, tools, regression checks).
//
// Definitions. The compared channels are the first n = CompareOptions.channels channels (all when
// 0). A sample is (x, y, c) with a = actual.at(x, y, c), r = reference.at(x, y, c). Samples where a
// or r is NaN or +-Inf are counted (nanCount/infCount for a, referenceNanCount/referenceInfCount for
// r) and excluded from everything else. Over the N = comparedSamples remaining samples, in double:
//   e            = |a - r|
//   maxAbsError  = max e                                   (0 if N = 0)
//   meanAbsError = sum e / N                               (0 if N = 0)
//   rmse         = sqrt(sum e^2 / N)                       (0 if N = 0)
//   rmsReference = sqrt(sum r^2 / N)
//   relativeRmse = rmse / rmsReference, or rmse when rmsReference = 0 (all-zero reference)
//   peak         = CompareOptions.peak if > 0, else max |r|, or 1 if that is 0
//   psnr         = 20 log10(peak / rmse) dB, +inf when rmse = 0
//   fractionOver = (number of samples with e > overThreshold) / N  (0 if N = 0)
//   worstX/worstY/worstChannel = first sample (in memory order: y, x, c) with e = maxAbsError, or
//                  -1 when maxAbsError = 0; x and y are Image coordinates (y = 0 is the bottom row).
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

/// Throws InvalidArgument (parameter "actual"/"reference" naming the mismatch: size or channels) if
/// the images are empty or cannot be compared, or for bad options.
ImageMetrics compareImages(const Image& actual, const Image& reference, const CompareOptions& options = {});

/// One line, e.g. "1 of 4 samples differ > 0: maxAbs=0.5 at (1,0,c0) [actual 1.5, ref 1], ...".
std::string describe(const ImageMetrics& metrics);

/// 3-channel image of |actual - reference| * amplification (finite, > 0), for viewing:
/// 1 channel -> (d, d, d); 2 -> (d0, d1, 0); 3 -> (d0, d1, d2); 4 -> (max(d0, dA), max(d1, dA),
/// max(d2, dA)). Pixels where any sample of either image is NaN/Inf are (1, 0, 1) (magenta).
/// Same shape requirements as compareImages with channels = 0.
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

/// True when every bound holds (bounds are inclusive: maxAbsError <= tolerance.maxAbsError, ...,
/// psnr >= minPsnr), actual has no NaN/Inf unless allowNonFinite, and at least one sample was
/// compared. Otherwise false and, if whyNot is given, the failed bounds separated by "; ".
/// Throws InvalidArgument ("ImageTolerance.overThreshold") when maxFractionOver < 1 but the metrics
/// were computed with a different overThreshold.
bool withinTolerance(const ImageMetrics& metrics, const ImageTolerance& tolerance,
                     std::string* whyNot = nullptr);

} // namespace crep
