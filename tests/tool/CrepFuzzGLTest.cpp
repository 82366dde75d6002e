// A seeded fuzz test of the crep tool: random command lines over the tool's real options and values,
// mutations of the example JSON frame, truncated and bit-flipped EXR inputs. Every case runs the built tool
// in a fresh folder (inputs, a FIFO, a folder, a file, a symbolic link) and must
//   - end with exit status 0, 1 or 2: never a signal, never a hang (60 s per case);
//   - leave no partial output: no temporary of the output rule anywhere, and when the status is not 0 the
//     folder exactly as it was (no new file, no changed or removed file);
//   - never change an input;
//   - name what is wrong: the error (the last line) names an option of the command line, one of its files,
//     or a field of the frame file, and is never an "unexpected error".
// Bounded: fixed case counts (a seed gives the same cases), the GL work tiny (sizes up to 32x18, maps up to
// 128, few march steps), and a time budget after which no new case starts (on slow builds: sanitizers).
// CREP_FUZZ_SEED overrides the seed (a failing case prints its seed, index and arguments); CREP_FUZZ_VERBOSE
// prints every case with its exit status and last line.
#include "common/gl_fixture.h"
#include "common/image_check.h"
#include "common/tool_runner.h"
#include "tool/frame_json_util.h"

#include <crep/core/image.h>
#include <crep/support/exr.h>

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <string>
#include <sys/stat.h>
#include <vector>

namespace {

namespace fs = std::filesystem;
using namespace crep::test::frame_json;
using crep::test::ArgvResult;

constexpr std::uint32_t kDefaultSeed = 28;
constexpr int kCommandLineCases = 160, kJsonCases = 80, kExrCases = 300;
/// No new case of a phase after its deadline (seconds since the start): command lines, JSON frames, EXR
/// files. The counts fit in about a minute on an idle 2-core machine; the deadlines bound slow or loaded
/// ones.
constexpr double kDeadlines[3] = {50.0, 72.0, 90.0};

/// A file's identity for the before / after comparison: its type, and for regular files size and content
/// hash, for links the target.
std::string describe(const fs::path& p) {
  struct stat s {};
  if (::lstat(p.c_str(), &s) != 0) return "missing";
  if (S_ISLNK(s.st_mode)) return "link " + fs::read_symlink(p).string();
  if (S_ISDIR(s.st_mode)) return "dir";
  if (S_ISFIFO(s.st_mode)) return "fifo";
  if (!S_ISREG(s.st_mode)) return "other";
  const std::string bytes = readText(p.string());
  return "file " + std::to_string(bytes.size()) + " " + std::to_string(std::hash<std::string>{}(bytes));
}

/// Every entry below `dir` except the atmosphere cache folder (a cache, not an output).
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator(); ++it) {
    const std::string name = it->path().lexically_relative(dir).string();
    if (name == "cache" || name.starts_with("cache/")) {
      if (it->is_directory() && !it->is_symlink()) it.disable_recursion_pending();
      continue;
    }
    out[name] = describe(it->path());
  }
  return out;
}

/// The example frame at the fuzz's image size (camera.size 32x18).
Json exampleFrame() {
  Json j = Json::parse(readText(kExample));
  j["camera"]["size"] = Json::array({32, 18});
  return j;
}

