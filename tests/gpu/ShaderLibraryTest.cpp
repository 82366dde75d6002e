// The shader library without GL: embedded files, include expansion, #line bookkeeping, log
// translation, and every shader of the library through glslangValidator (the Khronos reference
// front end), which catches what one driver would accept and another reject.
#include "common/shader_tools.h"

#include <crep/core/error.h>
#include <crep/gpu/shader_library.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <unistd.h>
#include <vector>

using crep::ExpandedShader;
using crep::ShaderDefine;
using crep::ShaderLibrary;

namespace {

std::string errorOf(std::string_view path, std::vector<ShaderDefine> defines = {}) {
  try {
    ShaderLibrary::expand(path, defines);
  } catch (const crep::ShaderError& e) {
    return e.what();
  }
  return "(no ShaderError)";
}

bool contains(std::string_view haystack, std::string_view needle) {
  return haystack.find(needle) != std::string_view::npos;
}

/// Shaders of the library (glsl/) and of examples/ (examples/glsl/, registered by test_main.cpp);
/// the "test/" files are the fixtures of tests/glsl/.
bool isLibraryFile(std::string_view path) {
  return !path.starts_with("test/");
}

using crep::test::findInPath;
using crep::test::RunResult;

/// Writes `text` to the test output folder with the stage's extension and runs glslangValidator on
/// it (plain validation: OpenGL GLSL semantics, no SPIR-V written).
RunResult glslang(const std::string& name, const std::string& extension, const std::string& text,
                  const std::string& flags = "") {
  const std::optional<std::filesystem::path> validator = findInPath("glslangValidator");
  REQUIRE_MESSAGE(
      validator.has_value(),
      "glslangValidator not found in PATH: install glslang-tools (apt-get install glslang-tools, part "
      "of the README's set-up command)");
  // One folder per process: the test cases run as parallel processes (ctest -j) on the same files.
  const std::filesystem::path dir =
      std::filesystem::path(CREP_TEST_OUTPUT_DIR) / "glslang" / std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  std::string flat = name;
  std::replace(flat.begin(), flat.end(), '/', '_');
  if (!flat.ends_with("." + extension)) flat += "." + extension;
  const std::filesystem::path file = dir / flat;
  std::ofstream(file, std::ios::binary) << text;
  // SPIR-V output (-G, -V, -H) goes next to the source, never into the working directory.
  const std::string output = flags.find("-G") != std::string::npos || flags.find("-V") != std::string::npos ||
                                     flags.find("-H") != std::string::npos
                                 ? " -o '" + file.string() + ".spv'"
                                 : "";
  return crep::test::runCommand("'" + validator->string() + "' " + flags + output + " '" + file.string() +
                                "'");
}

} // namespace

TEST_CASE("ShaderLibrary: files are embedded, sorted and unique") {
  const auto files = ShaderLibrary::files();
  REQUIRE(!files.empty());
  for (std::size_t i = 1; i < files.size(); ++i)
    CHECK(files[i - 1].path < files[i].path);
  for (const auto& f : files) {
    CHECK(!f.path.empty());
    CHECK(!f.path.starts_with("/"));
  }
  const auto has = [&](std::string_view p) {
    return std::any_of(files.begin(), files.end(), [&](const auto& f) { return f.path == p; });
  };
  CHECK(has("crep/common.glsl"));
  CHECK(has("crep/phase.glsl"));
  CHECK(has("passes/fullscreen.vert"));
  CHECK(has("test/test_fill.comp"));
  CHECK(contains(ShaderLibrary::source("test/test_fill.comp"), "CREP_FILL_VALUE"));
  CHECK_THROWS_AS(ShaderLibrary::source("passes/no_such_file.comp"), crep::ShaderError);
  CHECK(contains(errorOf("passes/no_such_file.comp"), "passes/no_such_file.comp"));
}

