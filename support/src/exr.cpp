// EXR I/O. Writing uses the OpenEXR C++ API. Reading first validates the file structure with a
// small bounded parser of our own (magic, version flags, every header attribute size, the data
// window against the size limits, the chunk offset table and every chunk header of the part that is
// read), so that OpenEXR never sees a header that would make it allocate according to an absurd
// size and truncated pixel data is detected independently of OpenEXR's behaviour. Pixels are then
// decoded by OpenEXR (Imf::MultiPartInputFile / Imf::InputPart) without chunk table
// reconstruction; every OpenEXR exception becomes a crep::FormatError naming the file.
#include <crep/support/exr.h>
#include <crep/support/output_file.h>

#include <crep/core/error.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <ImfOutputFile.h>
#include <ImfPartType.h>
#include <half.h>

#define ZLIB_CONST
#include <zlib.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <exception>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <new>
#include <numeric>
#include <set>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

namespace crep {

namespace {

namespace fs = std::filesystem;

// ------------------------------------------------------------------------------------------------
// Errors

std::string quoted(const fs::path& path) {
  return "'" + path.string() + "'";
}

[[noreturn]] void throwFormat(const fs::path& path, const std::string& what) {
  throw FormatError("crep: cannot read EXR file " + quoted(path) + ": " + what);
}

[[noreturn]] void throwRead(const fs::path& path, const std::string& what) {
  throw IoError("crep: cannot read EXR file " + quoted(path) + ": " + what);
}

// ------------------------------------------------------------------------------------------------
// Writing

const char* const kChannelSuffixes[4][4] = {
    {"Y", nullptr, nullptr, nullptr},
    {"R", "G", nullptr, nullptr},
    {"R", "G", "B", nullptr},
    {"R", "G", "B", "A"},
};

Imf::Compression toImf(ExrCompression compression) {
  switch (compression) {
  case ExrCompression::None:
    return Imf::NO_COMPRESSION;
  case ExrCompression::Zip:
    return Imf::ZIP_COMPRESSION;
  case ExrCompression::Piz:
    return Imf::PIZ_COMPRESSION;
  }
  throw InvalidArgument("ExrWriteOptions.compression",
                        detail::formatValue(static_cast<long long>(compression)), "unknown compression");
}

Imf::PixelType toImf(ExrPixelType type) {
  switch (type) {
  case ExrPixelType::Half:
    return Imf::HALF;
  case ExrPixelType::Float:
    return Imf::FLOAT;
  }
  throw InvalidArgument("ExrWriteOptions.pixelType", detail::formatValue(static_cast<long long>(type)),
                        "unknown pixel type");
}

std::string channelName(const std::string& layer, const char* suffix) {
  return layer.empty() ? std::string(suffix) : layer + "." + suffix;
}

void writeValidated(const fs::path& path, std::span<const ExrLayer> layers, Imf::Compression compression,
                    Imf::PixelType pixelType);

void writeLayers(const fs::path& path, std::span<const ExrLayer> layers, const ExrWriteOptions& options) {
  if (layers.empty()) throw InvalidArgument("layers", "0 layers", "at least one layer is required");
  const Imf::Compression compression = toImf(options.compression);
  const Imf::PixelType pixelType = toImf(options.pixelType);

  std::set<std::string> names;
  for (const ExrLayer& layer : layers) {
    if (layer.image == nullptr) throw InvalidArgument("ExrLayer.image", "null", "layer '" + layer.name + "'");
    if (layer.image->empty())
      throw InvalidArgument("ExrLayer.image", "empty image", "layer '" + layer.name + "' must not be empty");
    if (layer.name.size() > 200)
      throw InvalidArgument("ExrLayer.name", "'" + layer.name + "'", "must be at most 200 characters");
    if (!names.insert(layer.name).second)
      throw InvalidArgument("ExrLayer.name", "'" + layer.name + "'", "layer names must be unique");
    const Image& first = *layers.front().image;
    if (layer.image->width() != first.width() || layer.image->height() != first.height())
      throw InvalidArgument("ExrLayer.image",
                            std::to_string(layer.image->width()) + "x" +
                                std::to_string(layer.image->height()),
                            "layer '" + layer.name + "' must have the size of the first layer (" +
                                std::to_string(first.width()) + "x" + std::to_string(first.height()) + ")");
  }

  try {
    writeValidated(path, layers, compression, pixelType);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw IoError("crep: cannot write EXR file " + quoted(path) + ": " + e.what());
  }
}

void writeValidated(const fs::path& path, std::span<const ExrLayer> layers, Imf::Compression compression,
                    Imf::PixelType pixelType) {
  const int width = layers.front().image->width();
  const int height = layers.front().image->height();

  // EXR wants the top row first: flipped copies, interleaved as in the Image, in the file's type
  // (OpenEXR does not convert float frame buffers to half file channels).
  const std::size_t sampleBytes = pixelType == Imf::HALF ? sizeof(Imath::half) : sizeof(float);
  std::vector<std::vector<float>> floats(layers.size());
  std::vector<std::vector<Imath::half>> halves(layers.size());
  Imf::Header header(width, height);
  header.compression() = compression;
  Imf::FrameBuffer frameBuffer;
  for (std::size_t i = 0; i < layers.size(); ++i) {
    const Image& image = *layers[i].image;
    const std::size_t channels = static_cast<std::size_t>(image.channels());
    const std::size_t rowSamples = static_cast<std::size_t>(width) * channels;
    const std::span<const float> src = image.data();
    char* base = nullptr;
    if (pixelType == Imf::HALF) {
      std::vector<Imath::half>& rows = halves[i];
      rows.reserve(image.sampleCount());
      for (int y = height - 1; y >= 0; --y)
        for (std::size_t k = 0; k < rowSamples; ++k)
          rows.emplace_back(src[static_cast<std::size_t>(y) * rowSamples + k]);
      base = reinterpret_cast<char*>(rows.data());
    } else {
      std::vector<float>& rows = floats[i];
      rows.reserve(image.sampleCount());
      for (int y = height - 1; y >= 0; --y) {
        const auto row = src.subspan(static_cast<std::size_t>(y) * rowSamples, rowSamples);
        rows.insert(rows.end(), row.begin(), row.end());
      }
      base = reinterpret_cast<char*>(rows.data());
    }
    for (std::size_t c = 0; c < channels; ++c) {
      const std::string name = channelName(layers[i].name, kChannelSuffixes[channels - 1][c]);
      if (header.channels().findChannel(name) != nullptr)
        throw InvalidArgument("ExrLayer.name", "'" + layers[i].name + "'",
                              "channel '" + name + "' would be written twice");
      header.channels().insert(name, Imf::Channel(pixelType));
      frameBuffer.insert(name, Imf::Slice(pixelType, base + c * sampleBytes, channels * sampleBytes,
                                          rowSamples * sampleBytes));
    }
  }

  // The output rule (crep/support/output_file.h): a temporary in the target's directory renamed over it,
  // symbolic links followed, anything but a regular file refused; a failure leaves no file behind.
  try {
    writeOutputFile(path, [&](const fs::path& temporary) {
      Imf::OutputFile file(temporary.c_str(), header, 0);
      file.setFrameBuffer(frameBuffer);
      file.writePixels(height);
    });
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw IoError("crep: cannot write EXR file " + quoted(path) + ": " + e.what());
  }
}

// ------------------------------------------------------------------------------------------------
// Structural validation (bounded work and memory, no OpenEXR involved)

constexpr std::uint32_t kMagic = 20000630;
constexpr std::uint32_t kFlagTiled = 0x200;
constexpr std::uint32_t kFlagLongNames = 0x400;
constexpr std::uint32_t kFlagNonImage = 0x800;
constexpr std::uint32_t kFlagMultiPart = 0x1000;
constexpr std::uint32_t kKnownFlags = kFlagTiled | kFlagLongNames | kFlagNonImage | kFlagMultiPart;

// Sequential and random access reads on the file with the size known up front.
class FileReader {
public:
  FileReader(const fs::path& path) : path_(path) {
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (ec || !fs::exists(status)) throwRead(path, "file does not exist");
    if (fs::is_directory(status)) throwRead(path, "is a directory");
    in_.open(path, std::ios::binary);
    if (!in_) throwRead(path, "cannot open file for reading");
    in_.seekg(0, std::ios::end);
    const std::streamoff end = in_.tellg();
    if (end < 0) throwRead(path, "cannot determine the file size");
    size_ = static_cast<std::uint64_t>(end);
    in_.seekg(0);
  }

