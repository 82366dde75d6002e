// The public headers' comments name functions, types and members that an engine developer will look
// for; a renamed or never-written one silently misleads (an integration found
// `PrefilterPass::scatteringParams()` and `readDepthTexture` named in headers, neither in the library).
// This check reads every public header of the runtime library (<module>/include/crep/...), takes the
// names its comments cite as code (`name()`, `Type::name`, `crep::name`, `gl::name`), and requires each
// to be an identifier of the library's own code: its headers, sources and GLSL, comments removed. Names
// of other APIs (gl* / GL_* of OpenGL, std::, glm::, Eigen::) are not checked.
#include <doctest/doctest.h>

#include "common/source_tree.h"

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using crep::test::kLibraryModules;
using crep::test::readSourceFile;

/// Splits C++ / GLSL text into code (comments and string literals blanked) and comment text.
void splitComments(const std::string& text, std::string& code, std::string& comments) {
  code.clear();
  comments.clear();
  for (std::size_t i = 0; i < text.size();) {
    if (text.compare(i, 2, "//") == 0) {
      const std::size_t end = text.find('\n', i);
      const std::size_t stop = end == std::string::npos ? text.size() : end;
      comments.append(text, i + 2, stop - i - 2);
      comments.push_back('\n');
      code.push_back('\n');
      i = stop + (end == std::string::npos ? 0 : 1);
    } else if (text.compare(i, 2, "/*") == 0) {
      const std::size_t end = text.find("*/", i + 2);
      const std::size_t stop = end == std::string::npos ? text.size() : end + 2;
      comments.append(text, i + 2, stop - i - 2);
      comments.push_back('\n');
      code.push_back(' ');
      i = stop;
    } else if (text[i] == '"') {
      std::size_t j = i + 1;
      while (j < text.size() && text[j] != '"' && text[j] != '\n')
        j += text[j] == '\\' ? 2 : 1;
      code.push_back(' ');
      i = j + 1;
    } else {
      code.push_back(text[i++]);
    }
  }
}

std::set<std::string> identifiers(const std::string& code) {
  std::set<std::string> ids;
  static const std::regex id("[A-Za-z_][A-Za-z0-9_]*");
  for (std::sregex_iterator it(code.begin(), code.end(), id), end; it != end; ++it)
    ids.insert(it->str());
  return ids;
}

/// Words the comments use that are not code of the library: formats and API names in prose, math
/// symbols, and the caller's own objects in usage snippets.
const std::set<std::string> kProse = {
    "OpenGL",
    "OpenEXR",
    "NaN",
    "R32F",
    "D32F",
    "D24S8",
    "RGBA8",
    "RGBA32F", // formats and APIs
    "tX",
    "tY", // math: x tan(fovX), y tan(fovY)
    "scatteringTexture",
    "drawShadowCasters", // the engine's names in a snippet
    "shaderStorageImageExtendedFormats",
    "shaderStorageImageReadWithoutFormat",
    "shaderFloat64",      // Vulkan device features (VkPhysicalDeviceFeatures members)
    "OpTypeSampledImage", // a SPIR-V instruction
};

/// Removes "quoted" text (parameter names of error messages) from comment text.
std::string withoutQuotes(const std::string& text) {
  std::string out;
  bool inside = false;
  for (char c : text) {
    if (c == '"' || c == '\n')
      inside = c == '"' ? !inside : false;
    else if (!inside)
      out.push_back(c);
  }
  return out;
}

bool foreign(const std::string& qualified) {
  for (const char* prefix : {"std::", "glm::", "Eigen::", "doctest::"})
    if (qualified.rfind(prefix, 0) == 0) return true;
  for (const char* prefix : {"D3D12", "DXGI_", "MTL"})
    if (qualified.rfind(prefix, 0) == 0) return true; // a D3D12 or Metal type, enum or member
  if (qualified.size() > 2 && qualified[0] == 'V' && qualified[1] == 'k' &&
      std::isupper(static_cast<unsigned char>(qualified[2])))
    return true; // a member of a Vulkan struct, e.g. VkPhysicalDeviceFeatures2::features
  const std::string last =
      qualified.substr(qualified.rfind(':') == std::string::npos ? 0 : qualified.rfind(':') + 1);
  if (last.size() > 2 && last[0] == 'g' && last[1] == 'l' &&
      std::isupper(static_cast<unsigned char>(last[2])))
    return true; // an OpenGL function
  if (last.size() > 2 && (last[0] == 'v' || last[0] == 'V') && last[1] == 'k' &&
      std::isupper(static_cast<unsigned char>(last[2])))
    return true; // a Vulkan function or type
  return last.rfind("GL_", 0) == 0 || last.rfind("VK_", 0) == 0;
}

} // namespace