TEST_CASE("ShaderLibrary::addFiles: extra sets include library files, never shadow them") {
  // What examples/ and tests/ do with their generated sets (cmake/EmbedGlsl.cmake), by hand.
  static constexpr ShaderLibrary::File kExtra[] = {
      {"test/added/main.comp", "#version 450 core\n#include \"crep/phase.glsl\"\n#include \"helper.glsl\"\n"
                               "layout(local_size_x = 1) in;\nvoid main() {}\n"},
      {"test/added/helper.glsl", "const int crep_test_helper = 1;\n"}};
  const auto before = ShaderLibrary::files();
  const std::size_t countBefore = before.size();
  ShaderLibrary::addFiles(kExtra);
  ShaderLibrary::addFiles(kExtra); // the same set again: nothing changes
  const auto after = ShaderLibrary::files();
  CHECK(after.size() == countBefore + 2);
  CHECK(before.size() == countBefore); // a span taken earlier stays valid and unchanged
  CHECK(std::none_of(before.begin(), before.end(),
                     [](const auto& f) { return f.path.starts_with("test/added/"); }));
  for (std::size_t i = 1; i < after.size(); ++i)
    CHECK(after[i - 1].path < after[i].path);
  // Relative includes resolve inside the set, root includes reach the library's files.
  const ExpandedShader e = ShaderLibrary::expand("test/added/main.comp");
  CHECK(e.files == std::vector<std::string>{"test/added/main.comp", "crep/phase.glsl", "crep/common.glsl",
                                            "test/added/helper.glsl"});

  // Another source under a registered path is refused, and nothing of that set is added.
  static constexpr ShaderLibrary::File kShadow[] = {{"test/added/other.glsl", "// fine on its own\n"},
                                                    {"crep/common.glsl", "// not the library's\n"}};
  try {
    ShaderLibrary::addFiles(kShadow);
    FAIL("addFiles accepted a file that shadows crep/common.glsl");
  } catch (const crep::ShaderError& error) {
    CHECK(contains(error.what(), "\"crep/common.glsl\" is already registered"));
  }
  CHECK(ShaderLibrary::files().size() == countBefore + 2);
  CHECK(contains(ShaderLibrary::source("crep/common.glsl"), "crepuscular"));
  // Paths must be what include resolution produces; a set must not repeat a path.
  for (const char* path : {"", "/abs.glsl", "a/../b.glsl", "./a.glsl", "a//b.glsl", "dir/", "a\"b.glsl"}) {
    const ShaderLibrary::File bad[] = {{path, "\n"}};
    CAPTURE(path);
    CHECK_THROWS_AS(ShaderLibrary::addFiles(bad), crep::ShaderError);
  }
  static constexpr ShaderLibrary::File kTwice[] = {{"test/added/twice.glsl", "\n"},
                                                   {"test/added/twice.glsl", "\n"}};
  CHECK_THROWS_AS(ShaderLibrary::addFiles(kTwice), crep::ShaderError);
}

