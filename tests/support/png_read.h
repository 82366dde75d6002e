// Reading the tool's PNG outputs back in tests (stb_image): 8-bit RGB, row 0 at the top as in the file.
#pragma once

#include <filesystem>
#include <vector>

namespace crep::test {

/// A decoded PNG as 8-bit RGB, rows top to bottom; width = height = 0 when the file does not decode.
struct Png {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
  const unsigned char* at(int x, int y) const {
    return rgb.data() + (static_cast<std::size_t>(y) * width + x) * 3;
  }
};

Png readPng(const std::filesystem::path& path);

} // namespace crep::test
