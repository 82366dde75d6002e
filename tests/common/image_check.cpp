#include "common/image_check.h"

#include <crep/core/error.h>
#include <crep/support/exr.h>
#include <crep/support/png.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <random>
#include <system_error>
#include <unistd.h>

namespace crep::test {

double relativeRmse(std::span<const float> actual, std::span<const float> reference, long long& nonFinite) {
  REQUIRE(actual.size() == reference.size());
  double squared = 0.0, sum = 0.0;
  nonFinite = 0;
  for (std::size_t i = 0; i < actual.size(); ++i) {
    if (!std::isfinite(actual[i])) {
      ++nonFinite;
      continue;
    }
    const double d = static_cast<double>(actual[i]) - reference[i];
    squared += d * d;
    sum += static_cast<double>(reference[i]) * reference[i];
  }
  REQUIRE(sum > 0.0);
  return std::sqrt(squared / sum);
}

namespace {

std::string sanitize(const std::string& name) {
  std::string s = name.empty() ? std::string("image") : name;
  for (char& c : s) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                    c == '_' || c == '-';
    if (!ok) c = '_';
  }
  return s;
}

} // namespace

std::filesystem::path testOutputDir() {
  std::filesystem::path dir;
  const char* env = std::getenv("CREP_TEST_OUTPUT_DIR");
  if (env != nullptr && env[0] != '\0') {
    dir = env;
  } else {
#ifdef CREP_TEST_OUTPUT_DIR
    dir = CREP_TEST_OUTPUT_DIR;
#else
    dir = std::filesystem::temp_directory_path() / "crep-test-output";
#endif
  }
  std::filesystem::create_directories(dir);
  return dir;
}

std::vector<std::filesystem::path> writeFailureArtifacts(const Image& actual, const Image& reference,
                                                         const std::string& name, double amplification) {
  const std::filesystem::path dir = testOutputDir();
  const std::string base = sanitize(name);
  std::vector<std::filesystem::path> written;
  if (!actual.empty()) {
    written.push_back(dir / (base + ".actual.exr"));
    writeExr(written.back(), actual, ExrPixelType::Float);
  }
  if (!reference.empty()) {
    written.push_back(dir / (base + ".reference.exr"));
    writeExr(written.back(), reference, ExrPixelType::Float);
  }
  if (!actual.empty() && actual.sameShape(reference)) {
    written.push_back(dir / (base + ".diff.png"));
    writePng(written.back(), differenceImage(actual, reference, amplification));
  }
  return written;
}

ImageCheckResult evaluateImage(const Image& actual, const Image& reference, const ImageTolerance& tolerance,
                               const std::string& name) {
  ImageCheckResult result;
  std::string problem;
  try {
    result.metrics = compareImages(actual, reference, compareOptionsFor(tolerance));
    std::string whyNot;
    result.passed = withinTolerance(result.metrics, tolerance, &whyNot);
    result.message = "image '" + name + "': " + describe(result.metrics);
    if (result.passed) return result;
    result.message += "; outside tolerance: " + whyNot;
  } catch (const Error& e) {
    result.message = "image '" + name + "' cannot be compared: " + e.what();
  }
  // Failed: leave the images for inspection.
  const double maxAbs = result.metrics.maxAbsError;
  const double amplification =
      maxAbs > 0.0 && std::isfinite(maxAbs) ? std::clamp(1.0 / maxAbs, 1e-6, 1e12) : 1.0;
  try {
    result.artifacts = writeFailureArtifacts(actual, reference, name, amplification);
    for (const auto& path : result.artifacts)
      result.message += "\n  wrote " + path.string();
    result.message +=
        "\n  (difference amplified " + detail::formatValue(amplification) + "x, NaN/Inf magenta)";
  } catch (const std::exception& e) {
    result.message += std::string("\n  could not write the artifacts: ") + e.what();
  }
  return result;
}

bool checkImage(const Image& actual, const Image& reference, const ImageTolerance& tolerance,
                const std::string& name) {
  const ImageCheckResult result = evaluateImage(actual, reference, tolerance, name);
  CHECK_MESSAGE(result.passed, result.message);
  return result.passed;
}

TempDir::TempDir(const std::string& prefix) {
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path root = std::filesystem::temp_directory_path();
  std::random_device device;
  std::mt19937_64 random(
      device() ^ static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()));
  for (int attempt = 0; attempt < 100; ++attempt) {
    const std::filesystem::path candidate =
        root / (sanitize(prefix) + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" +
                std::to_string(random() % 1000000007ULL));
    std::error_code ec;
    if (std::filesystem::create_directory(candidate, ec)) {
      path_ = candidate;
      return;
    }
  }
  throw IoError("crep: cannot create a temporary directory under '" + root.string() + "'");
}

TempDir::~TempDir() {
  std::error_code ignored;
  if (!path_.empty()) std::filesystem::remove_all(path_, ignored);
}

} // namespace crep::test