TEST_CASE("ShaderLibrary: expand resolves includes with #line markers and a files table") {
  const std::vector<ShaderDefine> defines = {{"CREP_A", "1"}, {"CREP_B", ""}};
  const ExpandedShader e = ShaderLibrary::expand("test/include_main.comp", defines);
  // Relative to the including file first (include_a.glsl, sub/include_b.glsl, and test/shadowed.glsl
  // from test/sub/), else the root of the paths (test/shadowed.glsl from test/); include_a.glsl only once;
  // the #include inside a block comment is left alone; the #version line becomes an empty line.
  // Line k of the n-th file is numbered n * 100000 + k (kLineStride).
  const std::string expected =
      "#version 450 core\n"
      "#define CREP_A 1\n"
      "#define CREP_B\n"
      "#line 1 0\n"
      "// Test fixture: include resolution (relative first, root fallback, once-only, "
      "#version).\n"
      "\n"
      "#line 100001 1\n"
      "// include_a\n"
      "#line 200001 2\n"
      "/* include_b\n"
      "#include \"not_a_directive.glsl\" (inside a comment) */\n"
      "#line 300001 3\n"
      "const int crep_test_shadowed_sub = 3;\n"
      "#line 200004 2\n"
      "const int crep_test_b = 2;\n"
      "#line 100003 1\n"
      "const int crep_test_a = 1;\n"
      "#line 4 0\n"
      "#line 400001 4\n"
      "const int crep_test_shadowed_root = 4;\n"
      "#line 5 0\n"
      "// (already included) #include \"include_a.glsl\"\n"
      "layout(local_size_x = 1) in;\n"
      "void main() {}\n";
  CHECK(e.text == expected);
  const std::vector<std::string> files = {"test/include_main.comp", "test/include_a.glsl",
                                          "test/sub/include_b.glsl", "test/sub/test/shadowed.glsl",
                                          "test/shadowed.glsl"};
  CHECK(e.files == files);
}

TEST_CASE("ShaderLibrary: #version first, then the defines, then the body") {
  SUBCASE("the file's own #version") {
    const std::vector<ShaderDefine> defines = {{"CREP_FILL_VALUE", "2.5"}};
    const ExpandedShader e = ShaderLibrary::expand("test/test_fill.comp", defines);
    CHECK(e.text.starts_with("#version 450 core\n#define CREP_FILL_VALUE 2.5\n#line 1 0\n"));
    // The #version line of the body is gone (exactly one #version).
    CHECK(e.text.find("#version") == e.text.rfind("#version"));
    CHECK(e.files == std::vector<std::string>{"test/test_fill.comp"});
  }
  SUBCASE("no #version: 450 core") {
    const ExpandedShader e = ShaderLibrary::expand("crep/common.glsl");
    CHECK(e.text.starts_with("#version 450 core\n#line 1 0\n// crepuscular"));
  }
  SUBCASE("an include's includes resolve relative to it") {
    const ExpandedShader e = ShaderLibrary::expand("crep/phase.glsl");
    CHECK(e.files == std::vector<std::string>{"crep/phase.glsl", "crep/common.glsl"});
  }
  SUBCASE("bad define names and values") {
    for (const char* name : {"", "1ABC", "A B", "A-B", "A\nB"}) {
      const std::vector<ShaderDefine> defines = {{name, "1"}};
      CHECK_THROWS_AS(ShaderLibrary::expand("test/test_fill.comp", defines), crep::InvalidArgument);
    }
    const std::vector<ShaderDefine> defines = {{"A", "1\n#error"}};
    CHECK_THROWS_AS(ShaderLibrary::expand("test/test_fill.comp", defines), crep::InvalidArgument);
  }
}

TEST_CASE("ShaderLibrary: include errors name the file and line") {
  SUBCASE("missing include") {
    const std::string message = errorOf("test/missing_include.glsl");
    CHECK(contains(message, "test/missing_include.glsl:3"));
    CHECK(contains(message, "\"does_not_exist.glsl\""));
    CHECK(contains(message, "test/does_not_exist.glsl")); // the candidates tried
  }
  SUBCASE("include cycle") {
    const std::string message = errorOf("test/include_cycle_a.glsl");
    CHECK(contains(message, "include cycle"));
    CHECK(contains(message, "test/include_cycle_a.glsl:2"));
    CHECK(contains(message, "test/include_cycle_b.glsl:3"));
    // Entered from the other end, the cycle is reported from there.
    CHECK(contains(errorOf("test/include_cycle_b.glsl"), "test/include_cycle_b.glsl:3 includes"));
  }
  SUBCASE("malformed #include") {
    const std::string message = errorOf("test/malformed_include.glsl");
    CHECK(contains(message, "test/malformed_include.glsl:2"));
    CHECK(contains(message, "malformed #include"));
  }
  SUBCASE("#version in an included file") {
    const std::string message = errorOf("test/version_includer.glsl");
    CHECK(contains(message, "test/version_included.glsl:1"));
    CHECK(contains(message, "#version"));
  }
}