/// The fixtures every case starts from (copied into its own folder).
struct Template {
  crep::test::TempDir dir{"crep-fuzz"};
  fs::path root() const { return dir.path() / "template"; }
  Template() {
    fs::create_directories(root() / "folder");
    fs::create_directories(root() / "real");
    fs::create_directories(dir.path() / "cache");
    // A depth with structure (not constant, so that bit flips in a compressed stream matter), 32x18: the
    // example frame's aspect at a fifth of its size (camera.size follows), to keep the GL work small.
    crep::Image depth(32, 18, 1);
    for (int y = 0; y < 18; ++y)
      for (int x = 0; x < 32; ++x)
        depth.at(x, y) = y < 6 ? 1.0f : 0.95f + 0.0015f * float(x);
    crep::writeExr(root() / "depth.exr", depth, crep::ExrPixelType::Float);
    crep::writeExr(root() / "depth-raw.exr", depth,
                   crep::ExrWriteOptions(crep::ExrPixelType::Float, crep::ExrCompression::None));
    crep::writeExr(root() / "shadow.exr", crep::Image(256, 256, 1, 1.0f), crep::ExrPixelType::Float);
    crep::writeExr(root() / "spot.exr", crep::Image(64, 64, 1, 1.0f), crep::ExrPixelType::Float);
    crep::writeExr(root() / "point.exr", crep::Image(16, 96, 1, 1.0f), crep::ExrPixelType::Float);
    writeText(root() / "frame.json", exampleFrame().dump(2));
    writeText(root() / "file.txt", "a file");
    writeText(root() / "real/target.exr", "a link's target");
    fs::create_symlink("real/target.exr", root() / "link.exr");
  }
  /// A fresh copy for one case (FIFOs are made, not copied).
  fs::path makeCase(int index) const {
    const fs::path c = dir.path() / ("case" + std::to_string(index));
    fs::copy(root(), c, fs::copy_options::recursive | fs::copy_options::copy_symlinks);
    REQUIRE(::mkfifo((c / "fifo").c_str(), 0644) == 0);
    REQUIRE(::mkfifo((c / "pfifo.png").c_str(), 0644) == 0);
    return c;
  }
};

/// Option name -> values to draw from (valid ones, boundaries, garbage).
using Pools = std::map<std::string, std::vector<std::string>>;

const std::vector<std::string> kGarbage = {"",         "-1",         "0",      "1e999",
                                           "nan",      "inf",        "0x10",   " 1",
                                           "1,2",      "--debug-gl", "a\x01z", std::string(300, 'a'),
                                           "\xc3\xa9", "-0",         "1e-320", "+1",
                                           "1x1x1",    "..",         "/",      "-"};

const Pools kMethodPools = {
    {"method",
     {"prefilter", "reference", "minmax", "brute", "epipolar-sampling", "epipolar-prefilter", "froxel-esm",
      "froxel-prefilter", "radial", "atmosphere", "bogus"}},
    {"map-size", {"64", "128", "32", "16", "0", "17", "100000", "48"}},
    {"bases", {"4", "6", "10", "32", "128", "3", "130", "2"}},
    {"format", {"rgba8", "rgba16f", "rgba32f", "rgb8"}},
    {"splits", {"1", "2", "4", "8", "0", "17", "3"}},
    {"steps", {"1", "4", "8", "0", "70000"}},
    {"scale", {"1", "0.5", "0.25", "0.3", "2"}},
    {"slices", {"1", "16", "64", "0", "99999"}},
    {"samples", {"32", "64", "33", "0", "2048"}},
    {"initial-step", {"1", "2", "16", "3", "64"}},
    {"downscale", {"1", "2", "4", "3", "0"}},
};

const Pools kScenePools = {
    {"scene",
     {"colonnade", "boxes", "colonnade-night", "stained-glass", "sunset", "terrain", "bogus", "../colonnade",
      "forest"}},
    {"size", {"16x9", "8x8", "32x18", "1x1", "4x4", "2x8", "0x9", "16x", "100000x1", "16x9 "}},
    {"exposure", {"1", "0.5", "1e30", "1e-31", "nan", "1e39"}},
    {"out", {"out", "folder/", "missing/x", "pfifo", "fifo", "folder", ".", "real/x", "file.txt/x", "link"}},
};

