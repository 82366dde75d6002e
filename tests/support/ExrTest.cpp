// EXR reading/writing. Expectations are independent of OpenEXR where it matters: a small
// hand-written encoder of uncompressed EXR files (scanline, tiled, multi-part) provides files with
// known content for the reader, and the writer's uncompressed output is parsed byte by byte.
#include "common/image_check.h"

#include <crep/core/error.h>
#include <crep/core/image.h>
#include <crep/support/exr.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <sys/resource.h>

using crep::Image;
namespace fs = std::filesystem;

namespace {

using Bytes = std::vector<std::uint8_t>;

const float kInf = std::numeric_limits<float>::infinity();
const float kNan = std::numeric_limits<float>::quiet_NaN();

Bytes readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  REQUIRE(in);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void writeFile(const fs::path& path, const Bytes& bytes, std::size_t length) {
  // Remove first: truncating an existing file makes ext4 flush it on close (slow in loops).
  std::error_code ignored;
  fs::remove(path, ignored);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  REQUIRE(out);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(length));
  REQUIRE(out);
}
void writeFile(const fs::path& path, const Bytes& bytes) {
  writeFile(path, bytes, bytes.size());
}

std::uint32_t get32(const Bytes& b, std::size_t at) {
  REQUIRE(at + 4 <= b.size());
  return static_cast<std::uint32_t>(b[at]) | (static_cast<std::uint32_t>(b[at + 1]) << 8) |
         (static_cast<std::uint32_t>(b[at + 2]) << 16) | (static_cast<std::uint32_t>(b[at + 3]) << 24);
}
std::uint64_t get64(const Bytes& b, std::size_t at) {
  return static_cast<std::uint64_t>(get32(b, at)) | (static_cast<std::uint64_t>(get32(b, at + 4)) << 32);
}
float getFloat(const Bytes& b, std::size_t at) {
  const std::uint32_t bits = get32(b, at);
  float f = 0;
  std::memcpy(&f, &bits, 4);
  return f;
}
void put32(Bytes& b, std::size_t at, std::uint32_t v) {
  REQUIRE(at + 4 <= b.size());
  for (int i = 0; i < 4; ++i)
    b[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
}

std::uint32_t bitsOf(float v) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &v, 4);
  return bits;
}
float floatOf(std::uint32_t bits) {
  float v = 0;
  std::memcpy(&v, &bits, 4);
  return v;
}

// IEEE half to float, independent of Imath.
float halfToFloat(std::uint16_t h) {
  const int exponent = (h >> 10) & 31, mantissa = h & 1023;
  float v = 0;
  if (exponent == 0)
    v = std::ldexp(static_cast<float>(mantissa), -24);
  else if (exponent == 31)
    v = mantissa != 0 ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
  else
    v = std::ldexp(static_cast<float>(mantissa + 1024), exponent - 25);
  return (h & 0x8000) != 0 ? -v : v;
}

// Samples of `image` that come from memory nobody wrote: the reader's sentinel patterns (what its
// frame buffer holds before decoding) or AddressSanitizer's malloc fill byte 0xBE as a float or as a
// half converted to float (what OpenEXR's own, uninitialised, line buffers hold under ASan: its
// default max_malloc_fill_size fills the first 4096 bytes of every allocation, so the test images
// keep a chunk's raw data below that). Test images never hold these values.
int unwrittenSamples(const Image& image) {
  const std::uint32_t asanHalf = bitsOf(halfToFloat(0xBEBE));
  int count = 0;
  for (const float v : image.data()) {
    const std::uint32_t bits = bitsOf(v);
    if (bits == crep::detail::kExrUnwrittenSampleBits || bits == crep::detail::kExrUnwrittenSampleRetryBits ||
        bits == 0xBEBEBEBEu || bits == asanHalf)
      ++count;
  }
  return count;
}

// Position of the value of header attribute `name` (single-part files), or 0.
std::size_t findAttribute(const Bytes& b, const std::string& name, const std::string& type) {
  std::string key = name;
  key.push_back('\0');
  key += type;
  key.push_back('\0');
  const auto it = std::search(b.begin(), b.end(), key.begin(), key.end());
  if (it == b.end()) return 0;
  return static_cast<std::size_t>(it - b.begin()) + key.size() + 4; // skip the size field
}

// End of the single-part header: one past its terminating 0 byte.
std::size_t headerEnd(const Bytes& b) {
  std::size_t at = 8;
  for (;;) {
    REQUIRE(at < b.size());
    if (b[at] == 0) return at + 1;
    while (b[at] != 0)
      ++at; // name
    ++at;
    while (b[at] != 0)
      ++at; // type
    ++at;
    const std::uint32_t size = get32(b, at);
    at += 4 + size;
  }
}

// The chunk offset table of a single-part scanline file whose chunks follow the table (as OpenEXR
// writes them): the offset of every chunk.
std::vector<std::size_t> chunkOffsets(const Bytes& b) {
  const std::size_t tableStart = headerEnd(b);
  const std::size_t first = static_cast<std::size_t>(get64(b, tableStart));
  REQUIRE(first > tableStart);
  REQUIRE((first - tableStart) % 8 == 0);
  std::vector<std::size_t> offsets;
  for (std::size_t i = 0; i < (first - tableStart) / 8; ++i)
    offsets.push_back(static_cast<std::size_t>(get64(b, tableStart + i * 8)));
  return offsets;
}

// ---------------------------------------------------------------------------------------------------
// A minimal encoder of uncompressed EXR files (little endian, OpenEXR file layout 2.0).

struct Writer {
  Bytes b;
  void u8(std::uint8_t v) { b.push_back(v); }
  void u16(std::uint16_t v) {
    u8(static_cast<std::uint8_t>(v & 0xFF));
    u8(static_cast<std::uint8_t>(v >> 8));
  }
  void u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i)
      u8(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void u64(std::uint64_t v) {
    u32(static_cast<std::uint32_t>(v));
    u32(static_cast<std::uint32_t>(v >> 32));
  }
  void f32(float v) {
    std::uint32_t bits = 0;
    std::memcpy(&bits, &v, 4);
    u32(bits);
  }
  void str0(const std::string& s) {
    for (char c : s)
      u8(static_cast<std::uint8_t>(c));
    u8(0);
  }
  void append(const Bytes& other) { b.insert(b.end(), other.begin(), other.end()); }
  void attribute(const std::string& name, const std::string& type, const Bytes& value) {
    str0(name);
    str0(type);
    i32(static_cast<std::int32_t>(value.size()));
    append(value);
  }
};

// A zlib stream holding `data` in one stored (uncompressed) deflate block.
Bytes zlibStored(const Bytes& data) {
  REQUIRE(data.size() < 65536);
  const auto n = static_cast<std::uint16_t>(data.size());
  Writer z;
  z.u8(0x78); // deflate, 32 KiB window
  z.u8(0x01); // no preset dictionary, check bits
  z.u8(0x01); // final block, stored
  z.u16(n);
  z.u16(static_cast<std::uint16_t>(~n));
  for (const std::uint8_t byte : data)
    z.u8(byte);
  std::uint32_t a = 1, b = 0; // Adler-32, stored big-endian
  for (const std::uint8_t byte : data) {
    a = (a + byte) % 65521;
    b = (b + a) % 65521;
  }
  const std::uint32_t adler = (b << 16) | a;
  for (int shift = 24; shift >= 0; shift -= 8)
    z.u8(static_cast<std::uint8_t>(adler >> shift));
  return z.b;
}

enum : int { kUint = 0, kHalf = 1, kFloat = 2 };

struct RawChannel {
  std::string name;
  int type = kFloat;
  int xSampling = 1, ySampling = 1;
};

struct RawPart {
  std::vector<RawChannel> channels; // sorted by name, as EXR requires
  int minX = 0, minY = 0, maxX = 0, maxY = 0;
  int tileWidth = 0, tileHeight = 0; // tiled when > 0
  std::string name = "part";
  std::string type;        // explicit type attribute (multi-part files always get one)
  int compression = 0;     // attribute value only: the data written is always uncompressed...
  int fakeChunkBytes = -1; // ...unless >= 0: then every chunk holds this many zero bytes
  Bytes fakeChunk;         // ...or, if not empty, these bytes (scanline parts)
};

// The value stored for channel c of part p at EXR coordinates (x, y): an integer in [0, 1024),
// exact in half, float and uint.
float rawValue(int p, int c, int x, int y) {
  const int v = ((x * 13 + y * 29 + c * 97 + p * 311) % 1024 + 1024) % 1024;
  return static_cast<float>(v);
}

