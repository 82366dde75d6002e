// Self-tests of the image comparison: the metric definitions on hand-computable cases, and that
// tolerances catch a single changed sample while accepting small noise.
#include "common/image_check.h"

#include <crep/core/error.h>
#include <crep/core/image.h>
#include <crep/support/exr.h>
#include <crep/support/image_compare.h>

#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <random>
#include <string>

using crep::Image;
using crep::ImageMetrics;
using crep::ImageTolerance;

namespace {

const float kNan = std::numeric_limits<float>::quiet_NaN();
const float kInf = std::numeric_limits<float>::infinity();

Image randomImage(int width, int height, int channels, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> value(0.0f, 1.0f);
  Image image(width, height, channels);
  for (float& v : image.data())
    v = value(random);
  return image;
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

// Sets an environment variable for the lifetime of the object.
class ScopedEnv {
public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) {
      hadOld_ = true;
      old_ = old;
    }
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (hadOld_)
      ::setenv(name_, old_.c_str(), 1);
    else
      ::unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

private:
  const char* name_;
  bool hadOld_ = false;
  std::string old_;
};

} // namespace

TEST_CASE("compareImages: one sample off by 0.5 in a 2x2 single-channel image") {
  const Image reference(2, 2, 1, 1.0f);
  Image actual = reference;
  actual.at(1, 0) = 1.5f;
  crep::CompareOptions options;
  options.overThreshold = 0.1;
  const ImageMetrics m = crep::compareImages(actual, reference, options);
  CHECK(m.comparedSamples == 4);
  CHECK(m.totalSamples == 4);
  CHECK(m.maxAbsError == 0.5);
  CHECK(m.meanAbsError == 0.125);                 // 0.5 / 4
  CHECK(m.rmse == doctest::Approx(0.25));         // sqrt(0.25 / 4)
  CHECK(m.relativeRmse == doctest::Approx(0.25)); // rms(reference) = 1
  CHECK(m.peak == 1.0);                           // max |reference|
  CHECK(m.psnr == doctest::Approx(20.0 * std::log10(1.0 / 0.25)));
  CHECK(m.fractionOver == 0.25);
  CHECK(m.worstX == 1);
  CHECK(m.worstY == 0);
  CHECK(m.worstChannel == 0);
  CHECK(m.worstActual == 1.5);
  CHECK(m.worstReference == 1.0);
  CHECK(m.nanCount + m.infCount + m.referenceNanCount + m.referenceInfCount == 0);
}

TEST_CASE("compareImages: one channel of one pixel off in a 2x2 RGB image") {
  const Image reference(2, 2, 3, 2.0f);
  Image actual = reference;
  actual.at(0, 1, 2) = 1.5f;
  const ImageMetrics m = crep::compareImages(actual, reference);
  CHECK(m.comparedSamples == 12);
  CHECK(m.maxAbsError == 0.5);
  CHECK(m.meanAbsError == doctest::Approx(0.5 / 12));
  CHECK(m.rmse == doctest::Approx(std::sqrt(0.25 / 12)));
  CHECK(m.relativeRmse == doctest::Approx(std::sqrt(0.25 / 12) / 2.0)); // rms(reference) = 2
  CHECK(m.psnr == doctest::Approx(20.0 * std::log10(2.0 / std::sqrt(0.25 / 12))));
  CHECK(m.fractionOver == doctest::Approx(1.0 / 12)); // threshold 0
  CHECK(m.worstX == 0);
  CHECK(m.worstY == 1);
  CHECK(m.worstChannel == 2);
}

TEST_CASE("compareImages: identical images have zero error and infinite PSNR") {
  const Image image = randomImage(7, 5, 4, 1);
  const ImageMetrics m = crep::compareImages(image, image);
  CHECK(m.maxAbsError == 0.0);
  CHECK(m.meanAbsError == 0.0);
  CHECK(m.rmse == 0.0);
  CHECK(m.relativeRmse == 0.0);
  CHECK(std::isinf(m.psnr));
  CHECK(m.psnr > 0);
  CHECK(m.fractionOver == 0.0);
  CHECK(m.worstX == -1);
  CHECK(m.worstChannel == -1);
  CHECK(m.comparedSamples == 7 * 5 * 4);
  CHECK(crep::withinTolerance(m, ImageTolerance{0.0, 0.0, 0.0, 1000.0, 0.0, 0.0, false}));
}

