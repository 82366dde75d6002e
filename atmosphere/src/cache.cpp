// The disk cache of the atmosphere tables (crep/atmosphere/atmosphere.h, "Disk cache").
//
// ---------------------------------------------------------------------------------------------------
// Cache key (atmosphereCacheKey): FNV-1a 64 (Fowler, Noll and Vo) over, in this order, the ASCII tag
// "crep-atmosphere-key-4", then the little-endian IEEE-754 bytes of the 15 doubles of AtmosphereParameters
//   earthRadius, atmosphereHeight, rayleighScattering.x, .y, .z, rayleighScaleHeight,
//   mieScattering.x, .y, .z, mieAbsorption.x, .y, .z, mieScaleHeight, mieG, groundAlbedo
// and the little-endian int32 bytes of the 16 ints of AtmospherePrecomputeOptions
//   size.height, size.viewZenith, size.sunZenith, size.sunView, orders, singleSteps, orderSteps,
//   sphereSamples, opticalDepthHeight, opticalDepthZenith, opticalDepthSteps, ambientSize, combinedMie (0,
//   1), multipleScattering (0 Lut, 1 Orders), multipleScatteringSize, multipleScatteringSteps
// (keepOrders and the thread count do not change the tables and are left out). The key is the 64-bit
// digest as 16 lower-case hex digits. Exact bytes: 0.0 and -0.0 give different keys.
//
// File format (version 2; version 1 stored L1 with its phase functions and L_M), every number
// little-endian, no padding:
//   offset  size  field
//        0     8  magic "CREPATM1" (ASCII)
//        8     4  uint32 version = 2
//       12    16  the cache key of the stored parameters and options (16 ASCII hex digits)
//       28   120  15 float64: the AtmosphereParameters fields in the key's order
//      148    64  16 int32: the AtmospherePrecomputeOptions ints in the key's order
//      212     4  uint32 keepOrders (0 or 1)
//      216     4  uint32 K, the number of per-order tables that follow (0, or `orders` when keepOrders)
//      220    12  int32 width, height, channels of the optical depth image
//                 (must be opticalDepthHeight, opticalDepthZenith, 2)
//      232    12  int32 width, height, channels of the ambient image (must be ambientSize, 1, 3)
//      244    16  int32 N_h, N_alpha, N_phi, N_theta of every 4D table (must equal options.size)
//      260        float32 data, each block in its in-memory order:
//                   optical depth (W * H * 2), ambient (ambientSize * 3),
//                   Psi_ms (multipleScatteringSize^2 * 3; only when usesMultipleScatteringLut),
//                   single, singleMie (not with combinedMie), higherOrders, then the K order tables L1..LK
//                   (each N_h * N_alpha * N_phi * N_theta * 4, the packed order of AtmosphereTable4D)
//      end-8   8  uint64 checksum: FNV-1a 64 of every preceding byte of the file
// A reader checks the magic, the version, every size against the limits of validate(options) before it
// allocates anything, the file's length against the length the sizes imply, the checksum, the key against
// the stored parameters and options, and throws IoError naming the file and the reason otherwise.
// A writer writes `<path>.tmp-<unique>` and renames it over `path`, so a crash never leaves a partial file
// under the final name.
#include <crep/atmosphere/atmosphere.h>
#include <crep/core/error.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