  std::uint64_t size() const { return size_; }
  std::uint64_t position() const { return position_; }
  std::uint64_t remaining() const { return size_ - position_; }

  // Reads n bytes at `offset`; false if the file is shorter.
  bool readAt(std::uint64_t offset, void* dst, std::size_t n) {
    if (offset > size_ || n > size_ - offset) return false;
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(offset));
    in_.read(static_cast<char*>(dst), static_cast<std::streamsize>(n));
    if (static_cast<std::size_t>(in_.gcount()) != n) throwRead(path_, "read error");
    return true;
  }

  void read(void* dst, std::size_t n, const char* what) {
    if (!readAt(position_, dst, n)) throwFormat(path_, std::string("truncated file (") + what + ")");
    position_ += n;
  }
  void skip(std::uint64_t n, const char* what) {
    if (n > remaining()) throwFormat(path_, std::string("truncated file (") + what + ")");
    position_ += n;
  }
  std::uint8_t u8(const char* what) {
    std::uint8_t v = 0;
    read(&v, 1, what);
    return v;
  }
  std::uint32_t u32(const char* what) {
    std::array<std::uint8_t, 4> b{};
    read(b.data(), 4, what);
    return decode32(b.data());
  }
  std::uint64_t u64(const char* what) {
    std::array<std::uint8_t, 8> b{};
    read(b.data(), 8, what);
    return decode64(b.data());
  }
  // Null-terminated string of at most maxLength characters.
  std::string cstring(std::size_t maxLength, const char* what) {
    std::string s;
    for (;;) {
      const std::uint8_t c = u8(what);
      if (c == 0) return s;
      if (s.size() == maxLength) throwFormat(path_, std::string(what) + " is too long or not terminated");
      s.push_back(static_cast<char>(c));
    }
  }

