// The disk cache of the atmosphere tables (crep/atmosphere/atmosphere.h, "Disk cache"; the format at the top
// of atmosphere/src/cache.cpp): a saved file loads bit-identical with equal parameters and options, the key
// changes with every field that changes the tables and not with keepOrders, every truncation and every
// flipped byte of a small file is an IoError naming the file, and cachedAtmosphereTables computes once, then
// loads, and recomputes a corrupt file with exactly one warning, never returning its data. Tables are made by
// hand (arbitrary bit patterns), so these tests do not depend on the precomputation.
#include <crep/atmosphere/atmosphere.h>
#include <crep/core/error.h>

#include <doctest/doctest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <set>
#include <string>
#include <vector>

using namespace crep;
namespace fs = std::filesystem;

namespace {

/// A unique directory under the system's temporary directory, removed with everything in it at the end.
struct TempDir {
  fs::path path;
  TempDir() {
    static std::atomic<int> counter{0};
    const auto now = std::chrono::steady_clock::now().time_since_epoch().count();
    path = fs::temp_directory_path() /
           ("crep-atmosphere-cache-test-" + std::to_string(now) + "-" + std::to_string(counter++));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

AtmosphereParameters someParameters() {
  AtmosphereParameters p;
  p.earthRadius = 6371.0e3;
  p.rayleighScattering = glm::dvec3(5.5e-6, 13.0e-6, 22.4e-6);
  p.mieG = 0.8;
  return p;
}

AtmospherePrecomputeOptions smallOptions() {
  AtmospherePrecomputeOptions o;
  o.size = {2, 4, 2, 3};
  o.orders = 2;
  o.singleSteps = 7;
  o.orderSteps = 5;
  o.sphereSamples = 9;
  o.opticalDepthHeight = 3;
  o.opticalDepthZenith = 4;
  o.opticalDepthSteps = 11;
  o.ambientSize = 5;
  return o;
}

/// Deterministic float bit patterns (xorshift), finite and of mixed sign and magnitude, seeded per table.
float patternValue(std::uint32_t& state) {
  state ^= state << 13;
  state ^= state >> 17;
  state ^= state << 5;
  // Keep the exponent away from Inf/NaN so the values are ordinary floats of any magnitude.
  std::uint32_t bits = state & 0xbfffffffu;
  float v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

AtmosphereTable4D patternTable(const AtmosphereTableSize& size, std::uint32_t seed) {
  AtmosphereTable4D t;
  t.size = size;
  t.rgba.resize(static_cast<std::size_t>(size.height) * size.viewZenith * size.sunZenith * size.sunView * 4u);
  for (float& v : t.rgba)
    v = patternValue(seed);
  return t;
}

Image patternImage(int w, int h, int c, std::uint32_t seed) {
  Image image(w, h, c);
  for (float& v : image.data())
    v = patternValue(seed);
  return image;
}

/// Tables of (p, o) with arbitrary contents; `seed` changes every value.
AtmosphereTables patternTables(const AtmosphereParameters& p, const AtmospherePrecomputeOptions& o,
                               std::uint32_t seed) {
  AtmosphereTables t;
  t.parameters = p;
  t.options = o;
  t.opticalDepth = patternImage(o.opticalDepthHeight, o.opticalDepthZenith, 2, seed * 7u + 1u);
  t.ambient = patternImage(o.ambientSize, 1, 3, seed * 7u + 2u);
  t.single = patternTable(o.size, seed * 7u + 3u);
  t.higherOrders = patternTable(o.size, seed * 7u + 4u);
  if (!o.combinedMie) t.singleMie = patternTable(o.size, seed * 7u + 5u);
  if (usesMultipleScatteringLut(o))
    t.multipleScatteringLut =
        patternImage(o.multipleScatteringSize, o.multipleScatteringSize, 3, seed * 7u + 9u);
  if (o.keepOrders)
    for (int n = 0; n < o.orders; ++n)
      t.orders.push_back(patternTable(o.size, seed * 7u + 6u + 1000u * static_cast<std::uint32_t>(n)));
  return t;
}

// Empty blocks (a table the options leave out) compare equal without memcmp, whose pointers may be null.
bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}
bool sameBits(const Image& a, const Image& b) {
  return a.sameShape(b) &&
         (a.byteSize() == 0 || std::memcmp(a.data().data(), b.data().data(), a.byteSize()) == 0);
}
bool sameBits(const AtmosphereTable4D& a, const AtmosphereTable4D& b) {
  return a.size.height == b.size.height && a.size.viewZenith == b.size.viewZenith &&
         a.size.sunZenith == b.size.sunZenith && a.size.sunView == b.size.sunView && sameBits(a.rgba, b.rgba);
}

bool sameParameters(const AtmosphereParameters& a, const AtmosphereParameters& b) {
  return a.earthRadius == b.earthRadius && a.atmosphereHeight == b.atmosphereHeight &&
         a.rayleighScattering == b.rayleighScattering && a.rayleighScaleHeight == b.rayleighScaleHeight &&
         a.mieScattering == b.mieScattering && a.mieAbsorption == b.mieAbsorption &&
         a.mieScaleHeight == b.mieScaleHeight && a.mieG == b.mieG && a.groundAlbedo == b.groundAlbedo;
}

bool sameOptions(const AtmospherePrecomputeOptions& a, const AtmospherePrecomputeOptions& b) {
  return a.size.height == b.size.height && a.size.viewZenith == b.size.viewZenith &&
         a.size.sunZenith == b.size.sunZenith && a.size.sunView == b.size.sunView && a.orders == b.orders &&
         a.singleSteps == b.singleSteps && a.orderSteps == b.orderSteps &&
         a.sphereSamples == b.sphereSamples && a.opticalDepthHeight == b.opticalDepthHeight &&
         a.opticalDepthZenith == b.opticalDepthZenith && a.opticalDepthSteps == b.opticalDepthSteps &&
         a.ambientSize == b.ambientSize && a.keepOrders == b.keepOrders && a.combinedMie == b.combinedMie &&
         a.multipleScattering == b.multipleScattering &&
         a.multipleScatteringSize == b.multipleScatteringSize &&
         a.multipleScatteringSteps == b.multipleScatteringSteps;
}

/// Every table bit-identical (and the orders too).
bool sameTables(const AtmosphereTables& a, const AtmosphereTables& b) {
  if (a.orders.size() != b.orders.size()) return false;
  for (std::size_t i = 0; i < a.orders.size(); ++i)
    if (!sameBits(a.orders[i], b.orders[i])) return false;
  return sameBits(a.opticalDepth, b.opticalDepth) && sameBits(a.ambient, b.ambient) &&
         sameBits(a.single, b.single) && sameBits(a.higherOrders, b.higherOrders) &&
         sameBits(a.singleMie, b.singleMie) && a.singleMie.rgba.size() == b.singleMie.rgba.size() &&
         sameBits(a.multipleScatteringLut, b.multipleScatteringLut);
}

std::vector<char> readBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void writeBytes(const fs::path& path, const std::vector<char>& bytes, std::size_t n) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(n));
}

/// Overwrites byte `i` of an existing file in place.
void setByte(const fs::path& path, std::size_t i, char value) {
  std::fstream f(path, std::ios::binary | std::ios::in | std::ios::out);
  f.seekp(static_cast<std::streamoff>(i));
  f.put(value);
}

/// loadAtmosphereTables(path) throws an IoError whose message names the file; returns the message.
std::string loadError(const fs::path& path) {
  try {
    (void)loadAtmosphereTables(path);
  } catch (const IoError& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("not an IoError: ") + e.what();
  }
  return "no error";
}

} // namespace