namespace crep {

namespace {

namespace fs = std::filesystem;

constexpr char kMagic[8] = {'C', 'R', 'E', 'P', 'A', 'T', 'M', '1'};
constexpr std::uint32_t kVersion = 2;
constexpr std::size_t kKeyDigits = 16;
constexpr std::size_t kHeaderBytes = 260;
constexpr std::size_t kParameterFields = 15;
constexpr std::size_t kOptionFields = 16;
constexpr std::size_t kChecksumBytes = 8;

constexpr std::uint64_t kFnvOffset = 14695981039346656037ull;
constexpr std::uint64_t kFnvPrime = 1099511628211ull;

// FNV-1a 64 (Fowler, Noll and Vo): a running digest of bytes.
struct Fnv1a64 {
  std::uint64_t state = kFnvOffset;
  void add(const unsigned char* bytes, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      state ^= bytes[i];
      state *= kFnvPrime;
    }
  }
};

// Little-endian encoding of the scalar fields.
void putU32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i)
    out.push_back(static_cast<char>((v >> (8 * i)) & 0xffu));
}
void putU64(std::string& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i)
    out.push_back(static_cast<char>((v >> (8 * i)) & 0xffu));
}
void putI32(std::string& out, int v) {
  putU32(out, static_cast<std::uint32_t>(v));
}
void putF64(std::string& out, double v) {
  putU64(out, std::bit_cast<std::uint64_t>(v));
}

std::uint32_t getU32(const unsigned char* b) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i)
    v |= static_cast<std::uint32_t>(b[i]) << (8 * i);
  return v;
}
std::uint64_t getU64(const unsigned char* b) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i)
    v |= static_cast<std::uint64_t>(b[i]) << (8 * i);
  return v;
}
int getI32(const unsigned char* b) {
  return static_cast<int>(getU32(b));
}
double getF64(const unsigned char* b) {
  return std::bit_cast<double>(getU64(b));
}

// The 15 doubles of the parameters in the key's (and the file's) order.
std::array<double, kParameterFields> parameterFields(const AtmosphereParameters& p) {
  return {p.earthRadius,          p.atmosphereHeight,
          p.rayleighScattering.x, p.rayleighScattering.y,
          p.rayleighScattering.z, p.rayleighScaleHeight,
          p.mieScattering.x,      p.mieScattering.y,
          p.mieScattering.z,      p.mieAbsorption.x,
          p.mieAbsorption.y,      p.mieAbsorption.z,
          p.mieScaleHeight,       p.mieG,
          p.groundAlbedo};
}
AtmosphereParameters parametersFromFields(const std::array<double, kParameterFields>& f) {
  AtmosphereParameters p;
  p.earthRadius = f[0];
  p.atmosphereHeight = f[1];
  p.rayleighScattering = glm::dvec3(f[2], f[3], f[4]);
  p.rayleighScaleHeight = f[5];
  p.mieScattering = glm::dvec3(f[6], f[7], f[8]);
  p.mieAbsorption = glm::dvec3(f[9], f[10], f[11]);
  p.mieScaleHeight = f[12];
  p.mieG = f[13];
  p.groundAlbedo = f[14];
  return p;
}

// The 13 ints of the options in the key's (and the file's) order.
std::array<int, kOptionFields> optionFields(const AtmospherePrecomputeOptions& o) {
  return {o.size.height,
          o.size.viewZenith,
          o.size.sunZenith,
          o.size.sunView,
          o.orders,
          o.singleSteps,
          o.orderSteps,
          o.sphereSamples,
          o.opticalDepthHeight,
          o.opticalDepthZenith,
          o.opticalDepthSteps,
          o.ambientSize,
          o.combinedMie ? 1 : 0,
          static_cast<int>(o.multipleScattering),
          o.multipleScatteringSize,
          o.multipleScatteringSteps};
}
AtmospherePrecomputeOptions optionsFromFields(const std::array<int, kOptionFields>& f, bool keepOrders) {
  AtmospherePrecomputeOptions o;
  o.size = {f[0], f[1], f[2], f[3]};
  o.orders = f[4];
  o.singleSteps = f[5];
  o.orderSteps = f[6];
  o.sphereSamples = f[7];
  o.opticalDepthHeight = f[8];
  o.opticalDepthZenith = f[9];
  o.opticalDepthSteps = f[10];
  o.ambientSize = f[11];
  o.combinedMie = f[12] != 0;
  o.multipleScattering = static_cast<AtmosphereMultipleScattering>(f[13]);
  o.multipleScatteringSize = f[14];
  o.multipleScatteringSteps = f[15];
  o.keepOrders = keepOrders;
  return o;
}

