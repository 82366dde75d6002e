#include <crep/core/image.h>

#include <crep/core/error.h>

#include <string>

namespace crep {

namespace {

void requireInRange(const char* parameter, int value, int lo, int hi) {
  if (value < lo || value > hi)
    throw InvalidArgument(parameter, detail::formatValue(value),
                          "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

} // namespace

Image::Image(int width, int height, int channels, float fill) {
  requireInRange("Image.width", width, 1, kMaxDimension);
  requireInRange("Image.height", height, 1, kMaxDimension);
  requireInRange("Image.channels", channels, 1, 4);
  const long long pixels = static_cast<long long>(width) * static_cast<long long>(height);
  if (pixels > kMaxPixels)
    throw InvalidArgument("Image.width*height", detail::formatValue(pixels),
                          "must be <= Image::kMaxPixels = " + std::to_string(kMaxPixels));
  data_.assign(static_cast<std::size_t>(pixels) * static_cast<std::size_t>(channels), fill);
  width_ = width;
  height_ = height;
  channels_ = channels;
}

} // namespace crep