  static std::uint32_t decode32(const std::uint8_t* b) {
    return static_cast<std::uint32_t>(b[0]) | (static_cast<std::uint32_t>(b[1]) << 8) |
           (static_cast<std::uint32_t>(b[2]) << 16) | (static_cast<std::uint32_t>(b[3]) << 24);
  }
  static std::uint64_t decode64(const std::uint8_t* b) {
    return static_cast<std::uint64_t>(decode32(b)) | (static_cast<std::uint64_t>(decode32(b + 4)) << 32);
  }
  static std::int32_t toSigned(std::uint32_t v) {
    std::int32_t s = 0;
    std::memcpy(&s, &v, sizeof s);
    return s;
  }

private:
  fs::path path_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
  std::uint64_t position_ = 0;
};

// One entry of a part's channel list: pixel type (0 UINT, 1 HALF, 2 FLOAT) and sampling.
struct ChannelLayout {
  std::string name;
  int type = 0;
  std::int32_t xSampling = 1, ySampling = 1;
  int bytes() const { return type == 1 ? 2 : 4; }
};

struct PartLayout {
  bool hasChannels = false;
  std::vector<ChannelLayout> channels;
  bool hasDataWindow = false;
  std::int32_t minX = 0, minY = 0, maxX = -1, maxY = -1;
  int compression = -1;
  bool hasTiles = false;
  std::uint32_t tileWidth = 0, tileHeight = 0;
  int levelMode = 0, roundingMode = 0;
  std::string type;
  bool hasChunkCount = false;
  std::int32_t chunkCount = 0;
  long long width() const { return static_cast<long long>(maxX) - minX + 1; }
  long long height() const { return static_cast<long long>(maxY) - minY + 1; }
  bool tiled(std::uint32_t flags) const {
    return type.empty() ? (flags & kFlagTiled) != 0 : (type == "tiledimage" || type == "deeptile");
  }
  bool deep(std::uint32_t flags) const {
    return type.empty() ? (flags & kFlagNonImage) != 0 : (type == "deepscanline" || type == "deeptile");
  }
};

struct FileLayout {
  std::uint32_t flags = 0;
  std::vector<PartLayout> parts;
  std::uint64_t tablesStart = 0; // first byte after the headers
};

const char* compressionName(int compression) {
  static const char* const kNames[] = {"NONE",  "RLE", "ZIPS", "ZIP",  "PIZ",
                                       "PXR24", "B44", "B44A", "DWAA", "DWAB"};
  return compression >= 0 && compression < 10 ? kNames[compression] : "unknown";
}

// The channel list attribute ("chlist"): entries name\0, int32 pixel type, uint8 pLinear, 3 reserved
// bytes, int32 xSampling, int32 ySampling; terminated by an empty name.
std::vector<ChannelLayout> parseChannelList(const std::vector<std::uint8_t>& value, const fs::path& path) {
  std::vector<ChannelLayout> channels;
  std::size_t at = 0;
  for (;;) {
    if (at >= value.size()) throwFormat(path, "invalid channel list (not terminated)");
    if (value[at] == 0) return channels;
    ChannelLayout channel;
    while (at < value.size() && value[at] != 0)
      channel.name.push_back(static_cast<char>(value[at++]));
    if (channel.name.size() > 255 || value.size() - at < 17)
      throwFormat(path, "invalid channel list (truncated entry)");
    ++at;
    const std::int32_t type = FileReader::toSigned(FileReader::decode32(value.data() + at));
    channel.xSampling = FileReader::toSigned(FileReader::decode32(value.data() + at + 8));
    channel.ySampling = FileReader::toSigned(FileReader::decode32(value.data() + at + 12));
    at += 16;
    if (type < 0 || type > 2)
      throwFormat(path, "channel '" + channel.name + "' has an unknown pixel type " + std::to_string(type));
    if (channel.xSampling < 1 || channel.ySampling < 1)
      throwFormat(path, "channel '" + channel.name + "' has an invalid sampling " +
                            std::to_string(channel.xSampling) + "x" + std::to_string(channel.ySampling));
    channel.type = type;
    channels.push_back(std::move(channel));
  }
}

int linesPerChunk(int compression) {
  switch (compression) {
  case 0: // NONE
  case 1: // RLE
  case 2: // ZIPS
    return 1;
  case 3: // ZIP
  case 5: // PXR24
    return 16;
  case 4: // PIZ
  case 6: // B44
  case 7: // B44A
  case 8: // DWAA
    return 32;
  case 9: // DWAB
    return 256;
  default:
    return 0;
  }
}

FileLayout scanHeaders(FileReader& reader, const fs::path& path) {
  if (reader.size() == 0) throwFormat(path, "empty file");
  if (reader.size() < 8)
    throwFormat(path, "not an OpenEXR file (only " + std::to_string(reader.size()) + " bytes)");
  if (reader.u32("magic number") != kMagic) throwFormat(path, "not an OpenEXR file (bad magic number)");
  const std::uint32_t version = reader.u32("version");
  FileLayout layout;
  layout.flags = version & ~0xFFu;
  if ((version & 0xFFu) != 2) throwFormat(path, "unsupported EXR version " + std::to_string(version & 0xFFu));
  if ((layout.flags & ~kKnownFlags) != 0) throwFormat(path, "unknown version flags");
  const bool multiPart = (layout.flags & kFlagMultiPart) != 0;
  const std::size_t maxName = (layout.flags & kFlagLongNames) != 0 ? 255 : 31;

  for (;;) {
    // Multi-part files end the header list with an empty header (a lone 0 byte).
    if (multiPart && !layout.parts.empty()) {
      std::uint8_t next = 0;
      if (!reader.readAt(reader.position(), &next, 1)) throwFormat(path, "truncated file (header list)");
      if (next == 0) {
        reader.skip(1, "header list");
        break;
      }
    }
    if (layout.parts.size() >= 4096) throwFormat(path, "too many parts");
    PartLayout part;
    for (int attribute = 0;; ++attribute) {
      const std::string name = reader.cstring(maxName, "attribute name");
      if (name.empty()) break;
      if (attribute > 100000) throwFormat(path, "too many header attributes");
      const std::string typeName = reader.cstring(maxName, "attribute type name");
      const std::int32_t size = FileReader::toSigned(reader.u32("attribute size"));
      if (size < 0 || static_cast<std::uint64_t>(size) > reader.remaining())
        throwFormat(path, "invalid size " + std::to_string(size) + " of header attribute '" + name + "'");
      const std::uint64_t valueStart = reader.position();
      if (name == "dataWindow" && typeName == "box2i" && size == 16) {
        part.hasDataWindow = true;
        part.minX = FileReader::toSigned(reader.u32("dataWindow"));
        part.minY = FileReader::toSigned(reader.u32("dataWindow"));
        part.maxX = FileReader::toSigned(reader.u32("dataWindow"));
        part.maxY = FileReader::toSigned(reader.u32("dataWindow"));
      } else if (name == "channels" && typeName == "chlist") {
        std::vector<std::uint8_t> value(static_cast<std::size_t>(size));
        reader.read(value.data(), value.size(), "channels");
        part.channels = parseChannelList(value, path);
        part.hasChannels = true;
      } else if (name == "compression" && typeName == "compression" && size == 1) {
        part.compression = reader.u8("compression");
      } else if (name == "tiles" && typeName == "tiledesc" && size == 9) {
        part.hasTiles = true;
        part.tileWidth = reader.u32("tiles");
        part.tileHeight = reader.u32("tiles");
        const std::uint8_t mode = reader.u8("tiles");
        part.levelMode = mode & 0x0F;
        part.roundingMode = mode >> 4;
      } else if (name == "type" && typeName == "string" && size <= 64) {
        part.type.resize(static_cast<std::size_t>(size));
        reader.read(part.type.data(), part.type.size(), "type");
      } else if (name == "chunkCount" && typeName == "int" && size == 4) {
        part.hasChunkCount = true;
        part.chunkCount = FileReader::toSigned(reader.u32("chunkCount"));
      }
      reader.skip(valueStart + static_cast<std::uint64_t>(size) - reader.position(), "header attribute");
    }
    layout.parts.push_back(std::move(part));
    if (!multiPart) break;
  }
  if (layout.parts.empty()) throwFormat(path, "no parts");
  layout.tablesStart = reader.position();
  return layout;
}

int roundedLog2(long long x, int roundingMode) {
  int floorLog = 0;
  while ((x >> (floorLog + 1)) != 0)
    ++floorLog;
  const bool exact = x == (1LL << floorLog);
  return roundingMode == 0 || exact ? floorLog : floorLog + 1;
}

long long levelSize(long long base, int level, int roundingMode) {
  const long long size = roundingMode == 0 ? base >> level : (base + (1LL << level) - 1) >> level;
  return std::max(size, 1LL);
}

long long tilesIn(long long w, long long h, const PartLayout& part) {
  return ((w + part.tileWidth - 1) / part.tileWidth) * ((h + part.tileHeight - 1) / part.tileHeight);
}

// Number of chunks of a tiled part, all levels (as laid out in its offset table).
long long tiledChunkCount(const PartLayout& part, long long w, long long h) {
  switch (part.levelMode) {
  case 0: // ONE_LEVEL
    return tilesIn(w, h, part);
  case 1: { // MIPMAP_LEVELS
    const int levels = roundedLog2(std::max(w, h), part.roundingMode) + 1;
    long long count = 0;
    for (int l = 0; l < levels; ++l)
      count += tilesIn(levelSize(w, l, part.roundingMode), levelSize(h, l, part.roundingMode), part);
    return count;
  }
  case 2: { // RIPMAP_LEVELS
    const int levelsX = roundedLog2(w, part.roundingMode) + 1,
              levelsY = roundedLog2(h, part.roundingMode) + 1;
    long long count = 0;
    for (int ly = 0; ly < levelsY; ++ly)
      for (int lx = 0; lx < levelsX; ++lx)
        count += tilesIn(levelSize(w, lx, part.roundingMode), levelSize(h, ly, part.roundingMode), part);
    return count;
  }
  default:
    return -1;
  }
}

long long floorDiv(long long a, long long b) { // b > 0
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}

// Number of multiples of s in [a, b]: the sampled lines or columns of a channel with sampling s.
long long sampleCount(long long s, long long a, long long b) {
  return b < a ? 0 : floorDiv(b, s) - floorDiv(a - 1, s);
}

// What a chunk of a part must hold, from its place in the offset table.
struct ExpectedChunk {
  bool tiled = false;
  std::int32_t y0 = 0, y1 = 0;                 // scanline chunk: lines y0..y1
  std::int32_t dx = 0, dy = 0, lx = 0, ly = 0; // tiled chunk: tile and level
  long long width = 0, height = 0;             // pixels covered
  std::uint64_t rawBytes = 0;                  // size of its uncompressed pixel data
};

std::string describe(const ExpectedChunk& c) {
  if (c.tiled)
    return "tile (" + std::to_string(c.dx) + ", " + std::to_string(c.dy) + ") of level (" +
           std::to_string(c.lx) + ", " + std::to_string(c.ly) + ")";
  return c.y0 == c.y1 ? "scanline " + std::to_string(c.y0)
                      : "scanlines " + std::to_string(c.y0) + "-" + std::to_string(c.y1);
}

// Calls f(index, expected) for every chunk of a flat (not deep) part, in offset table order:
// scanline chunks top to bottom; tiles level by level (mip levels 0, 1, ...; rip levels with ly
// outer and lx inner), each level row by row. Its raw size is what OpenEXR's readers compute: per
// line, every channel sampled on it contributes its sampled columns times its sample size.
// The part's size and chunk count must have been validated. The work is one call per table entry
// after O(channels + height * log(height)) to sum the line sizes.
template <class F>
void forEachChunk(const PartLayout& part, bool tiled, F&& f) {
  const long long w = part.width(), h = part.height();
  long long index = 0;
  if (!tiled) {
    // Bytes of the lines before line minY + k, from the channels grouped by their y sampling.
    std::map<long long, std::uint64_t> bytesBySampling;
    for (const ChannelLayout& channel : part.channels)
      bytesBySampling[channel.ySampling] +=
          static_cast<std::uint64_t>(sampleCount(channel.xSampling, part.minX, part.maxX) * channel.bytes());
    std::vector<std::uint64_t> before(static_cast<std::size_t>(h) + 1, 0);
    for (const auto& [sampling, bytes] : bytesBySampling)
      for (long long y = floorDiv(part.minY + sampling - 1, sampling) * sampling; y <= part.maxY;
           y += sampling)
        before[static_cast<std::size_t>(y - part.minY) + 1] += bytes;
    std::partial_sum(before.begin(), before.end(), before.begin());
    const int lines = linesPerChunk(part.compression);
    for (long long y0 = part.minY; y0 <= part.maxY; y0 += lines) {
      ExpectedChunk c;
      c.y0 = static_cast<std::int32_t>(y0);
      c.y1 = static_cast<std::int32_t>(std::min<long long>(y0 + lines - 1, part.maxY));
      c.width = w;
      c.height = static_cast<long long>(c.y1) - c.y0 + 1;
      c.rawBytes = before[static_cast<std::size_t>(c.y1 - part.minY) + 1] -
                   before[static_cast<std::size_t>(c.y0 - part.minY)];
      f(index++, c);
    }
    return;
  }
  std::uint64_t pixelBytes = 0; // tiled parts have no subsampled channels (checked)
  for (const ChannelLayout& channel : part.channels)
    pixelBytes += static_cast<std::uint64_t>(channel.bytes());
  const auto level = [&](int lx, int ly) {
    const long long lw = levelSize(w, lx, part.roundingMode), lh = levelSize(h, ly, part.roundingMode);
    for (long long ty = 0; ty * part.tileHeight < lh; ++ty)
      for (long long tx = 0; tx * part.tileWidth < lw; ++tx) {
        ExpectedChunk c;
        c.tiled = true;
        c.dx = static_cast<std::int32_t>(tx);
        c.dy = static_cast<std::int32_t>(ty);
        c.lx = lx;
        c.ly = ly;
        c.width = std::min<long long>(part.tileWidth, lw - tx * part.tileWidth);
        c.height = std::min<long long>(part.tileHeight, lh - ty * part.tileHeight);
        c.rawBytes = static_cast<std::uint64_t>(c.width * c.height) * pixelBytes;
        f(index++, c);
      }
  };
  if (part.levelMode == 0) {
    level(0, 0);
  } else if (part.levelMode == 1) {
    const int levels = roundedLog2(std::max(w, h), part.roundingMode) + 1;
    for (int l = 0; l < levels; ++l)
      level(l, l);
  } else {
    const int levelsX = roundedLog2(w, part.roundingMode) + 1,
              levelsY = roundedLog2(h, part.roundingMode) + 1;
    for (int ly = 0; ly < levelsY; ++ly)
      for (int lx = 0; lx < levelsX; ++lx)
        level(lx, ly);
  }
}

// The rule for a chunk's data size field. Uncompressed data must be exactly the raw size. Compressed
// data is never larger than the raw data and is empty only if that is: OpenEXR's writers store a
// chunk uncompressed when its codec does not make it smaller, and its readers decode a chunk only if
// it is smaller than the raw size (a chunk of exactly the raw size is read as uncompressed data).
bool validDataSize(int compression, std::int32_t stated, std::uint64_t raw) {
  if (stated < 0) return false;
  const std::uint64_t size = static_cast<std::uint64_t>(stated);
  if (compression == 0) return size == raw;
  return size <= raw && (size > 0 || raw == 0);
}

std::string expectedDataSize(int compression, const ExpectedChunk& c) {
  const std::string pixels = std::to_string(c.width) + "x" + std::to_string(c.height) + " pixels";
  if (compression == 0)
    return "exactly " + std::to_string(c.rawBytes) + " (the uncompressed data of " + pixels + ")";
  return (c.rawBytes == 0 ? std::string("0") : "1 to " + std::to_string(c.rawBytes)) + " (" +
         compressionName(compression) + " data of " + pixels + ", never larger than uncompressed)";
}

// The part readExr decodes, with where its offset table is.
struct CheckedPart {
  const PartLayout* part = nullptr;
  bool tiled = false;
  std::uint64_t tableOffset = 0;
  long long chunkCount = 0;
  std::uint64_t chunkHeaderBytes = 0; // bytes before the pixel data of each chunk
};

// Pass 1 of validateLayout for one part: its data window against the size limits (`selected`: the part
// readExr decodes, also against maxPixels), its channel list and tile description; returns its chunk count.
long long checkedChunkCount(const FileLayout& layout, const PartLayout& part, bool selected,
                            long long maxPixels, const std::string& which, const fs::path& path) {
  const bool multiPart = (layout.flags & kFlagMultiPart) != 0;
  if (!part.hasDataWindow) throwFormat(path, which + "missing or invalid dataWindow attribute");
  const long long w = part.width(), h = part.height();
  if (w <= 0 || h <= 0)
    throwFormat(path, which + "empty or inverted data window (" + std::to_string(part.minX) + ", " +
                          std::to_string(part.minY) + ") - (" + std::to_string(part.maxX) + ", " +
                          std::to_string(part.maxY) + ")");
  const long long pixelLimit = selected ? std::min(maxPixels, Image::kMaxPixels) : Image::kMaxPixels;
  if (w > Image::kMaxDimension || h > Image::kMaxDimension || w * h > pixelLimit)
    throwFormat(path, which + "data window " + std::to_string(w) + "x" + std::to_string(h) +
                          " is too large (limits: " + std::to_string(Image::kMaxDimension) + " per side, " +
                          std::to_string(pixelLimit) + " pixels)");
  const bool deep = part.deep(layout.flags);
  if (selected && deep) throwFormat(path, which + "deep images are not supported");
  if (!deep && !part.hasChannels) throwFormat(path, which + "missing channels attribute");
  long long count = 0;
  if (part.tiled(layout.flags)) {
    if (!part.hasTiles) throwFormat(path, which + "tiled part without a valid tiles attribute");
    if (part.tileWidth == 0 || part.tileHeight == 0 || part.tileWidth > Image::kMaxDimension ||
        part.tileHeight > Image::kMaxDimension ||
        static_cast<long long>(part.tileWidth) * part.tileHeight > std::max(w * h, 1LL << 20))
      throwFormat(path, which + "invalid tile size " + std::to_string(part.tileWidth) + "x" +
                            std::to_string(part.tileHeight));
    if (part.roundingMode > 1) throwFormat(path, which + "invalid tile rounding mode");
    count = tiledChunkCount(part, w, h);
    if (count < 0) throwFormat(path, which + "invalid tile level mode " + std::to_string(part.levelMode));
    for (const ChannelLayout& channel : part.channels)
      if (!deep && (channel.xSampling != 1 || channel.ySampling != 1))
        throwFormat(path, which + "channel '" + channel.name + "' of a tiled part is subsampled");
  } else {
    const int lines = linesPerChunk(part.compression);
    if (lines == 0)
      throwFormat(path, which + "missing or unknown compression " + std::to_string(part.compression));
    count = (h + lines - 1) / lines;
  }
  if (multiPart && (!part.hasChunkCount || part.chunkCount != count))
    throwFormat(path, which + "missing or inconsistent chunkCount attribute (expected " +
                          std::to_string(count) + ")");
  return count;
}

// Pass 2 of validateLayout for part p: every chunk of its offset table `table` (read from the file) starts
// after the tables (tablesEnd) and, with its size field, ends inside the file; a flat part's chunk headers
// name the line or tile of their entry and a data size possible for the compression (validDataSize).
void checkChunks(FileReader& reader, const FileLayout& layout, std::size_t p,
                 const std::vector<std::uint8_t>& table, std::uint64_t tablesEnd, const std::string& which,
                 const fs::path& path) {
  const PartLayout& part = layout.parts[p];
  const bool multiPart = (layout.flags & kFlagMultiPart) != 0;
  const long long count = static_cast<long long>(table.size() / 8);
  // Deep chunks have a different header; only their position and part number are checked.
  const bool deep = part.deep(layout.flags);
  const bool tiled = part.tiled(layout.flags);
  const std::uint64_t headerBytes = (multiPart ? 4u : 0u) + (deep ? 0u : (tiled ? 20u : 8u));
  // Reads the header of chunk i after checking its position and part number; returns its offset.
  std::array<std::uint8_t, 24> chunkHeader{};
  const auto locate = [&](long long i) {
    const std::uint64_t offset = FileReader::decode64(table.data() + i * 8);
    if (offset == 0)
      throwFormat(path, which + "incomplete file (chunk " + std::to_string(i) + " is missing)");
    if (offset < tablesEnd || offset >= reader.size() ||
        !reader.readAt(offset, chunkHeader.data(), headerBytes))
      throwFormat(path, which + "truncated or corrupt file (chunk " + std::to_string(i) + " at offset " +
                            std::to_string(offset) + " lies outside the pixel data of the " +
                            std::to_string(reader.size()) + "-byte file)");
    if (multiPart && FileReader::decode32(chunkHeader.data()) != static_cast<std::uint32_t>(p))
      throwFormat(path, which + "corrupt chunk " + std::to_string(i) + " (wrong part number)");
    return offset;
  };
  if (deep) {
    for (long long i = 0; i < count; ++i)
      locate(i);
    return;
  }
  forEachChunk(part, tiled, [&](long long i, const ExpectedChunk& expected) {
    const std::uint64_t offset = locate(i);
    const std::uint8_t* fields = chunkHeader.data() + (multiPart ? 4 : 0);
    const auto field = [&](int k) { return FileReader::toSigned(FileReader::decode32(fields + 4 * k)); };
    const std::string chunk = which + "corrupt chunk " + std::to_string(i) + " (" + describe(expected) + ")";
    if (tiled && (field(0) != expected.dx || field(1) != expected.dy || field(2) != expected.lx ||
                  field(3) != expected.ly))
      throwFormat(path, chunk + ": its header names tile (" + std::to_string(field(0)) + ", " +
                            std::to_string(field(1)) + ") of level (" + std::to_string(field(2)) + ", " +
                            std::to_string(field(3)) + ")");
    if (!tiled && field(0) != expected.y0)
      throwFormat(path, chunk + ": its header names scanline " + std::to_string(field(0)));
    const std::int32_t dataSize = field(tiled ? 4 : 1);
    if (!validDataSize(part.compression, dataSize, expected.rawBytes))
      throwFormat(path, chunk + ": data size " + std::to_string(dataSize) + " bytes, expected " +
                            expectedDataSize(part.compression, expected));
    if (static_cast<std::uint64_t>(dataSize) > reader.size() - offset - headerBytes)
      throwFormat(path, which + "truncated or corrupt file (chunk " + std::to_string(i) + " of " +
                            std::to_string(dataSize) + " bytes at offset " + std::to_string(offset) +
                            " ends beyond the " + std::to_string(reader.size()) + "-byte file)");
  });
}

// Checks, before OpenEXR sees the file:
// - every part's data window against the size limits (OpenEXR sets up every part),
// - every flat part's channel list (pixel types, sampling; no subsampling in tiled parts),
// - the tile description and the chunk count of every part,
// - that the offset tables fit in the file,
// - that every chunk of every part starts after the tables and, with its size field, ends inside
//   the file (this is what detects truncated pixel data),
// - for flat parts, that every chunk header names the line or tile of its table entry and that its
//   data size is possible for its compression and pixel count (validDataSize). OpenEXR 3.1 trusts
//   this size: it converts a whole line or tile from its line buffer even when the chunk supplied
//   fewer bytes, so the rest of the pixels would come from stale or uninitialised memory. This also
//   bounds the pixel memory by the file: uncompressed pixel data must be present byte for byte.
// The work is bounded by the file size: a table entry takes 8 bytes of the file.
CheckedPart validateLayout(FileReader& reader, const FileLayout& layout, int partIndex, long long maxPixels,
                           const fs::path& path) {
  const bool multiPart = (layout.flags & kFlagMultiPart) != 0;
  if (partIndex >= static_cast<int>(layout.parts.size()))
    throwFormat(path, "part " + std::to_string(partIndex) + " requested but the file has " +
                          std::to_string(layout.parts.size()) + " part(s)");
  const auto which = [&](std::size_t p) {
    return multiPart ? "part " + std::to_string(p) + ": " : std::string();
  };

  // Pass 1: sizes and chunk counts.
  std::vector<long long> counts;
  std::uint64_t tablesEnd = layout.tablesStart;
  for (std::size_t p = 0; p < layout.parts.size(); ++p) {
    const long long count = checkedChunkCount(layout, layout.parts[p], static_cast<int>(p) == partIndex,
                                              maxPixels, which(p), path);
    if (static_cast<std::uint64_t>(count) > (reader.size() - tablesEnd) / 8)
      throwFormat(path,
                  which(p) + "truncated file (chunk offset table of " + std::to_string(count) + " entries)");
    tablesEnd += static_cast<std::uint64_t>(count) * 8;
    counts.push_back(count);
  }

  // Pass 2: every chunk of every part.
  CheckedPart checked;
  std::uint64_t tableOffset = layout.tablesStart;
  std::vector<std::uint8_t> table;
  for (std::size_t p = 0; p < layout.parts.size(); ++p) {
    const PartLayout& part = layout.parts[p];
    const bool tiled = part.tiled(layout.flags);
    table.resize(static_cast<std::size_t>(counts[p]) * 8);
    if (!reader.readAt(tableOffset, table.data(), table.size()))
      throwFormat(path, which(p) + "truncated file (chunk offset table)");
    if (static_cast<int>(p) == partIndex) {
      const std::uint64_t headerBytes =
          (multiPart ? 4u : 0u) + (part.deep(layout.flags) ? 0u : (tiled ? 20u : 8u));
      checked = {&part, tiled, tableOffset, counts[p], headerBytes};
    }
    tableOffset += table.size();
    checkChunks(reader, layout, p, table, tablesEnd, which(p), path);
  }
  return checked;
}

// Size of the output of an RLE chunk as OpenEXR decodes it (a signed count byte c < 0: -c literal
// bytes follow; c >= 0: the next byte repeated c + 1 times), or -1 if the stream is malformed.
// Counting stops once the output exceeds `limit`.
long long rleDecodedSize(const std::vector<std::uint8_t>& in, std::uint64_t limit) {
  std::uint64_t out = 0;
  std::size_t at = 0;
  while (at < in.size() && out <= limit) {
    const int count = static_cast<std::int8_t>(in[at++]);
    if (count < 0) {
      const std::size_t literal = static_cast<std::size_t>(-count);
      if (in.size() - at < literal) return -1;
      at += literal;
      out += literal;
    } else {
      if (at == in.size()) return -1;
      ++at;
      out += static_cast<std::uint64_t>(count) + 1;
    }
  }
  return static_cast<long long>(out);
}

// Inflates with bounded memory to learn the decoded size of a zlib stream (ZIP, ZIPS), or -1 if it is
// not a complete zlib stream. Bytes after the end of the stream are ignored, as OpenEXR does.
// Inflating stops once the output exceeds `limit`.
class ZlibSizer {
public:
  ZlibSizer() {
    if (inflateInit_(&stream_, ZLIB_VERSION, static_cast<int>(sizeof(z_stream))) != Z_OK)
      throw std::bad_alloc();
  }
  ~ZlibSizer() { inflateEnd(&stream_); }
  ZlibSizer(const ZlibSizer&) = delete;
  ZlibSizer& operator=(const ZlibSizer&) = delete;