Pools renderPools() {
  Pools p = kMethodPools;
  p.insert(kScenePools.begin(), kScenePools.end());
  p["export-frame"] = {"exp", "file.txt", "fifo", "/proc/crep-fuzz", "folder", "exp/sub", "out.exr", ""};
  p["tonemap"] = {"reinhard", "all", "uncharted2", "log", "bogus"};
  p["middle-grey"] = {"0.18", "0", "1001"};
  p["white-point"] = {"3", "0.0001"};
  p["saturation"] = {"1", "9"};
  p["sun-elevation"] = {"30", "-5", "91"};
  p["sun-azimuth"] = {"10", "400"};
  p["camera-elevation"] = {"5", "90"};
  p["shafts"] = {"integrated", "lut", "prefiltered", "none", "bogus"};
  p["meters-per-unit"] = {"50", "0"};
  p["origin-altitude"] = {"0", "-1"};
  p["atmosphere-table"] = {"16x32x16x8", "16x31x16x8", "1x1x1x1", "x"};
  p["orders"] = {"1", "2", "0", "17"};
  p["atmosphere-cache"] = {"none", "cache", "", "file.txt"};
  p["sun-irradiance"] = {"10", "0"};
  return p;
}

Pools scatterPools() {
  Pools p = kMethodPools;
  p["method"].erase(std::find(p["method"].begin(), p["method"].end(), "atmosphere"));
  p["depth"] = {"depth.exr", "missing.exr", "folder", "frame.json", "shadow.exr", "fifo", "depth-raw.exr"};
  p["shadow"] = {"shadow.exr", "missing.exr", "depth.exr", "spot.exr"};
  p["frame"] = {"frame.json", "missing.json", "depth.exr", "folder"};
  p["out"] = {"out.exr", "fifo", "link.exr", "folder", "missing/o.exr", "depth.exr", "frame.json", "o.exr"};
  p["png"] = {"p.png", "fifo", "out.exr", "folder", "pfifo.png", "link.exr"};
  p["exposure"] = kScenePools.at("exposure");
  return p;
}

Pools comparePools() {
  Pools p = kMethodPools;
  p.erase("method");
  p.insert(kScenePools.begin(), kScenePools.end());
  p["amplify"] = {"20", "1e6", "0", "-1", "1e7"};
  p["tile-width"] = {"16", "64", "15", "5000", "x"};
  p["methods"] = {"prefilter", "reference",  "minmax,brute", "froxel-esm,radial",  "epipolar-sampling",
                  "",          "prefilter,", "bogus",        "prefilter,prefilter"};
  return p;
}

Pools rectifyPools() {
  const std::vector<std::string> vec = {"0,1,5",   "1,2",    "0,0,0",   "1e300,0,0",
                                        "nan,0,0", "0,-1,0", "1,-1,0.2"};
  return {{"camera-pos", vec},
          {"camera-target", vec},
          {"camera-up", vec},
          {"fovy-deg", {"60", "0.001", "180", "1e-300", "90"}},
          {"aspect", {"1.5", "0", "-1", "1e300"}},
          {"near", {"0.1", "1000", "-1", "0", "5"}},
          {"far", {"120", "0.01", "1e300", "1"}},
          {"light-dir", vec},
          {"splits", {"1", "4", "16", "0", "100"}},
          {"scheme", {"uniform", "logarithmic", "blend", "x"}},
          {"blend", {"0.5", "-1", "2"}}};
}

const std::set<std::string> kRenderFlags = {"debug-gl", "auto-exposure"};

struct Case {
  std::vector<std::string> args;
  std::vector<std::string> names; ///< what an error may name: options and files of the case
};

class Generator {
public:
  explicit Generator(std::uint32_t seed) : rng_(seed) {}
  std::uint32_t next(std::uint32_t n) { return n == 0 ? 0 : rng_() % n; }
  bool chance(double p) { return double(rng_()) / double(std::mt19937::max()) < p; }
  template <class T>
  const T& pick(const std::vector<T>& v) {
    return v[next(static_cast<std::uint32_t>(v.size()))];
  }

