// 8-bit standard RGB PNG output of linear float images (previews, difference images, documentation).
// Encoding of a sample, channels, alpha, row order: support/README.md, "crep/support/png.h".
#pragma once

#include <crep/core/image.h>

#include <cstdint>
#include <filesystem>

namespace crep {

struct ToneMap {
  float exposure = 1.0f;  ///< multiplies linear RGB before encoding; must be finite and >= 0
  bool keepAlpha = false; ///< 4-channel images: write RGBA instead of RGB
};

/// Writes `image` as an 8-bit PNG by the output rule (output_file.h). Throws InvalidArgument (empty image,
/// bad exposure), IoError naming the path (no partial file is left behind).
void writePng(const std::filesystem::path& path, const Image& image, const ToneMap& toneMap = {});

/// The standard RGB OETF of a linear value clamped to [0, 1] (NaN -> 0), in [0, 1].
float linearToSrgb(float linear);
/// The 8-bit code written for a linear sample (exposure 1).
std::uint8_t encodeSrgb8(float linear);
/// Inverse: the standard RGB EOTF of an encoded value in [0, 1] (clamped; NaN -> 0).
float srgbToLinear(float encoded);

} // namespace crep