TEST_CASE("AtmosphereCache: save and load are bit-identical with equal parameters and options") {
  TempDir dir;
  for (bool keepOrders : {false, true}) {
    AtmospherePrecomputeOptions o = smallOptions();
    o.keepOrders = keepOrders;
    const AtmosphereTables tables = patternTables(someParameters(), o, keepOrders ? 11u : 12u);
    const fs::path file = dir.path / (keepOrders ? "orders.bin" : "plain.bin");
    saveAtmosphereTables(tables, file);
    const AtmosphereTables loaded = loadAtmosphereTables(file);
    CHECK(sameParameters(loaded.parameters, tables.parameters));
    CHECK(sameOptions(loaded.options, tables.options));
    CHECK(loaded.orders.size() == (keepOrders ? 2u : 0u));
    CHECK(sameTables(loaded, tables));
    // Only the final file is left: the temporary one was renamed.
    int files = 0;
    for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir.path))
      ++files;
    CHECK(files == (keepOrders ? 2 : 1));
  }
  // Saving over an existing file replaces it.
  const fs::path file = dir.path / "plain.bin";
  const AtmosphereTables other = patternTables(someParameters(), smallOptions(), 99u);
  saveAtmosphereTables(other, file);
  CHECK(sameTables(loadAtmosphereTables(file), other));
}

