// 8-bit sRGB PNG output of linear float images (previews, difference images, documentation).
//
// Encoding of one colour sample v (linear):
//   1. non-finite input (NaN, +-Inf) -> 0 (black), so a broken pixel never looks plausible
//      (image comparison counts non-finite samples separately);
//   2. x = clamp(v * exposure, 0, 1), computed in double;
//   3. sRGB OETF (IEC 61966-2-1): s = 12.92 x for x <= 0.0031308, else 1.055 x^(1/2.4) - 0.055;
//   4. 8-bit code = floor(s * 255 + 0.5).
// Channels: 1 -> grey (one PNG channel, encoded as above); 2 -> RGB (R, G, 0); 3 -> RGB;
// 4 -> RGB with alpha dropped, or RGBA if ToneMap.keepAlpha. Alpha is not exposed or
// sRGB-encoded: code = floor(clamp(a, 0, 1) * 255 + 0.5), non-finite -> 0.
// Rows are written top first (Image row height-1 is the first PNG row).
#pragma once

#include <crep/core/image.h>

#include <cstdint>
#include <filesystem>

namespace crep {

struct ToneMap {
  float exposure = 1.0f;  ///< multiplies linear RGB before encoding; must be finite and >= 0
  bool keepAlpha = false; ///< 4-channel images: write RGBA instead of RGB
};

/// Writes `image` as an 8-bit PNG by the output rule of crep/support/output_file.h (a temporary renamed
/// over the target, symbolic links followed, anything but a regular file refused). Throws InvalidArgument
/// for an empty image or a bad exposure, IoError naming the path if the file cannot be written (no partial
/// file is left behind).
void writePng(const std::filesystem::path& path, const Image& image, const ToneMap& toneMap = {});

/// sRGB OETF of a linear value clamped to [0, 1] (steps 1, 3 above without exposure), in [0, 1].
float linearToSrgb(float linear);
/// Steps 1-4 above with exposure 1: the 8-bit code written for a linear sample.
std::uint8_t encodeSrgb8(float linear);
/// Inverse: sRGB EOTF of an encoded value in [0, 1] (clamped; NaN -> 0):
/// v / 12.92 for v <= 0.04045, else ((v + 0.055) / 1.055)^2.4.
float srgbToLinear(float encoded);

} // namespace crep