bool sameParameters(const AtmosphereParameters& a, const AtmosphereParameters& b) {
  return parameterFields(a) == parameterFields(b);
}
// Every field that changes the tables (keepOrders excluded).
bool sameOptions(const AtmospherePrecomputeOptions& a, const AtmospherePrecomputeOptions& b) {
  return optionFields(a) == optionFields(b);
}

std::string quoted(const fs::path& path) {
  return "'" + path.string() + "'";
}

[[noreturn]] void throwRead(const fs::path& path, const std::string& why) {
  throw IoError("crep: cannot read atmosphere tables " + quoted(path) + ": " + why);
}
[[noreturn]] void throwWrite(const fs::path& path, const std::string& why) {
  throw IoError("crep: cannot write atmosphere tables " + quoted(path) + ": " + why);
}

std::size_t tableFloats(const AtmosphereTableSize& s) {
  return static_cast<std::size_t>(s.height) * static_cast<std::size_t>(s.viewZenith) *
         static_cast<std::size_t>(s.sunZenith) * static_cast<std::size_t>(s.sunView) * 4u;
}

// The limits of validate(AtmospherePrecomputeOptions) (atmosphere.h), checked on a file's sizes before
// anything is allocated from them. Returns the reason, or empty when they hold.
std::string sizeProblem(const std::array<int, kOptionFields>& f) {
  static const char* const names[kOptionFields] = {"size.height",
                                                   "size.viewZenith",
                                                   "size.sunZenith",
                                                   "size.sunView",
                                                   "orders",
                                                   "singleSteps",
                                                   "orderSteps",
                                                   "sphereSamples",
                                                   "opticalDepthHeight",
                                                   "opticalDepthZenith",
                                                   "opticalDepthSteps",
                                                   "ambientSize",
                                                   "combinedMie",
                                                   "multipleScattering",
                                                   "multipleScatteringSize",
                                                   "multipleScatteringSteps"};
  for (std::size_t i = 0; i < kOptionFields; ++i) {
    const int v = f[i];
    int lo = 2, hi = 2048;
    if (i == 4) {
      lo = 1;
      hi = 16;
    } else if (i >= 5 && i <= 7) {
      lo = 1;
      hi = 4096;
    } else if (i == 10) {
      lo = 1;
      hi = 4096;
    } else if (i == 12 || i == 13) {
      lo = 0;
      hi = 1;
    } else if (i == 15) {
      lo = 1;
      hi = 4096;
    }
    if (v < lo || v > hi)
      return std::string("stored ") + names[i] + " = " + std::to_string(v) + " outside [" +
             std::to_string(lo) + ", " + std::to_string(hi) + "]";
  }
  if (f[1] < 4 || f[1] % 2 != 0)
    return "stored size.viewZenith = " + std::to_string(f[1]) + " is not even and >= 4";
  if (static_cast<long long>(f[2]) * f[3] > 2048)
    return "stored packed depth size.sunZenith * size.sunView = " +
           std::to_string(static_cast<long long>(f[2]) * f[3]) + " > 2048";
  return {};
}

std::string hex64(std::uint64_t v) {
  static const char digits[] = "0123456789abcdef";
  std::string s(kKeyDigits, '0');
  for (std::size_t i = 0; i < kKeyDigits; ++i)
    s[kKeyDigits - 1 - i] = digits[(v >> (4 * i)) & 0xfu];
  return s;
}

// Appends `n` floats little-endian.
void putFloats(std::string& out, const float* data, std::size_t n) {
  if constexpr (std::endian::native == std::endian::little) {
    out.append(reinterpret_cast<const char*>(data), n * sizeof(float));
  } else {
    for (std::size_t i = 0; i < n; ++i)
      putU32(out, std::bit_cast<std::uint32_t>(data[i]));
  }
}

