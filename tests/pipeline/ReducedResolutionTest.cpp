// Reduced-resolution evaluation, CPU rules (crep/pipeline/reduced_resolution.h): the checkerboard min/max
// depth downsample, the depth-aware upsample reducing exactly to the bilinear upsample on a constant depth,
// and keeping each side of a depth edge; bad input named.
#include "common/error_checks.h"

#include <crep/core/camera.h>
#include <crep/core/error.h>
#include <crep/pipeline/reduced_resolution.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

using namespace crep;
using crep::test::invalidParameter;

namespace {

Camera testCamera() {
  return Camera::lookAt({0, 2, 0}, {0, 2, -1}, {0, 1, 0}, 1.0, 16.0 / 9.0, 0.1, 100.0);
}

/// Plain bilinear upsample by `f` with the same footprint rule (u = (x + 0.5) / f - 0.5, clamped).
double bilinear(const Image& low, int f, int x, int y, int c) {
  const double u = (x + 0.5) / f - 0.5, v = (y + 0.5) / f - 0.5;
  const int i0 = static_cast<int>(std::floor(u)), j0 = static_cast<int>(std::floor(v));
  const double fx = u - i0, fy = v - j0;
  const auto at = [&](int i, int j) {
    return double(low.at(std::clamp(i, 0, low.width() - 1), std::clamp(j, 0, low.height() - 1), c));
  };
  return (1 - fy) * ((1 - fx) * at(i0, j0) + fx * at(i0 + 1, j0)) +
         fy * ((1 - fx) * at(i0, j0 + 1) + fx * at(i0 + 1, j0 + 1));
}

} // namespace

TEST_CASE("reduced resolution: the depth downsample is a checkerboard of block minima and maxima") {
  for (const int f : {2, 4}) {
    CAPTURE(f);
    Image depth(8 * f, 4 * f, 1);
    for (int y = 0; y < depth.height(); ++y)
      for (int x = 0; x < depth.width(); ++x)
        depth.at(x, y) = static_cast<float>(((x * 7 + y * 13) % 17) / 17.0);
    const Image low = downsampleDepth(depth, f);
    REQUIRE(low.width() == 8);
    REQUIRE(low.height() == 4);
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 8; ++i) {
        float lo = 2.0f, hi = -1.0f;
        for (int y = 0; y < f; ++y)
          for (int x = 0; x < f; ++x) {
            lo = std::min(lo, depth.at(i * f + x, j * f + y));
            hi = std::max(hi, depth.at(i * f + x, j * f + y));
          }
        CHECK(low.at(i, j) == ((i + j) % 2 == 0 ? lo : hi));
      }
  }
}

TEST_CASE("reduced resolution: on a constant depth the upsample is exactly the bilinear one") {
  const Camera camera = testCamera();
  for (const float d : {0.3f, 0.999f, 1.0f}) { // a surface, a far surface, the sky
    CAPTURE(d);
    for (const int f : {2, 4}) {
      CAPTURE(f);
      const Image full(16 * f, 9 * f, 1, d);
      const Image lowDepth = downsampleDepth(full, f);
      Image low(16, 9, 4);
      for (int j = 0; j < 9; ++j)
        for (int i = 0; i < 16; ++i)
          for (int c = 0; c < 4; ++c)
            low.at(i, j, c) = static_cast<float>(std::sin(0.7 * i + 1.3 * j + c) + 2.0);
      const Image up = depthAwareUpsample(low, lowDepth, full, camera, f);
      double worst = 0.0;
      for (int y = 0; y < full.height(); ++y)
        for (int x = 0; x < full.width(); ++x)
          for (int c = 0; c < 4; ++c)
            worst = std::max(worst, std::abs(up.at(x, y, c) - bilinear(low, f, x, y, c)));
      CHECK(worst < 1e-6); // float storage of the same value
    }
  }
}

TEST_CASE("reduced resolution: the upsample keeps each side of a depth edge") {
  // Left half a near wall (depth 0.5), right half the sky; the low image carries 1 on near pixels and 5 on
  // far ones. Bilinear mixes them over two low pixels around the edge; the depth-aware upsample gives every
  // full pixel (almost) its own side's value.
  const Camera camera = testCamera();
  const int f = 2, W = 32, H = 8;
  Image full(W, H, 1);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      full.at(x, y) = x < 15 ? 0.5f : 1.0f; // the edge inside low column 7 (full columns 14 | 15)
  const Image lowDepth = downsampleDepth(full, f);
  Image low(W / f, H / f, 1);
  for (int j = 0; j < H / f; ++j)
    for (int i = 0; i < W / f; ++i)
      low.at(i, j) = lowDepth.at(i, j) < 1.0f ? 1.0f : 5.0f;
  const Image up = depthAwareUpsample(low, lowDepth, full, camera, f);
  double worstAware = 0.0, worstBilinear = 0.0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const double truth = x < 15 ? 1.0 : 5.0;
      worstAware = std::max(worstAware, std::abs(up.at(x, y) - truth));
      worstBilinear = std::max(worstBilinear, std::abs(bilinear(low, f, x, y, 0) - truth));
    }
  MESSAGE("depth edge: worst error depth-aware " << worstAware << ", bilinear " << worstBilinear);
  CHECK(worstBilinear > 1.0);
  CHECK(worstAware < 0.1 * worstBilinear);
}

TEST_CASE("reduced resolution: bad input is named") {
  const Image d(8, 8, 1, 0.5f);
  CHECK(invalidParameter([&] { downsampleDepth(d, 3); }) == "downsampleDepth.factor");
  CHECK(invalidParameter([&] { downsampleDepth(Image(6, 8, 1, 0.5f), 4); }) == "downsampleDepth.depth");
  const Image lowDepth = downsampleDepth(d, 2);
  CHECK(invalidParameter([&] { depthAwareUpsample(Image(3, 4, 4), lowDepth, d, testCamera(), 2); }) ==
        "depthAwareUpsample.low");
  CHECK(invalidParameter([&] { depthAwareUpsample(Image(4, 4, 4), Image(2, 2, 1), d, testCamera(), 2); }) ==
        "depthAwareUpsample.lowDepth");
}
