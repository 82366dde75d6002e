// End-to-end tests of the crep tool that need no GL: usage errors and `crep rectify`.
#include "common/image_check.h"
#include "common/tool_runner.h"

#include <crep/core/camera.h>

#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <regex>
#include <string>
#include <vector>

namespace {
std::vector<std::vector<double>> splitMatrices(const std::string& json) {
  std::vector<std::vector<double>> out;
  const std::regex matrix(R"re("rectClipFromWorld": \[([^\]]*)\])re");
  for (auto it = std::sregex_iterator(json.begin(), json.end(), matrix); it != std::sregex_iterator(); ++it) {
    std::vector<double> values;
    std::string list = (*it)[1];
    char* p = list.data();
    while (*p) {
      char* end = nullptr;
      values.push_back(std::strtod(p, &end));
      if (end == p) break;
      p = end;
      while (*p == ',' || *p == ' ')
        ++p;
    }
    out.push_back(values);
  }
  return out;
}
} // namespace

TEST_CASE("crep rectify: JSON splits contain the camera frustum") {
  const auto r =
      crep::test::runCrep("rectify --camera-pos 0,1,5 --camera-target 0,1,0 --camera-up 0,1,0 "
                          "--fovy-deg 50 --aspect 1.5 --near 0.2 --far 40 --light-dir 1,-1,0.2 --splits 3");
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find(R"("status": "projective")") != std::string::npos);
  const auto matrices = splitMatrices(r.output);
  REQUIRE(matrices.size() == 3);
  const crep::Camera camera =
      crep::Camera::lookAt({0, 1, 5}, {0, 1, 0}, {0, 1, 0}, 50.0 * std::numbers::pi / 180.0, 1.5, 0.2, 40.0);
  // Every sampled point of the frustum lies in the NDC cube of at least one split (parsed from the
  // printed column-major numbers).
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 4; ++j)
      for (double dist : {0.2, 0.5, 3.0, 17.0, 40.0}) {
        const glm::dvec3 dir = camera.rayDirection(i / 2.0 - 1.0, j / 2.0 - 1.0);
        const glm::dvec3 p = camera.position() + dir * (dist / glm::dot(dir, camera.forward()));
        bool inside = false;
        for (const auto& m : matrices) {
          REQUIRE(m.size() == 16);
          glm::dmat4 clip;
          for (int k = 0; k < 16; ++k)
            clip[k / 4][k % 4] = m[static_cast<std::size_t>(k)];
          const glm::dvec4 c = clip * glm::dvec4(p, 1.0);
          const glm::dvec3 ndc = glm::dvec3(c) / c.w;
          const double tol = 1e-9;
          inside = inside || (c.w > 0 && std::abs(ndc.x) <= 1 + tol && std::abs(ndc.y) <= 1 + tol &&
                              std::abs(ndc.z) <= 1 + tol);
        }
        CHECK(inside);
      }
}

TEST_CASE("crep rectify: light in view gives a fallback with its reason") {
  const auto r = crep::test::runCrep("rectify --camera-pos 0,0,0 --camera-target 0,0,-1 --light-dir 0.1,0,1");
  INFO(r.output);
  REQUIRE(r.status == 0);
  CHECK(r.output.find(R"("status": "fallback")") != std::string::npos);
  CHECK(r.output.find(R"("splits": [])") != std::string::npos);
}

TEST_CASE("crep rectify: invalid options exit 2 naming the option") {
  struct Case {
    const char* args;
    const char* mentions;
  };
  for (const Case& c :
       {Case{"rectify --near 5 --far 1", "--far"}, Case{"rectify --light-dir 0,0,0", "--light-dir"},
        Case{"rectify --splits 0", "--splits"}, Case{"rectify --fovy-deg 180", "--fovy-deg"},
        Case{"rectify --aspect -1", "--aspect"}, Case{"rectify --near nan", "--near"},
        Case{"rectify --camera-pos 1,2", "--camera-pos"}, Case{"rectify --scheme cubic", "--scheme"},
        Case{"rectify --camera-target 0,0,0 --camera-pos 0,0,0", "--camera-target"}}) {
    const auto r = crep::test::runCrep(c.args);
    INFO(c.args << " -> " << r.output);
    CHECK(r.status == 2);
    CHECK(r.output.find(c.mentions) != std::string::npos);
  }
}