TEST_CASE("compareImages: all-zero reference and explicit peak") {
  const Image reference(2, 2, 1, 0.0f);
  Image actual = reference;
  actual.at(0, 0) = 0.5f;
  ImageMetrics m = crep::compareImages(actual, reference);
  CHECK(m.rmse == doctest::Approx(0.25));
  CHECK(m.relativeRmse == doctest::Approx(0.25)); // rms(reference) = 0: relativeRmse = rmse
  CHECK(m.peak == 1.0);                           // max |reference| = 0: peak 1
  CHECK(m.psnr == doctest::Approx(20.0 * std::log10(1.0 / 0.25)));
  crep::CompareOptions options;
  options.peak = 2.0;
  m = crep::compareImages(actual, reference, options);
  CHECK(m.peak == 2.0);
  CHECK(m.psnr == doctest::Approx(20.0 * std::log10(2.0 / 0.25)));
}

TEST_CASE("compareImages: the channels option compares the first n channels") {
  const Image reference = randomImage(3, 3, 4, 2);
  Image actual = reference;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x)
      actual.at(x, y, 3) += 1.0f; // alpha differs everywhere
  crep::CompareOptions options;
  options.channels = 3;
  const ImageMetrics m = crep::compareImages(actual, reference, options);
  CHECK(m.maxAbsError == 0.0);
  CHECK(m.comparedSamples == 27);
  CHECK(crep::compareImages(actual, reference).maxAbsError == doctest::Approx(1.0));

  Image rgb(3, 3, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x)
      for (int c = 0; c < 3; ++c)
        rgb.at(x, y, c) = reference.at(x, y, c);
  CHECK(crep::compareImages(rgb, reference, options).maxAbsError == 0.0);
  options.channels = 4;
  CHECK_THROWS_AS((void)crep::compareImages(rgb, reference, options), crep::InvalidArgument);
}

TEST_CASE("compareImages: size, channel and option mismatches throw InvalidArgument naming the problem") {
  const Image a(4, 3, 3), wider(5, 3, 3), grey(4, 3, 1);
  try {
    (void)crep::compareImages(wider, a);
    FAIL_CHECK("no exception");
  } catch (const crep::InvalidArgument& e) {
    CHECK(e.parameter() == "actual");
    CHECK(contains(e.what(), "5x3"));
    CHECK(contains(e.what(), "4x3"));
  }
  try {
    (void)crep::compareImages(grey, a);
    FAIL_CHECK("no exception");
  } catch (const crep::InvalidArgument& e) {
    CHECK(e.parameter() == "actual");
    CHECK(contains(e.what(), "channels"));
  }
  CHECK_THROWS_AS((void)crep::compareImages(Image(), a), crep::InvalidArgument);
  CHECK_THROWS_AS((void)crep::compareImages(a, Image()), crep::InvalidArgument);
  crep::CompareOptions bad;
  bad.overThreshold = -1.0;
  CHECK_THROWS_AS((void)crep::compareImages(a, a, bad), crep::InvalidArgument);
  bad = {};
  bad.peak = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS((void)crep::compareImages(a, a, bad), crep::InvalidArgument);
  bad = {};
  bad.channels = 5;
  CHECK_THROWS_AS((void)crep::compareImages(a, a, bad), crep::InvalidArgument);
  CHECK_THROWS_AS((void)crep::differenceImage(wider, a, 1.0), crep::InvalidArgument);
  CHECK_THROWS_AS((void)crep::differenceImage(a, a, 0.0), crep::InvalidArgument);
}

