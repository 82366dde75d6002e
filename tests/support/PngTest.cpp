// PNG output. Files are decoded with stb_image (an independent decoder, header-only, from the same
// Debian package as stb_image_write) to check content and orientation.
#include "common/image_check.h"
#include "common/png_read.h"

#include <crep/core/error.h>
#include <crep/core/image.h>
#include <crep/support/png.h>

#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

using crep::Image;
namespace fs = std::filesystem;

namespace {

const float kNan = std::numeric_limits<float>::quiet_NaN();
const float kInf = std::numeric_limits<float>::infinity();

std::vector<std::uint8_t> readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  REQUIRE(in);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::uint32_t bigEndian32(const std::vector<std::uint8_t>& b, std::size_t at) {
  REQUIRE(at + 4 <= b.size());
  return (static_cast<std::uint32_t>(b[at]) << 24) | (static_cast<std::uint32_t>(b[at + 1]) << 16) |
         (static_cast<std::uint32_t>(b[at + 2]) << 8) | static_cast<std::uint32_t>(b[at + 3]);
}

/// The PNG at `path` in its own channel count (stb_image), required to decode.
crep::test::Png decodePng(const fs::path& path) {
  const crep::test::Png d = crep::test::readPng(path, 0);
  REQUIRE_MESSAGE(d.width > 0, "stb_image cannot decode " << path.string());
  return d;
}

} // namespace

TEST_CASE("PNG: encodeSrgb8 known values (sRGB OETF, 8-bit rounding)") {
  // Expected codes computed independently: floor(255 * oetf(v) + 0.5).
  CHECK(crep::encodeSrgb8(0.0f) == 0);
  CHECK(crep::encodeSrgb8(1.0f) == 255);
  CHECK(crep::encodeSrgb8(0.001f) == 3);      // linear segment: 12.92 * 0.001 * 255 = 3.29
  CHECK(crep::encodeSrgb8(0.0031308f) == 10); // segment boundary: 0.04045 * 255 = 10.31
  CHECK(crep::encodeSrgb8(0.01f) == 25);
  CHECK(crep::encodeSrgb8(0.1f) == 89);
  CHECK(crep::encodeSrgb8(0.18f) == 118);
  CHECK(crep::encodeSrgb8(0.2f) == 124);
  CHECK(crep::encodeSrgb8(0.5f) == 188);
  CHECK(crep::encodeSrgb8(0.8f) == 231);
  CHECK(crep::encodeSrgb8(0.9f) == 243);
  // Clamping and non-finite input.
  CHECK(crep::encodeSrgb8(-0.5f) == 0);
  CHECK(crep::encodeSrgb8(7.0f) == 255);
  CHECK(crep::encodeSrgb8(kNan) == 0);
  CHECK(crep::encodeSrgb8(kInf) == 0);
  CHECK(crep::encodeSrgb8(-kInf) == 0);
}

TEST_CASE("PNG: the two sRGB segments meet at 0.0031308 and the inverse round-trips every code") {
  const double below = crep::linearToSrgb(0.0031308f);
  CHECK(below == doctest::Approx(0.04045).epsilon(1e-5));
  const double above = crep::linearToSrgb(std::nextafter(0.0031308f, 1.0f));
  CHECK(above >= below);
  CHECK(above - below < 1e-6);
  CHECK(crep::srgbToLinear(0.04045f) == doctest::Approx(0.0031308).epsilon(1e-5));
  CHECK(crep::srgbToLinear(0.0f) == 0.0f);
  CHECK(crep::srgbToLinear(1.0f) == doctest::Approx(1.0).epsilon(1e-6));
  CHECK(crep::srgbToLinear(188.0f / 255.0f) == doctest::Approx(0.5).epsilon(0.005));
  CHECK(crep::srgbToLinear(kNan) == 0.0f);
  for (int code = 0; code < 256; ++code) {
    CAPTURE(code);
    CHECK(crep::encodeSrgb8(crep::srgbToLinear(static_cast<float>(code) / 255.0f)) == code);
  }
  float previous = -1.0f;
  for (int i = 0; i <= 1000; ++i) {
    const float s = crep::linearToSrgb(static_cast<float>(i) / 1000.0f);
    CHECK(s > previous);
    previous = s;
  }
}

