// The shape of the repository that a maintainer relies on, checked so it does not drift back: a README
// that is a front page, public headers that are contracts (comment lines at most half the code lines, no
// measured figures: those live in docs/ and the module READMEs beside their commands), no function of the
// library, the tool or the benchmarks longer than 120 lines, and binding points named (crep/bindings.h)
// rather than written as numbers in the shaders or in the library's host code that binds them.
#include <doctest/doctest.h>

#include "common/source_tree.h"

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const fs::path kRoot = crep::test::kSourceRoot;
using crep::test::kLibraryModules;
using crep::test::readSourceFile;

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);)
    out.push_back(l);
  return out;
}

std::string trim(const std::string& s) {
  const std::size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return {};
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

std::vector<fs::path> filesUnder(const fs::path& dir, const std::vector<std::string>& extensions) {
  std::vector<fs::path> out;
  if (!fs::exists(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    for (const auto& x : extensions)
      if (e.path().extension() == x) out.push_back(e.path());
  }
  return out;
}

std::vector<fs::path> publicHeaders() {
  std::vector<fs::path> out;
  for (const auto& m : kLibraryModules)
    for (const auto& h : filesUnder(kRoot / m / "include", {".h"}))
      out.push_back(h);
  return out;
}

struct CommentCount {
  int comment = 0;
  int code = 0;
};

/// Non-blank lines: a line that starts with // or /* or lies inside a /* */ block is a comment line.
CommentCount countComments(const std::string& text) {
  CommentCount c;
  bool block = false;
  for (const auto& raw : lines(text)) {
    const std::string l = trim(raw);
    if (l.empty()) continue;
    if (block) {
      ++c.comment;
      if (l.find("*/") != std::string::npos) block = false;
    } else if (l.rfind("//", 0) == 0) {
      ++c.comment;
    } else if (l.rfind("/*", 0) == 0) {
      ++c.comment;
      block = l.find("*/") == std::string::npos;
    } else {
      ++c.code;
    }
  }
  return c;
}

/// The text with comments, string and character literals blanked (newlines kept), raw strings included.
std::string codeOnly(const std::string& t) {
  std::string out = t;
  for (std::size_t i = 0; i < t.size();) {
    const auto blank = [&](std::size_t from, std::size_t to) {
      for (std::size_t k = from; k < to && k < t.size(); ++k)
        if (out[k] != '\n') out[k] = ' ';
    };
    if (t.compare(i, 2, "//") == 0) {
      const std::size_t e = t.find('\n', i);
      const std::size_t stop = e == std::string::npos ? t.size() : e;
      blank(i, stop);
      i = stop;
    } else if (t.compare(i, 2, "/*") == 0) {
      const std::size_t e = t.find("*/", i + 2);
      const std::size_t stop = e == std::string::npos ? t.size() : e + 2;
      blank(i, stop);
      i = stop;
    } else if (t.compare(i, 2, "R\"") == 0 &&
               (i == 0 || !std::isalnum(static_cast<unsigned char>(t[i - 1])))) {
      const std::size_t open = t.find('(', i + 2);
      const std::string close = ")" + t.substr(i + 2, open - i - 2) + "\"";
      const std::size_t e = t.find(close, open);
      const std::size_t stop = e == std::string::npos ? t.size() : e + close.size();
      blank(i, stop);
      i = stop;
    } else if (t[i] == '"' ||
               (t[i] == '\'' && !(i > 0 && std::isxdigit(static_cast<unsigned char>(t[i - 1]))))) {
      const char q = t[i];
      std::size_t k = i + 1;
      while (k < t.size() && t[k] != q && t[k] != '\n')
        k += t[k] == '\\' ? 2 : 1;
      blank(i, k + 1);
      i = k + 1;
    } else {
      ++i;
    }
  }
  return out;
}

struct LongFunction {
  std::string where;
  int lines;
};

/// Bodies of functions (outermost braces whose header ends like a function's: `) {`, `) const {`,
/// `) noexcept {`, `) override {`, `-> T {`, or a constructor's initializer list) longer than `limit` lines.
std::vector<LongFunction> longFunctions(const fs::path& file, int limit) {
  const std::string code = codeOnly(readSourceFile(file));
  std::vector<LongFunction> out;
  static const std::regex functionHeader(
      R"(\)\s*(const|noexcept|override|final|mutable|\s)*(->\s*[\w:<>,\s\*&]+)?\s*$|\)\s*:\s*[\w:]+[\(\{][^;]*[\)\}]\s*$)");
  static const std::regex notFunction(
      R"(^\s*(if|for|while|switch|catch|else|do|namespace|struct|class|enum|union)\b)");
  struct Open {
    std::size_t line;
    bool function;
  };
  std::vector<Open> stack;
  std::size_t line = 1, headerStart = 0;
  int inFunction = 0;
  for (std::size_t i = 0; i < code.size(); ++i) {
    const char c = code[i];
    if (c == '\n') ++line;
    if (c == '{') {
      bool isFunction = false;
      if (inFunction == 0) {
        std::string header = code.substr(headerStart, i - headerStart);
        const std::size_t hash = header.rfind('#'); // a preprocessor line before the header
        if (hash != std::string::npos && header.find('\n', hash) != std::string::npos)
          header = header.substr(header.find('\n', hash) + 1);
        std::string flat;
        for (char h : header)
          flat += h == '\n' ? ' ' : h;
        isFunction = std::regex_search(flat, functionHeader) && !std::regex_search(flat, notFunction) &&
                     flat.find('=') == std::string::npos;
      }
      stack.push_back({line, isFunction});
      if (isFunction) ++inFunction;
      headerStart = i + 1;
    } else if (c == '}' || c == ';') {
      if (c == '}' && !stack.empty()) {
        const Open o = stack.back();
        stack.pop_back();
        if (o.function) {
          --inFunction;
          const int n = static_cast<int>(line - o.line + 1);
          if (n > limit)
            out.push_back({fs::relative(file, kRoot).string() + ":" + std::to_string(o.line), n});
        }
      }
      headerStart = i + 1;
    }
  }
  return out;
}

} // namespace

TEST_CASE("README.md is a front page of at most 300 lines") {
  const auto readme = lines(readSourceFile(kRoot / "README.md"));
  CAPTURE(readme.size());
  CHECK(readme.size() > 20); // read the right file
  CHECK(readme.size() <= 300);
}

TEST_CASE("public headers are contracts: comment lines at most half the code lines, no measured figures") {
  CommentCount total;
  std::vector<std::string> figures;
  // A measurement quoted in a header goes stale with the next change: "Measured", timings, error figures.
  static const std::regex figure(R"(([Mm]easured|\b\d+(\.\d+)?\s?ms\b|RMSE|PSNR|llvmpipe))");
  for (const auto& h : publicHeaders()) {
    const std::string text = readSourceFile(h);
    const CommentCount c = countComments(text);
    total.comment += c.comment;
    total.code += c.code;
    int n = 0;
    for (const auto& l : lines(text)) {
      ++n;
      if (std::regex_search(l, figure))
        figures.push_back(fs::relative(h, kRoot).string() + ":" + std::to_string(n));
    }
  }
  REQUIRE(total.code > 1000); // read the right files
  const double ratio = static_cast<double>(total.comment) / total.code;
  MESSAGE("public headers: " << total.comment << " comment lines / " << total.code
                             << " code lines = " << ratio);
  CHECK(ratio <= 0.5);
  std::string where;
  for (const auto& f : figures)
    where += "\n  " + f;
  CHECK_MESSAGE(figures.empty(), "measured figures in public headers:" << where);
}

TEST_CASE("no function of the library, the tool or the benchmarks is longer than 120 lines") {
  std::vector<std::string> folders = kLibraryModules;
  for (const char* f : {"support", "examples", "bench"})
    folders.emplace_back(f);
  int files = 0;
  std::string where;
  for (const auto& folder : folders)
    for (const auto& f : filesUnder(kRoot / folder, {".cpp", ".h"})) {
      ++files;
      for (const auto& l : longFunctions(f, 120))
        where += "\n  " + l.where + " (" + std::to_string(l.lines) + " lines)";
    }
  CHECK(files > 100);
  CHECK_MESSAGE(where.empty(), "functions over 120 lines:" << where);
}

TEST_CASE(
    "the counter of function lengths finds a long function and ignores braces in strings and comments") {
  // The check above is only as good as its brace matching: a synthetic file with one long function, a
  // namespace, a struct, a lambda, braces in strings, characters, a raw string and comments.
  const fs::path tmp = fs::temp_directory_path() / "crep_house_rules_probe.cpp";
  {
    std::ofstream out(tmp);
    out << "namespace a {\nstruct S {\n  int f() const {\n    return 1;\n  }\n};\n";
    out << "const char* s = \"}}}\"; // }\n/* { */\nchar c = '{';\nconst char* r = R\"x(}{)x\";\n";
    out << "void longOne(int x)\n{\n  auto l = [&](int y) {\n    return y;\n  };\n";
    for (int i = 0; i < 130; ++i)
      out << "  x += l(" << i << ");\n";
    out << "}\nint shortOne() { return 2; }\n} // namespace a\n";
  }
  const auto found = longFunctions(tmp, 120);
  fs::remove(tmp);
  REQUIRE(found.size() == 1);
  CHECK(found[0].lines == 135); // from the line of its opening brace to the line of its closing one
}

TEST_CASE("binding points are named once: no literal binding numbers in the shaders") {
  // Library shaders bind by the names of crep/bindings.h; the tool's own shaders (examples/glsl) may keep
  // a few literal ones.
  static const std::regex literal(R"(binding\s*=\s*[0-9])");
  int library = 0, tool = 0;
  std::string where;
  for (const auto& [dir, count] :
       {std::pair<fs::path, int*>{kRoot / "glsl", &library}, {kRoot / "examples", &tool}})
    for (const auto& f : filesUnder(dir, {".glsl", ".comp", ".vert", ".frag", ".h"})) {
      if (dir == kRoot / "examples" && f.extension() == ".h") continue;
      int n = 0;
      for (const auto& l : lines(readSourceFile(f))) {
        ++n;
        if (trim(l).rfind("//", 0) == 0) continue;
        if (std::regex_search(l, literal)) {
          ++*count;
          where += "\n  " + fs::relative(f, kRoot).string() + ":" + std::to_string(n);
        }
      }
    }
  CAPTURE(where);
  CHECK(library == 0);
  CHECK(library + tool <= 20);
}

TEST_CASE("binding points are named once: the library's host code binds by the names of crep/bindings.h") {
  // glBind{BufferBase,BufferRange,TextureUnit,ImageTexture,Sampler} and LayoutBuffers::bind with a literal
  // binding point repeat a number the shader names; the probe line shows the pattern matches one.
  static const std::regex literal(
      R"((glBind(BufferBase|BufferRange|TextureUnit|ImageTexture|Sampler)\((GL_[A-Z_]+,\s*)?|\.bind\()[0-9]+\s*[,)])");
  REQUIRE(std::regex_search(std::string("  glBindBufferBase(GL_UNIFORM_BUFFER, 2, buffer);"), literal));
  REQUIRE(std::regex_search(std::string("  glBindTextureUnit(0, texture);"), literal));
  REQUIRE_FALSE(
      std::regex_search(std::string("  glBindTextureUnit(CREP_MARCH_MAP_UNIT, texture);"), literal));
  int count = 0;
  std::string where;
  for (const auto& m : kLibraryModules)
    for (const auto& f : filesUnder(kRoot / m / "src", {".cpp", ".h"})) {
      int n = 0;
      for (const auto& l : lines(readSourceFile(f))) {
        ++n;
        if (trim(l).rfind("//", 0) == 0 || !std::regex_search(l, literal)) continue;
        ++count;
        where += "\n  " + fs::relative(f, kRoot).string() + ":" + std::to_string(n);
      }
    }
  CAPTURE(where);
  CHECK(count == 0);
}

TEST_CASE("the seam speaks its own words: no GL in its headers, no backend picked by its name") {
  // The seam's headers (backend, checks, shader library) and the Vulkan backend's include no GL header and
  // name no GL type or enum outside comments; no library source compares Backend::name() (the kind is
  // gpu::Backend::kind()). The probes show the patterns match what they must.
  static const std::regex glWord(R"(\bgl::|\bGL_[A-Z]|crep/gpu/gl(_backend|_state)?\.h)");
  static const std::regex nameCompare(R"(name\(\)\s*[!=]=)");
  REQUIRE(std::regex_search(std::string("gl::TextureLevel f();"), glWord));
  REQUIRE(std::regex_search(std::string("#include <crep/gpu/gl.h>"), glWord));
  REQUIRE_FALSE(std::regex_search(std::string("std::string_view name() const;"), nameCompare));
  REQUIRE(std::regex_search(std::string("if (b.name() == \"OpenGL\")"), nameCompare));
  std::string where;
  for (const char* header :
       {"gpu/include/crep/gpu/backend.h", "gpu/include/crep/gpu/checks.h",
        "gpu/include/crep/gpu/shader_library.h", "vulkan/include/crep/vulkan/vulkan_backend.h"}) {
    const fs::path f = kRoot / header;
    REQUIRE(fs::exists(f));
    int n = 0;
    for (const auto& l : lines(readSourceFile(f))) {
      ++n;
      const std::string code = l.substr(0, l.find("//"));
      if (std::regex_search(code, glWord)) where += "\n  " + std::string(header) + ":" + std::to_string(n);
    }
  }
  for (const auto& m : kLibraryModules)
    for (const auto& f : filesUnder(kRoot / m, {".cpp", ".h"})) {
      int n = 0;
      for (const auto& l : lines(readSourceFile(f))) {
        ++n;
        if (std::regex_search(l.substr(0, l.find("//")), nameCompare))
          where += "\n  " + fs::relative(f, kRoot).string() + ":" + std::to_string(n);
      }
    }
  CHECK_MESSAGE(where.empty(), "GL in the seam, or a backend picked by name:" << where);
}