TEST_CASE("AtmosphereCache: combinedMie stores no single Mie table and round-trips") {
  TempDir dir;
  AtmospherePrecomputeOptions o = smallOptions();
  o.combinedMie = true;
  const AtmosphereTables tables = patternTables(someParameters(), o, 21u);
  const fs::path combined = dir.path / "combined.bin", separate = dir.path / "separate.bin";
  saveAtmosphereTables(tables, combined);
  const AtmosphereTables loaded = loadAtmosphereTables(combined);
  CHECK(loaded.options.combinedMie);
  CHECK(loaded.singleMie.rgba.empty());
  CHECK(sameTables(loaded, tables));
  // One 4D table (N_h N_alpha N_phi N_theta RGBA floats) less than the separate form.
  o.combinedMie = false;
  saveAtmosphereTables(patternTables(someParameters(), o, 21u), separate);
  const auto table4D = static_cast<std::uintmax_t>(o.size.height) * o.size.viewZenith * o.size.sunZenith *
                       o.size.sunView * 4u * sizeof(float);
  CHECK(fs::file_size(separate) - fs::file_size(combined) == table4D);
}

TEST_CASE("AtmosphereCache: the multiple scattering LUT is stored and round-trips") {
  TempDir dir;
  AtmospherePrecomputeOptions o = smallOptions();
  o.multipleScattering = AtmosphereMultipleScattering::Lut;
  o.multipleScatteringSize = 6;
  REQUIRE(usesMultipleScatteringLut(o));
  const AtmosphereTables tables = patternTables(someParameters(), o, 31u);
  const fs::path file = dir.path / "lut.bin";
  saveAtmosphereTables(tables, file);
  const AtmosphereTables loaded = loadAtmosphereTables(file);
  CHECK(loaded.options.multipleScattering == AtmosphereMultipleScattering::Lut);
  CHECK(loaded.options.multipleScatteringSize == 6);
  CHECK(loaded.parameters.groundAlbedo == tables.parameters.groundAlbedo);
  CHECK(loaded.multipleScatteringLut.width() == 6);
  CHECK(sameTables(loaded, tables));
  // A LUT of the wrong size is refused on save, naming the file.
  AtmosphereTables bad = tables;
  bad.multipleScatteringLut = Image(5, 6, 3);
  CHECK_THROWS_AS(saveAtmosphereTables(bad, dir.path / "bad.bin"), IoError);
}