TEST_CASE("ExpandedShader::translateLog maps source numbers to paths") {
  ExpandedShader e;
  e.files = {"passes/main.comp", "crep/common.glsl"};
  // Mesa
  CHECK(e.translateLog("1:7(3): error: x") == "crep/common.glsl:7(3): error: x");
  CHECK(e.translateLog("0:12(10): warning: y\n1:2(1): error: z\n") ==
        "passes/main.comp:12(10): warning: y\ncrep/common.glsl:2(1): error: z\n");
  // glslang
  CHECK(e.translateLog("ERROR: 1:7: 'x' : undeclared identifier") ==
        "ERROR: crep/common.glsl:7: 'x' : undeclared identifier");
  CHECK(e.translateLog("WARNING: 0:3: 'y' : z") == "WARNING: passes/main.comp:3: 'y' : z");
  // NVIDIA
  CHECK(e.translateLog("1(7) : error C1008: undefined variable") ==
        "crep/common.glsl(7) : error C1008: undefined variable");
  // Lines numbered n * kLineStride + k belong to files[n] whatever the reported number (Mesa reports 0
  // for many errors in included files).
  static_assert(ExpandedShader::kLineStride == 100000);
  CHECK(e.translateLog("0:100007(3): error: x") == "crep/common.glsl:7(3): error: x");
  CHECK(e.translateLog("1:100007(3): error: x") == "crep/common.glsl:7(3): error: x");
  CHECK(e.translateLog("ERROR: 1:100012: 'x' : y") == "ERROR: crep/common.glsl:12: 'x' : y");
  CHECK(e.translateLog("1(100007) : error C1008: z") == "crep/common.glsl(7) : error C1008: z");
  CHECK(e.translateLog("0:200007(3): error: x") == "0:200007(3): error: x"); // no files[2]
  // Left alone: unknown source numbers and lines without a location.
  CHECK(e.translateLog("5:7(3): error: x") == "5:7(3): error: x");
  CHECK(e.translateLog("ERROR: 2 compilation errors.  No code generated.") ==
        "ERROR: 2 compilation errors.  No code generated.");
  CHECK(e.translateLog("error: linking failed") == "error: linking failed");
  CHECK(e.translateLog("") == "");
}

TEST_CASE("glslangValidator accepts every shader of the library") {
  int checked = 0;
  for (const auto& file : ShaderLibrary::files()) {
    if (!isLibraryFile(file.path)) continue;
    const std::string path(file.path);
    CAPTURE(path);
    ExpandedShader e = ShaderLibrary::expand(path);
    std::string extension = path.substr(path.rfind('.') + 1);
    if (extension == "glsl" || extension == "h") { // an include (crep/bindings.h is one too)
      // A public include must compile on its own (it is self-contained): as a compute shader.
      e.text += "layout(local_size_x = 1) in;\nvoid main() {}\n";
      extension = "comp";
    }
    REQUIRE((extension == "vert" || extension == "frag" || extension == "comp"));
    const RunResult r = glslang(path, extension, e.text);
    CHECK_MESSAGE(r.exitCode == 0, "glslangValidator rejects " << path << ":\n" << e.translateLog(r.output));
    ++checked;
  }
  CHECK(checked >= 5);
}

TEST_CASE("glslangValidator understands the #line markers of an expansion") {
  // Source-string numbers > 0 are accepted, and its log maps back to the included file and line.
  CHECK(glslang("test/include_main.comp", "comp", ShaderLibrary::expand("test/include_main.comp").text)
            .exitCode == 0);
  const ExpandedShader e = ShaderLibrary::expand("test/compile_error.comp");
  const RunResult r = glslang("test/compile_error.comp", "comp", e.text);
  CHECK(r.exitCode != 0);
  const std::string log = e.translateLog(r.output);
  CAPTURE(log);
  CHECK(contains(log, "ERROR: test/compile_error_inc.glsl:4: 'crep_test_undefined_symbol'"));
}