  /// Adds "--name value" (or "--name=value") to `c`.
  void option(Case& c, const std::string& name, const std::string& value) {
    if (chance(0.2)) {
      c.args.push_back("--" + name + "=" + value);
    } else {
      c.args.push_back("--" + name);
      c.args.push_back(value);
    }
    c.names.push_back("--" + name);
    // A file name counts as named too (an I/O error may name the file rather than the option).
    const bool fileLike = value.size() >= 3 && value.find_first_of("/.") != std::string::npos &&
                          value.find_first_not_of("0123456789.e-") != std::string::npos;
    if (fileLike || value == "fifo" || value == "folder") c.names.push_back(value);
  }

  Case commandLine() {
    Case c;
    const std::uint32_t kind = next(100);
    if (kind < 5) {
      c.args = pick(std::vector<std::vector<std::string>>{{"help"},
                                                          {"--version"},
                                                          {},
                                                          {"frobnicate"},
                                                          {"help", "render"},
                                                          {"help", "bogus"},
                                                          {"render", "--help"},
                                                          {"-h"}});
      c.names = {"frobnicate", "bogus", "render"};
      return c;
    }
    std::string command;
    Pools pools;
    if (kind < 45) {
      command = "render";
      pools = renderPools();
    } else if (kind < 72) {
      command = "scatter";
      pools = scatterPools();
    } else if (kind < 82) {
      command = "compare";
      pools = comparePools();
    } else {
      command = "rectify";
      pools = rectifyPools();
    }
    c.args.push_back(command);
    std::vector<std::string> names;
    for (const auto& [name, values] : pools)
      names.push_back(name);
    std::set<std::string> used;
    const int count = static_cast<int>(next(6));
    for (int i = 0; i < count; ++i) {
      const std::uint32_t what = next(100);
      if (what < 4) { // not an option
        const std::string bad = pick(std::vector<std::string>{"--bogus", "positional", "-x", "--", "--=1"});
        c.args.push_back(bad);
        c.names.push_back(bad);
        continue;
      }
      if (what < 8 && command != "rectify") {
        const std::string flag =
            command == "render" ? pick(std::vector<std::string>(kRenderFlags.begin(), kRenderFlags.end()))
                                : "debug-gl";
        c.args.push_back("--" + flag);
        c.names.push_back("--" + flag);
        continue;
      }
      const std::string& name = pick(names);
      if (used.count(name) && !chance(0.1)) continue; // sometimes repeated: a usage error
      used.insert(name);
      option(c, name, chance(0.85) ? pick(pools.at(name)) : pick(kGarbage));
    }
    // Keep the GL work tiny: a small size, map and march unless the case chose its own.
    if (command == "render" || command == "compare") {
      if (!used.count("size")) option(c, "size", pick(std::vector<std::string>{"16x9", "8x8", "32x18"}));
      if (!used.count("map-size")) option(c, "map-size", "64");
      if (!used.count("steps")) option(c, "steps", "8");
      if (!used.count("slices")) option(c, "slices", "64");
      if (!used.count("out") && chance(0.7)) option(c, "out", "out");
    }
    if (command == "compare" && !used.count("methods") && chance(0.8))
      option(c, "methods", pick(comparePools().at("methods")));
    if (command == "render" && std::find(c.args.begin(), c.args.end(), "atmosphere") != c.args.end()) {
      if (!used.count("atmosphere-table")) option(c, "atmosphere-table", "16x32x16x8");
      if (!used.count("orders")) option(c, "orders", "1");
      if (!used.count("atmosphere-cache")) option(c, "atmosphere-cache", chance(0.5) ? "none" : "cache");
    }
    if (command == "scatter") {
      for (const char* required : {"depth", "shadow", "frame"})
        if (!used.count(required) && chance(0.95))
          option(c, required,
                 std::string(required) == "depth"    ? "depth.exr"
                 : std::string(required) == "shadow" ? "shadow.exr"
                                                     : "frame.json");
      if (!used.count("steps")) option(c, "steps", "4");
      if (!used.count("map-size")) option(c, "map-size", "64");
      if (!used.count("slices")) option(c, "slices", "64");
    }
    return c;
  }