TEST_CASE("crep: usage errors exit 2 and name the option") {
  // These fail before any GL work, so they need no context.
  struct Case {
    const char* args;
    const char* mentions;
  };
  std::vector<Case> cases = {Case{"render --size 0x90", "--size"},
                             Case{"render --size abc", "--size"},
                             Case{"render --map-size -3", "--map-size"},
                             Case{"render --exposure nan", "--exposure"},
                             Case{"render --bogus 1", "--bogus"},
                             Case{"render --steps", "--steps"},
                             Case{"render --export-frame ''", "--export-frame"},
                             Case{"render --method bogus", "--method"},
                             Case{"scatter", "--depth"},
                             Case{"compare --amplify 0", "--amplify"},
                             Case{"compare --size 8x", "--size"},
                             Case{"compare --methods prefilter,bogus", "--methods"},
                             Case{"frobnicate", "frobnicate"}};
  if (CREP_TOOL_HAS_BENCH) // `crep bench` exists when bench/ is built
    cases.insert(cases.end(), {Case{"bench --repeat 0", "--repeat"}, Case{"bench --map 12", "--map"}});
  for (const Case& c : cases) {
    const auto r = crep::test::runCrep(c.args);
    INFO(c.args << " -> " << r.output);
    CHECK(r.status == 2);
    CHECK(r.output.find(c.mentions) != std::string::npos);
  }
  const auto help = crep::test::runCrep("help");
  CHECK(help.status == 0);
  CHECK(help.output.find("render") != std::string::npos);
  // bench/ registers `crep bench` with the tool's command registry (examples/ does not know bench/).
  CHECK((help.output.find("\n  bench     the benchmark suite") != std::string::npos) ==
        (CREP_TOOL_HAS_BENCH != 0));
}

namespace {
/// Runs crep and checks a failure: exit status, every mention in the output, no internal names.
crep::test::ToolResult expectFailure(const std::string& args, int status,
                                     std::initializer_list<std::string> mentions) {
  const auto r = crep::test::runCrep(args);
  INFO(args);
  crep::test::expectFailure(r, status, mentions);
  return r;
}

/// Files in `dir` (none should be written by a command that failed validation).
std::size_t fileCount(const crep::test::TempDir& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path()))
    ++n;
  return n;
}
} // namespace

TEST_CASE("crep compare: a contact sheet beyond the image limits is a usage error naming --tile-width") {
  // --size 1x1 used to crash (a 1-pixel default tile); now the default tile is at least 16 wide
  // (CrepCompareGLTest), and a sheet that would exceed the image limits is refused before any work.
  crep::test::TempDir dir;
  const std::string out = " --out '" + (dir / "sheet").string() + "'";
  expectFailure("compare --size 1x32768" + out, 2, {"--tile-width", "--size", "1x32768"});
  expectFailure("compare --size 100x1000 --tile-width 4096" + out, 2, {"--tile-width", "4096"});
  expectFailure("compare --tile-width 15" + out, 2, {"--tile-width", "[16, 4096]"});
  CHECK(fileCount(dir) == 0);
}

