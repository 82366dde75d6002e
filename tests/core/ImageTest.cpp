#include <crep/core/error.h>
#include <crep/core/image.h>

#include <doctest/doctest.h>

#include <string>

using crep::Image;
using crep::InvalidArgument;

namespace {

// Expects InvalidArgument whose parameter() is `parameter` and whose message names it and the value.
void expectInvalid(int width, int height, int channels, const std::string& parameter,
                   const std::string& value) {
  CAPTURE(width);
  CAPTURE(height);
  CAPTURE(channels);
  try {
    Image image(width, height, channels);
    FAIL("no exception for " << width << "x" << height << "x" << channels);
  } catch (const InvalidArgument& e) {
    const std::string what = e.what();
    CHECK(e.parameter() == parameter);
    CHECK_MESSAGE(what.find(parameter) != std::string::npos, what);
    CHECK_MESSAGE(what.find(value) != std::string::npos, what);
  }
}

} // namespace

TEST_CASE("Image: a default image is empty") {
  const Image image;
  CHECK(image.empty());
  CHECK(image.width() == 0);
  CHECK(image.height() == 0);
  CHECK(image.channels() == 0);
  CHECK(image.pixelCount() == 0);
  CHECK(image.sampleCount() == 0);
  CHECK(image.byteSize() == 0);
  CHECK(image.data().empty());
}

TEST_CASE("Image: constructor rejects bad sizes and channel counts, naming the parameter and value") {
  expectInvalid(0, 10, 3, "Image.width", "0");
  expectInvalid(-5, 10, 3, "Image.width", "-5");
  expectInvalid(Image::kMaxDimension + 1, 1, 1, "Image.width", std::to_string(Image::kMaxDimension + 1));
  expectInvalid(10, 0, 3, "Image.height", "0");
  expectInvalid(10, -1, 3, "Image.height", "-1");
  expectInvalid(1, Image::kMaxDimension + 1, 1, "Image.height", std::to_string(Image::kMaxDimension + 1));
  expectInvalid(10, 10, 0, "Image.channels", "0");
  expectInvalid(10, 10, 5, "Image.channels", "5");
  expectInvalid(10, 10, -1, "Image.channels", "-1");
  // Both sides within kMaxDimension but too many pixels (checked before allocating).
  static_assert(static_cast<long long>(Image::kMaxDimension) * Image::kMaxDimension > Image::kMaxPixels);
  expectInvalid(Image::kMaxDimension, Image::kMaxDimension, 1, "Image.width*height",
                std::to_string(static_cast<long long>(Image::kMaxDimension) * Image::kMaxDimension));
}

TEST_CASE("Image: limits are inclusive") {
  const Image wide(Image::kMaxDimension, 1, 1);
  CHECK(wide.width() == Image::kMaxDimension);
  const Image tall(1, Image::kMaxDimension, 4);
  CHECK(tall.height() == Image::kMaxDimension);
  for (int channels = 1; channels <= 4; ++channels)
    CHECK(Image(2, 3, channels).channels() == channels);
}

TEST_CASE("Image: sizes and fill value") {
  const Image image(7, 5, 3, 0.25f);
  CHECK(image.width() == 7);
  CHECK(image.height() == 5);
  CHECK(image.channels() == 3);
  CHECK(image.pixelCount() == 35);
  CHECK(image.sampleCount() == 105);
  CHECK(image.byteSize() == 105 * sizeof(float));
  CHECK(image.data().size() == 105);
  for (float v : image.data())
    CHECK(v == 0.25f);
  CHECK(Image(2, 2, 1).data()[3] == 0.0f);
}

TEST_CASE(
    "Image: interleaved layout, rows bottom to top: at(x, y, c) = data[(y * width + x) * channels + c]") {
  Image image(4, 3, 2);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 2; ++c)
        image.at(x, y, c) = static_cast<float>(100 * y + 10 * x + c);
  const auto data = image.data();
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 2; ++c)
        CHECK(data[static_cast<std::size_t>((y * 4 + x) * 2 + c)] ==
              static_cast<float>(100 * y + 10 * x + c));
  CHECK(data[0] == 0.0f);       // (0, 0) bottom-left, channel 0
  CHECK(data[1] == 1.0f);       // (0, 0) channel 1
  CHECK(data[2] == 10.0f);      // (1, 0)
  CHECK(data[8] == 100.0f);     // (0, 1): second row from the bottom
  CHECK(data.back() == 231.0f); // (3, 2, 1): top-right, last channel
  const Image& constImage = image;
  CHECK(constImage.at(3, 2, 1) == 231.0f);
  CHECK(constImage.at(2, 1) == 120.0f); // channel defaults to 0
}

TEST_CASE("Image: sameShape compares width, height and channels") {
  CHECK(Image(3, 2, 1).sameShape(Image(3, 2, 1)));
  CHECK_FALSE(Image(3, 2, 1).sameShape(Image(2, 3, 1)));
  CHECK_FALSE(Image(3, 2, 1).sameShape(Image(3, 2, 3)));
  CHECK(Image().sameShape(Image()));
}
