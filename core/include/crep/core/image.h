// CPU images: interleaved float32 channels, rows stored bottom-to-top as OpenGL reads them
// (row 0 is the bottom row; EXR/PNG writers flip to their top-first order).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace crep {

class Image {
public:
  /// Largest accepted width or height and pixel count (also the cap applied before reading files).
  static constexpr int kMaxDimension = 32768;
  static constexpr long long kMaxPixels = 1LL << 28;

  Image() = default;
  /// Throws InvalidArgument for width/height <= 0 or > kMaxDimension, pixels > kMaxPixels, or
  /// channels outside 1..4. Pixels start at `fill`.
  Image(int width, int height, int channels, float fill = 0.0f);

  int width() const noexcept { return width_; }
  int height() const noexcept { return height_; }
  int channels() const noexcept { return channels_; }
  bool empty() const noexcept { return data_.empty(); }
  std::size_t pixelCount() const noexcept {
    return static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  }
  /// Number of floats: pixelCount() * channels().
  std::size_t sampleCount() const noexcept { return data_.size(); }
  /// Size of the pixel data in bytes: sampleCount() * sizeof(float).
  std::size_t byteSize() const noexcept { return data_.size() * sizeof(float); }
  /// Same width, height and channel count.
  bool sameShape(const Image& other) const noexcept {
    return width_ == other.width_ && height_ == other.height_ && channels_ == other.channels_;
  }

  float& at(int x, int y, int c = 0) noexcept { return data_[index(x, y, c)]; }
  float at(int x, int y, int c = 0) const noexcept { return data_[index(x, y, c)]; }

  std::span<float> data() noexcept { return data_; }
  std::span<const float> data() const noexcept { return data_; }

private:
  std::size_t index(int x, int y, int c) const noexcept {
    return (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) *
               static_cast<std::size_t>(channels_) +
           static_cast<std::size_t>(c);
  }
  int width_ = 0, height_ = 0, channels_ = 0;
  std::vector<float> data_;
};

} // namespace crep