std::uint16_t halfOfSmallInteger(float v) {
  const int n = static_cast<int>(v);
  REQUIRE(static_cast<float>(n) == v);
  REQUIRE(n >= 0);
  REQUIRE(n < 2048);
  if (n == 0) return 0;
  int e = 0;
  while ((n >> (e + 1)) != 0)
    ++e;
  const int mantissa = (n - (1 << e)) << (10 - e);
  return static_cast<std::uint16_t>(((e + 15) << 10) | mantissa);
}

void sample(Writer& w, int type, float v) {
  if (type == kUint)
    w.u32(static_cast<std::uint32_t>(v));
  else if (type == kHalf)
    w.u16(halfOfSmallInteger(v));
  else
    w.f32(v);
}

Bytes partHeader(const RawPart& part, bool multiPart, int chunkCount, const RawPart& displayPart) {
  Writer h;
  Writer channels;
  for (const RawChannel& c : part.channels) {
    channels.str0(c.name);
    channels.i32(c.type);
    channels.u8(0);
    channels.u8(0);
    channels.u8(0);
    channels.u8(0);
    channels.i32(c.xSampling);
    channels.i32(c.ySampling);
  }
  channels.u8(0);
  h.attribute("channels", "chlist", channels.b);
  if (multiPart) {
    Writer count;
    count.i32(chunkCount);
    h.attribute("chunkCount", "int", count.b);
  }
  h.attribute("compression", "compression", {static_cast<std::uint8_t>(part.compression)});
  Writer box;
  box.i32(part.minX);
  box.i32(part.minY);
  box.i32(part.maxX);
  box.i32(part.maxY);
  h.attribute("dataWindow", "box2i", box.b);
  Writer display; // shared by all parts of a multi-part file
  display.i32(displayPart.minX);
  display.i32(displayPart.minY);
  display.i32(displayPart.maxX);
  display.i32(displayPart.maxY);
  h.attribute("displayWindow", "box2i", display.b);
  h.attribute("lineOrder", "lineOrder", {0});
  if (multiPart) {
    Writer name;
    for (char c : part.name)
      name.u8(static_cast<std::uint8_t>(c));
    h.attribute("name", "string", name.b);
  }
  Writer one;
  one.f32(1.0f);
  h.attribute("pixelAspectRatio", "float", one.b);
  Writer centre;
  centre.f32(0.0f);
  centre.f32(0.0f);
  h.attribute("screenWindowCenter", "v2f", centre.b);
  h.attribute("screenWindowWidth", "float", one.b);
  if (part.tileWidth > 0) {
    Writer tiles;
    tiles.u32(static_cast<std::uint32_t>(part.tileWidth));
    tiles.u32(static_cast<std::uint32_t>(part.tileHeight));
    tiles.u8(0); // ONE_LEVEL, round down
    h.attribute("tiles", "tiledesc", tiles.b);
  }
  std::string type = part.type;
  if (type.empty() && multiPart) type = part.tileWidth > 0 ? "tiledimage" : "scanlineimage";
  if (!type.empty()) {
    Writer t;
    for (char c : type)
      t.u8(static_cast<std::uint8_t>(c));
    h.attribute("type", "string", t.b);
  }
  h.u8(0);
  return h.b;
}

bool sampled(int v, int sampling) {
  return ((v % sampling) + sampling) % sampling == 0;
}

// The chunks of one part (without the multi-part part number prefix).
std::vector<Bytes> partChunks(const RawPart& part, int p) {
  std::vector<Bytes> chunks;
  if (part.tileWidth == 0) {
    // Fake chunks cover as many lines as the compression puts in a chunk; real data is written
    // uncompressed, one line per chunk.
    const bool fake = part.fakeChunkBytes >= 0 || !part.fakeChunk.empty();
    const int linesPerChunk[10] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
    const int step = fake ? linesPerChunk[part.compression] : 1;
    for (int y = part.minY; y <= part.maxY; y += step) {
      Writer data;
      for (std::size_t c = 0; c < part.channels.size(); ++c) {
        const RawChannel& ch = part.channels[c];
        if (!sampled(y, ch.ySampling)) continue;
        for (int x = part.minX; x <= part.maxX; ++x)
          if (sampled(x, ch.xSampling)) sample(data, ch.type, rawValue(p, static_cast<int>(c), x, y));
      }
      if (part.fakeChunkBytes >= 0) data.b.assign(static_cast<std::size_t>(part.fakeChunkBytes), 0);
      if (!part.fakeChunk.empty()) data.b = part.fakeChunk;
      Writer chunk;
      chunk.i32(y);
      chunk.i32(static_cast<std::int32_t>(data.b.size()));
      chunk.append(data.b);
      chunks.push_back(chunk.b);
    }
    return chunks;
  }
  const int width = part.maxX - part.minX + 1, height = part.maxY - part.minY + 1;
  const int tilesX = (width + part.tileWidth - 1) / part.tileWidth;
  const int tilesY = (height + part.tileHeight - 1) / part.tileHeight;
  for (int ty = 0; ty < tilesY; ++ty) {
    for (int tx = 0; tx < tilesX; ++tx) {
      const int x0 = part.minX + tx * part.tileWidth, y0 = part.minY + ty * part.tileHeight;
      const int x1 = std::min(x0 + part.tileWidth - 1, part.maxX),
                y1 = std::min(y0 + part.tileHeight - 1, part.maxY);
      Writer data;
      for (int y = y0; y <= y1; ++y)
        for (std::size_t c = 0; c < part.channels.size(); ++c)
          for (int x = x0; x <= x1; ++x)
            sample(data, part.channels[c].type, rawValue(p, static_cast<int>(c), x, y));
      Writer chunk;
      chunk.i32(tx);
      chunk.i32(ty);
      chunk.i32(0);
      chunk.i32(0);
      chunk.i32(static_cast<std::int32_t>(data.b.size()));
      chunk.append(data.b);
      chunks.push_back(chunk.b);
    }
  }
  return chunks;
}

Bytes buildExr(const std::vector<RawPart>& parts, std::uint32_t extraFlags = 0) {
  const bool multiPart = parts.size() > 1;
  std::vector<std::vector<Bytes>> chunks;
  for (std::size_t p = 0; p < parts.size(); ++p)
    chunks.push_back(partChunks(parts[p], static_cast<int>(p)));
  Writer w;
  w.u32(20000630);
  std::uint32_t version = 2 | extraFlags;
  if (multiPart)
    version |= 0x1000;
  else if (parts[0].tileWidth > 0)
    version |= 0x200;
  w.u32(version);
  for (std::size_t p = 0; p < parts.size(); ++p)
    w.append(partHeader(parts[p], multiPart, static_cast<int>(chunks[p].size()), parts[0]));
  if (multiPart) w.u8(0);
  std::size_t tableEntries = 0;
  for (const auto& c : chunks)
    tableEntries += c.size();
  std::uint64_t offset = w.b.size() + tableEntries * 8;
  for (const auto& partChunkList : chunks) {
    for (const Bytes& chunk : partChunkList) {
      w.u64(offset);
      offset += chunk.size() + (multiPart ? 4 : 0);
    }
  }
  for (std::size_t p = 0; p < parts.size(); ++p) {
    for (const Bytes& chunk : chunks[p]) {
      if (multiPart) w.i32(static_cast<std::int32_t>(p));
      w.append(chunk);
    }
  }
  return w.b;
}

RawPart scanlinePart(std::vector<RawChannel> channels, int width, int height, int minX = 0, int minY = 0) {
  RawPart part;
  part.channels = std::move(channels);
  part.minX = minX;
  part.minY = minY;
  part.maxX = minX + width - 1;
  part.maxY = minY + height - 1;
  return part;
}

// Checks that `image` holds channels `fileChannels` (indices into the part's sorted channel list)
// of the raw part, flipped to bottom-first rows.
void checkRawContent(const Image& image, const RawPart& part, int p, const std::vector<int>& fileChannels) {
  REQUIRE(image.width() == part.maxX - part.minX + 1);
  REQUIRE(image.height() == part.maxY - part.minY + 1);
  REQUIRE(image.channels() == static_cast<int>(fileChannels.size()));
  int bad = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < image.channels(); ++c) {
        const float expected =
            rawValue(p, fileChannels[static_cast<std::size_t>(c)], part.minX + x, part.maxY - y);
        if (image.at(x, y, c) != expected && bad++ < 5)
          FAIL_CHECK("pixel (" << x << "," << y << "," << c << ") = " << image.at(x, y, c) << ", expected "
                               << expected);
      }
  CHECK(bad == 0);
}