TEST_CASE("no shader uses a double type by default: neither its preprocessed source nor its SPIR-V") {
  // Consumer GPUs run fp64 at 1/16 to 1/64 of the float rate and several have none (Metal has no double):
  // every shader of the library and the tool, with its default defines and with each switch a pass turns
  // on (CREP_FP64 is the one opt-in that may use double), compiled to OpenGL SPIR-V by glslangValidator
  // (-G -H prints the disassembly): no OpTypeFloat 64, and no double / dvec / dmat token in the source
  // after preprocessing (-E).
  const std::vector<std::vector<ShaderDefine>> variants = {
      {},
      {{"CREP_EVAL_LAYOUT", "1"}},
      {{"CREP_EVAL_LAYOUT", "0"}},
      {{"CREP_NEAR_PLANE_CORRECTION", "1"}},
      {{"CREP_RINGING_LANCZOS", "1"}},
      {{"CREP_BASES", "32"}},
      {{"CREP_MARCH_TREE", "1"}},
      {{"CREP_LAYOUT", "1"}},
      {{"CREP_VISIBILITY_TABLE_SAMPLES", "128"}},
      {{"CREP_VISIBILITY_TABLE_SAMPLES", "128"}, {"CREP_SCATTERING_PREFIX", "1"}},
  };
  int compiled = 0;
  for (const auto& file : ShaderLibrary::files()) {
    if (!isLibraryFile(file.path)) continue;
    const std::string path(file.path);
    std::string extension = path.substr(path.rfind('.') + 1);
    const std::string source(ShaderLibrary::source(path));
    for (const auto& defines : variants) {
      // A switch variant only for the files whose text (or includes) reads that switch.
      ExpandedShader e = ShaderLibrary::expand(path);
      if (!defines.empty() && !contains(e.text, defines.front().name)) continue;
      e = ShaderLibrary::expand(path, defines);
      std::string ext = extension;
      if (ext == "glsl" || ext == "h") {
        e.text += "layout(local_size_x = 1) in;\nvoid main() {}\n";
        ext = "comp";
      }
      const std::string variant = defines.empty() ? "" : defines.front().name + "=" + defines.front().value;
      CAPTURE(path);
      CAPTURE(variant);
      const std::string name = path + (variant.empty() ? "" : "." + variant);
      const RunResult spirv = glslang(name, ext, e.text, "-G -H");
      REQUIRE_MESSAGE(spirv.exitCode == 0, e.translateLog(spirv.output));
      CHECK_MESSAGE(!contains(spirv.output, "TypeFloat 64"),
                    "SPIR-V of " << name << " declares a 64-bit float");
      const RunResult pre = glslang(name, ext, e.text, "-E");
      REQUIRE(pre.exitCode == 0);
      for (const char* token : {"double", "dvec", "dmat"})
        CHECK_MESSAGE(!contains(pre.output, token), "preprocessed " << name << " uses " << token);
      ++compiled;
    }
  }
  MESSAGE(compiled << " shader variants compiled to SPIR-V without a double type");
  CHECK(compiled >= 15);
  // The check itself: the opt-in CREP_FP64 path does declare doubles, and the test sees them.
  const std::vector<ShaderDefine> opt = {{"CREP_FP64", "1"}};
  ExpandedShader fp64 = ShaderLibrary::expand("passes/prefilter/prefilter.comp", opt);
  const RunResult r = glslang("passes/prefilter.comp.CREP_FP64", "comp", fp64.text, "-G -H");
  REQUIRE(r.exitCode == 0);
  CHECK(contains(r.output, "TypeFloat 64"));
}
