// OpenEXR reading and writing of crep::Image (OpenEXR 3, private). Orientation, channel names written and
// selected when reading, validation: support/README.md, "crep/support/exr.h".
#pragma once

#include <crep/core/image.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace crep {

/// Storage type of the channels written: Half rounds (README), Float is bit exact.
enum class ExrPixelType { Half, Float };

/// Lossless compression of the written file.
enum class ExrCompression { None, Zip, Piz };

struct ExrWriteOptions {
  // Implicit on purpose (README); default Float: half's 11 bits lose depth and scattering data.
  ExrWriteOptions(ExrPixelType type = ExrPixelType::Float, ExrCompression comp = ExrCompression::Zip)
      : pixelType(type), compression(comp) {}
  ExrPixelType pixelType;
  ExrCompression compression;
};

/// One layer of a multi-layer file: channels "<name>.R", ...; an empty name writes unprefixed channels.
struct ExrLayer {
  std::string name;
  const Image* image = nullptr;
};

struct ExrReadOptions {
  /// Largest accepted width * height, checked on the header before any pixel memory is allocated.
  long long maxPixels = Image::kMaxPixels;
  /// Layer to read: "" = the channels without '.', "name" = "name.X" channels (README).
  std::string layer;
  /// Part of a multi-part file (0 for single-part files).
  int part = 0;
};

/// Description of a file's selected part, from its header only.
struct ExrChannelInfo {
  std::string name;
  ExrPixelType pixelType = ExrPixelType::Half;
  bool isUint = false; ///< UINT channel (pixelType is then meaningless)
};
struct ExrFileInfo {
  int width = 0, height = 0; ///< data window size
  int dataWindowMinX = 0, dataWindowMinY = 0;
  int partCount = 1;
  bool tiled = false;
  std::vector<ExrChannelInfo> channels; ///< every channel of the part, sorted by name
};

/// Writes a single-layer scanline file by the output rule (output_file.h). Throws InvalidArgument for an
/// empty image, IoError naming the path if it cannot be written (no partial file is left behind).
void writeExr(const std::filesystem::path& path, const Image& image, const ExrWriteOptions& options = {});

/// Writes several layers into one single-part file. Throws InvalidArgument (empty span, null or empty
/// image, different sizes, duplicate names); IoError as writeExr.
void writeExrLayers(const std::filesystem::path& path, std::span<const ExrLayer> layers,
                    const ExrWriteOptions& options = {});

/// Reads one layer of a scanline or tiled part (its data window) into a float image, the whole file
/// structure validated before any pixel memory is allocated (README). Throws IoError (missing,
/// unreadable), FormatError naming the file (not EXR, corrupt, truncated, deep, no matching channels, too
/// large, incomplete), InvalidArgument (options.maxPixels <= 0, options.part < 0). O(pixels).
Image readExr(const std::filesystem::path& path, const ExrReadOptions& options = {});

/// Describes part `part` from its header, after readExr's structural validation; same exceptions.
ExrFileInfo readExrInfo(const std::filesystem::path& path, int part = 0);

namespace detail {
/// The fill patterns readExr uses to detect samples the decoder did not write (README). Public for tests.
inline constexpr std::uint32_t kExrUnwrittenSampleBits = 0x7F800DEAu;
inline constexpr std::uint32_t kExrUnwrittenSampleRetryBits = 0x7F800BADu;
} // namespace detail

} // namespace crep