// ---------------------------------------------------------------------------------------------------

Image patternImage(int width, int height, int channels) {
  // k / 1024 with |k| <= 1024: exact in half.
  Image image(width, height, channels);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < channels; ++c)
        image.at(x, y, c) = static_cast<float>((x * 37 + y * 101 + c * 211) % 2049 - 1024) / 1024.0f;
  return image;
}

void requireIdentical(const Image& actual, const Image& expected) {
  REQUIRE(actual.width() == expected.width());
  REQUIRE(actual.height() == expected.height());
  REQUIRE(actual.channels() == expected.channels());
  int bad = 0;
  for (std::size_t i = 0; i < actual.data().size(); ++i) {
    const float a = actual.data()[i], e = expected.data()[i];
    const bool same = (std::isnan(a) && std::isnan(e)) || std::memcmp(&a, &e, sizeof a) == 0;
    if (!same && bad++ < 5) FAIL_CHECK("sample " << i << ": " << a << " != " << e);
  }
  CHECK(bad == 0);
}

template <class Exception>
std::string expectThrows(const fs::path& path, const crep::ExrReadOptions& options = {}) {
  try {
    (void)crep::readExr(path, options);
  } catch (const Exception& e) {
    return e.what();
  } catch (const std::exception& e) {
    FAIL_CHECK("wrong exception type: " << e.what());
    return e.what();
  }
  FAIL_CHECK("no exception reading " << path.string());
  return {};
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

} // namespace

// ---------------------------------------------------------------------------------------------------

TEST_CASE("EXR: half round trip is exact for values k/1024, for 1 to 4 channels and every compression") {
  crep::test::TempDir dir;
  for (int channels = 1; channels <= 4; ++channels) {
    for (crep::ExrCompression compression :
         {crep::ExrCompression::Zip, crep::ExrCompression::Piz, crep::ExrCompression::None}) {
      CAPTURE(channels);
      CAPTURE(static_cast<int>(compression));
      const Image image = patternImage(37, 23, channels);
      const fs::path path = dir / "half.exr";
      crep::writeExr(path, image, crep::ExrWriteOptions(crep::ExrPixelType::Half, compression));
      requireIdentical(crep::readExr(path), image);
      const crep::ExrFileInfo info = crep::readExrInfo(path);
      CHECK(info.width == 37);
      CHECK(info.height == 23);
      REQUIRE(info.channels.size() == static_cast<std::size_t>(channels));
      for (const auto& channel : info.channels)
        CHECK(channel.pixelType == crep::ExrPixelType::Half);
    }
  }
}

TEST_CASE("EXR: channel names written for 1, 2, 3 and 4 channels") {
  crep::test::TempDir dir;
  const std::vector<std::vector<std::string>> expected = {
      {"Y"}, {"G", "R"}, {"B", "G", "R"}, {"A", "B", "G", "R"}}; // sorted, as stored
  for (int channels = 1; channels <= 4; ++channels) {
    crep::writeExr(dir / "names.exr", Image(3, 2, channels));
    const crep::ExrFileInfo info = crep::readExrInfo(dir / "names.exr");
    std::vector<std::string> names;
    for (const auto& c : info.channels)
      names.push_back(c.name);
    CHECK(names == expected[static_cast<std::size_t>(channels - 1)]);
  }
}

TEST_CASE("EXR: float round trip is bit exact, including extremes, denormals, NaN and Inf") {
  crep::test::TempDir dir;
  const float specials[] = {1.0f / 3.0f,
                            -1e-30f,
                            1e30f,
                            1e-40f /* denormal */,
                            0.1f,
                            -0.0f,
                            std::numeric_limits<float>::max(),
                            kInf,
                            -kInf,
                            kNan,
                            123456.789f};
  for (int channels : {1, 2, 3, 4}) {
    Image image(37, 23, channels);
    std::size_t i = 0;
    for (float& v : image.data()) {
      v = specials[i % std::size(specials)] * (i % 7 == 3 ? -1.0f : 1.0f);
      ++i;
    }
    const fs::path path = dir / "float.exr";
    crep::writeExr(path, image, crep::ExrPixelType::Float);
    requireIdentical(crep::readExr(path), image);
    for (const auto& channel : crep::readExrInfo(path).channels)
      CHECK(channel.pixelType == crep::ExrPixelType::Float);
  }
}

TEST_CASE("EXR: half rounds non-representable values to nearest, overflows to Inf, keeps NaN") {
  crep::test::TempDir dir;
  Image image(5, 1, 1);
  image.at(0, 0) = 1.0f / 3.0f;
  image.at(1, 0) = 0.1f;
  image.at(2, 0) = 70000.0f;  // > 65504: Inf
  image.at(3, 0) = -70000.0f; // -Inf
  image.at(4, 0) = kNan;
  crep::writeExr(dir / "round.exr", image, crep::ExrPixelType::Half);
  const Image back = crep::readExr(dir / "round.exr");
  const double halfUlpRelative = std::ldexp(1.0, -11);
  for (int x = 0; x < 2; ++x) {
    const double v = image.at(x, 0), r = back.at(x, 0);
    CHECK(r != v); // not representable in half
    CHECK(std::abs(r - v) <= halfUlpRelative * std::abs(v));
  }
  CHECK(back.at(2, 0) == kInf);
  CHECK(back.at(3, 0) == -kInf);
  CHECK(std::isnan(back.at(4, 0)));
}

TEST_CASE("EXR: orientation: Image (0, 0) is the bottom-left pixel, written as the last EXR row") {
  crep::test::TempDir dir;
  const int w = 37, h = 23;
  Image image(w, h, 1);
  image.at(0, 0) = 1.0f;         // bottom-left
  image.at(w - 1, h - 1) = 2.0f; // top-right
  for (int x = 0; x < w; ++x)
    image.at(x, 1) = 0.5f; // second row from the bottom
  const fs::path path = dir / "orientation.exr";
  crep::writeExr(path, image, crep::ExrWriteOptions(crep::ExrPixelType::Float, crep::ExrCompression::None));

  SUBCASE("round trip keeps every pixel in place") {
    requireIdentical(crep::readExr(path), image);
  }
  SUBCASE("file layout: EXR scanline y (top first) holds Image row h - 1 - y") {
    // Uncompressed single-channel float: after the header come h offsets, then chunks
    // [int32 y][int32 size][w floats].
    const Bytes bytes = readFile(path);
    const std::size_t tableStart = headerEnd(bytes);
    for (int y = 0; y < h; ++y) {
      const std::size_t chunk =
          static_cast<std::size_t>(get64(bytes, tableStart + static_cast<std::size_t>(y) * 8));
      REQUIRE(static_cast<int>(get32(bytes, chunk)) == y);
      REQUIRE(get32(bytes, chunk + 4) == static_cast<std::uint32_t>(w * 4));
      for (int x = 0; x < w; ++x)
        CHECK(getFloat(bytes, chunk + 8 + static_cast<std::size_t>(x) * 4) == image.at(x, h - 1 - y));
    }
    // Explicitly: the first EXR row's last pixel is the top-right 2, the last row's first pixel the 1.
    const std::size_t first = static_cast<std::size_t>(get64(bytes, tableStart));
    CHECK(getFloat(bytes, first + 8 + static_cast<std::size_t>(w - 1) * 4) == 2.0f);
    const std::size_t last =
        static_cast<std::size_t>(get64(bytes, tableStart + static_cast<std::size_t>(h - 1) * 8));
    CHECK(getFloat(bytes, last + 8) == 1.0f);
  }
}