// Decodes `n` little-endian floats.
void getFloats(const unsigned char* bytes, float* data, std::size_t n) {
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(data, bytes, n * sizeof(float));
  } else {
    for (std::size_t i = 0; i < n; ++i)
      data[i] = std::bit_cast<float>(getU32(bytes + 4 * i));
  }
}

// Reads a file block by block, hashing every byte it hands out.
class HashingReader {
public:
  HashingReader(std::ifstream& in, const fs::path& path) : in_(in), path_(path) {}
  void read(unsigned char* out, std::size_t n, const char* what) {
    in_.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(n));
    if (static_cast<std::size_t>(in_.gcount()) != n) throwRead(path_, std::string("truncated in ") + what);
    hash_.add(out, n);
  }
  // Reads `n` floats into `data` in chunks (no buffer the size of the table).
  void readFloats(float* data, std::size_t n, const char* what) {
    constexpr std::size_t kChunk = 1u << 16;
    std::vector<unsigned char> buffer(std::min(n, kChunk) * sizeof(float));
    for (std::size_t done = 0; done < n;) {
      const std::size_t m = std::min(kChunk, n - done);
      read(buffer.data(), m * sizeof(float), what);
      getFloats(buffer.data(), data + done, m);
      done += m;
    }
  }
  std::uint64_t digest() const { return hash_.state; }

private:
  std::ifstream& in_;
  const fs::path& path_;
  Fnv1a64 hash_;
};

std::string uniqueSuffix() {
  static std::atomic<unsigned long long> counter{0};
  const auto now =
      static_cast<unsigned long long>(std::chrono::steady_clock::now().time_since_epoch().count());
  std::ostringstream s;
  s << ".tmp-" << std::hash<std::thread::id>{}(std::this_thread::get_id()) << "-" << now << "-" << counter++;
  return s.str();
}

} // namespace