TEST_CASE("crep: out-of-range numbers are usage errors naming the option, before any output") {
  crep::test::TempDir dir;
  const std::string out = " --out '" + (dir / "x").string() + "'";
  // --exposure 1e39 used to write the EXR, then fail naming ToneMap.exposure with exit 1.
  expectFailure("render --size 16x9 --exposure 1e39" + out, 2, {"--exposure", "[1e-30, 1e30]"});
  expectFailure("render --size 16x9 --exposure 1e-31" + out, 2, {"--exposure"});
  expectFailure("render --size 16x9 --exposure 1e999" + out, 2, {"--exposure", "out of range"});
  expectFailure("compare --size 16x9 --exposure 1e39" + out, 2, {"--exposure"});
  expectFailure("compare --size 16x9 --amplify 1e300" + out, 2, {"--amplify"});
  expectFailure("render --size 16x9 --map-size 32768" + out, 2, {"--map-size", "16384"});
  expectFailure("render --size 32768x32768" + out, 2, {"--size", "pixels"});
  expectFailure("compare --size 16x9 --map-size 16385" + out, 2, {"--map-size"});
  if (CREP_TOOL_HAS_BENCH) {
    // Used to fail inside the rectification, naming Rectification.splitViewport.width.
    // Scattering's defaults: 8 splits x 2 prefilter regions (--quick: a multiple of 16), and up to 4 regions
    // per split in the parallelization rows (a multiple of 32).
    for (const char* map : {"1x1", "4x4", "24x24", "48x48"}) {
      const auto r = expectFailure(std::string("bench --map ") + map, 2, {"--map", "multiple of 32"});
      CHECK(r.output.find("Rectification") == std::string::npos);
    }
    expectFailure("bench --quick --map 8x8", 2, {"--map", "multiple of 16"});
    expectFailure("bench --map 32x1", 2, {"--map", "height"});
    expectFailure("bench --map 32768x16", 2, {"--map"});
  }
  CHECK(fileCount(dir) == 0);
}

TEST_CASE("crep: numbers and sizes are parsed strictly (decimal, no spaces, no '+', no hex)") {
  struct Case {
    const char* args;
    const char* mentions;
  };
  for (const Case& c :
       {Case{"render --size ' 160x90'", "--size"}, Case{"render --size '160x90 '", "--size"},
        Case{"render --size +160x+90", "--size"}, Case{"render --size 0x10x90", "--size"},
        Case{"render --size 160x-90", "--size"}, Case{"render --exposure 0x10", "--exposure"},
        Case{"render --exposure ' 1'", "--exposure"}, Case{"render --exposure '1 '", "--exposure"},
        Case{"render --exposure +1", "--exposure"}, Case{"render --exposure inf", "--exposure"},
        Case{"render --exposure 1e", "--exposure"}, Case{"render --exposure .", "--exposure"},
        Case{"render --steps +5", "--steps"}, Case{"render --steps ' 5'", "--steps"},
        Case{"render --steps 5.0", "--steps"}, Case{"render --steps 0x10", "--steps"},
        Case{"render --map-size 99999999999999999999", "--map-size"},
        Case{"rectify --camera-pos '0, 1, 5'", "--camera-pos"}, Case{"rectify --aspect 0x1p1", "--aspect"}}) {
    const auto r = crep::test::runCrep(c.args);
    INFO(c.args << " -> " << r.output);
    CHECK(r.status == 2);
    CHECK(r.output.find(c.mentions) != std::string::npos);
  }
  // What the grammar accepts (args.h): fractions, exponents, a leading '-'.
  for (const char* ok : {"rectify --aspect 1.5", "rectify --aspect .5e1", "rectify --aspect 2.",
                         "rectify --aspect 15E-1", "rectify --light-dir -1,-1e0,0.25 --fovy-deg 6e1"}) {
    const auto r = crep::test::runCrep(ok);
    INFO(ok << " -> " << r.output);
    CHECK(r.status == 0);
  }
}