TEST_CASE("EXR: reader on independently encoded files: data window offset, pixel types, orientation") {
  crep::test::TempDir dir;
  SUBCASE("single float channel Y with a negative, offset data window") {
    const RawPart part = scanlinePart({{"Y", kFloat}}, 7, 5, -3, 5);
    writeFile(dir / "y.exr", buildExr({part}));
    checkRawContent(crep::readExr(dir / "y.exr"), part, 0, {0});
    const crep::ExrFileInfo info = crep::readExrInfo(dir / "y.exr");
    CHECK(info.dataWindowMinX == -3);
    CHECK(info.dataWindowMinY == 5);
  }
  SUBCASE("mixed uint/half/float RGBA is converted to float") {
    // Sorted: A(float) B(uint) G(half) R(float).
    const RawPart part = scanlinePart({{"A", kFloat}, {"B", kUint}, {"G", kHalf}, {"R", kFloat}}, 9, 4);
    writeFile(dir / "rgba.exr", buildExr({part}));
    checkRawContent(crep::readExr(dir / "rgba.exr"), part, 0, {3, 2, 1, 0});
    const crep::ExrFileInfo info = crep::readExrInfo(dir / "rgba.exr");
    REQUIRE(info.channels.size() == 4);
    CHECK(info.channels[1].isUint);
    CHECK(info.channels[2].pixelType == crep::ExrPixelType::Half);
  }
  SUBCASE("tiled, one level, edge tiles clipped") {
    RawPart part = scanlinePart({{"B", kHalf}, {"G", kHalf}, {"R", kHalf}}, 37, 23, 2, -4);
    part.tileWidth = 8;
    part.tileHeight = 16;
    writeFile(dir / "tiled.exr", buildExr({part}));
    checkRawContent(crep::readExr(dir / "tiled.exr"), part, 0, {2, 1, 0});
    CHECK(crep::readExrInfo(dir / "tiled.exr").tiled);
  }
  SUBCASE("multi-part: parts are selected with ExrReadOptions.part") {
    RawPart part0 = scanlinePart({{"Z", kFloat}}, 5, 4);
    part0.name = "depth";
    RawPart part1 = scanlinePart({{"B", kFloat}, {"G", kFloat}, {"R", kFloat}}, 6, 3, 1, 1);
    part1.tileWidth = 4;
    part1.tileHeight = 2;
    part1.name = "beauty";
    writeFile(dir / "multi.exr", buildExr({part0, part1}));
    checkRawContent(crep::readExr(dir / "multi.exr"), part0, 0, {0});
    crep::ExrReadOptions second;
    second.part = 1;
    checkRawContent(crep::readExr(dir / "multi.exr", second), part1, 1, {2, 1, 0});
    CHECK(crep::readExrInfo(dir / "multi.exr", 1).partCount == 2);
    crep::ExrReadOptions third;
    third.part = 2;
    CHECK(contains(expectThrows<crep::FormatError>(dir / "multi.exr", third), "part 2"));
  }
}

TEST_CASE("EXR: channel selection rules") {
  crep::test::TempDir dir;
  struct Case {
    std::vector<std::string> channels; // sorted
    std::string layer;
    std::vector<int> expected; // indices into channels; empty = FormatError
  };
  const Case cases[] = {
      {{"A", "B", "G", "R"}, "", {3, 2, 1, 0}},
      {{"B", "G", "R"}, "", {2, 1, 0}},
      {{"G", "R"}, "", {1, 0}},
      {{"A", "G", "R"}, "", {2, 1}},
      {{"A", "Y"}, "", {1}},
      {{"Y", "Z"}, "", {0}},
      {{"Z", "depth"}, "", {0}},
      {{"R", "depth"}, "", {1}},
      {{"A", "R"}, "", {1}},
      {{"weird"}, "", {0}},
      {{"foo", "weird"}, "", {}},
      {{"B", "G", "R", "a.B", "a.G", "a.R"}, "a", {5, 4, 3}},
      {{"B", "G", "R", "a.B", "a.G", "a.R"}, "", {2, 1, 0}},
      {{"a.Y", "a.b.Y"}, "a", {0}},
      {{"a.Y", "a.b.Y"}, "a.b", {1}},
      {{"R", "a.Y"}, "b", {}},
  };
  for (const Case& c : cases) {
    std::vector<RawChannel> channels;
    for (const std::string& name : c.channels)
      channels.push_back({name, kHalf});
    CAPTURE(c.layer);
    CAPTURE(c.channels.front());
    CAPTURE(c.channels.size());
    const RawPart part = scanlinePart(channels, 3, 2);
    writeFile(dir / "select.exr", buildExr({part}));
    crep::ExrReadOptions options;
    options.layer = c.layer;
    if (c.expected.empty()) {
      const std::string what = expectThrows<crep::FormatError>(dir / "select.exr", options);
      CHECK(contains(what, "select.exr"));
      CHECK(contains(what, "channels"));
    } else {
      checkRawContent(crep::readExr(dir / "select.exr", options), part, 0, c.expected);
    }
  }
}

TEST_CASE("EXR: deep and subsampled files are rejected with a clear message") {
  crep::test::TempDir dir;
  RawPart deep = scanlinePart({{"Z", kFloat}}, 4, 4);
  deep.type = "deepscanline";
  writeFile(dir / "deep.exr", buildExr({deep}, 0x800));
  CHECK(contains(expectThrows<crep::FormatError>(dir / "deep.exr"), "deep"));

  const RawPart sub = scanlinePart({{"Y", kFloat, 2, 2}}, 8, 4);
  writeFile(dir / "sub.exr", buildExr({sub}));
  CHECK(contains(expectThrows<crep::FormatError>(dir / "sub.exr"), "subsampled"));
}

