// How closely a GPU resampled rectified map follows the CPU reference (crep::resampleShadowMap): float
// light rays pick a neighbouring standard texel now and then, so a few texels may differ much; the rest
// agree to the float precision of the mapping. Used by the resampling tests of every backend.
#pragma once

#include <crep/core/image.h>

#include <doctest/doctest.h>

#include <cmath>
#include <span>
#include <string>

namespace crep::test {

/// `gpu`: width x height floats, row by row (row 0 at the bottom, as Image). Checks that under 1% of the
/// texels differ from `cpu` by more than 1e-3 and that the others differ by less than 5e-5 on average.
inline void checkResampledMap(const std::string& name, std::span<const float> gpu, const Image& cpu) {
  const int W = cpu.width(), H = cpu.height();
  REQUIRE(gpu.size() == static_cast<std::size_t>(W) * static_cast<std::size_t>(H));
  int differ = 0;
  double mean = 0.0;
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) {
      const double d = std::abs(gpu[static_cast<std::size_t>(j * W + i)] - cpu.at(i, j));
      if (d > 1e-3)
        ++differ;
      else
        mean += d / (W * H);
    }
  MESSAGE(name << ": " << differ << " of " << W * H << " texels differ by > 1e-3, the others by " << mean
               << " on average");
  CHECK(differ < W * H / 100);
  CHECK(mean < 5e-5);
}

} // namespace crep::test