TEST_CASE("PNG: signature, IHDR size and colour type, content and orientation decode correctly") {
  crep::test::TempDir dir;
  const int w = 37, h = 23;
  Image image(w, h, 3);
  image.at(0, 0, 0) = 1.0f;         // bottom-left red
  image.at(w - 1, h - 1, 2) = 0.5f; // top-right blue 188
  image.at(5, 7, 1) = 0.18f;        // green 118
  const fs::path path = dir / "rgb.png";
  crep::writePng(path, image);

  const std::vector<std::uint8_t> bytes = readFile(path);
  const std::uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  REQUIRE(bytes.size() > 33);
  for (int i = 0; i < 8; ++i)
    CHECK(bytes[static_cast<std::size_t>(i)] == signature[i]);
  CHECK(std::string(bytes.begin() + 12, bytes.begin() + 16) == "IHDR");
  CHECK(bigEndian32(bytes, 16) == static_cast<std::uint32_t>(w));
  CHECK(bigEndian32(bytes, 20) == static_cast<std::uint32_t>(h));
  CHECK(bytes[24] == 8); // bit depth
  CHECK(bytes[25] == 2); // colour type RGB

  const crep::test::Png d = decodePng(path);
  REQUIRE(d.width == w);
  REQUIRE(d.height == h);
  REQUIRE(d.channels == 3);
  // PNG row 0 is the top: Image row h - 1.
  CHECK(d.at(0, h - 1, 0) == 255);
  CHECK(d.at(0, h - 1, 1) == 0);
  CHECK(d.at(w - 1, 0, 2) == 188);
  CHECK(d.at(5, h - 1 - 7, 1) == 118);
  CHECK(d.at(1, 1, 0) == 0);
}

TEST_CASE("PNG: exposure multiplies before encoding, NaN and Inf become 0") {
  crep::test::TempDir dir;
  Image image(4, 1, 3, 0.25f);
  image.at(1, 0, 0) = kNan;
  image.at(2, 0, 1) = kInf;
  image.at(3, 0, 2) = -kInf;
  crep::ToneMap toneMap;
  toneMap.exposure = 2.0f;
  crep::writePng(dir / "exposure.png", image, toneMap);
  const crep::test::Png d = decodePng(dir / "exposure.png");
  CHECK(d.at(0, 0, 0) == 188); // 0.25 * 2 = 0.5
  CHECK(d.at(1, 0, 0) == 0);
  CHECK(d.at(1, 0, 1) == 188);
  CHECK(d.at(2, 0, 1) == 0);
  CHECK(d.at(3, 0, 2) == 0);
  toneMap.exposure = 0.0f;
  crep::writePng(dir / "black.png", image, toneMap);
  for (std::uint8_t v : decodePng(dir / "black.png").pixels)
    CHECK(v == 0);
}

TEST_CASE("PNG: channel mapping: grey, RG, RGB with alpha dropped or kept") {
  crep::test::TempDir dir;
  SUBCASE("1 channel -> grey") {
    crep::writePng(dir / "grey.png", Image(3, 2, 1, 0.5f));
    CHECK(readFile(dir / "grey.png")[25] == 0);
    const crep::test::Png d = decodePng(dir / "grey.png");
    REQUIRE(d.channels == 1);
    CHECK(d.at(2, 1, 0) == 188);
  }
  SUBCASE("2 channels -> RGB with blue 0") {
    Image image(3, 2, 2, 1.0f);
    crep::writePng(dir / "rg.png", image);
    const crep::test::Png d = decodePng(dir / "rg.png");
    REQUIRE(d.channels == 3);
    CHECK(d.at(0, 0, 0) == 255);
    CHECK(d.at(0, 0, 1) == 255);
    CHECK(d.at(0, 0, 2) == 0);
  }
  SUBCASE("4 channels -> RGB, or RGBA with linear alpha when keepAlpha") {
    Image image(3, 2, 4, 0.5f);
    image.at(1, 0, 3) = 0.2f;
    crep::writePng(dir / "rgb.png", image);
    CHECK(readFile(dir / "rgb.png")[25] == 2);
    CHECK(decodePng(dir / "rgb.png").channels == 3);
    crep::ToneMap keep;
    keep.keepAlpha = true;
    keep.exposure = 0.5f; // alpha is not exposed
    crep::writePng(dir / "rgba.png", image, keep);
    CHECK(readFile(dir / "rgba.png")[25] == 6);
    const crep::test::Png d = decodePng(dir / "rgba.png");
    REQUIRE(d.channels == 4);
    CHECK(d.at(0, 0, 0) == crep::encodeSrgb8(0.25f));
    CHECK(d.at(0, 0, 3) == 128); // floor(0.5 * 255 + 0.5)
    CHECK(d.at(1, 1, 3) == 51);  // 0.2 * 255 = 51, Image row 0 is PNG row 1
  }
}

TEST_CASE("PNG: invalid arguments and write failures") {
  crep::test::TempDir dir;
  crep::ToneMap bad;
  bad.exposure = -1.0f;
  try {
    crep::writePng(dir / "bad.png", Image(2, 2, 3), bad);
    FAIL_CHECK("no exception");
  } catch (const crep::InvalidArgument& e) {
    CHECK(e.parameter() == "ToneMap.exposure");
  }
  bad.exposure = kNan;
  CHECK_THROWS_AS(crep::writePng(dir / "bad.png", Image(2, 2, 3), bad), crep::InvalidArgument);
  CHECK_THROWS_AS(crep::writePng(dir / "bad.png", Image()), crep::InvalidArgument);
  const fs::path missing = dir / "missing" / "out.png";
  try {
    crep::writePng(missing, Image(2, 2, 3));
    FAIL_CHECK("no exception");
  } catch (const crep::IoError& e) {
    CHECK(std::string(e.what()).find(missing.string()) != std::string::npos);
  }
  CHECK_FALSE(fs::exists(missing));
}