  /// A random path to a leaf (or an object member) of `j`, and its parent.
  Json* randomNode(Json& j, int depth = 0) {
    if (depth > 6 || !(j.is_object() || j.is_array()) || j.empty() || chance(0.25)) return &j;
    if (j.is_array()) return randomNode(j[next(static_cast<std::uint32_t>(j.size()))], depth + 1);
    auto it = j.begin();
    std::advance(it, next(static_cast<std::uint32_t>(j.size())));
    return randomNode(*it, depth + 1);
  }

  Json randomValue() {
    switch (next(16)) {
    case 0:
      return 0;
    case 1:
      return -1;
    case 2:
      return 1e30;
    case 3:
      return -1e30;
    case 4:
      return 1e-30;
    case 5:
      return 1e308;
    case 6:
      return 0.5;
    case 7:
      return "x";
    case 8:
      return nullptr;
    case 9:
      return true;
    case 10:
      return Json::array();
    case 11:
      return Json::object();
    case 12:
      return Json::array({1, 2, 3});
    case 13:
      return 1e29;
    case 14:
      return static_cast<double>(next(1000)) - 500.0;
    default:
      return 2;
    }
  }

  Json localLight() {
    if (chance(0.5)) {
      Json spot = exampleSpotJson();
      spot["shadowMap"] = {{"file", "spot.exr"},
                           {"lightClipFromWorld", matrixJson(exampleSpot().lightClipFromWorld())}};
      return spot;
    }
    return Json{{"type", "point"},
                {"position", Json::array({4.0, 3.0, -2.0})},
                {"color", Json::array({1.0, 1.0, 1.0})},
                {"intensity", 10},
                {"range", 50},
                {"shadowMap", {{"file", "point.exr"}}}};
  }

  /// One structural mutation of a frame.
  void mutate(Json& j) {
    switch (next(8)) {
    case 0:
      *randomNode(j) = randomValue();
      break;
    case 1: {
      Json* node = randomNode(j);
      if (node->is_object() && !node->empty()) {
        auto it = node->begin();
        std::advance(it, next(static_cast<std::uint32_t>(node->size())));
        const std::string key = it.key();
        node->erase(key);
      }
      break;
    }
    case 2: {
      Json* node = randomNode(j);
      if (node->is_object()) (*node)["bogusField"] = 1;
      break;
    }
    case 3:
      j["lights"] = Json::array({localLight()});
      break;
    case 4:
      j["light"]["type"] = pick(std::vector<std::string>{"spot", "point", "directional", "bogus"});
      break;
    case 5:
      j["camera"]["maxDistance"] = randomValue();
      break;
    case 6:
      if (!j.contains("lights")) j["lights"] = Json::array({localLight()});
      *randomNode(j["lights"]) = randomValue();
      break;
    default:
      j["medium"]["hgG"] = randomValue();
      break;
    }
  }

  /// The example frame mutated 1-3 times (structure or text).
  std::string jsonFrame() {
    Json j = exampleFrame();
    const int mutations = 1 + static_cast<int>(next(3));
    for (int m = 0; m < mutations; ++m) {
      try {
        mutate(j);
      } catch (const Json::exception&) {
        // A mutation that does not apply to what earlier ones left (e.g. "light" is no longer an object).
      }
    }
    std::string text = j.dump(chance(0.5) ? 2 : -1);
    if (chance(0.35) && !text.empty()) { // text-level damage
      const std::size_t at = next(static_cast<std::uint32_t>(text.size()));
      switch (next(4)) {
      case 0:
        text.resize(at);
        break;
      case 1:
        text[at] = static_cast<char>(text[at] ^ (1 << next(8)));
        break;
      case 2:
        text.insert(at, 1, '\0');
        break;
      default:
        text.insert(at, "\"camera\": 1, ");
        break;
      }
    }
    return text;
  }

