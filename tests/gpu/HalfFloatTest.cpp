// gpu::halfBits / roundedToHalf (crep/gpu/backend.h): IEEE 754 binary16 rounding to the nearest, ties
// to even, checked against the format's definition: every half value maps to itself, every midpoint between
// two neighbours goes to the even one, and the special values.
#include <crep/gpu/backend.h>

#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <limits>

namespace {

/// The value of half bits h from the format's definition (sign, 5-bit exponent biased 15, 10-bit fraction).
double halfValue(std::uint16_t h) {
  const int sign = (h >> 15) != 0 ? -1 : 1, exponent = (h >> 10) & 31, fraction = h & 1023;
  if (exponent == 0) return sign * std::ldexp(fraction, -24);
  return sign * std::ldexp(1024 + fraction, exponent - 25);
}

} // namespace

TEST_CASE("half floats: every finite half maps to itself and every midpoint to its even neighbour") {
  int checked = 0;
  for (std::uint32_t h = 0; h < 0x7c00u; ++h) { // the positive finite halves; negatives by symmetry below
    const double v = halfValue(static_cast<std::uint16_t>(h));
    CHECK(crep::gpu::halfBits(static_cast<float>(v)) == h);
    CHECK(crep::gpu::halfBits(static_cast<float>(-v)) == (h | 0x8000u));
    CHECK(crep::gpu::roundedToHalf(static_cast<float>(v)) == static_cast<float>(v));
    if (h + 1 < 0x7c00u) {
      const double next = halfValue(static_cast<std::uint16_t>(h + 1));
      const double mid = 0.5 * (v + next); // exact in float: halves have 11 significant bits
      const std::uint32_t even = (h & 1u) == 0 ? h : h + 1;
      CHECK(crep::gpu::halfBits(static_cast<float>(mid)) == even);
      // Just off the midpoint: the nearer neighbour.
      CHECK(crep::gpu::halfBits(std::nextafter(static_cast<float>(mid), 0.0f)) == h);
      CHECK(crep::gpu::halfBits(std::nextafter(static_cast<float>(mid), 1e9f)) == h + 1);
    }
    ++checked;
  }
  CHECK(checked == 0x7c00);
}

TEST_CASE("half floats: the special values") {
  using crep::gpu::halfBits;
  CHECK(halfBits(1.0f) == 0x3c00u);
  CHECK(halfBits(65504.0f) == 0x7bffu);  // the largest half
  CHECK(halfBits(65519.99f) == 0x7bffu); // below the midpoint to 65536
  CHECK(halfBits(65520.0f) == 0x7c00u);  // the midpoint rounds to even: infinity
  CHECK(halfBits(1e30f) == 0x7c00u);
  CHECK(halfBits(-1e30f) == 0xfc00u);
  CHECK(halfBits(std::numeric_limits<float>::infinity()) == 0x7c00u);
  CHECK((halfBits(std::numeric_limits<float>::quiet_NaN()) & 0x7c00u) == 0x7c00u);
  CHECK((halfBits(std::numeric_limits<float>::quiet_NaN()) & 0x03ffu) != 0u); // still a NaN
  CHECK(halfBits(std::ldexp(1.0f, -24)) == 0x0001u);                          // the smallest subnormal
  CHECK(halfBits(std::ldexp(1.0f, -25)) == 0x0000u);    // half of it: the tie goes to even, zero
  CHECK(halfBits(std::ldexp(3.0f, -25)) == 0x0002u);    // 1.5 steps: the tie goes to even, 2
  CHECK(halfBits(std::ldexp(1.0f, -14)) == 0x0400u);    // the smallest normal
  CHECK(halfBits(std::ldexp(1023.5f, -24)) == 0x0400u); // the largest subnormal's midpoint carries over
  CHECK(halfBits(-0.0f) == 0x8000u);
  CHECK(halfBits(1.0f + std::ldexp(1.0f, -11)) == 0x3c00u); // a tie below an odd neighbour: down
  CHECK(halfBits(1.0f + std::ldexp(3.0f, -11)) == 0x3c02u); // a tie below an even neighbour: up
}
