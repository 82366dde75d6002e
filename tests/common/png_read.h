// Reading PNGs back in tests (stb_image): 8-bit samples, rows top to bottom as in the file.
#pragma once

#include <cstddef>
#include <filesystem>
#include <vector>

namespace crep::test {

/// A decoded PNG; width = height = 0 when the file does not decode.
struct Png {
  int width = 0, height = 0, channels = 0;
  std::vector<unsigned char> pixels; ///< row-major from the top row, `channels` per pixel
  int at(int x, int row, int c) const {
    return pixels[(static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
                   static_cast<std::size_t>(x)) *
                      static_cast<std::size_t>(channels) +
                  static_cast<std::size_t>(c)];
  }
};

/// The PNG at `path` with `channels` samples per pixel (stb_image converts), or 0 for the file's own.
Png readPng(const std::filesystem::path& path, int channels = 3);

} // namespace crep::test