TEST_CASE("AtmosphereCache: the key changes with every field that changes the tables, not keepOrders") {
  const AtmosphereParameters p0 = someParameters();
  const AtmospherePrecomputeOptions o0 = smallOptions();
  const std::string key0 = atmosphereCacheKey(p0, o0);
  MESSAGE("key of the small options: " << key0);
  CHECK(key0.size() == 16u);
  CHECK(key0.find_first_not_of("0123456789abcdef") == std::string::npos);
  CHECK(atmosphereCacheKey(p0, o0) == key0); // stable

  AtmospherePrecomputeOptions keep = o0;
  keep.keepOrders = true;
  CHECK(atmosphereCacheKey(p0, keep) == key0);

  std::vector<std::function<void(AtmosphereParameters&)>> parameterChanges = {
      [](AtmosphereParameters& p) { p.earthRadius += 1.0; },
      [](AtmosphereParameters& p) { p.atmosphereHeight += 1.0; },
      [](AtmosphereParameters& p) { p.rayleighScattering.x *= 1.0 + 1e-15; },
      [](AtmosphereParameters& p) { p.rayleighScattering.y *= 1.01; },
      [](AtmosphereParameters& p) { p.rayleighScattering.z *= 1.01; },
      [](AtmosphereParameters& p) { p.rayleighScaleHeight += 1.0; },
      [](AtmosphereParameters& p) { p.mieScattering.x *= 1.01; },
      [](AtmosphereParameters& p) { p.mieScattering.y *= 1.01; },
      [](AtmosphereParameters& p) { p.mieScattering.z *= 1.01; },
      [](AtmosphereParameters& p) { p.mieAbsorption.x *= 1.01; },
      [](AtmosphereParameters& p) { p.mieAbsorption.y *= 1.01; },
      [](AtmosphereParameters& p) { p.mieAbsorption.z *= 1.01; },
      [](AtmosphereParameters& p) { p.mieScaleHeight += 1.0; },
      [](AtmosphereParameters& p) { p.mieG = 0.81; },
      [](AtmosphereParameters& p) { p.groundAlbedo = 0.2; },
  };
  std::vector<std::function<void(AtmospherePrecomputeOptions&)>> optionChanges = {
      [](AtmospherePrecomputeOptions& o) { o.size.height += 1; },
      [](AtmospherePrecomputeOptions& o) { o.size.viewZenith += 2; },
      [](AtmospherePrecomputeOptions& o) { o.size.sunZenith += 1; },
      [](AtmospherePrecomputeOptions& o) { o.size.sunView += 1; },
      [](AtmospherePrecomputeOptions& o) { o.orders += 1; },
      [](AtmospherePrecomputeOptions& o) { o.singleSteps += 1; },
      [](AtmospherePrecomputeOptions& o) { o.orderSteps += 1; },
      [](AtmospherePrecomputeOptions& o) { o.sphereSamples += 1; },
      [](AtmospherePrecomputeOptions& o) { o.opticalDepthHeight += 1; },
      [](AtmospherePrecomputeOptions& o) { o.opticalDepthZenith += 1; },
      [](AtmospherePrecomputeOptions& o) { o.opticalDepthSteps += 1; },
      [](AtmospherePrecomputeOptions& o) { o.ambientSize += 1; },
      [](AtmospherePrecomputeOptions& o) { o.combinedMie = true; },
      [](AtmospherePrecomputeOptions& o) { o.multipleScattering = AtmosphereMultipleScattering::Lut; },
      [](AtmospherePrecomputeOptions& o) { o.multipleScatteringSize += 1; },
      [](AtmospherePrecomputeOptions& o) { o.multipleScatteringSteps += 1; },
  };
  std::set<std::string> keys{key0};
  for (std::size_t i = 0; i < parameterChanges.size(); ++i) {
    AtmosphereParameters p = p0;
    parameterChanges[i](p);
    const std::string key = atmosphereCacheKey(p, o0);
    CAPTURE(i);
    CHECK(key != key0);
    keys.insert(key);
  }
  for (std::size_t i = 0; i < optionChanges.size(); ++i) {
    AtmospherePrecomputeOptions o = o0;
    optionChanges[i](o);
    const std::string key = atmosphereCacheKey(p0, o);
    CAPTURE(i);
    CHECK(key != key0);
    keys.insert(key);
  }
  // 15 parameter fields and 16 option fields: 32 distinct keys with the original.
  CHECK(keys.size() == 1u + parameterChanges.size() + optionChanges.size());
}

