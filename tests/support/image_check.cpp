#include "support/image_check.h"

#include <crep/core/error.h>
#include <crep/core/exr.h>
#include <crep/core/png.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <random>
#include <system_error>
#include <unistd.h>

namespace crep::test {

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

// Writes what can be written; returns a description of the files (or of the failures).
std::string writeArtifacts(const Image& actual, const Image& reference, const std::string& name,
                           double maxAbsError) {
  std::string report;
  std::filesystem::path dir;
  try {
    dir = testOutputDir();
  } catch (const std::exception& e) {
    return std::string("(no artifacts: ") + e.what() + ")";
  }
  const std::string base = sanitize(name);
  const auto attempt = [&](const std::string& file, auto&& write) {
    const std::filesystem::path path = dir / file;
    try {
      write(path);
      report += "\n  wrote " + path.string();
    } catch (const std::exception& e) {
      report += "\n  could not write " + path.string() + ": " + e.what();
    }
  };
  if (!actual.empty())
    attempt(base + ".actual.exr", [&](const auto& p) { writeExr(p, actual, ExrPixelType::Float); });
  if (!reference.empty())
    attempt(base + ".reference.exr", [&](const auto& p) { writeExr(p, reference, ExrPixelType::Float); });
  if (!actual.empty() && actual.sameShape(reference)) {
    const double amplification =
        maxAbsError > 0.0 && std::isfinite(maxAbsError) ? std::clamp(1.0 / maxAbsError, 1e-6, 1e12) : 1.0;
    attempt(base + ".diff.png", [&](const auto& p) { writePng(p, differenceImage(actual, reference, amplification)); });
    report += " (difference amplified " + detail::formatValue(amplification) + "x)";
  }
  return report;
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

bool checkImage(const Image& actual, const Image& reference, const ImageTolerance& tolerance,
                const std::string& name) {
  ImageMetrics metrics;
  try {
    metrics = compareImages(actual, reference, compareOptionsFor(tolerance));
  } catch (const Error& e) {
    const std::string artifacts = writeArtifacts(actual, reference, name, 0.0);
    FAIL_CHECK("image '" << name << "' cannot be compared: " << e.what() << artifacts);
    return false;
  }
  std::string whyNot;
  const bool ok = withinTolerance(metrics, tolerance, &whyNot);
  if (ok) {
    CHECK_MESSAGE(ok, "image '" << name << "': " << describe(metrics));
    return true;
  }
  const std::string artifacts = writeArtifacts(actual, reference, name, metrics.maxAbsError);
  INFO("image '" << name << "': " << describe(metrics));
  CHECK_MESSAGE(ok, "image '" << name << "' outside tolerance: " << whyNot << artifacts);
  return false;
}

TempDir::TempDir(const std::string& prefix) {
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path root = std::filesystem::temp_directory_path();
  std::random_device device;
  std::mt19937_64 random(device() ^ static_cast<std::uint64_t>(
                                        std::chrono::steady_clock::now().time_since_epoch().count()));
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