TEST_CASE(
    "EXR: a chunk whose data size does not fit its compression and width is a FormatError naming the chunk") {
  crep::test::TempDir dir;
  SUBCASE(
      "uncompressed 160-pixel float rows in 12-byte chunks (OpenEXR would fill the rows from stale memory)") {
    RawPart part = scanlinePart({{"Y", kFloat}}, 160, 90);
    part.fakeChunkBytes = 12;
    writeFile(dir / "short.exr", buildExr({part}));
    const std::string what = expectThrows<crep::FormatError>(dir / "short.exr");
    INFO(what);
    CHECK(contains(what, (dir / "short.exr").string()));
    CHECK(contains(what, "chunk 0 (scanline 0)"));
    CHECK(contains(what, "data size 12 bytes"));
    CHECK(contains(what, "expected exactly 640"));
    CHECK_THROWS_AS((void)crep::readExrInfo(dir / "short.exr"), crep::FormatError);
  }
  SUBCASE("size fields of a file written by OpenEXR patched: smaller, larger, zero, negative") {
    crep::writeExr(dir / "ok.exr", Image(160, 90, 1, 0.5f),
                   crep::ExrWriteOptions(crep::ExrPixelType::Float, crep::ExrCompression::None));
    const Bytes original = readFile(dir / "ok.exr");
    const std::vector<std::size_t> chunks = chunkOffsets(original);
    REQUIRE(chunks.size() == 90);
    Bytes all = original;
    for (const std::size_t chunk : chunks)
      put32(all, chunk + 4, 12);
    writeFile(dir / "patched.exr", all);
    CHECK(contains(expectThrows<crep::FormatError>(dir / "patched.exr"),
                   "chunk 0 (scanline 0): data size 12 bytes, expected exactly 640"));
    for (const std::int32_t size : {12, 639, 641, 0, -1}) {
      CAPTURE(size);
      Bytes b = original;
      put32(b, chunks[7] + 4, static_cast<std::uint32_t>(size));
      writeFile(dir / "patched.exr", b);
      const std::string what = expectThrows<crep::FormatError>(dir / "patched.exr");
      INFO(what);
      CHECK(contains(what, "patched.exr"));
      CHECK(contains(what, "chunk 7 (scanline 7): data size " + std::to_string(size) + " bytes"));
    }
  }
  SUBCASE("compressed chunks: empty, or larger than the uncompressed data") {
    crep::writeExr(dir / "ok.exr", patternImage(37, 40, 3),
                   crep::ExrWriteOptions(crep::ExrPixelType::Half, crep::ExrCompression::Zip));
    const Bytes original = readFile(dir / "ok.exr");
    const std::vector<std::size_t> chunks = chunkOffsets(original);
    REQUIRE(chunks.size() == 3); // 16 lines per chunk
    for (const std::uint32_t size : {0u, 16u * 37 * 3 * 2 + 1, 0x7FFFFFFFu}) {
      CAPTURE(size);
      Bytes b = original;
      put32(b, chunks[1] + 4, size);
      writeFile(dir / "patched.exr", b);
      const std::string what = expectThrows<crep::FormatError>(dir / "patched.exr");
      INFO(what);
      CHECK(contains(what, "chunk 1 (scanlines 16-31)"));
      CHECK(contains(what, "expected 1 to 3552 (ZIP data of 37x16 pixels"));
    }
  }
  SUBCASE("a chunk header naming another line or tile") {
    crep::writeExr(dir / "ok.exr", Image(16, 8, 1, 0.5f),
                   crep::ExrWriteOptions(crep::ExrPixelType::Float, crep::ExrCompression::None));
    Bytes b = readFile(dir / "ok.exr");
    put32(b, chunkOffsets(b)[3], 2);
    writeFile(dir / "line.exr", b);
    CHECK(contains(expectThrows<crep::FormatError>(dir / "line.exr"),
                   "chunk 3 (scanline 3): its header names scanline 2"));

    RawPart tiled = scanlinePart({{"G", kHalf}, {"R", kFloat}}, 13, 11);
    tiled.tileWidth = 4;
    tiled.tileHeight = 4;
    const Bytes tiledBytes = buildExr({tiled});
    const std::size_t tableStart = headerEnd(tiledBytes);
    const std::size_t tile5 = static_cast<std::size_t>(get64(tiledBytes, tableStart + 5 * 8)); // tile (1, 1)
    b = tiledBytes;
    put32(b, tile5, 2);
    writeFile(dir / "tile.exr", b);
    CHECK(contains(expectThrows<crep::FormatError>(dir / "tile.exr"),
                   "chunk 5 (tile (1, 1) of level (0, 0)): its header names tile (2, 1)"));
    b = tiledBytes;
    put32(b, tile5 + 16, 4 * 4 * 6 - 2); // 4x4 pixels of half + float
    writeFile(dir / "tile.exr", b);
    CHECK(contains(expectThrows<crep::FormatError>(dir / "tile.exr"),
                   "chunk 5 (tile (1, 1) of level (0, 0)): data size 94 bytes, expected exactly 96"));
    // The clipped edge tile (3, 2) holds 1x3 pixels.
    const std::size_t edge = static_cast<std::size_t>(get64(tiledBytes, tableStart + 11 * 8));
    CHECK(get32(tiledBytes, edge + 16) == 3 * 6);
  }
  SUBCASE("chunk sizes of subsampled (chroma) channels follow their sampling") {
    // Luminance/chroma layout: full-resolution Y, BY and RY on every second line and column.
    const RawPart part = scanlinePart({{"BY", kHalf, 2, 2}, {"RY", kHalf, 2, 2}, {"Y", kHalf}}, 8, 6);
    writeFile(dir / "yc.exr", buildExr({part}));
    checkRawContent(crep::readExr(dir / "yc.exr"), part, 0, {2});
    Bytes b = readFile(dir / "yc.exr");
    const std::vector<std::size_t> chunks = chunkOffsets(b);
    CHECK(get32(b, chunks[0] + 4) == 8 * 2 + 2 * 4 * 2); // Y, then BY and RY at 4 columns
    CHECK(get32(b, chunks[1] + 4) == 8 * 2);             // odd line: Y only
    put32(b, chunks[1] + 4, 8 * 2 + 2 * 4 * 2);
    writeFile(dir / "yc.exr", b);
    CHECK(contains(expectThrows<crep::FormatError>(dir / "yc.exr"), "expected exactly 16"));
  }
  SUBCASE("RLE and ZIP chunks must decode to their full size (OpenEXR 3.1 does not check it)") {
    RawPart rle = scanlinePart({{"Y", kFloat}}, 160, 4);
    rle.compression = 1;
    rle.fakeChunk = {11, 0x80}; // a run of 12 bytes, for 640-byte lines
    writeFile(dir / "rle.exr", buildExr({rle}));
    CHECK(contains(expectThrows<crep::FormatError>(dir / "rle.exr"),
                   "chunk 0 (scanline 0): its RLE data decodes to 12 bytes, expected 640"));
    rle.fakeChunk.clear();
    for (int run = 0; run < 6; ++run) // 6 runs of 128 bytes: more than a line
      rle.fakeChunk.insert(rle.fakeChunk.end(), {127, 0x80});
    writeFile(dir / "rle.exr", buildExr({rle}));
    CHECK(contains(expectThrows<crep::FormatError>(dir / "rle.exr"), "decodes to more than 640 bytes"));
    rle.fakeChunk = {0x85, 1, 2}; // a literal run of 123 bytes with 2 present
    writeFile(dir / "rle.exr", buildExr({rle}));
    CHECK(contains(expectThrows<crep::FormatError>(dir / "rle.exr"), "its RLE data cannot be decoded"));

    RawPart zip = scanlinePart({{"Y", kFloat}}, 160, 20);
    zip.compression = 3; // 16 lines per chunk
    zip.fakeChunk = zlibStored(Bytes(12, 0x80));
    writeFile(dir / "zip.exr", buildExr({zip}));
    CHECK(contains(expectThrows<crep::FormatError>(dir / "zip.exr"),
                   "chunk 0 (scanlines 0-15): its ZIP data decodes to 12 bytes, expected 10240"));
    const Bytes stream = zlibStored(Bytes(12, 0x80));
    zip.fakeChunk.assign(stream.begin(), stream.begin() + 11); // no Adler-32: the stream is incomplete
    writeFile(dir / "zip.exr", buildExr({zip}));
    CHECK(contains(expectThrows<crep::FormatError>(dir / "zip.exr"), "its ZIP data cannot be decoded"));
    zip.compression = 2; // ZIPS: one line per chunk
    zip.fakeChunk = zlibStored(Bytes(600, 0x80));
    writeFile(dir / "zip.exr", buildExr({zip}));
    CHECK(contains(expectThrows<crep::FormatError>(dir / "zip.exr"), "its ZIPS data decodes to 600 bytes"));
  }
}

TEST_CASE("EXR: a 16384x16384 header over 64-byte chunks fails fast, before allocating the image") {
  crep::test::TempDir dir;
  const auto peakKiB = [] {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<long long>(usage.ru_maxrss);
  };
  struct Case {
    int compression, lines;
    const char* mentions;
  };
  const Case cases[] = {{0, 1, "chunk 0 (scanline 0): data size 64 bytes, expected exactly 65536"},
                        {3, 16, "implausibly large"},
                        {4, 32, "implausibly large"}};
  for (const Case& c : cases) {
    CAPTURE(c.compression);
    RawPart part = scanlinePart({{"Y", kFloat}}, 16384, 16384);
    part.compression = c.compression;
    // Built directly: buildExr would encode 1 GiB of pixels first.
    Writer w;
    w.u32(20000630);
    w.u32(2);
    w.append(partHeader(part, false, 0, part));
    const int chunks = 16384 / c.lines;
    const std::uint64_t first = w.b.size() + static_cast<std::uint64_t>(chunks) * 8;
    for (int i = 0; i < chunks; ++i)
      w.u64(first + static_cast<std::uint64_t>(i) * 72);
    for (int i = 0; i < chunks; ++i) {
      w.i32(i * c.lines);
      w.i32(64);
      w.append(Bytes(64, 0));
    }
    writeFile(dir / "huge.exr", w.b);
    const long long before = peakKiB();
    const auto start = std::chrono::steady_clock::now();
    const std::string what = expectThrows<crep::FormatError>(dir / "huge.exr");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    INFO(what);
    CHECK(contains(what, "huge.exr"));
    CHECK(contains(what, c.mentions));
    CHECK_MESSAGE(seconds < 1.0, "took " << seconds << " s");
    // The image would be 1 GiB of floats; the peak resident size must not have grown by 64 MiB.
    CHECK(peakKiB() - before < 64 * 1024);
  }
}

TEST_CASE("EXR: FLOAT samples holding the reader's sentinel bit patterns read back bit-exact") {
  crep::test::TempDir dir;
  Image image = patternImage(37, 23, 3);
  std::size_t i = 0;
  for (float& v : image.data()) {
    if (i % 5 == 0) v = floatOf(crep::detail::kExrUnwrittenSampleBits);
    if (i % 7 == 0) v = floatOf(crep::detail::kExrUnwrittenSampleRetryBits);
    ++i;
  }
  for (crep::ExrCompression compression :
       {crep::ExrCompression::None, crep::ExrCompression::Zip, crep::ExrCompression::Piz}) {
    CAPTURE(static_cast<int>(compression));
    crep::writeExr(dir / "sentinel.exr", image,
                   crep::ExrWriteOptions(crep::ExrPixelType::Float, compression));
    const Image back = crep::readExr(dir / "sentinel.exr");
    REQUIRE(back.sameShape(image));
    int bad = 0;
    for (std::size_t k = 0; k < image.data().size(); ++k)
      if (bitsOf(back.data()[k]) != bitsOf(image.data()[k]) && bad++ < 5)
        FAIL_CHECK("sample " << k << ": bits " << bitsOf(back.data()[k])
                             << " != " << bitsOf(image.data()[k]));
    CHECK(bad == 0);
  }
}

