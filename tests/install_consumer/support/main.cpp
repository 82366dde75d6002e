// A tool-side consumer of the installed support library: writes a small EXR into the folder given as
// its argument and reads it back.
#include <crep/core/image.h>
#include <crep/support/exr.h>

#include <cstdio>
#include <exception>
#include <filesystem>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer <output folder>\n");
    return 2;
  }
  try {
    crep::Image image(5, 3, 4);
    for (int y = 0; y < image.height(); ++y)
      for (int x = 0; x < image.width(); ++x)
        for (int c = 0; c < image.channels(); ++c)
          image.at(x, y, c) = 0.25f * float(x) + 0.5f * float(y) + float(c);
    const std::filesystem::path path = std::filesystem::path(argv[1]) / "support-consumer.exr";
    crep::writeExr(path, image, crep::ExrPixelType::Float);
    const crep::Image back = crep::readExr(path);
    if (back.width() != image.width() || back.height() != image.height() ||
        back.channels() != image.channels()) {
      std::fprintf(stderr, "support consumer: read back %dx%dx%d\n", back.width(), back.height(),
                   back.channels());
      return 1;
    }
    for (int y = 0; y < image.height(); ++y)
      for (int x = 0; x < image.width(); ++x)
        for (int c = 0; c < image.channels(); ++c)
          if (back.at(x, y, c) != image.at(x, y, c)) {
            std::fprintf(stderr, "support consumer: pixel (%d, %d) channel %d differs\n", x, y, c);
            return 1;
          }
    std::printf("support consumer ok: %dx%d RGBA EXR written and read back exactly\n", image.width(),
                image.height());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "support consumer: %s\n", e.what());
    return 1;
  }
  return 0;
}