std::string atmosphereCacheKey(const AtmosphereParameters& p, const AtmospherePrecomputeOptions& o) {
  std::string bytes = "crep-atmosphere-key-4";
  for (double v : parameterFields(p))
    putF64(bytes, v);
  for (int v : optionFields(o))
    putI32(bytes, v);
  Fnv1a64 hash;
  hash.add(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
  return hex64(hash.state);
}

void saveAtmosphereTables(const AtmosphereTables& tables, const fs::path& path) {
  const AtmospherePrecomputeOptions& o = tables.options;
  const std::array<int, kOptionFields> sizes = optionFields(o);
  if (const std::string problem = sizeProblem(sizes); !problem.empty()) throwWrite(path, problem);
  const std::size_t floats4D = tableFloats(o.size);
  const bool withOrders = o.keepOrders && !tables.orders.empty();
  if (withOrders && tables.orders.size() != static_cast<std::size_t>(o.orders))
    throwWrite(path, std::to_string(tables.orders.size()) +
                         " order tables for orders = " + std::to_string(o.orders));
  // Every block must have the size the options imply (what a reader checks).
  auto checkTable = [&](const AtmosphereTable4D& t, const std::string& name) {
    if (t.size.height != o.size.height || t.size.viewZenith != o.size.viewZenith ||
        t.size.sunZenith != o.size.sunZenith || t.size.sunView != o.size.sunView || t.rgba.size() != floats4D)
      throwWrite(path, "table " + name + " does not have the options' size (" +
                           std::to_string(t.rgba.size()) + " floats, expected " + std::to_string(floats4D) +
                           ")");
  };
  checkTable(tables.single, "single");
  if (!o.combinedMie) checkTable(tables.singleMie, "singleMie");
  checkTable(tables.higherOrders, "higherOrders");
  if (withOrders)
    for (std::size_t i = 0; i < tables.orders.size(); ++i)
      checkTable(tables.orders[i], "orders[" + std::to_string(i) + "]");
  if (tables.opticalDepth.width() != o.opticalDepthHeight ||
      tables.opticalDepth.height() != o.opticalDepthZenith || tables.opticalDepth.channels() != 2)
    throwWrite(path, "the optical depth image is not opticalDepthHeight x opticalDepthZenith x 2");
  if (tables.ambient.width() != o.ambientSize || tables.ambient.height() != 1 ||
      tables.ambient.channels() != 3)
    throwWrite(path, "the ambient image is not ambientSize x 1 x 3");
  if (usesMultipleScatteringLut(o) && (tables.multipleScatteringLut.width() != o.multipleScatteringSize ||
                                       tables.multipleScatteringLut.height() != o.multipleScatteringSize ||
                                       tables.multipleScatteringLut.channels() != 3))
    throwWrite(path, "the multiple scattering table is not multipleScatteringSize^2 x 3");

  std::string header;
  header.append(kMagic, sizeof kMagic);
  putU32(header, kVersion);
  header += atmosphereCacheKey(tables.parameters, o);
  for (double v : parameterFields(tables.parameters))
    putF64(header, v);
  for (int v : sizes)
    putI32(header, v);
  putU32(header, withOrders ? 1u : 0u);
  putU32(header, withOrders ? static_cast<std::uint32_t>(tables.orders.size()) : 0u);
  putI32(header, tables.opticalDepth.width());
  putI32(header, tables.opticalDepth.height());
  putI32(header, tables.opticalDepth.channels());
  putI32(header, tables.ambient.width());
  putI32(header, tables.ambient.height());
  putI32(header, tables.ambient.channels());
  putI32(header, o.size.height);
  putI32(header, o.size.viewZenith);
  putI32(header, o.size.sunZenith);
  putI32(header, o.size.sunView);
  if (header.size() != kHeaderBytes)
    throwWrite(path, "internal error: header of " + std::to_string(header.size()) + " bytes");

  fs::path temporary = path;
  temporary += uniqueSuffix();
  try {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throwWrite(path, "cannot create the temporary file " + quoted(temporary));
    Fnv1a64 hash;
    auto emit = [&](const std::string& block) {
      hash.add(reinterpret_cast<const unsigned char*>(block.data()), block.size());
      out.write(block.data(), static_cast<std::streamsize>(block.size()));
    };
    emit(header);
    // Float blocks in chunks, so no copy of a whole table is made.
    auto emitFloats = [&](const float* data, std::size_t n) {
      constexpr std::size_t kChunk = 1u << 16;
      std::string block;
      for (std::size_t done = 0; done < n;) {
        const std::size_t m = std::min(kChunk, n - done);
        block.clear();
        putFloats(block, data + done, m);
        emit(block);
        done += m;
      }
    };
    emitFloats(tables.opticalDepth.data().data(), tables.opticalDepth.sampleCount());
    emitFloats(tables.ambient.data().data(), tables.ambient.sampleCount());
    if (usesMultipleScatteringLut(o))
      emitFloats(tables.multipleScatteringLut.data().data(), tables.multipleScatteringLut.sampleCount());
    emitFloats(tables.single.rgba.data(), floats4D);
    if (!o.combinedMie) emitFloats(tables.singleMie.rgba.data(), floats4D);
    emitFloats(tables.higherOrders.rgba.data(), floats4D);
    if (withOrders)
      for (const AtmosphereTable4D& t : tables.orders)
        emitFloats(t.rgba.data(), floats4D);
    std::string checksum;
    putU64(checksum, hash.state);
    out.write(checksum.data(), static_cast<std::streamsize>(checksum.size()));
    out.close();
    if (!out) throwWrite(path, "writing " + quoted(temporary) + " failed");
    fs::rename(temporary, path);
  } catch (const IoError&) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw;
  } catch (const std::exception& e) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throwWrite(path, e.what());
  }
}

