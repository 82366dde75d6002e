// OpenEXR reading and writing of crep::Image (OpenEXR 3; the OpenEXR headers stay private).
//
// Orientation: an Image stores its rows bottom-to-top (row 0 = bottom, as glReadPixels returns
// them) while EXR stores the top row first. Writers and the reader flip, so Image::at(x, y) is the
// same pixel before writing and after reading, and the file shows the image upright in any viewer.
//
// Channel names written (per layer, see writeExrLayers):
//   1 channel  -> "Y"                (luminance, shown as grey by viewers; also used for depth)
//   2 channels -> "R", "G"           (like a GL RG texture)
//   3 channels -> "R", "G", "B"
//   4 channels -> "R", "G", "B", "A"
//
// Channel selection when reading (among the channels of the selected layer, see ExrReadOptions):
//   1. "R", "G" and "B" present        -> 3 channels R, G, B; 4 channels R, G, B, A if "A" exists.
//   2. otherwise "R" and "G" present   -> 2 channels R, G.
//   3. otherwise the first present of "Y", "Z", "depth", "R" -> 1 channel (other channels, e.g.
//      "A", "RY", "BY", are ignored).
//   4. otherwise, if the layer has exactly one channel, whatever its name -> 1 channel.
//   5. otherwise FormatError listing the channels found.
// Pixel types HALF, FLOAT and UINT are all converted to float (UINT values above 2^24 lose
// precision). Subsampled channels are rejected.
#pragma once

#include <crep/core/image.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace crep {

/// Storage type of the channels written. Half is lossless for values k * 2^-10 with |k| <= 2048
/// and otherwise rounds to nearest even (relative error <= 2^-11 in the normal range);
/// |values| >= 65520 become +-Inf, NaN stays NaN. Float is bit exact.
enum class ExrPixelType { Half, Float };

/// Lossless compression of the written file.
enum class ExrCompression { None, Zip, Piz };

struct ExrWriteOptions {
  // Implicit on purpose: writeExr(path, image, ExrPixelType::Half) reads naturally. Default Float: depth
  // buffers and scattering images are data, and half's 11 bits lose them (a depth of 0.9995 is 1 in half).
  ExrWriteOptions(ExrPixelType type = ExrPixelType::Float, ExrCompression comp = ExrCompression::Zip)
      : pixelType(type), compression(comp) {}
  ExrPixelType pixelType;
  ExrCompression compression;
};

/// One layer of a multi-layer file: channels are named "<name>.R", "<name>.G", ... (mapping as
/// above, e.g. "depth.Y"). An empty name writes unprefixed channels ("R", "G", ...).
struct ExrLayer {
  std::string name;
  const Image* image = nullptr;
};

struct ExrReadOptions {
  /// Largest accepted width * height, checked on the header before any pixel memory is allocated
  /// (in addition to Image::kMaxDimension per side and Image::kMaxPixels).
  long long maxPixels = Image::kMaxPixels;
  /// Layer to read: "" selects the channels whose name has no '.', "name" selects "name.X"
  /// channels where X has no further '.'.
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

/// Writes a single-layer scanline file by the output rule of crep/support/output_file.h (a temporary renamed
/// over the target, symbolic links followed, anything but a regular file refused). Throws InvalidArgument
/// for an empty image, IoError if the file cannot be written (the message names the path; no partial file
/// is left behind).
void writeExr(const std::filesystem::path& path, const Image& image, const ExrWriteOptions& options = {});

/// Writes several layers into one single-part file. Throws InvalidArgument for an empty span, a
/// null or empty image, layers of different sizes or duplicate names; IoError on write failure (the
/// output rule of writeExr).
void writeExrLayers(const std::filesystem::path& path, std::span<const ExrLayer> layers,
                    const ExrWriteOptions& options = {});

/// Reads one layer of a scanline or tiled (level 0 of mip/rip maps) part into a float image.
/// The image is the data window (the display window is ignored); data window row maxY (the bottom
/// row in EXR's y-down convention) becomes row 0.
/// Before any pixel memory is allocated, the whole file structure is validated: header attribute
/// sizes and channel lists, every part's data window (<= kMaxDimension per side and kMaxPixels; the
/// selected part also <= options.maxPixels), the offset tables, and for every chunk of every part
/// its position, the line or tile its header names, and its data size, which must end inside the
/// file (so truncated pixel data is always detected) and fit its compression and pixel count:
/// uncompressed chunks exactly the size of their lines or tile (sum over channels of sampled pixels
/// times 2 or 4 bytes), compressed ones from 1 byte up to that size (never more: OpenEXR stores a
/// chunk uncompressed when compression does not make it smaller). The image size must be plausible
/// for the file size (at most 4096 bytes of float output per byte of file, plus 16 MiB; not applied
/// to DWAA/DWAB, whose ratio on constant images is unbounded in practice), and the RLE, ZIPS and ZIP
/// chunks of the part read must decode to exactly their uncompressed size. Every sample of the image
/// is checked to have been written by the decoder (see detail::kExrUnwrittenSampleBits).
/// Throws IoError if the file is missing or unreadable; FormatError naming the file if it is not an
/// EXR file, is corrupt or truncated (the message names the chunk: its index, line or tile, size
/// found and expected), is deep, has no matching channels or subsampled ones, is too large, or its
/// pixel data is incomplete. InvalidArgument for options.maxPixels <= 0 or options.part < 0.
Image readExr(const std::filesystem::path& path, const ExrReadOptions& options = {});

/// Describes part `part` from its header, after the same structural validation as readExr (a
/// truncated file is rejected even though no pixel is decoded). Same exceptions as readExr.
ExrFileInfo readExrInfo(const std::filesystem::path& path, int part = 0);

namespace detail {
/// readExr fills the image with this float bit pattern (a signalling NaN that no HALF or UINT sample
/// converts to) before decoding, and with kExrUnwrittenSampleRetryBits for a second decode where a
/// FLOAT channel holds the pattern itself: an image readExr returns never holds a sample the
/// decoder did not write (it throws FormatError "incomplete pixel data" instead). Public for tests.
inline constexpr std::uint32_t kExrUnwrittenSampleBits = 0x7F800DEAu;
inline constexpr std::uint32_t kExrUnwrittenSampleRetryBits = 0x7F800BADu;
} // namespace detail

} // namespace crep