TEST_CASE("compareImages: NaN and Inf are counted, excluded from the sums, and fail the tolerance") {
  const Image reference(3, 2, 2, 1.0f);
  Image actual = reference;
  actual.at(0, 0, 0) = kNan;
  actual.at(1, 0, 1) = kInf;
  actual.at(2, 1, 0) = -kInf;
  actual.at(2, 1, 1) = 1.25f;
  Image badReference = reference;
  badReference.at(0, 1, 0) = kNan;
  const ImageMetrics m = crep::compareImages(actual, badReference);
  CHECK(m.nanCount == 1);
  CHECK(m.infCount == 2);
  CHECK(m.referenceNanCount == 1);
  CHECK(m.referenceInfCount == 0);
  CHECK(m.totalSamples == 12);
  CHECK(m.comparedSamples == 8);
  CHECK(m.maxAbsError == 0.25);
  CHECK(m.meanAbsError == doctest::Approx(0.25 / 8));
  std::string why;
  CHECK_FALSE(crep::withinTolerance(m, ImageTolerance{}, &why));
  CHECK(contains(why, "1 NaN"));
  CHECK(contains(why, "2 Inf"));
  ImageTolerance lenient;
  lenient.allowNonFinite = true;
  CHECK(crep::withinTolerance(m, lenient));
  CHECK(contains(crep::describe(m), "NaN/Inf=1/2"));

  // Nothing finite to compare never passes.
  const Image allNan(2, 2, 1, kNan);
  const ImageMetrics none = crep::compareImages(Image(2, 2, 1), allNan);
  CHECK(none.comparedSamples == 0);
  CHECK_FALSE(crep::withinTolerance(none, lenient, &why));
  CHECK(contains(why, "no finite samples"));
}

TEST_CASE("withinTolerance: a single changed channel of a single pixel fails, tolerated noise passes") {
  const Image reference = randomImage(37, 23, 3, 42);
  ImageTolerance tolerance;
  tolerance.maxAbsError = 2e-3;

  Image changed = reference;
  changed.at(17, 11, 1) += 0.01f;
  std::string why;
  const ImageMetrics changedMetrics =
      crep::compareImages(changed, reference, crep::compareOptionsFor(tolerance));
  CHECK_FALSE(crep::withinTolerance(changedMetrics, tolerance, &why));
  CHECK(contains(why, "maxAbsError"));
  CHECK(changedMetrics.worstX == 17);
  CHECK(changedMetrics.worstY == 11);
  CHECK(changedMetrics.worstChannel == 1);
  // Averages barely notice it: the mean alone would not have caught the change.
  CHECK(changedMetrics.meanAbsError < 1e-5);

  Image noisy = reference;
  std::mt19937 random(7);
  std::uniform_real_distribution<float> noise(-1e-3f, 1e-3f);
  for (float& v : noisy.data())
    v += noise(random);
  const ImageMetrics noisyMetrics = crep::compareImages(noisy, reference, crep::compareOptionsFor(tolerance));
  CHECK(crep::withinTolerance(noisyMetrics, tolerance, &why));
  CHECK(why.empty());
  CHECK(noisyMetrics.maxAbsError <= 1.0001e-3);
  CHECK(noisyMetrics.maxAbsError > 5e-4);
}