  /// `bytes` truncated, or with 1-8 bits flipped.
  std::string damage(std::string bytes) {
    if (chance(0.4)) {
      bytes.resize(next(static_cast<std::uint32_t>(bytes.size())));
      return bytes;
    }
    const int flips = 1 + static_cast<int>(next(8));
    for (int i = 0; i < flips; ++i) {
      const std::size_t at = next(static_cast<std::uint32_t>(bytes.size()));
      bytes[at] = static_cast<char>(bytes[at] ^ (1 << next(8)));
    }
    return bytes;
  }

private:
  std::mt19937 rng_;
};

struct Tally {
  int cases = 0, status[3] = {0, 0, 0};
  double seconds = 0.0;
};

/// Runs one case in `dir` and checks every property of the file's header comment.
void runCase(const std::string& label, const Case& c, const fs::path& dir, const fs::path& cache,
             Tally& tally) {
  const std::map<std::string, std::string> before = snapshot(dir);
  crep::test::RunOptions options;
  options.workingDirectory = dir.string();
  options.timeoutSeconds = 60.0;
  options.environment = {"XDG_CACHE_HOME=" + cache.string()};
  const ArgvResult r = crep::test::runCrepArgv(c.args, options);
  std::string command;
  for (const std::string& a : c.args)
    command += " '" + a + "'";
  INFO(label << ":" << command << "\n" << r.output);
  REQUIRE_FALSE(r.timedOut);
  REQUIRE(r.signal == 0);
  REQUIRE((r.status == 0 || r.status == 1 || r.status == 2));
  ++tally.status[r.status];
  if (std::getenv("CREP_FUZZ_VERBOSE")) { // every case, its status and its last line
    std::string tail = r.output;
    while (!tail.empty() && tail.back() == '\n')
      tail.pop_back();
    std::printf("%s: exit %d:%s\n  %s\n", label.substr(0, 200).c_str(), r.status, command.c_str(),
                tail.substr(tail.rfind('\n') == std::string::npos ? 0 : tail.rfind('\n') + 1).c_str());
  }
  const std::map<std::string, std::string> after = snapshot(dir);
  for (const auto& [name, what] : after) {
    INFO(name);
    CHECK(name.find(".partial") == std::string::npos);
    CHECK(name.find(".crep-") == std::string::npos);
  }
  // Inputs never change.
  for (const char* input : {"depth.exr", "depth-raw.exr", "shadow.exr", "spot.exr", "point.exr", "frame.json",
                            "file.txt", "real/target.exr", "link.exr", "fifo", "pfifo.png", "folder"})
    if (before.count(input)) CHECK(after.count(input) == 1);
  for (const char* input : {"depth.exr", "depth-raw.exr", "shadow.exr", "spot.exr", "point.exr", "frame.json",
                            "file.txt", "link.exr", "fifo", "pfifo.png"})
    if (before.count(input) && after.count(input)) CHECK(before.at(input) == after.at(input));
  if (r.status == 0) return;
  CHECK(after == before); // a failed command leaves nothing behind
  // The error names something of the case.
  std::string last = r.output;
  while (!last.empty() && last.back() == '\n')
    last.pop_back();
  last = last.substr(last.rfind('\n') == std::string::npos ? 0 : last.rfind('\n') + 1);
  CHECK(last.find("unexpected error") == std::string::npos);
  bool named = false;
  for (const std::string& n : c.names)
    named = named || (!n.empty() && last.find(n) != std::string::npos);
  if (!named) named = last.find("crep help") != std::string::npos;
  if (c.args.empty()) named = r.output.starts_with("crep - single scattering"); // the usage text
  INFO("error line: " << last);
  CHECK(named);
}

std::uint32_t seed() {
  if (const char* s = std::getenv("CREP_FUZZ_SEED"); s && *s)
    return static_cast<std::uint32_t>(std::strtoul(s, nullptr, 10));
  return kDefaultSeed;
}

} // namespace