  long long decodedSize(const std::vector<std::uint8_t>& in, std::uint64_t limit) {
    if (inflateReset(&stream_) != Z_OK) return -1;
    stream_.next_in = in.data();
    stream_.avail_in = static_cast<uInt>(in.size());
    std::uint64_t out = 0;
    for (;;) {
      stream_.next_out = scratch_.data();
      stream_.avail_out = static_cast<uInt>(scratch_.size());
      const int result = inflate(&stream_, Z_NO_FLUSH);
      out += scratch_.size() - stream_.avail_out;
      if (result == Z_STREAM_END || (result == Z_OK && out > limit)) return static_cast<long long>(out);
      if (result != Z_OK) return -1; // corrupt, or the input ended before the stream did
    }
  }

private:
  z_stream stream_{};
  std::array<Bytef, 1 << 16> scratch_{};
};

// OpenEXR 3.1 does not check that an RLE, ZIPS or ZIP chunk decodes to its full raw size: it converts
// the whole chunk from its decompression buffer, whose end then holds stale or uninitialised memory
// (PIZ, PXR24, B44 and DWA check their decoded size themselves). The chunks of these codecs that
// OpenEXR will decompress (those smaller than their raw size) are decoded here first, with bounded
// memory, and must yield exactly the raw size. Runs after the plausibility check of the image size,
// so the work is bounded by the pixel memory the caller accepted.
void verifyDecodedSizes(FileReader& reader, const CheckedPart& checked, const fs::path& path) {
  const int compression = checked.part->compression;
  if (compression < 1 || compression > 3) return;
  std::vector<std::uint8_t> table(static_cast<std::size_t>(checked.chunkCount) * 8);
  if (!reader.readAt(checked.tableOffset, table.data(), table.size()))
    throwFormat(path, "truncated file (chunk offset table)");
  std::unique_ptr<ZlibSizer> zlib;
  std::vector<std::uint8_t> packed;
  forEachChunk(*checked.part, checked.tiled, [&](long long i, const ExpectedChunk& expected) {
    const std::uint64_t offset = FileReader::decode64(table.data() + i * 8);
    std::array<std::uint8_t, 4> sizeField{};
    if (!reader.readAt(offset + checked.chunkHeaderBytes - 4, sizeField.data(), sizeField.size()))
      throwFormat(path, "truncated file (chunk " + std::to_string(i) + ")");
    const std::uint64_t dataSize = FileReader::decode32(sizeField.data()); // validated: <= raw size
    if (dataSize == 0 || dataSize >= expected.rawBytes) return;            // stored uncompressed
    packed.resize(static_cast<std::size_t>(dataSize));
    if (!reader.readAt(offset + checked.chunkHeaderBytes, packed.data(), packed.size()))
      throwFormat(path, "truncated file (chunk " + std::to_string(i) + ")");
    long long decoded = 0;
    if (compression == 1) {
      decoded = rleDecodedSize(packed, expected.rawBytes);
    } else {
      if (!zlib) zlib = std::make_unique<ZlibSizer>();
      decoded = zlib->decodedSize(packed, expected.rawBytes);
    }
    const std::string chunk = "corrupt chunk " + std::to_string(i) + " (" + describe(expected) + "): its " +
                              compressionName(compression) + " data ";
    if (decoded < 0) throwFormat(path, chunk + "cannot be decoded");
    if (static_cast<std::uint64_t>(decoded) != expected.rawBytes)
      throwFormat(path, chunk + "decodes to " +
                            (static_cast<std::uint64_t>(decoded) > expected.rawBytes ? "more than " : "") +
                            std::to_string(std::min<std::uint64_t>(static_cast<std::uint64_t>(decoded),
                                                                   expected.rawBytes)) +
                            " bytes, expected " + std::to_string(expected.rawBytes));
  });
}

// ------------------------------------------------------------------------------------------------
// Channel selection

std::vector<std::string> selectChannels(const std::vector<std::string>& available, const std::string& layer,
                                        const fs::path& path) {
  const std::string prefix = layer.empty() ? std::string() : layer + ".";
  std::vector<std::string> inLayer; // suffixes
  for (const std::string& name : available) {
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string suffix = name.substr(prefix.size());
    if (suffix.find('.') == std::string::npos) inLayer.push_back(suffix);
  }
  const auto has = [&](const char* s) {
    return std::find(inLayer.begin(), inLayer.end(), s) != inLayer.end();
  };
  std::vector<std::string> chosen;
  if (has("R") && has("G") && has("B")) {
    chosen = {"R", "G", "B"};
    if (has("A")) chosen.push_back("A");
  } else if (has("R") && has("G")) {
    chosen = {"R", "G"};
  } else {
    for (const char* single : {"Y", "Z", "depth", "R"})
      if (has(single)) {
        chosen = {single};
        break;
      }
    if (chosen.empty() && inLayer.size() == 1) chosen = inLayer;
  }
  if (chosen.empty()) {
    std::string list;
    for (const std::string& name : available)
      list += (list.empty() ? "" : ", ") + name;
    throwFormat(path, "no usable channels in layer '" + layer +
                          "' (channels: " + (list.empty() ? "none" : list) +
                          "; expected R,G,B[,A], R,G, Y, Z, depth or a single channel)");
  }
  for (std::string& s : chosen)
    s = prefix + s;
  return chosen;
}

std::vector<std::string> channelNames(const Imf::Header& header) {
  std::vector<std::string> names;
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
    names.emplace_back(it.name());
  return names;
}

} // namespace

