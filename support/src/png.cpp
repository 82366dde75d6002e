#include <crep/support/png.h>

#include <crep/support/output_file.h>

#include <crep/core/error.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

// stb_image_write, compiled into this translation unit only, with internal linkage.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wold-style-cast"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wshadow"
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#include <stb_image_write.h>
#pragma GCC diagnostic pop

namespace crep {

namespace {

double clamp01(double v) {
  return std::min(1.0, std::max(0.0, v));
}

double oetf(double x) {
  return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055;
}

std::uint8_t quantize(double s) {
  return static_cast<std::uint8_t>(std::floor(clamp01(s) * 255.0 + 0.5));
}

std::uint8_t encodeColour(float v, double exposure) {
  if (!std::isfinite(v)) return 0;
  return quantize(oetf(clamp01(static_cast<double>(v) * exposure)));
}

std::uint8_t encodeAlpha(float a) {
  if (!std::isfinite(a)) return 0;
  return quantize(static_cast<double>(a));
}

struct WriteContext {
  std::ofstream* out;
};

void writeCallback(void* context, void* data, int size) {
  auto* ctx = static_cast<WriteContext*>(context);
  if (size > 0) ctx->out->write(static_cast<const char*>(data), size);
}

} // namespace

float linearToSrgb(float linear) {
  if (!std::isfinite(linear)) return 0.0f;
  return static_cast<float>(oetf(clamp01(static_cast<double>(linear))));
}

std::uint8_t encodeSrgb8(float linear) {
  return encodeColour(linear, 1.0);
}

float srgbToLinear(float encoded) {
  if (std::isnan(encoded)) return 0.0f;
  const double v = clamp01(static_cast<double>(encoded));
  return static_cast<float>(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}

void writePng(const std::filesystem::path& path, const Image& image, const ToneMap& toneMap) {
  if (image.empty()) throw InvalidArgument("image", "empty image", "writePng needs a non-empty image");
  requireNonNegative("ToneMap.exposure", static_cast<double>(toneMap.exposure));
  const double exposure = static_cast<double>(toneMap.exposure);

  const int width = image.width(), height = image.height(), channels = image.channels();
  const int outChannels = channels == 1 ? 1 : (channels == 4 && toneMap.keepAlpha ? 4 : 3);
  std::vector<std::uint8_t> pixels(image.pixelCount() * static_cast<std::size_t>(outChannels));
  std::size_t o = 0;
  for (int row = 0; row < height; ++row) {
    const int y = height - 1 - row; // PNG is top first
    for (int x = 0; x < width; ++x) {
      if (channels == 1) {
        pixels[o++] = encodeColour(image.at(x, y, 0), exposure);
        continue;
      }
      for (int c = 0; c < 3; ++c)
        pixels[o++] = c < channels ? encodeColour(image.at(x, y, c), exposure) : 0;
      if (outChannels == 4) pixels[o++] = encodeAlpha(image.at(x, y, 3));
    }
  }

  // The output rule (crep/support/output_file.h): a temporary in the target's directory renamed over it,
  // symbolic links followed, anything but a regular file refused; a failure leaves no file behind.
  writeOutputFile(path, [&](const std::filesystem::path& temporary) {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError("crep: cannot write PNG file '" + path.string() + "': cannot open for writing");
    WriteContext context{&out};
    const int ok = stbi_write_png_to_func(&writeCallback, &context, width, height, outChannels, pixels.data(),
                                          width * outChannels);
    out.close();
    if (ok == 0 || !out) throw IoError("crep: cannot write PNG file '" + path.string() + "': write failed");
  });
}

} // namespace crep