TEST_CASE("EXR: chunks OpenEXR stores uncompressed because compression does not help are read") {
  // Random bits do not compress: OpenEXR's writer then stores the chunk raw, with a size equal to the
  // uncompressed size, which the reader must accept for every codec.
  crep::test::TempDir dir;
  std::mt19937 random(77);
  Image image(37, 40, 3);
  for (float& v : image.data())
    v = floatOf(static_cast<std::uint32_t>(random()) & 0xBF7FFFFFu); // finite: exponent bit 30 clear
  for (crep::ExrCompression compression : {crep::ExrCompression::Zip, crep::ExrCompression::Piz}) {
    CAPTURE(static_cast<int>(compression));
    const int lines = compression == crep::ExrCompression::Zip ? 16 : 32;
    crep::writeExr(dir / "noise.exr", image, crep::ExrWriteOptions(crep::ExrPixelType::Float, compression));
    const Bytes b = readFile(dir / "noise.exr");
    int stored = 0;
    for (const std::size_t chunk : chunkOffsets(b)) {
      const int y = static_cast<int>(get32(b, chunk));
      const std::uint32_t raw = static_cast<std::uint32_t>(std::min(lines, 40 - y) * 37 * 3 * 4);
      CHECK(get32(b, chunk + 4) <= raw);
      stored += get32(b, chunk + 4) == raw ? 1 : 0;
    }
    CHECK(stored > 0);
    const Image back = crep::readExr(dir / "noise.exr");
    REQUIRE(back.sameShape(image));
    CHECK(std::memcmp(back.data().data(), image.data().data(), image.byteSize()) == 0);
  }
}

TEST_CASE("EXR: writeExrLayers round trip, channel naming and validation") {
  crep::test::TempDir dir;
  const Image beauty = patternImage(37, 23, 4);
  const Image depth = patternImage(37, 23, 1);
  const Image motion = patternImage(37, 23, 2);
  const crep::ExrLayer layers[] = {{"", &beauty}, {"depth", &depth}, {"motion", &motion}};
  for (crep::ExrPixelType type : {crep::ExrPixelType::Half, crep::ExrPixelType::Float}) {
    const fs::path path = dir / "layers.exr";
    crep::writeExrLayers(path, layers, type);
    std::vector<std::string> names;
    for (const auto& c : crep::readExrInfo(path).channels)
      names.push_back(c.name);
    CHECK(names == std::vector<std::string>{"A", "B", "G", "R", "depth.Y", "motion.G", "motion.R"});
    requireIdentical(crep::readExr(path), beauty);
    crep::ExrReadOptions options;
    options.layer = "depth";
    requireIdentical(crep::readExr(path, options), depth);
    options.layer = "motion";
    requireIdentical(crep::readExr(path, options), motion);
    options.layer = "missing";
    CHECK(contains(expectThrows<crep::FormatError>(path, options), "missing"));
  }

  const auto expectInvalid = [&](std::span<const crep::ExrLayer> bad, const std::string& parameter) {
    try {
      crep::writeExrLayers(dir / "bad.exr", bad);
      FAIL_CHECK("no exception, expected one for " << parameter);
    } catch (const crep::InvalidArgument& e) {
      CHECK(e.parameter() == parameter);
    }
    CHECK_FALSE(fs::exists(dir / "bad.exr"));
  };
  const Image smaller(36, 23, 3);
  const Image empty;
  const crep::ExrLayer mismatch[] = {{"a", &beauty}, {"b", &smaller}};
  const crep::ExrLayer duplicate[] = {{"a", &beauty}, {"a", &depth}};
  const crep::ExrLayer null[] = {{"a", nullptr}};
  const crep::ExrLayer emptyImage[] = {{"a", &empty}};
  expectInvalid(mismatch, "ExrLayer.image");
  expectInvalid(duplicate, "ExrLayer.name");
  expectInvalid(null, "ExrLayer.image");
  expectInvalid(emptyImage, "ExrLayer.image");
  expectInvalid({}, "layers");
  CHECK_THROWS_AS(crep::writeExr(dir / "bad.exr", empty), crep::InvalidArgument);
}

TEST_CASE("EXR: write failures are IoError naming the path and leave no file") {
  crep::test::TempDir dir;
  const fs::path path = dir / "no" / "such" / "dir" / "out.exr";
  try {
    crep::writeExr(path, Image(4, 4, 3));
    FAIL_CHECK("no exception");
  } catch (const crep::IoError& e) {
    CHECK(contains(e.what(), path.string()));
  }
  CHECK_FALSE(fs::exists(path));
  CHECK(fs::is_empty(dir.path()));
}

TEST_CASE("EXR: missing, empty, non-EXR and too-large files") {
  crep::test::TempDir dir;
  SUBCASE("missing file and directory are IoError naming the path") {
    CHECK(contains(expectThrows<crep::IoError>(dir / "missing.exr"), "missing.exr"));
    CHECK_THROWS_AS(crep::readExr(dir.path()), crep::IoError);
  }
  SUBCASE("empty file") {
    writeFile(dir / "empty.exr", {});
    const std::string what = expectThrows<crep::FormatError>(dir / "empty.exr");
    CHECK(contains(what, "empty.exr"));
    CHECK(contains(what, "empty"));
  }
  SUBCASE("random bytes and text") {
    std::mt19937 random(12345);
    Bytes noise(4096);
    for (auto& b : noise)
      b = static_cast<std::uint8_t>(random());
    writeFile(dir / "noise.exr", noise);
    CHECK(contains(expectThrows<crep::FormatError>(dir / "noise.exr"), "not an OpenEXR file"));
    const std::string text = "P3\n1 1\n255\n0 0 0\n";
    writeFile(dir / "text.exr", Bytes(text.begin(), text.end()));
    CHECK(contains(expectThrows<crep::FormatError>(dir / "text.exr"), "text.exr"));
    writeFile(dir / "magic-only.exr", Bytes{0x76, 0x2f, 0x31, 0x01});
    CHECK_THROWS_AS(crep::readExr(dir / "magic-only.exr"), crep::FormatError);
  }
  SUBCASE("data window 100000x100000, inverted or overflowing: rejected from the header") {
    crep::writeExr(dir / "small.exr", patternImage(37, 23, 3));
    const Bytes original = readFile(dir / "small.exr");
    const std::size_t dw = findAttribute(original, "dataWindow", "box2i");
    REQUIRE(dw != 0);
    const auto patched = [&](std::int32_t minX, std::int32_t minY, std::int32_t maxX, std::int32_t maxY) {
      Bytes b = original;
      put32(b, dw, static_cast<std::uint32_t>(minX));
      put32(b, dw + 4, static_cast<std::uint32_t>(minY));
      put32(b, dw + 8, static_cast<std::uint32_t>(maxX));
      put32(b, dw + 12, static_cast<std::uint32_t>(maxY));
      writeFile(dir / "patched.exr", b);
      return expectThrows<crep::FormatError>(dir / "patched.exr");
    };
    CHECK(contains(patched(0, 0, 99999, 99999), "too large"));
    CHECK(contains(patched(0, 0, 32768, 0), "too large"));     // 32769 wide
    CHECK(contains(patched(0, 0, 20000, 20000), "too large")); // sides ok, pixel count not
    const std::int32_t lo = std::numeric_limits<std::int32_t>::min(),
                       hi = std::numeric_limits<std::int32_t>::max();
    CHECK(contains(patched(lo, lo, hi, hi), "too large"));
    CHECK(contains(patched(10, 10, 0, 0), "data window"));
    CHECK(contains(patched(0, 0, 36, 40), "patched.exr")); // larger than the data: table/chunks don't match
  }
  SUBCASE("a small file claiming many pixels is rejected before allocating the image") {
    // 32768 x 2048 float (256 MiB) in a ~37 KB file: RLE chunks of 2 bytes each.
    RawPart part = scanlinePart({{"Y", kFloat}}, 32768, 2048);
    part.compression = 1; // RLE: one line per chunk
    part.fakeChunkBytes = 2;
    writeFile(dir / "bomb.exr", buildExr({part}));
    CHECK(contains(expectThrows<crep::FormatError>(dir / "bomb.exr"), "implausibly large"));
  }
  SUBCASE("ExrReadOptions.maxPixels is checked before reading") {
    crep::writeExr(dir / "small.exr", patternImage(37, 23, 3));
    crep::ExrReadOptions options;
    options.maxPixels = 37 * 23 - 1;
    CHECK(contains(expectThrows<crep::FormatError>(dir / "small.exr", options), "too large"));
    options.maxPixels = 37 * 23;
    CHECK(crep::readExr(dir / "small.exr", options).pixelCount() == 37 * 23);
    options.maxPixels = 0;
    CHECK_THROWS_AS(crep::readExr(dir / "small.exr", options), crep::InvalidArgument);
    crep::ExrReadOptions badPart;
    badPart.part = -1;
    CHECK_THROWS_AS(crep::readExr(dir / "small.exr", badPart), crep::InvalidArgument);
  }
  SUBCASE("absurd attribute size") {
    crep::writeExr(dir / "small.exr", patternImage(37, 23, 3));
    Bytes b = readFile(dir / "small.exr");
    const std::size_t value = findAttribute(b, "compression", "compression");
    REQUIRE(value != 0);
    put32(b, value - 4, 0x7FFFFFFF);
    writeFile(dir / "attr.exr", b);
    CHECK(contains(expectThrows<crep::FormatError>(dir / "attr.exr"), "invalid size"));
  }
}

