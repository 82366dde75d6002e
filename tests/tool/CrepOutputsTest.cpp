// The crep tool's output rule and usage errors that need no GL (README "The crep tool", "Outputs"): an output
// that is a FIFO, a device, a socket or a directory (itself or its link's target) is refused naming the
// option and the path and stays what it was; every output folder and path is checked before any output is
// written and before the GL context exists; usage errors exit 2 naming the option the user set; inputs the
// documentation does not allow (depth EXRs without a Y, Z, depth or R channel, a JSON file with a NUL byte)
// are refused naming the file.
#include "common/image_check.h"
#include "common/tool_runner.h"
#include "tool/frame_json_util.h"

#include <crep/core/image.h>
#include <crep/support/exr.h>

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <string>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>
#include <vector>

namespace {

namespace fs = std::filesystem;
using namespace crep::test::frame_json;
using crep::test::ArgvResult;
using crep::test::runCrepArgv;

std::size_t lineCount(const std::string& text) {
  std::size_t n = 0;
  for (char c : text)
    n += c == '\n';
  return n;
}

/// A failure: exit status, every mention, no "unexpected error"; the whole output is the one error line (the
/// GL context, which prints the renderer, was never created).
void expectEarlyFailure(const ArgvResult& r, int status, std::initializer_list<std::string> mentions) {
  INFO(r.output);
  CHECK(r.signal == 0);
  CHECK(r.status == status);
  for (const std::string& m : mentions)
    CHECK(r.output.find(m) != std::string::npos);
  CHECK(r.output.find("unexpected error") == std::string::npos);
  CHECK(lineCount(r.output) == 1);
}

/// Valid scatter inputs for the example frame: depth.exr (160x90, 0.9), shadow.exr (256x256, 1), frame.json.
struct ScatterInputs : ScatterFolder {
  ScatterInputs() : ScatterFolder("crep-outputs") { writeExampleFrame(); }
  std::vector<std::string> args(std::initializer_list<std::string> extra) const {
    std::vector<std::string> a = {"scatter",          "--depth", path("depth.exr"), "--shadow",
                                  path("shadow.exr"), "--frame", path("frame.json")};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
};

/// A UNIX socket bound at `path` (kept until the test's directory goes).
void makeSocket(const fs::path& path) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  REQUIRE(fd >= 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  const std::string p = path.string();
  REQUIRE(p.size() < sizeof address.sun_path);
  std::copy(p.begin(), p.end(), address.sun_path);
  REQUIRE(::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0);
  ::close(fd);
}

bool isFifo(const fs::path& p) {
  struct stat s {};
  return ::lstat(p.c_str(), &s) == 0 && S_ISFIFO(s.st_mode);
}

/// Rewrites the channel name of a single-channel EXR written by crep::writeExr ("Y") to `name` (one
/// character: the channel list keeps its size).
void renameChannel(const fs::path& path, char name) {
  std::string bytes = readText(path.string());
  const std::string marker = std::string("channels") + '\0' + "chlist" + '\0';
  const std::size_t at = bytes.find(marker);
  REQUIRE(at != std::string::npos);
  const std::size_t first = at + marker.size() + 4; // after the attribute's size
  REQUIRE(bytes.at(first) == 'Y');
  REQUIRE(bytes.at(first + 1) == '\0');
  bytes[first] = name;
  writeText(path, bytes);
}

} // namespace

TEST_CASE("crep outputs: a FIFO, socket, directory or device is refused naming the option and the path, and "
          "stays what it was") {
  const ScatterInputs in;
  REQUIRE(::mkfifo(in.path("fifo").c_str(), 0644) == 0);
  fs::create_directory(in.dir / "folder");
  makeSocket(in.dir / "sock");
  fs::create_symlink("fifo", in.dir / "link-to-fifo");
  fs::create_symlink("link-to-fifo", in.dir / "chain-to-fifo");
  const std::set<std::string> before = listing(in.dir.path());
  struct Case {
    std::vector<std::string> args;
    std::vector<std::string> mentions;
  };
  const std::vector<Case> cases = {
      {in.args({"--out", in.path("fifo")}), {"--out", "fifo", "FIFO"}},
      {in.args({"--png", in.path("fifo")}), {"--png", "fifo", "FIFO"}},
      {in.args({"--out", in.path("sock")}), {"--out", "sock", "socket"}},
      {in.args({"--out", in.path("folder")}), {"--out", "folder", "directory"}},
      {in.args({"--out", in.path("link-to-fifo")}), {"--out", "link-to-fifo", "FIFO"}},
      {in.args({"--out", in.path("chain-to-fifo")}), {"--out", "chain-to-fifo", "FIFO"}},
      {in.args({"--out", "/dev/null"}), {"--out", "/dev/null", "character device"}},
      {in.args({"--png", "/dev/zero"}), {"--png", "/dev/zero", "character device"}},
  };
  for (const Case& c : cases) {
    const ArgvResult r = runCrepArgv(c.args);
    INFO(c.args[c.args.size() - 2] << " " << c.args.back());
    expectEarlyFailure(r, 1, {});
    for (const std::string& m : c.mentions)
      CHECK(r.output.find(m) != std::string::npos);
    CHECK(r.output.find("not a regular file") != std::string::npos);
  }
  CHECK(listing(in.dir.path()) == before); // nothing written, nothing replaced
  CHECK(isFifo(in.dir / "fifo"));
  CHECK(fs::is_symlink(in.dir / "link-to-fifo"));
  CHECK(fs::is_directory(in.dir / "folder"));
  CHECK(fs::is_character_file("/dev/null")); // as root the old rename replaced it with a regular file
  CHECK(fs::is_character_file("/dev/zero"));

  // render, compare and the export folder follow the same rule, before the GL context.
  REQUIRE(::mkfifo(in.path("pic.png").c_str(), 0644) == 0);
  expectEarlyFailure(runCrepArgv({"render", "--size", "16x9", "--out", in.path("pic")}), 1,
                     {"--out", "pic.png", "FIFO"});
  REQUIRE(::mkfifo(in.path("sheet.csv").c_str(), 0644) == 0);
  expectEarlyFailure(runCrepArgv({"compare", "--size", "16x9", "--out", in.path("sheet")}), 1,
                     {"--out", "sheet.csv", "FIFO"});
  fs::create_directory(in.dir / "export");
  REQUIRE(::mkfifo(in.path("export/frame.json").c_str(), 0644) == 0);
  expectEarlyFailure(
      runCrepArgv({"render", "--size", "16x9", "--out", in.path("x"), "--export-frame", in.path("export")}),
      1, {"--export-frame", "frame.json", "FIFO"});
  fs::create_directory(in.dir / "export/depth.exr");
  expectEarlyFailure(
      runCrepArgv({"render", "--size", "16x9", "--out", in.path("x"), "--export-frame", in.path("export")}),
      1, {"--export-frame", "depth.exr", "directory"});
  CHECK_FALSE(fs::exists(in.dir / "x.exr"));
  CHECK_FALSE(fs::exists(in.dir / "x.png"));
  CHECK_FALSE(fs::exists(in.dir / "pic.exr"));
  CHECK_FALSE(fs::exists(in.dir / "sheet.png"));
  CHECK(isFifo(in.dir / "pic.png"));
  CHECK(isFifo(in.dir / "sheet.csv"));
}

TEST_CASE("crep outputs: an export folder that cannot be created fails before any output and any GL work") {
  crep::test::TempDir dir{"crep-outputs"};
  // /proc takes no new directory, even as root: the folder used to be created after X.exr and X.png were
  // written, which stayed behind.
  const std::string x = (dir / "x").string();
  expectEarlyFailure(
      runCrepArgv({"render", "--size", "16x9", "--out", x, "--export-frame", "/proc/crep-newdir"}), 1,
      {"--export-frame", "/proc/crep-newdir"});
  CHECK_FALSE(fs::exists("/proc/crep-newdir"));
  // A folder under a file.
  writeText(dir / "file.txt", "a file");
  expectEarlyFailure(runCrepArgv({"render", "--size", "16x9", "--out", x, "--export-frame",
                                  (dir / "file.txt/sub").string()}),
                     1, {"--export-frame", "file.txt", "not a directory"});
  // A folder the command created is removed again when a later check fails (--out's directory is missing).
  expectEarlyFailure(runCrepArgv({"render", "--size", "16x9", "--export-frame", (dir / "new/deeper").string(),
                                  "--out", (dir / "missing/x").string()}),
                     1, {"--out", "missing", "does not exist"});
  CHECK(listing(dir.path()) == std::set<std::string>{"file.txt"});
  // The default prefix of a scene name with a directory part used to be blamed on --out.
  expectEarlyFailure(runCrepArgv({"render", "--size", "16x9", "--scene", "../colonnade"}), 2,
                     {"option --scene", "../colonnade"});
}

TEST_CASE("crep: usage errors come before any GL work, exit 2 and name the option the user set") {
  struct Case {
    std::vector<std::string> args;
    std::vector<std::string> mentions;
    std::vector<std::string> absent;
  };
  std::vector<Case> cases = {
      {{"render", "--scene", "bogus"}, {"option --scene", "bogus", "colonnade"}, {"invalid scene"}},
      {{"compare", "--scene", "bogus"}, {"option --scene", "bogus"}, {}},
      {{"render", "--scene", "../colonnade"}, {"option --scene"}, {"--out"}},
      {{"render", "--size", "160x90", "--scale", "0.25"},
       {"option --scale", "0.25", "160x90"},
       {"CreateInfo"}},
      {{"render", "--size", "160x90", "--scale", "0.5", "--method", "epipolar-prefilter"},
       {"option --scale", "epipolar-prefilter"},
       {"CreateInfo"}},
      {{"render", "--size", "160x90", "--method", "epipolar-sampling", "--downscale", "4"},
       {"option --downscale", "4", "160x90"},
       {"CreateInfo"}},
      {{"compare", "--size", "160x90", "--downscale", "4"}, {"option --downscale"}, {"CreateInfo"}},
      {{"compare", "--size", "160x90", "--scale", "0.25"}, {"option --scale"}, {"CreateInfo"}},
      {{"render", "--size", "160x90", "--downscale", "3", "--method", "epipolar-sampling"},
       {"option --downscale", "1, 2 or 4"},
       {}},
      {{"render", "--initial-step", "64", "--samples", "32"}, {"option --initial-step", "samples"}, {}},
      {{"render", "--epipole-block", "bogus"}, {"option --epipole-block", "bogus", "tree or world"}, {}},
      {{"render", "--epipole-block-radius", "0.7"}, {"option --epipole-block-radius", "0.7"}, {}},
      {{"compare", "--epipole-block-pixels", "-1"}, {"option --epipole-block-pixels", "-1"}, {}},
      {{"rectify", "--near", "1000"}, {"option --near", "1000"}, {"option --far"}},
      {{"rectify", "--far", "0.01"}, {"option --far", "0.01"}, {"option --near"}},
      {{"rectify", "--near", "5", "--far", "1"}, {"--near", "--far"}, {}},
      {{"compare", "--methods", ""}, {"option --methods", "empty"}, {}},
      {{"compare", "--methods", "prefilter,"}, {"option --methods", "empty method name"}, {}},
      {{"compare", "--methods", ",prefilter"}, {"option --methods", "empty method name"}, {}},
      {{"compare", "--methods", "prefilter,,minmax"}, {"option --methods", "empty method name"}, {}},
      {{"render", "--out", "--debug-gl"}, {"option --out", "--debug-gl", "--out=VALUE"}, {}},
      {{"scatter", "--depth", "--frame", "f.json"}, {"option --depth", "--frame"}, {}},
      {{"render", "--size=16x9", "--out=--debug-gl", "--bogus"}, {"--bogus"}, {}},
  };
  if (CREP_TOOL_HAS_BENCH)
    cases.push_back({{"bench", "--quick", "--scene", "bogus"}, {"option --scene"}, {}});
  for (const Case& c : cases) {
    crep::test::TempDir dir{"crep-usage"};
    crep::test::RunOptions options;
    options.workingDirectory = dir.path().string();
    const ArgvResult r = runCrepArgv(c.args, options);
    INFO(c.args[0] << " " << c.args[1] << " " << c.args.back());
    expectEarlyFailure(r, 2, {});
    for (const std::string& m : c.mentions)
      CHECK(r.output.find(m) != std::string::npos);
    for (const std::string& m : c.absent)
      CHECK(r.output.find(m) == std::string::npos);
    CHECK(fs::is_empty(dir.path())); // "--out --debug-gl" used to write ./--debug-gl.exr
  }
  // The option value that starts with "--" is still possible, attached.
  const ArgvResult attached = runCrepArgv({"rectify", "--light-dir=1,-1,0"});
  INFO(attached.output);
  CHECK(attached.status == 0);
}

TEST_CASE("crep scatter: depth and shadow EXRs whose only channel is not Y, Z, depth or R are refused naming "
          "the file and the channels") {
  const ScatterInputs in;
  for (const char channel : {'G', 'B', 'A', 'y'}) {
    for (const std::string option : {"--depth", "--shadow"}) {
      const std::string file = option == "--depth" ? "depth.exr" : "shadow.exr";
      const crep::Image image =
          option == "--depth" ? crep::Image(160, 90, 1, 0.9f) : crep::Image(256, 256, 1, 1.0f);
      crep::writeExr(in.dir / file, image, crep::ExrPixelType::Float);
      renameChannel(in.dir / file, channel);
      const ArgvResult r = runCrepArgv(in.args({"--out", in.path("out.exr")}));
      INFO(option << " with channel " << channel);
      expectEarlyFailure(r, 1, {option, file, std::string("channels: ") + channel, "Y, Z, depth or R"});
      crep::writeExr(in.dir / file, image, crep::ExrPixelType::Float); // valid again
    }
  }
  CHECK_FALSE(fs::exists(in.dir / "out.exr"));
}

TEST_CASE("crep scatter: a frame file with a NUL byte is refused naming the file") {
  const ScatterInputs in;
  const std::string text = readText(kExample);
  for (const std::string& bad : {text + std::string(1, '\0'), text + std::string(1, '\0') + "{}",
                                 std::string(1, '\0') + text, text.substr(0, 10) + '\0' + text.substr(10)}) {
    writeText(in.dir / "frame.json", bad);
    const ArgvResult r = runCrepArgv(in.args({"--out", in.path("out.exr")}));
    expectEarlyFailure(r, 1, {"frame.json", "NUL byte", "line"});
  }
  CHECK_FALSE(fs::exists(in.dir / "out.exr"));
}

TEST_CASE("crep scatter: a local light's radiance bound names the field to change: nearPlane or intensity") {
  const ScatterInputs in;
  crep::writeExr(in.dir / "point.exr", crep::Image(32, 192, 1, 1.0f), crep::ExrPixelType::Float);
  const auto run = [&](const std::function<void(Json&)>& edit) {
    Json j = Json::parse(readText(kExample));
    j["lights"] = Json::array({Json{{"type", "point"},
                                    {"position", Json::array({4.0, 3.0, -2.0})},
                                    {"color", Json::array({1.0, 1.0, 1.0})},
                                    {"intensity", 10},
                                    {"range", 50},
                                    {"shadowMap", {{"file", "point.exr"}}}}});
    edit(j);
    writeText(in.dir / "frame.json", j.dump(2));
    return runCrepArgv(in.args({"--out", in.path("out.exr")}));
  };
  // Used to be blamed on light.intensity / lights[i].intensity.
  expectEarlyFailure(run([](Json& j) {
                       j["lights"][0]["nearPlane"] = 1e-30;
                       j["lights"][0]["intensity"] = 100;
                     }),
                     1,
                     {"frame.json: lights[0].nearPlane: with this medium the in-scattered radiance can reach",
                      "raise lights[0].nearPlane"});
  // A nearPlane at or above range x 1e-3 (the default floor): the intensity is what to lower.
  expectEarlyFailure(
      run([](Json& j) {
        j["lights"][0]["intensity"] = 1e30;
        j["lights"][0]["nearPlane"] = 0.06;
      }),
      1, {"frame.json: lights[0].intensity: with this medium the in-scattered radiance can reach"});
  // The main light a spot: its own path.
  expectEarlyFailure(
      run([](Json& j) {
        j["light"] = exampleSpotJson();
        j["light"]["nearPlane"] = 1e-30;
        j["shadowMap"] = {{"lightClipFromWorld", matrixJson(exampleSpot().lightClipFromWorld())}};
      }),
      1, {"frame.json: light.nearPlane: with this medium"});
  // The directional light's own bound still names light.intensity.
  expectEarlyFailure(run([](Json& j) {
                       j["light"]["intensity"] = 1e28;
                       j["medium"]["hgG"] = 0.999;
                     }),
                     1, {"frame.json: light.intensity: with this medium"});
  CHECK_FALSE(fs::exists(in.dir / "out.exr"));
}

TEST_CASE(
    "crep scatter: camera.maxDistance beyond the near plane's resolution names maxDistance when the far "
    "plane is infinite") {
  const ScatterInputs in;
  Json j = Json::parse(readText(kExample));
  Json& p = j["camera"]["clipFromView"];
  p[14] = p[14].get<double>() / (1.0 - p[10].get<double>()) * 2.0; // -2 near: an infinite far plane
  p[10] = -1.0;
  j["camera"]["maxDistance"] = 1e29;
  writeText(in.dir / "frame.json", j.dump(2));
  expectEarlyFailure(runCrepArgv(in.args({"--out", in.path("out.exr")})), 1,
                     {"frame.json: camera.maxDistance", "near plane"});
}