TEST_CASE("AtmosphereCache: truncated, flipped, wrong magic and missing files are IoErrors naming the file") {
  TempDir dir;
  AtmospherePrecomputeOptions o = smallOptions();
  o.keepOrders = true;
  const AtmosphereTables tables = patternTables(someParameters(), o, 5u);
  const fs::path good = dir.path / "good.bin";
  saveAtmosphereTables(tables, good);
  const std::vector<char> bytes = readBytes(good);
  MESSAGE("small cache file: " << bytes.size() << " bytes");
  REQUIRE(bytes.size() > 240u);
  const fs::path bad = dir.path / "bad.bin";

  // Cut lengths: every one within the header and the first table, then every 7th, and the last 16.
  std::vector<std::size_t> cuts;
  for (std::size_t n = 0; n < bytes.size(); ++n)
    if (n < 400 || n % 7 == 0 || n + 16 >= bytes.size()) cuts.push_back(n);
  int truncatedFailures = 0;
  writeBytes(bad, bytes, bytes.size());
  for (std::size_t n : cuts) {
    fs::resize_file(bad, n);
    const std::string message = loadError(bad);
    if (message.find(bad.string()) == std::string::npos || message.rfind("crep:", 0) != 0) {
      if (truncatedFailures++ < 5) MESSAGE("cut at " << n << ": " << message);
    }
    writeBytes(bad, bytes, bytes.size());
  }
  MESSAGE(cuts.size() << " cut lengths of " << bytes.size());
  CHECK(truncatedFailures == 0);
  {
    writeBytes(bad, bytes, bytes.size() / 2);
    const std::string message = loadError(bad);
    MESSAGE("cut in half: " << message);
    CHECK(message.find("truncated") != std::string::npos);
  }
  // A longer file (an extra byte) is wrong too.
  {
    std::vector<char> longer = bytes;
    longer.push_back('\0');
    writeBytes(bad, longer, longer.size());
    const std::string message = loadError(bad);
    CHECK(message.find(bad.string()) != std::string::npos);
  }
  // Flipped bytes, one at a time, edited in place: every byte of the header, the first table and the
  // checksum, then every 5th, each with one bit and with all bits flipped.
  int flipFailures = 0, flips = 0;
  writeBytes(bad, bytes, bytes.size());
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (!(i < 400 || i % 5 == 0 || i + 8 >= bytes.size())) continue;
    for (unsigned char mask : {0x01u, 0xffu}) {
      setByte(bad, i, static_cast<char>(static_cast<unsigned char>(bytes[i]) ^ mask));
      const std::string message = loadError(bad);
      ++flips;
      if (message.find(bad.string()) == std::string::npos || message.rfind("crep:", 0) != 0) {
        if (flipFailures++ < 5) MESSAGE("byte " << i << " ^ " << int(mask) << ": " << message);
      }
    }
    setByte(bad, i, bytes[i]);
  }
  MESSAGE(flips << " flipped bytes");
  CHECK(flipFailures == 0);
  CHECK(sameTables(loadAtmosphereTables(bad), tables)); // restored in place: intact again
  {
    std::vector<char> flipped = bytes;
    flipped[bytes.size() - 20] ^= 0x10;
    writeBytes(bad, flipped, flipped.size());
    const std::string message = loadError(bad);
    MESSAGE("flipped data byte: " << message);
    CHECK(message.find("checksum") != std::string::npos);
  }
  {
    std::vector<char> wrongMagic = bytes;
    wrongMagic[7] = '2'; // "CREPATM2"
    writeBytes(bad, wrongMagic, wrongMagic.size());
    const std::string message = loadError(bad);
    MESSAGE("wrong magic: " << message);
    CHECK(message.find(bad.string()) != std::string::npos);
    CHECK(message.find("magic") != std::string::npos);
  }
  {
    std::vector<char> wrongVersion = bytes;
    wrongVersion[8] = 1; // version 1 held L1 with its phase functions and L_M
    writeBytes(bad, wrongVersion, wrongVersion.size());
    const std::string message = loadError(bad);
    CHECK(message.find(bad.string()) != std::string::npos);
    CHECK(message.find("version") != std::string::npos);
  }
  {
    // A size beyond the options' limits (size.height = 2^31 - 1) is refused before any allocation.
    std::vector<char> huge = bytes;
    huge[148] = huge[149] = huge[150] = static_cast<char>(0xff); // the options' first int (offset 148)
    huge[151] = 0x7f;
    writeBytes(bad, huge, huge.size());
    const std::string message = loadError(bad);
    MESSAGE("huge size: " << message);
    CHECK(message.find(bad.string()) != std::string::npos);
    CHECK(message.find("size.height") != std::string::npos);
  }
  const fs::path missing = dir.path / "missing.bin";
  const std::string message = loadError(missing);
  CHECK(message.find(missing.string()) != std::string::npos);
  // The intact file still loads.
  CHECK(sameTables(loadAtmosphereTables(good), tables));
}