TEST_CASE("withinTolerance: every bound is checked, inclusively") {
  const Image reference(2, 2, 1, 1.0f);
  Image actual = reference;
  actual.at(1, 1) = 1.5f; // max 0.5, mean 0.125, relRmse 0.25, psnr 12.04 dB, 25% over 0.1
  ImageTolerance t;
  t.overThreshold = 0.1;
  const ImageMetrics m = crep::compareImages(actual, reference, crep::compareOptionsFor(t));
  std::string why;
  t.maxAbsError = 0.5;
  t.meanAbsError = 0.125;
  t.relativeRmse = 0.25;
  t.minPsnr = 12.0;
  t.maxFractionOver = 0.25;
  CHECK(crep::withinTolerance(m, t, &why));
  ImageTolerance u = t;
  u.maxAbsError = 0.49;
  CHECK_FALSE(crep::withinTolerance(m, u, &why));
  CHECK(contains(why, "maxAbsError"));
  u = t;
  u.meanAbsError = 0.12;
  CHECK_FALSE(crep::withinTolerance(m, u, &why));
  CHECK(contains(why, "meanAbsError"));
  u = t;
  u.relativeRmse = 0.2;
  CHECK_FALSE(crep::withinTolerance(m, u, &why));
  CHECK(contains(why, "relativeRmse"));
  u = t;
  u.minPsnr = 13.0;
  CHECK_FALSE(crep::withinTolerance(m, u, &why));
  CHECK(contains(why, "psnr"));
  u = t;
  u.maxFractionOver = 0.2;
  CHECK_FALSE(crep::withinTolerance(m, u, &why));
  CHECK(contains(why, "fraction"));
  // Several failures are all listed.
  u.maxAbsError = 0.1;
  CHECK_FALSE(crep::withinTolerance(m, u, &why));
  CHECK(contains(why, "maxAbsError"));
  CHECK(contains(why, "; "));
  // A fraction bound evaluated on metrics computed with another threshold is a usage error.
  u = t;
  u.overThreshold = 0.2;
  CHECK_THROWS_AS((void)crep::withinTolerance(m, u), crep::InvalidArgument);
}

TEST_CASE("describe: one line with the key numbers") {
  const Image reference(2, 2, 1, 1.0f);
  Image actual = reference;
  actual.at(1, 0) = 1.5f;
  const std::string line = crep::describe(crep::compareImages(actual, reference));
  CHECK(line.find('\n') == std::string::npos);
  CHECK(contains(line, "maxAbs=0.5"));
  CHECK(contains(line, "(1,0,c0)"));
  CHECK(contains(line, "meanAbs=0.125"));
  CHECK(contains(line, "psnr="));
  CHECK(contains(line, "4/4 samples"));
}

TEST_CASE("differenceImage: amplified |a - b| as RGB, non-finite pixels magenta") {
  SUBCASE("RGB") {
    const Image reference(2, 1, 3, 0.5f);
    Image actual = reference;
    actual.at(0, 0, 0) = 0.6f;
    actual.at(0, 0, 2) = 0.45f;
    actual.at(1, 0, 1) = kNan;
    const Image d = crep::differenceImage(actual, reference, 10.0);
    REQUIRE(d.channels() == 3);
    CHECK(d.at(0, 0, 0) == doctest::Approx(1.0).epsilon(1e-5));
    CHECK(d.at(0, 0, 1) == 0.0f);
    CHECK(d.at(0, 0, 2) == doctest::Approx(0.5).epsilon(1e-5));
    CHECK(d.at(1, 0, 0) == 1.0f);
    CHECK(d.at(1, 0, 1) == 0.0f);
    CHECK(d.at(1, 0, 2) == 1.0f);
  }
  SUBCASE("grey becomes grey RGB; alpha differences show in every colour channel") {
    const Image grey = crep::differenceImage(Image(1, 1, 1, 0.25f), Image(1, 1, 1, 0.0f), 2.0);
    CHECK(grey.at(0, 0, 0) == 0.5f);
    CHECK(grey.at(0, 0, 1) == 0.5f);
    CHECK(grey.at(0, 0, 2) == 0.5f);
    Image rgba(1, 1, 4, 0.0f);
    rgba.at(0, 0, 3) = 0.25f;
    rgba.at(0, 0, 0) = 0.5f;
    const Image d = crep::differenceImage(rgba, Image(1, 1, 4, 0.0f), 1.0);
    CHECK(d.at(0, 0, 0) == 0.5f);
    CHECK(d.at(0, 0, 1) == 0.25f);
    CHECK(d.at(0, 0, 2) == 0.25f);
  }
}