TEST_CASE("EXR: large constant images (maximal compression ratio) are not mistaken for bombs") {
  crep::test::TempDir dir;
  const Image image(2048, 1024, 4, 0.25f); // 32 MiB as float
  for (crep::ExrCompression compression : {crep::ExrCompression::Zip, crep::ExrCompression::Piz}) {
    CAPTURE(static_cast<int>(compression));
    crep::writeExr(dir / "constant.exr", image, crep::ExrWriteOptions(crep::ExrPixelType::Half, compression));
    const auto fileSize = fs::file_size(dir / "constant.exr");
    CAPTURE(fileSize);
    const Image back = crep::readExr(dir / "constant.exr");
    REQUIRE(back.sameShape(image));
    CHECK(std::all_of(back.data().begin(), back.data().end(), [](float v) { return v == 0.25f; }));
  }
}

TEST_CASE("EXR: every truncation of a valid file is a FormatError, never a crash or a partial image") {
  crep::test::TempDir dir;
  const auto start = std::chrono::steady_clock::now();
  struct Variant {
    std::string name;
    Bytes bytes;
  };
  std::vector<Variant> variants;
  for (crep::ExrCompression compression :
       {crep::ExrCompression::Zip, crep::ExrCompression::Piz, crep::ExrCompression::None}) {
    crep::writeExr(dir / "full.exr", patternImage(37, 23, 4),
                   crep::ExrWriteOptions(crep::ExrPixelType::Half, compression));
    variants.push_back({"writer", readFile(dir / "full.exr")});
  }
  RawPart tiled = scanlinePart({{"G", kHalf}, {"R", kFloat}}, 13, 11);
  tiled.tileWidth = 4;
  tiled.tileHeight = 4;
  variants.push_back({"tiled", buildExr({tiled})});
  RawPart first = scanlinePart({{"Y", kFloat}}, 5, 4);
  first.name = "first";
  variants.push_back({"multi-part", buildExr({first, tiled})});
  for (const Variant& variant : variants) {
    CAPTURE(variant.name);
    REQUIRE_NOTHROW(writeFile(dir / "full.exr", variant.bytes));
    REQUIRE_NOTHROW((void)crep::readExr(dir / "full.exr"));
    // Every length through the headers and offset tables, then 200 evenly spread lengths
    // (including 10%, 50%, 90%) and the last 16 (all but 1 byte, ...).
    const std::size_t size = variant.bytes.size();
    std::set<std::size_t> lengths;
    for (std::size_t length = 0; length < std::min<std::size_t>(size, 600); ++length)
      lengths.insert(length);
    for (std::size_t k = 0; k < 200; ++k)
      lengths.insert(k * size / 200);
    for (std::size_t k = 1; k <= 16 && k <= size; ++k)
      lengths.insert(size - k);
    int wrong = 0;
    for (const std::size_t length : lengths) {
      writeFile(dir / "cut.exr", variant.bytes, length);
      try {
        (void)crep::readExr(dir / "cut.exr");
        if (wrong++ < 5)
          FAIL_CHECK("truncated to " << length << " of " << variant.bytes.size() << " bytes: no error");
      } catch (const crep::FormatError& e) {
        if (!contains(e.what(), "cut.exr") && wrong++ < 5)
          FAIL_CHECK("message does not name the file: " << e.what());
      } catch (const std::exception& e) {
        if (wrong++ < 5) FAIL_CHECK("truncated to " << length << ": wrong exception type: " << e.what());
      }
    }
    CHECK(wrong == 0);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK_MESSAGE(seconds < 60.0, "truncation sweep took " << seconds << " s");
}

namespace {

// The image an uncompressed half RGB file written by writeExr holds according to its bytes: chunk y at
// the offset its table gives, [y][size] then the B, G and R halves of the line.
Image decodeUncompressedHalfRgb(const Bytes& b, int width, int height) {
  Image image(width, height, 3);
  const std::size_t tableStart = headerEnd(b);
  for (int y = 0; y < height; ++y) {
    const std::size_t data =
        static_cast<std::size_t>(get64(b, tableStart + static_cast<std::size_t>(y) * 8)) + 8;
    for (int fileChannel = 0; fileChannel < 3; ++fileChannel) // B, G, R
      for (int x = 0; x < width; ++x) {
        const std::size_t at = data + static_cast<std::size_t>(fileChannel * width + x) * 2;
        REQUIRE(at + 2 <= b.size());
        const auto half = static_cast<std::uint16_t>(b[at] | (b[at + 1] << 8));
        image.at(x, height - 1 - y, 2 - fileChannel) = halfToFloat(half);
      }
  }
  return image;
}

// Same samples, NaN matching any NaN.
int differingSamples(const Image& actual, const Image& expected) {
  REQUIRE(actual.sameShape(expected));
  int bad = 0;
  for (std::size_t i = 0; i < actual.data().size(); ++i) {
    const float a = actual.data()[i], e = expected.data()[i];
    if (!(std::isnan(a) && std::isnan(e)) && bitsOf(a) != bitsOf(e)) ++bad;
  }
  return bad;
}

// Rebuilds a single-part scanline file whose chunks follow its table, with the pixel data of chunk i
// cut to keep[i] bytes where keep[i] >= 0 (its size field to match), the later chunks moved up and
// the offset table updated. Bytes after the last chunk are kept.
Bytes withShortChunks(const Bytes& b, const std::vector<std::size_t>& chunks,
                      const std::vector<std::int64_t>& keep) {
  const std::size_t tableStart = headerEnd(b);
  Writer out;
  for (std::size_t k = 0; k < chunks.front(); ++k)
    out.u8(b[k]); // header and table
  std::size_t end = 0;
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    const std::size_t size = get32(b, chunks[i] + 4);
    const std::size_t kept = keep[i] >= 0 ? static_cast<std::size_t>(keep[i]) : size;
    put32(out.b, tableStart + i * 8, static_cast<std::uint32_t>(out.b.size()));
    put32(out.b, tableStart + i * 8 + 4, 0);
    out.u32(get32(b, chunks[i])); // y
    out.u32(static_cast<std::uint32_t>(kept));
    for (std::size_t k = 0; k < kept; ++k)
      out.u8(b[chunks[i] + 8 + k]);
    end = chunks[i] + 8 + size;
  }
  for (std::size_t k = end; k < b.size(); ++k)
    out.u8(b[k]);
  return out.b;
}

} // namespace