TEST_CASE("AtmosphereCache: cachedAtmosphereTables computes once, loads, and recomputes a corrupt file") {
  TempDir dir;
  const fs::path cacheDir = dir.path / "cache" / "nested"; // created by the cache
  const AtmosphereParameters p = someParameters();
  const AtmospherePrecomputeOptions o = smallOptions();
  int computed = 0;
  std::uint32_t seed = 100u;
  auto compute = [&] {
    ++computed;
    return patternTables(p, o, seed);
  };
  std::vector<std::string> warnings;
  auto warn = [&](const std::string& m) { warnings.push_back(m); };
  const fs::path file = cacheDir / ("atmosphere-" + atmosphereCacheKey(p, o) + ".bin");

  const AtmosphereTables first = cachedAtmosphereTables(cacheDir, p, o, compute, warn);
  CHECK(computed == 1);
  CHECK(warnings.empty());
  CHECK(fs::is_regular_file(file));
  CHECK(sameTables(first, patternTables(p, o, 100u)));

  // Second run: loaded, not computed (a different seed would show), bit-identical.
  seed = 200u;
  const AtmosphereTables second = cachedAtmosphereTables(cacheDir, p, o, compute, warn);
  CHECK(computed == 1);
  CHECK(warnings.empty());
  CHECK(sameTables(second, first));
  CHECK(sameParameters(second.parameters, p));
  CHECK(sameOptions(second.options, o));

  // Corrupt one byte of the data: exactly one warning naming the file, recomputed, never the corrupt data.
  {
    std::vector<char> bytes = readBytes(file);
    bytes[bytes.size() / 2] ^= 0x40;
    writeBytes(file, bytes, bytes.size());
  }
  seed = 300u;
  const AtmosphereTables third = cachedAtmosphereTables(cacheDir, p, o, compute, warn);
  CHECK(computed == 2);
  REQUIRE(warnings.size() == 1u);
  MESSAGE("warning: " << warnings[0]);
  CHECK(warnings[0].find(file.string()) != std::string::npos);
  CHECK(warnings[0].find("recomputing") != std::string::npos);
  CHECK(sameTables(third, patternTables(p, o, 300u)));
  // The recomputed tables were saved over the corrupt file: the next run loads them.
  seed = 400u;
  CHECK(sameTables(cachedAtmosphereTables(cacheDir, p, o, compute, warn), third));
  CHECK(computed == 2);
  CHECK(warnings.size() == 1u);

  // A truncated file: the same.
  {
    const std::vector<char> bytes = readBytes(file);
    writeBytes(file, bytes, bytes.size() - 3);
  }
  seed = 500u;
  CHECK(sameTables(cachedAtmosphereTables(cacheDir, p, o, compute, warn), patternTables(p, o, 500u)));
  CHECK(computed == 3);
  CHECK(warnings.size() == 2u);

  // A valid file of other parameters under this key's name: a warning and a recompute, never used.
  {
    AtmosphereParameters q = p;
    q.mieG = 0.5;
    saveAtmosphereTables(patternTables(q, o, 600u), file);
  }
  seed = 700u;
  const AtmosphereTables mismatched = cachedAtmosphereTables(cacheDir, p, o, compute, warn);
  CHECK(computed == 4);
  REQUIRE(warnings.size() == 3u);
  MESSAGE("mismatch warning: " << warnings[2]);
  CHECK(warnings[2].find(file.string()) != std::string::npos);
  CHECK(sameTables(mismatched, patternTables(p, o, 700u)));

  // keepOrders: the per-order tables are not cached, so such a request is computed (and keeps them); the
  // saved file has none and still serves a request without them.
  {
    AtmospherePrecomputeOptions keep = o;
    keep.keepOrders = true;
    int keepComputed = 0;
    auto computeKeep = [&] {
      ++keepComputed;
      return patternTables(p, keep, 800u);
    };
    const AtmosphereTables withOrders = cachedAtmosphereTables(cacheDir, p, keep, computeKeep, warn);
    CHECK(keepComputed == 1);
    CHECK(withOrders.orders.size() == 2u);
    CHECK(warnings.size() == 3u);
    const AtmosphereTables loaded = loadAtmosphereTables(file);
    CHECK(loaded.orders.empty());
    CHECK(!loaded.options.keepOrders);
    AtmosphereTables expected = patternTables(p, keep, 800u);
    expected.orders.clear();
    CHECK(sameTables(loaded, expected));
    const int before = computed;
    CHECK(sameTables(cachedAtmosphereTables(cacheDir, p, o, compute, warn), expected));
    CHECK(computed == before);
  }
}