TEST_CASE("checkImage: passes silently within tolerance") {
  const Image reference = randomImage(8, 6, 3, 3);
  ImageTolerance tolerance;
  tolerance.maxAbsError = 1e-6;
  CHECK(crep::test::checkImage(reference, reference, tolerance, "identical"));
}

TEST_CASE("evaluateImage: a failure names the failed bound and writes the artifacts") {
  crep::test::TempDir dir;
  const ScopedEnv env("CREP_TEST_OUTPUT_DIR", dir.path().string());
  const Image reference = randomImage(8, 6, 3, 3);
  Image actual = reference;
  actual.at(2, 3, 0) += 0.5f;
  ImageTolerance tolerance;
  tolerance.maxAbsError = 1e-3;
  const auto result = crep::test::evaluateImage(actual, reference, tolerance, "expected failure");
  CHECK_FALSE(result.passed);
  CHECK(contains(result.message, "expected failure"));
  CHECK(contains(result.message, "maxAbsError 0.5 > 0.001"));
  CHECK(contains(result.message, "(2,3,c0)"));
  REQUIRE(result.artifacts.size() == 3);
  for (const auto& file : result.artifacts) {
    CHECK(std::filesystem::exists(file));
    CHECK(contains(result.message, file.string()));
  }
  CHECK(result.artifacts[2].filename() == "expected_failure.diff.png");

  const auto mismatch = crep::test::evaluateImage(Image(3, 3, 3), reference, tolerance, "mismatch");
  CHECK_FALSE(mismatch.passed);
  CHECK(contains(mismatch.message, "cannot be compared"));
  CHECK(mismatch.artifacts.size() == 2); // no difference image

  const auto pass = crep::test::evaluateImage(reference, reference, tolerance, "pass");
  CHECK(pass.passed);
  CHECK(pass.artifacts.empty());
  CHECK_FALSE(std::filesystem::exists(dir / "pass.actual.exr"));
}

TEST_CASE("checkImage artifacts: actual/reference EXR and amplified difference PNG in the output directory") {
  crep::test::TempDir dir;
  const ScopedEnv env("CREP_TEST_OUTPUT_DIR", (dir.path() / "nested" / "out").string());
  CHECK(crep::test::testOutputDir() == dir.path() / "nested" / "out");
  CHECK(std::filesystem::is_directory(dir.path() / "nested" / "out"));
  const Image reference = randomImage(8, 6, 3, 3);
  Image actual = reference;
  actual.at(2, 3, 0) += 0.5f;
  const auto files = crep::test::writeFailureArtifacts(actual, reference, "my test/case 1", 2.0);
  REQUIRE(files.size() == 3);
  const auto out = dir.path() / "nested" / "out";
  CHECK(files[0] == out / "my_test_case_1.actual.exr");
  CHECK(files[1] == out / "my_test_case_1.reference.exr");
  CHECK(files[2] == out / "my_test_case_1.diff.png");
  for (const auto& f : files)
    CHECK(std::filesystem::file_size(f) > 0);
  CHECK(crep::compareImages(crep::readExr(files[0]), actual).maxAbsError == 0.0); // float: exact
  CHECK(crep::compareImages(crep::readExr(files[1]), reference).maxAbsError == 0.0);
  // Mismatched shapes: no difference image.
  CHECK(crep::test::writeFailureArtifacts(Image(2, 2, 1), reference, "mismatch", 1.0).size() == 2);
}

TEST_CASE("TempDir: unique, exists while alive, removed with its content") {
  std::filesystem::path first, second;
  {
    crep::test::TempDir a("crep-tempdir-test"), b("crep-tempdir-test");
    first = a.path();
    second = b.path();
    CHECK(first != second);
    CHECK(std::filesystem::is_directory(first));
    std::filesystem::create_directories(a / "sub" / "dir");
    crep::writeExr(a / "sub" / "file.exr", Image(2, 2, 1));
  }
  CHECK_FALSE(std::filesystem::exists(first));
  CHECK_FALSE(std::filesystem::exists(second));
}