AtmosphereTables loadAtmosphereTables(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throwRead(path, "no such file");
  const std::uintmax_t fileBytes = fs::file_size(path, ec);
  if (ec) throwRead(path, "cannot query its size (" + ec.message() + ")");
  std::ifstream in(path, std::ios::binary);
  if (!in) throwRead(path, "cannot open it");
  HashingReader reader(in, path);

  std::array<unsigned char, kHeaderBytes> h{};
  if (fileBytes < kHeaderBytes + kChecksumBytes)
    throwRead(path, "truncated: " + std::to_string(fileBytes) + " bytes, shorter than the header");
  reader.read(h.data(), kHeaderBytes, "the header");
  if (std::memcmp(h.data(), kMagic, sizeof kMagic) != 0) throwRead(path, "bad magic (not a CREPATM1 file)");
  if (const std::uint32_t version = getU32(h.data() + 8); version != kVersion)
    throwRead(path, "unsupported version " + std::to_string(version) + " (expected " +
                        std::to_string(kVersion) + ")");
  const std::string storedKey(reinterpret_cast<const char*>(h.data() + 12), kKeyDigits);
  std::array<double, kParameterFields> pf{};
  for (std::size_t i = 0; i < pf.size(); ++i)
    pf[i] = getF64(h.data() + 28 + 8 * i);
  std::array<int, kOptionFields> of{};
  for (std::size_t i = 0; i < of.size(); ++i)
    of[i] = getI32(h.data() + 148 + 4 * i);
  const std::uint32_t keepOrders = getU32(h.data() + 212);
  const std::uint32_t orderCount = getU32(h.data() + 216);
  std::array<int, 10> dims{};
  for (std::size_t i = 0; i < dims.size(); ++i)
    dims[i] = getI32(h.data() + 220 + 4 * i);

  if (const std::string problem = sizeProblem(of); !problem.empty()) throwRead(path, "bad sizes: " + problem);
  if (keepOrders > 1) throwRead(path, "bad sizes: keepOrders = " + std::to_string(keepOrders));
  if (orderCount != (keepOrders ? static_cast<std::uint32_t>(of[4]) : 0u))
    throwRead(path, "bad sizes: " + std::to_string(orderCount) + " order tables for keepOrders = " +
                        std::to_string(keepOrders) + ", orders = " + std::to_string(of[4]));
  const AtmospherePrecomputeOptions o = optionsFromFields(of, keepOrders != 0);
  if (dims[0] != o.opticalDepthHeight || dims[1] != o.opticalDepthZenith || dims[2] != 2)
    throwRead(path, "bad sizes: optical depth image does not match the options");
  if (dims[3] != o.ambientSize || dims[4] != 1 || dims[5] != 3)
    throwRead(path, "bad sizes: ambient image does not match the options");
  if (dims[6] != o.size.height || dims[7] != o.size.viewZenith || dims[8] != o.size.sunZenith ||
      dims[9] != o.size.sunView)
    throwRead(path, "bad sizes: 4D table size does not match the options");

  // Sizes are bounded by the limits above (at most 2048^2 * 2048 * 4 floats a table): no overflow.
  const std::size_t floats4D = tableFloats(o.size);
  const std::size_t depthFloats = static_cast<std::size_t>(o.opticalDepthHeight) * o.opticalDepthZenith * 2u;
  const std::size_t ambientFloats = static_cast<std::size_t>(o.ambientSize) * 3u;
  const std::size_t lutFloats = usesMultipleScatteringLut(o)
                                    ? static_cast<std::size_t>(o.multipleScatteringSize) *
                                          static_cast<std::size_t>(o.multipleScatteringSize) * 3u
                                    : 0u;
  const std::uintmax_t expected =
      kHeaderBytes + kChecksumBytes +
      (depthFloats + ambientFloats + lutFloats + floats4D * ((o.combinedMie ? 2u : 3u) + orderCount)) *
          sizeof(float);
  if (fileBytes != expected)
    throwRead(path, (fileBytes < expected ? "truncated: " : "wrong length: ") + std::to_string(fileBytes) +
                        " bytes, the sizes imply " + std::to_string(expected));

  // Allocation is now bounded by the length of the file that is there.
  AtmosphereTables t;
  t.parameters = parametersFromFields(pf);
  t.options = o;
  t.opticalDepth = Image(o.opticalDepthHeight, o.opticalDepthZenith, 2);
  t.ambient = Image(o.ambientSize, 1, 3);
  reader.readFloats(t.opticalDepth.data().data(), depthFloats, "the optical depth table");
  reader.readFloats(t.ambient.data().data(), ambientFloats, "the ambient table");
  if (lutFloats > 0) {
    t.multipleScatteringLut = Image(o.multipleScatteringSize, o.multipleScatteringSize, 3);
    reader.readFloats(t.multipleScatteringLut.data().data(), lutFloats, "the multiple scattering table");
  }
  auto readTable = [&](AtmosphereTable4D& table, const char* what) {
    table.size = o.size;
    table.rgba.resize(floats4D);
    reader.readFloats(table.rgba.data(), floats4D, what);
  };
  readTable(t.single, "the single scattering table");
  if (!o.combinedMie) readTable(t.singleMie, "the single Mie scattering table");
  readTable(t.higherOrders, "the higher orders table");
  t.orders.resize(orderCount);
  for (AtmosphereTable4D& table : t.orders)
    readTable(table, "an order table");
  const std::uint64_t computed = reader.digest();
  std::array<unsigned char, kChecksumBytes> c{};
  in.read(reinterpret_cast<char*>(c.data()), kChecksumBytes);
  if (static_cast<std::size_t>(in.gcount()) != kChecksumBytes) throwRead(path, "truncated in the checksum");
  if (getU64(c.data()) != computed)
    throwRead(path,
              "checksum mismatch (stored " + hex64(getU64(c.data())) + ", computed " + hex64(computed) + ")");
  if (storedKey != atmosphereCacheKey(t.parameters, t.options))
    throwRead(path, "the stored key " + storedKey + " does not match the stored parameters and options");
  return t;
}

