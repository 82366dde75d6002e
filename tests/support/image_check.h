// Test helpers for image results: tolerance checks that leave inspectable files behind on
// failure, the test output directory and self-removing temporary directories.
#pragma once

#include <crep/core/image.h>
#include <crep/core/image_compare.h>

#include <filesystem>
#include <string>

namespace crep::test {

/// Directory for test artifacts: $CREP_TEST_OUTPUT_DIR if set and non-empty, else the
/// CREP_TEST_OUTPUT_DIR macro (set by tests/CMakeLists.txt), else <temp>/crep-test-output.
/// Created if missing.
std::filesystem::path testOutputDir();

/// Compares `actual` against `reference` with compareOptionsFor(tolerance) and records a doctest
/// CHECK with the metrics. On failure (including a size/channel mismatch) writes
/// <testOutputDir()>/<name>.actual.exr, <name>.reference.exr (float) and <name>.diff.png (difference
/// normalised so that maxAbsError is white, NaN/Inf magenta) and names them in the failure message.
/// `name` is sanitised to [A-Za-z0-9._-]. Returns whether the check passed.
bool checkImage(const crep::Image& actual, const crep::Image& reference, const crep::ImageTolerance& tolerance,
                const std::string& name);

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
