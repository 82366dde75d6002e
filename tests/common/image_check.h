// Test helpers for image results: tolerance checks that leave inspectable files behind on
// failure, the test output directory and self-removing temporary directories.
#pragma once

#include <crep/core/image.h>
#include <crep/support/image_compare.h>

#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace crep::test {

/// Relative RMSE of the float values `actual` against `reference` (same count; doctest REQUIRE), skipping
/// the non-finite values of `actual`, which `nonFinite` counts; the reference must not be all zero.
double relativeRmse(std::span<const float> actual, std::span<const float> reference, long long& nonFinite);

/// Directory for test artifacts: $CREP_TEST_OUTPUT_DIR if set and non-empty, else the
/// CREP_TEST_OUTPUT_DIR macro (set by tests/CMakeLists.txt), else <temp>/crep-test-output.
/// Created if missing.
std::filesystem::path testOutputDir();

struct ImageCheckResult {
  bool passed = false;
  crep::ImageMetrics metrics;                   ///< valid when the images could be compared
  std::string message;                          ///< one line: name, metrics, failed bounds, files
  std::vector<std::filesystem::path> artifacts; ///< files written on failure
};

/// The work of checkImage without doctest: compares `actual` against `reference` with
/// compareOptionsFor(tolerance); on failure (including a size/channel mismatch) writes
/// <testOutputDir()>/<name>.actual.exr, <name>.reference.exr (float) and <name>.diff.png (difference
/// normalised so that maxAbsError is white, NaN/Inf magenta). `name` is sanitised to [A-Za-z0-9._-].
ImageCheckResult evaluateImage(const crep::Image& actual, const crep::Image& reference,
                               const crep::ImageTolerance& tolerance, const std::string& name);

/// evaluateImage + a doctest CHECK carrying the message (metrics, failed bounds, artifact paths).
/// Returns whether the check passed.
bool checkImage(const crep::Image& actual, const crep::Image& reference,
                const crep::ImageTolerance& tolerance, const std::string& name);

/// What checkImage writes on failure: the files that exist afterwards (actual/reference EXR when
/// non-empty, the difference PNG when both have the same shape), with `amplification` applied to the
/// difference. Throws crep::Error if the output directory cannot be created or a file not written.
std::vector<std::filesystem::path> writeFailureArtifacts(const crep::Image& actual,
                                                         const crep::Image& reference,
                                                         const std::string& name, double amplification);

/// A fresh, uniquely named directory under the system temporary directory, removed with its
/// content on destruction.
class TempDir {
public:
  explicit TempDir(const std::string& prefix = "crep-test");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const noexcept { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

private:
  std::filesystem::path path_;
};

} // namespace crep::test