TEST_CASE("EXR: corrupted bytes give an image or a FormatError, never a crash or another exception") {
  crep::test::TempDir dir;
  const auto start = std::chrono::steady_clock::now();
  std::vector<Bytes> originals;
  for (crep::ExrCompression compression :
       {crep::ExrCompression::Zip, crep::ExrCompression::Piz, crep::ExrCompression::None}) {
    crep::writeExr(dir / "ok.exr", patternImage(37, 23, 3),
                   crep::ExrWriteOptions(crep::ExrPixelType::Half, compression));
    originals.push_back(readFile(dir / "ok.exr"));
  }
  // Where the pixel data of the uncompressed file starts (its header and offset table end).
  const std::size_t uncompressedPixels = chunkOffsets(originals[2]).front();
  std::mt19937 random(20240601);
  int formatErrors = 0, successes = 0, checkedAgainstBytes = 0;
  for (int iteration = 0; iteration < 600; ++iteration) {
    const std::size_t variant = static_cast<std::size_t>(iteration) % originals.size();
    Bytes b = originals[variant];
    const int flips = 1 + static_cast<int>(random() % 8);
    // Half the mutations hit the header, where they are most dangerous.
    const std::size_t region = iteration % 2 == 0 ? std::min<std::size_t>(b.size(), 400) : b.size();
    std::size_t lowest = b.size();
    for (int f = 0; f < flips; ++f) {
      const std::size_t at = random() % region;
      lowest = std::min(lowest, at);
      b[at] = random() % 3 == 0 ? static_cast<std::uint8_t>(0xFF) : static_cast<std::uint8_t>(random());
    }
    writeFile(dir / "fuzz.exr", b);
    try {
      const Image image = crep::readExr(dir / "fuzz.exr");
      CHECK(image.pixelCount() <= static_cast<std::size_t>(Image::kMaxPixels));
      // No sample of an accepted file comes from unwritten memory...
      if (const int unwritten = unwrittenSamples(image); unwritten != 0)
        FAIL_CHECK("iteration " << iteration << ": " << unwritten << " samples from unwritten memory");
      // ...and an uncompressed file with an intact header and offset table holds exactly its bytes.
      if (variant == 2 && lowest >= uncompressedPixels) {
        ++checkedAgainstBytes;
        if (const int bad = differingSamples(image, decodeUncompressedHalfRgb(b, 37, 23)); bad != 0)
          FAIL_CHECK("iteration " << iteration << ": " << bad << " samples differ from the file's bytes");
      }
      ++successes;
    } catch (const crep::FormatError&) {
      ++formatErrors;
    } catch (const std::exception& e) {
      FAIL_CHECK("iteration " << iteration << ": unexpected exception type: " << e.what());
    }
  }
  MESSAGE(formatErrors << " rejected, " << successes << " accepted (" << checkedAgainstBytes
                       << " checked against the file's bytes)");
  // Both outcomes occur (e.g. a changed pixel value of an uncompressed file is still a valid file).
  CHECK(formatErrors > 0);
  CHECK(successes > 0);
  CHECK(checkedAgainstBytes > 0);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  CHECK_MESSAGE(seconds < 60.0, "corruption sweep took " << seconds << " s");
}

TEST_CASE(
    "EXR: corrupted chunk sizes (NONE, ZIP, PIZ) are rejected or read in full, never from unwritten memory") {
  crep::test::TempDir dir;
  // A smooth image (values 1 + k/64, exact in half, in a narrow range of half bit patterns), so that
  // ZIP and PIZ shrink every chunk; 20 pixels wide, so that a chunk's raw data (<= 32 lines x 20 x 3
  // x 2 bytes) stays below ASan's fill limit.
  Image image(20, 70, 3);
  for (int y = 0; y < 70; ++y)
    for (int x = 0; x < 20; ++x)
      for (int c = 0; c < 3; ++c)
        image.at(x, y, c) = 1.0f + static_cast<float>((x + 2 * y + 5 * c) % 64) / 64.0f;
  struct Variant {
    crep::ExrCompression compression;
    int lines;
    Bytes bytes;
    std::vector<std::size_t> chunks;
    std::vector<std::uint32_t> sizes, raw;
  };
  std::vector<Variant> variants = {
      {crep::ExrCompression::None, 1, {}, {}, {}, {}},
      {crep::ExrCompression::Zip, 16, {}, {}, {}, {}},
      {crep::ExrCompression::Piz, 32, {}, {}, {}, {}},
  };
  for (Variant& v : variants) {
    crep::writeExr(dir / "ok.exr", image, crep::ExrWriteOptions(crep::ExrPixelType::Half, v.compression));
    v.bytes = readFile(dir / "ok.exr");
    // Trailing bytes, so that the last chunk can grow inside the file. (OpenEXR reads the chunks of a
    // single-part file one after the other, so an earlier chunk that grows misplaces the next one.)
    v.bytes.resize(v.bytes.size() + 1024, 0);
    writeFile(dir / "ok.exr", v.bytes);
    v.chunks = chunkOffsets(v.bytes);
    REQUIRE(v.chunks.size() == static_cast<std::size_t>((70 + v.lines - 1) / v.lines));
    for (std::size_t i = 0; i < v.chunks.size(); ++i) {
      v.sizes.push_back(get32(v.bytes, v.chunks[i] + 4));
      v.raw.push_back(
          static_cast<std::uint32_t>(std::min(v.lines, 70 - static_cast<int>(i) * v.lines) * 20 * 3 * 2));
      CAPTURE(i);
      if (v.compression == crep::ExrCompression::None)
        REQUIRE(v.sizes.back() == v.raw.back());
      else
        REQUIRE(v.sizes.back() < v.raw.back()); // really compressed
    }
    requireIdentical(crep::readExr(dir / "ok.exr"), image);
  }

  std::mt19937 random(20240602);
  int rejected = 0, rejectedCut = 0, accepted = 0, acceptedRaw = 0, acceptedCut = 0, acceptedChanged = 0;
  for (int iteration = 0; iteration < 360; ++iteration) {
    const Variant& v = variants[static_cast<std::size_t>(iteration) % variants.size()];
    Bytes b = v.bytes;
    // A quarter of the files get every chunk's size replaced, the others one chunk's, half of the
    // time the last one's.
    const bool all = random() % 4 == 0;
    const std::size_t one = random() % 2 == 0 ? v.chunks.size() - 1 : random() % v.chunks.size();
    const int kind = static_cast<int>(random() % 14);
    // A third of the smaller sizes also cut the chunk's data to match, and the file is laid out
    // again around it: a consistent file whose chunks are short (as in the report that led to the
    // size checks), which OpenEXR reads to the end, converting whole lines from its buffers.
    const bool cut = random() % 3 == 0;
    std::vector<std::int64_t> keep(v.chunks.size(), -1);
    bool changed = false, storedRaw = false, payloadCut = false;
    for (std::size_t i = 0; i < v.chunks.size(); ++i) {
      if (!all && i != one) continue;
      const std::int64_t size = v.sizes[i], raw = v.raw[i];
      const std::int64_t replacements[14] = {size - 1,
                                             size / 2,
                                             12,
                                             1,
                                             0,
                                             -1,
                                             std::numeric_limits<std::int32_t>::min(),
                                             std::numeric_limits<std::int32_t>::max(),
                                             size + 1,
                                             size * 2,
                                             raw - 1,
                                             raw,
                                             raw + 1,
                                             static_cast<std::int32_t>(random())};
      const auto replacement = static_cast<std::uint32_t>(replacements[kind]);
      if (cut && replacements[kind] >= 0 && replacements[kind] < size) {
        keep[i] = replacements[kind];
        payloadCut = true;
      }
      put32(b, v.chunks[i] + 4, replacement);
      changed = changed || replacement != static_cast<std::uint32_t>(size);
      // A compressed chunk of exactly the raw size is read as uncompressed data.
      storedRaw = storedRaw || (v.compression != crep::ExrCompression::None && replacement == raw);
    }
    if (payloadCut) b = withShortChunks(v.bytes, v.chunks, keep);
    writeFile(dir / "sizes.exr", b);
    CAPTURE(iteration);
    try {
      const Image back = crep::readExr(dir / "sizes.exr");
      ++accepted;
      CHECK(unwrittenSamples(back) == 0);
      if (v.compression == crep::ExrCompression::None) CHECK_FALSE(changed); // exact sizes only
      if (payloadCut) {
        ++acceptedCut; // a compressed stream that still decodes once cut: whatever it holds
      } else if (storedRaw) {
        ++acceptedRaw; // its pixels are the file's bytes, whatever they mean
      } else {
        // The pixel data itself is intact: an accepted file is the original image.
        CHECK(differingSamples(back, image) == 0);
        acceptedChanged += changed ? 1 : 0;
      }
    } catch (const crep::FormatError& e) {
      ++rejected;
      rejectedCut += payloadCut ? 1 : 0;
      CHECK(contains(e.what(), "sizes.exr"));
    } catch (const std::exception& e) {
      FAIL_CHECK("unexpected exception type: " << e.what());
    }
  }
  MESSAGE(rejected << " rejected (" << rejectedCut << " with cut data), " << accepted << " accepted ("
                   << acceptedChanged << " with a changed size, " << acceptedRaw << " read as stored raw, "
                   << acceptedCut << " with cut data)");
  CHECK(rejected > 0);
  CHECK(accepted > 0);
}

TEST_CASE("EXR: writeExr writes float by default (data images keep every bit)") {
  crep::test::TempDir dir;
  Image image(3, 1, 1);
  image.at(0, 0) = 1.0f / 3.0f;
  image.at(1, 0) = 0.9995f; // a depth half rounds to 1 (the sky)
  image.at(2, 0) = 70000.0f;
  crep::writeExr(dir / "default.exr", image);
  const Image back = crep::readExr(dir / "default.exr");
  for (int x = 0; x < 3; ++x)
    CHECK(back.at(x, 0) == image.at(x, 0));
  CHECK(crep::readExrInfo(dir / "default.exr").channels.at(0).pixelType == crep::ExrPixelType::Float);
}