TEST_CASE("crep rectify: a field of view below 0.001 degrees is a usage error, help and docs/FORMATS.md list "
          "the empty status") {
  // --fovy-deg 1e-300 used to print the undocumented status "empty".
  for (const char* fovy : {"1e-300", "1e-12", "0.0009", "180", "0"})
    expectFailure(std::string("rectify --fovy-deg ") + fovy, 2, {"--fovy-deg", "[0.001, 180)"});
  const auto smallest = crep::test::runCrep("rectify --fovy-deg 0.001");
  INFO(smallest.output);
  CHECK(smallest.status == 0);
  CHECK(smallest.output.find(R"("status": "projective")") != std::string::npos);
  // "empty" remains a status of the library (spot and point lights), so both documents list it.
  const auto help = crep::test::runCrep("help");
  CHECK(help.output.find(R"("projective"|"fallback"|"empty")") != std::string::npos);
  std::ifstream formats(std::string(CREP_SOURCE_DIR) + "/docs/FORMATS.md");
  const std::string text((std::istreambuf_iterator<char>(formats)), std::istreambuf_iterator<char>());
  CHECK(text.find(R"("status": "projective" | "fallback" | "empty")") != std::string::npos);
}

TEST_CASE("crep: every command answers --help with its own section on stdout, --version prints the version") {
  std::vector<std::string> commands = {"render", "scatter", "compare", "rectify"};
  if (CREP_TOOL_HAS_BENCH) commands.push_back("bench");
  for (const std::string& command : commands)
    for (const std::string& form : {command + " --help", command + " --size 8x8 --help", "help " + command}) {
      // stderr to /dev/null: the help text must be on stdout.
      const auto r = crep::test::runCrep(form + " 2>/dev/null; exit $?");
      INFO(form << " -> " << r.output);
      CHECK(r.status == 0);
      CHECK(r.output.starts_with("usage: crep " + command + " [options]\n"));
      CHECK(r.output.find("\n  " + command + " ") != std::string::npos);
      CHECK(r.output.find("Exit status") != std::string::npos);
      for (const std::string& other : commands)
        if (other != command) CHECK(r.output.find("\n  " + other + " ") == std::string::npos);
    }
  const auto render = crep::test::runCrep("render --help");
  CHECK(render.output.find("--export-frame") != std::string::npos);
  CHECK(render.output.find("--tile-width") == std::string::npos);
  CHECK(render.output.find("unknown option") == std::string::npos);

  const auto version = crep::test::runCrep("--version 2>/dev/null; exit $?");
  INFO(version.output);
  CHECK(version.status == 0);
  CHECK(std::regex_match(version.output, std::regex(R"(crep \d+\.\d+\.\d+\n)")));
  expectFailure("help frobnicate", 2, {"frobnicate"});
}

TEST_CASE("crep render and compare: outputs that collide or cannot be written fail before any work") {
  crep::test::TempDir dir;
  std::filesystem::create_directory(dir / "frame");
  std::ofstream(dir / "file.txt") << "not a directory";
  const std::string d = dir.path().string();
  // PREFIX.exr would be the exported depth.exr.
  expectFailure("render --size 16x9 --out '" + d + "/frame/depth' --export-frame '" + d + "/frame'", 2,
                {"--export-frame", "--out", "depth.exr"});
  expectFailure("render --size 16x9 --out '" + d + "/frame/'", 2, {"--out", "directory"});
  expectFailure("render --size 16x9 --out ''", 2, {"--out", "empty"});
  expectFailure("render --size 16x9 --out '" + d + "/missing/x'", 1, {"--out", "missing", "does not exist"});
  expectFailure("render --size 16x9 --out '" + d + "/x' --export-frame '" + d + "/file.txt'", 1,
                {"--export-frame", "file.txt", "not a directory"});
  expectFailure("render --size 16x9 --out '" + d + "/x' --export-frame '" + d + "/file.txt/sub'", 1,
                {"--export-frame", "file.txt", "not a directory"});
  expectFailure("compare --size 16x9 --out '" + d + "/missing/x'", 1, {"--out", "missing", "does not exist"});
  expectFailure("compare --size 16x9 --out '" + d + "/'", 2, {"--out", "directory"});
  CHECK(fileCount(dir) == 2); // frame/ and file.txt, nothing else
  CHECK(std::filesystem::is_empty(dir / "frame"));
}