// --------------------------------------------------------------------------------------------------

void writeExr(const std::filesystem::path& path, const Image& image, const ExrWriteOptions& options) {
  if (image.empty()) throw InvalidArgument("image", "empty image", "writeExr needs a non-empty image");
  const ExrLayer layer{std::string(), &image};
  writeLayers(path, std::span<const ExrLayer>(&layer, 1), options);
}

void writeExrLayers(const std::filesystem::path& path, std::span<const ExrLayer> layers,
                    const ExrWriteOptions& options) {
  writeLayers(path, layers, options);
}

Image readExr(const std::filesystem::path& path, const ExrReadOptions& options) {
  if (options.maxPixels <= 0)
    throw InvalidArgument("ExrReadOptions.maxPixels", detail::formatValue(options.maxPixels), "must be > 0");
  if (options.part < 0)
    throw InvalidArgument("ExrReadOptions.part", detail::formatValue(options.part), "must be >= 0");

  FileReader reader(path);
  const FileLayout layout = scanHeaders(reader, path);
  const CheckedPart checked = validateLayout(reader, layout, options.part, options.maxPixels, path);
  const PartLayout& part = *checked.part;
  const int width = static_cast<int>(part.width());
  const int height = static_cast<int>(part.height());

  try {
    Imf::MultiPartInputFile file(path.c_str(), 0, /*reconstructChunkOffsetTable=*/false);
    if (options.part >= file.parts())
      throwFormat(path, "part " + std::to_string(options.part) + " not found");
    const Imf::Header& header = file.header(options.part);
    if (header.hasType() && Imf::isDeepData(header.type()))
      throwFormat(path, "deep images are not supported");
    const Imath::Box2i& dataWindow = header.dataWindow();
    if (dataWindow.min.x != part.minX || dataWindow.min.y != part.minY || dataWindow.max.x != part.maxX ||
        dataWindow.max.y != part.maxY)
      throwFormat(path, "inconsistent data window");

    const std::vector<std::string> selected = selectChannels(channelNames(header), options.layer, path);
    for (const std::string& name : selected) {
      const Imf::Channel& channel = header.channels()[name];
      if (channel.xSampling != 1 || channel.ySampling != 1)
        throwFormat(path, "channel '" + name + "' is subsampled, which is not supported");
    }

    // Uncompressed pixel data is present byte for byte (validateLayout). The codecs other than DWA
    // cannot shrink pixel data by much more than zlib's ~1032:1 (half samples, 2 bytes, become 4-byte
    // floats: 2064:1): a header promising far more pixels than the file can hold is rejected before
    // the image is allocated. DWAA/DWAB (zlib over RLE or DCT coefficients) can legitimately exceed
    // this on constant images and are only size-limited.
    const bool dwa = part.compression == 8 || part.compression == 9;
    const double imageBytes =
        static_cast<double>(width) * height * static_cast<double>(selected.size()) * 4.0;
    if (!dwa && imageBytes > 4096.0 * static_cast<double>(reader.size()) + 16.0 * 1024 * 1024)
      throwFormat(path, "data window " + std::to_string(width) + "x" + std::to_string(height) +
                            " is implausibly large for a " + std::to_string(reader.size()) + "-byte file");
    verifyDecodedSizes(reader, checked, path);

    Imf::InputPart input(file, options.part);
    if (!input.isComplete()) throwFormat(path, "incomplete file (missing pixel data)");

    // No sample may be returned that the decoder did not write. The image is filled with a NaN bit
    // pattern, kExrUnwrittenSampleBits, before decoding and checked after it. No HALF or UINT sample
    // converts to it (UINT values are never NaN; a half NaN becomes a float whose 13 low mantissa bits
    // are zero, and the pattern's are not), but a FLOAT channel may hold any bit pattern. So where the
    // pattern survives, those samples are set to a second pattern and the pixels decoded again: a
    // sample the decoder writes gets the same value both times, an unwritten one keeps the second
    // pattern. Exact for every file, and the second decode only happens for files that contain the
    // pattern themselves (or are incomplete).
    const std::size_t channels = selected.size();
    Image image(width, height, static_cast<int>(channels),
                std::bit_cast<float>(detail::kExrUnwrittenSampleBits));
    const std::size_t xStride = channels * sizeof(float);
    const std::size_t yStride = static_cast<std::size_t>(width) * xStride;
    Imf::FrameBuffer frameBuffer;
    for (std::size_t c = 0; c < channels; ++c)
      frameBuffer.insert(selected[c], Imf::Slice::Make(Imf::FLOAT, image.data().data() + c, dataWindow,
                                                       xStride, yStride, 1, 1, 0.0));
    input.setFrameBuffer(frameBuffer);
    input.readPixels(dataWindow.min.y, dataWindow.max.y);

    const std::span<float> data = image.data();
    const auto bits = [](float v) { return std::bit_cast<std::uint32_t>(v); };
    std::size_t survivors = 0; // a vectorisable count first: usually 0
    for (const float v : data)
      survivors += bits(v) == detail::kExrUnwrittenSampleBits ? 1 : 0;
    if (survivors != 0) {
      std::vector<std::size_t> suspects;
      suspects.reserve(survivors);
      for (std::size_t i = 0; i < data.size(); ++i)
        if (bits(data[i]) == detail::kExrUnwrittenSampleBits) suspects.push_back(i);
      for (const std::size_t i : suspects)
        data[i] = std::bit_cast<float>(detail::kExrUnwrittenSampleRetryBits);
      input.readPixels(dataWindow.min.y, dataWindow.max.y);
      for (const std::size_t i : suspects)
        if (bits(data[i]) != detail::kExrUnwrittenSampleBits) {
          const std::size_t row = i / (static_cast<std::size_t>(width) * channels);
          const std::size_t column = i / channels % static_cast<std::size_t>(width);
          throwFormat(path, "incomplete pixel data (sample (" +
                                std::to_string(part.minX + static_cast<long long>(column)) + ", " +
                                std::to_string(part.minY + static_cast<long long>(row)) + ") of channel '" +
                                selected[i % channels] + "' was not decoded)");
        }
    }

    // The rows were read top first; the Image wants the bottom row first.
    const std::size_t rowFloats = static_cast<std::size_t>(width) * channels;
    for (int y = 0; y < height / 2; ++y) {
      auto top = data.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(y) * rowFloats);
      auto bottom =
          data.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(height - 1 - y) * rowFloats);
      std::swap_ranges(top, top + static_cast<std::ptrdiff_t>(rowFloats), bottom);
    }
    return image;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throwFormat(path, e.what());
  }
}

ExrFileInfo readExrInfo(const std::filesystem::path& path, int part) {
  if (part < 0) throw InvalidArgument("part", detail::formatValue(part), "must be >= 0");
  FileReader reader(path);
  const FileLayout layout = scanHeaders(reader, path);
  const PartLayout& selected = *validateLayout(reader, layout, part, Image::kMaxPixels, path).part;
  try {
    Imf::MultiPartInputFile file(path.c_str(), 0, /*reconstructChunkOffsetTable=*/false);
    const Imf::Header& header = file.header(part);
    ExrFileInfo info;
    info.width = static_cast<int>(selected.width());
    info.height = static_cast<int>(selected.height());
    info.dataWindowMinX = selected.minX;
    info.dataWindowMinY = selected.minY;
    info.partCount = file.parts();
    info.tiled = selected.tiled(layout.flags);
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
      ExrChannelInfo channel;
      channel.name = it.name();
      channel.isUint = it.channel().type == Imf::UINT;
      channel.pixelType = it.channel().type == Imf::FLOAT ? ExrPixelType::Float : ExrPixelType::Half;
      info.channels.push_back(std::move(channel));
    }
    return info;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throwFormat(path, e.what());
  }
}

} // namespace crep