TEST_CASE("crep fuzz: command lines, JSON frames and EXR inputs: no crash, no hang, no partial output, every "
          "error named") {
  CREP_REQUIRE_GL();
  const Template templ;
  const std::uint32_t s = seed();
  Generator gen(s);
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  Tally commandLines, frames, exrs;
  int index = 0;
  bool budgetHit = false;
  const auto timed = [&](Tally& t, const std::function<void()>& run) {
    const double t0 = elapsed();
    run();
    ++t.cases;
    t.seconds += elapsed() - t0;
  };

  const auto over = [&](int phase) {
    const bool late = elapsed() > kDeadlines[phase];
    budgetHit = budgetHit || late;
    return late;
  };
  for (int i = 0; i < kCommandLineCases && !over(0); ++i, ++index) {
    const Case c = gen.commandLine();
    const fs::path dir = templ.makeCase(index);
    timed(commandLines, [&] {
      runCase("seed " + std::to_string(s) + ", command line " + std::to_string(i), c, dir,
              templ.dir.path() / "cache", commandLines);
    });
    fs::remove_all(dir);
  }

  const std::vector<std::string> methods = {"reference", "prefilter", "minmax", "froxel-esm", "brute"};
  for (int i = 0; i < kJsonCases && !over(1); ++i, ++index) {
    const fs::path dir = templ.makeCase(index);
    writeText(dir / "mutated.json", gen.jsonFrame());
    Case c;
    c.args = {"scatter",         "--depth",      "depth.exr", "--shadow",   "shadow.exr",
              "--frame",         "mutated.json", "--out",     "out.exr",    "--method",
              gen.pick(methods), "--steps",      "4",         "--map-size", "64"};
    c.names = {"mutated.json", "spot.exr", "point.exr", "--depth",
               "--shadow",     "--frame",  "depth.exr", "shadow.exr"};
    timed(frames, [&] {
      runCase("seed " + std::to_string(s) + ", JSON frame " + std::to_string(i) +
                  " (mutated.json: " + readText((dir / "mutated.json").string()).substr(0, 4000) + ")",
              c, dir, templ.dir.path() / "cache", frames);
    });
    fs::remove_all(dir);
  }

  for (int i = 0; i < kExrCases && !over(2); ++i, ++index) {
    const fs::path dir = templ.makeCase(index);
    const std::string source = gen.pick(std::vector<std::string>{"depth.exr", "depth-raw.exr", "shadow.exr"});
    const std::string option = source == "shadow.exr" ? "--shadow" : "--depth";
    writeText(dir / "damaged.exr", gen.damage(readText((dir / source).string())));
    Case c;
    c.args = {"scatter", option,     "damaged.exr", "--frame", "frame.json", "--out",
              "out.exr", "--method", "reference",   "--steps", "4"};
    c.args.push_back(option == "--depth" ? "--shadow" : "--depth");
    c.args.push_back(option == "--depth" ? "shadow.exr" : "depth.exr");
    c.names = {option, "damaged.exr"};
    timed(exrs, [&] {
      runCase("seed " + std::to_string(s) + ", EXR " + std::to_string(i) + " (" + source + ")", c, dir,
              templ.dir.path() / "cache", exrs);
    });
    fs::remove_all(dir);
  }

  const auto line = [](const char* what, const Tally& t) {
    return std::string(what) + ": " + std::to_string(t.cases) +
           " cases (exit 0/1/2: " + std::to_string(t.status[0]) + "/" + std::to_string(t.status[1]) + "/" +
           std::to_string(t.status[2]) + "), " + std::to_string(static_cast<int>(t.seconds + 0.5)) + " s";
  };
  const std::string summary = "seed " + std::to_string(s) + "; " + line("command lines", commandLines) +
                              "; " + line("JSON frames", frames) + "; " + line("EXR files", exrs) +
                              "; total " + std::to_string(static_cast<int>(elapsed() + 0.5)) + " s" +
                              (budgetHit ? " (a deadline was reached: fewer cases than configured)" : "");
  MESSAGE(summary);
  CHECK(commandLines.cases > 0);
}