TEST_CASE("every function and type a public header's comments cite exists in the library") {
  const fs::path root = crep::test::kSourceRoot;
  std::set<std::string> known;
  std::vector<fs::path> headers;
  const auto scan = [&](const fs::path& dir, bool isHeaderDir) {
    if (!fs::exists(dir)) return;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
      if (!e.is_regular_file()) continue;
      const std::string ext = e.path().extension().string();
      if (ext != ".h" && ext != ".cpp" && ext != ".glsl" && ext != ".comp" && ext != ".vert" &&
          ext != ".frag")
        continue;
      std::string code, comments;
      splitComments(readSourceFile(e.path()), code, comments);
      const std::set<std::string> ids = identifiers(code);
      known.insert(ids.begin(), ids.end());
      if (isHeaderDir && ext == ".h") headers.push_back(e.path());
    }
  };
  for (const std::string& m : kLibraryModules) {
    scan(root / m / "include", true);
    scan(root / m / "src", false);
  }
  scan(root / "glsl", false);
  // Headers may also name the support library (tools' context, image I/O), the tests that measure a
  // claim and the build's CMake modules: those must exist too.
  scan(root / "support", false);
  std::set<std::string> files;
  for (const fs::path& dir : {root / "tests", root / "cmake"})
    for (const auto& e : fs::recursive_directory_iterator(dir))
      if (e.is_regular_file()) files.insert(e.path().stem().string());
  REQUIRE(headers.size() > 20);

  // Cited as code: name(), A::b(::c...), crep::name, gl::name.
  // ... and camelCase / PascalCase words with an inner capital (readDepthTexture, EvaluatePass).
  static const std::regex cited(
      R"(((?:[A-Za-z_][A-Za-z0-9_]*::)+[A-Za-z_][A-Za-z0-9_]*|[A-Za-z_][A-Za-z0-9_]*\(\)|\b[a-z]+[A-Z][A-Za-z0-9]*\b|\b[A-Z][a-z0-9]+[A-Z][A-Za-z0-9]*\b))");
  int checked = 0;
  std::vector<std::string> missing;
  for (const fs::path& h : headers) {
    std::string code, comments;
    splitComments(readSourceFile(h), code, comments);
    comments = withoutQuotes(comments);
    for (std::sregex_iterator it(comments.begin(), comments.end(), cited), end; it != end; ++it) {
      std::string name = it->str();
      if (name.size() > 2 && name.compare(name.size() - 2, 2, "()") == 0) name.resize(name.size() - 2);
      if (foreign(name) || kProse.count(name)) continue;
      if (name.find("::") == std::string::npos && files.count(name)) { // a test or CMake module by name
        ++checked;
        continue;
      }
      // Every component of a qualified name must be a library identifier (crep and its namespaces too).
      std::size_t start = 0;
      bool ok = true;
      while (start <= name.size()) {
        const std::size_t sep = name.find("::", start);
        const std::string part =
            name.substr(start, sep == std::string::npos ? std::string::npos : sep - start);
        if (!part.empty() && !known.count(part)) ok = false;
        if (sep == std::string::npos) break;
        start = sep + 2;
      }
      ++checked;
      if (!ok) missing.push_back(fs::relative(h, root).string() + ": " + it->str());
    }
  }
  // The check itself: the two names an integration found cited without existing are flagged.
  for (const char* wrong : {"PrefilterPass::scatteringParams", "readDepthTexture"}) {
    bool flagged = false;
    std::string w(wrong);
    for (std::size_t start = 0;;) {
      const std::size_t sep = w.find("::", start);
      if (!known.count(w.substr(start, sep == std::string::npos ? std::string::npos : sep - start)))
        flagged = true;
      if (sep == std::string::npos) break;
      start = sep + 2;
    }
    CHECK_MESSAGE(flagged, wrong << " would not be flagged");
  }
  std::string list;
  for (const std::string& m : missing)
    list += "\n  " + m;
  MESSAGE(checked << " names cited in " << headers.size() << " public headers checked");
  CHECK_MESSAGE(missing.empty(),
                "names cited in public header comments that the library does not have:" << list);
  CHECK(checked > 100);
}