AtmosphereTables cachedAtmosphereTables(const fs::path& directory, const AtmosphereParameters& p,
                                        const AtmospherePrecomputeOptions& o,
                                        const std::function<AtmosphereTables()>& compute,
                                        const std::function<void(const std::string&)>& warn) {
  const fs::path file = directory / ("atmosphere-" + atmosphereCacheKey(p, o) + ".bin");
  auto say = [&](const std::string& message) {
    if (warn) warn(message);
  };
  // The cache holds the tables without the per-order tables: a request that keeps them is computed.
  std::error_code ec;
  if (!o.keepOrders && fs::exists(file, ec)) {
    try {
      AtmosphereTables loaded = loadAtmosphereTables(file);
      if (sameParameters(loaded.parameters, p) && sameOptions(loaded.options, o)) {
        loaded.options.keepOrders = false;
        loaded.orders.clear();
        return loaded;
      }
      say("crep: atmosphere cache " + quoted(file) +
          ": its stored parameters or options differ from the requested ones; recomputing");
    } catch (const IoError& e) {
      say(std::string(e.what()) + "; recomputing"); // names the file and the reason
    } catch (const Error& e) {
      say("crep: atmosphere cache " + quoted(file) + ": " + e.what() + "; recomputing");
    }
  }
  AtmosphereTables tables = compute();
  try {
    fs::create_directories(directory);
    AtmosphereTables stored;
    const AtmosphereTables* toSave = &tables;
    if (!tables.orders.empty() || tables.options.keepOrders) {
      // Save without the per-order tables (they are not cached); copies only in that rarer case.
      stored = tables;
      stored.orders.clear();
      stored.options.keepOrders = false;
      toSave = &stored;
    }
    saveAtmosphereTables(*toSave, file);
  } catch (const std::exception& e) {
    say("crep: atmosphere cache " + quoted(file) + ": cannot save (" + e.what() + ")");
  }
  return tables;
}

} // namespace crep