TEST_CASE("AtmosphereCache: a failure to save is a warning, not an error") {
  TempDir dir;
  // The cache "directory" is a regular file: it cannot be created, nothing can be saved in it.
  const fs::path notADirectory = dir.path / "file";
  writeBytes(notADirectory, std::vector<char>{'x'}, 1);
  const AtmosphereParameters p = someParameters();
  const AtmospherePrecomputeOptions o = smallOptions();
  int computed = 0;
  std::vector<std::string> warnings;
  const AtmosphereTables t = cachedAtmosphereTables(
      notADirectory, p, o,
      [&] {
        ++computed;
        return patternTables(p, o, 1u);
      },
      [&](const std::string& m) { warnings.push_back(m); });
  CHECK(computed == 1);
  REQUIRE(warnings.size() == 1u);
  MESSAGE("save failure warning: " << warnings[0]);
  CHECK(warnings[0].find("cannot save") != std::string::npos);
  CHECK(sameTables(t, patternTables(p, o, 1u)));

  // saveAtmosphereTables itself throws IoError naming the file.
  const fs::path target = notADirectory / "atmosphere.bin";
  try {
    saveAtmosphereTables(t, target);
    FAIL("no error");
  } catch (const IoError& e) {
    CHECK(std::string(e.what()).find(target.string()) != std::string::npos);
  }
}

TEST_CASE("AtmosphereCache: precomputed tables round-trip through the cache bit-identically") {
  TempDir dir;
  AtmospherePrecomputeOptions o;
  o.size = {4, 8, 4, 4};
  o.orders = 2;
  o.singleSteps = 16;
  o.orderSteps = 8;
  o.sphereSamples = 16;
  o.opticalDepthHeight = 8;
  o.opticalDepthZenith = 16;
  o.opticalDepthSteps = 32;
  o.ambientSize = 8;
  const AtmosphereParameters p;
  int computed = 0;
  auto compute = [&] {
    ++computed;
    return precomputeAtmosphere(p, o, 1);
  };
  std::vector<std::string> warnings;
  auto warn = [&](const std::string& m) { warnings.push_back(m); };
  const AtmosphereTables first = cachedAtmosphereTables(dir.path, p, o, compute, warn);
  const AtmosphereTables second = cachedAtmosphereTables(dir.path, p, o, compute, warn);
  CHECK(computed == 1);
  CHECK(warnings.empty());
  CHECK(sameTables(first, second));
  CHECK(sameParameters(second.parameters, p));
  CHECK(sameOptions(second.options, o));
  // The occluded rays' optical depth (kOccludedDensity) survives as the same float.
  bool occluded = false;
  for (float v : second.opticalDepth.data())
    occluded = occluded || v == static_cast<float>(kOccludedDensity);
  CHECK(occluded);
}
