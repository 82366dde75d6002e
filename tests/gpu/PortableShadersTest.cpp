// The portable shaders of the build (cmake/CrepPortableShaders.cmake): every pass of the library and the
// declared variants (glsl/portable_variants.txt) as Vulkan SPIR-V, HLSL and MSL, and resources.json, checked
// against the GLSL sources and crep/bindings.h they come from. The build itself runs spirv-val and glslang's
// HLSL front end on each; the GL side (work-group sizes, the variants a frame builds) is in
// tests/pipeline/PortableVariantsGLTest.cpp, the HLSL run on Vulkan in
// tests/vulkan/InstalledHlslVulkanTest.cpp.
#include "common/shader_tools.h"

#include <crep/gpu/shader_library.h>

#include <doctest/doctest.h>

#include <cctype>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using crep::ShaderLibrary;
using crep::test::portableShaderDir;
using crep::test::vulkanBindingBase;
using nlohmann::json;

std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::set<std::string> libraryPasses() {
  std::set<std::string> out;
  for (const auto& f : ShaderLibrary::files())
    if (crep::test::isLibraryPass(f.path)) out.insert(std::string(f.path));
  return out;
}

/// The GL binding number the preprocessed GLSL declares for `resource` (a block's name or an opaque
/// variable's): `layout(... binding = N ...) ... resource`; -1 if there is none.
int declaredBinding(const std::string& preprocessed, const std::string& resource) {
  const std::regex declaration("layout\\s*\\(([^)]*)binding\\s*=\\s*([0-9]+)[^)]*\\)[^;{]*\\b" + resource +
                               "\\b");
  std::smatch m;
  return std::regex_search(preprocessed, m, declaration) ? std::stoi(m[2].str()) : -1;
}

/// A shipped variant's defines (resources.json's "defines"; none for a pass's default variant).
std::vector<crep::ShaderDefine> definesOf(const json& entry) {
  std::vector<crep::ShaderDefine> out;
  if (entry.contains("defines"))
    for (const json& d : entry.at("defines"))
      out.push_back({d.at("name").get<std::string>(), d.at("value").get<std::string>()});
  return out;
}

/// Every shipped shader of resources.json: the passes' defaults ("passes"), then the declared variants
/// ("variants").
std::vector<const json*> shipped(const json& resources) {
  std::vector<const json*> out;
  for (const json& pass : resources.at("passes"))
    out.push_back(&pass);
  for (const json& variant : resources.at("variants"))
    out.push_back(&variant);
  return out;
}

/// A shipped shader's variant through the GLSL preprocessor (glslangValidator -E: its GL form, macros
/// replaced, inactive branches gone), or its Vulkan form (VULKAN defined, as glslc and shaderc define it).
std::string preprocessed(const json& entry, bool vulkan = false) {
  const std::string name = entry.at("name");
  std::string text = ShaderLibrary::expand(name, definesOf(entry)).text;
  if (vulkan) text.insert(text.find('\n') + 1, "#define VULKAN 100\n");
  const crep::test::RunResult r = crep::test::preprocessCompute(name, text);
  REQUIRE_MESSAGE(r.exitCode == 0, r.output);
  return r.output;
}

int baseOf(const std::string& kind) {
  if (kind == "sampled_texture") return vulkanBindingBase("UNIT");
  if (kind == "storage_image") return vulkanBindingBase("IMAGE");
  if (kind == "uniform_buffer") return vulkanBindingBase("UNIFORM");
  if (kind == "storage_buffer") return vulkanBindingBase("STORAGE");
  FAIL("unknown kind " << kind);
  return -1;
}

} // namespace

TEST_CASE(
    "portable shaders: every pass of the library has SPIR-V, HLSL, MSL and an entry in resources.json") {
  const json resources = crep::test::portableShaderResources();
  const std::set<std::string> passes = libraryPasses();
  REQUIRE(passes.size() >= 30);
  std::set<std::string> described;
  for (const json& pass : resources.at("passes")) {
    const std::string name = pass.at("name");
    CAPTURE(name);
    CHECK(passes.count(name) == 1);
    described.insert(name);
    const std::string spirv = readFile(portableShaderDir() / pass.at("spirv").get<std::string>());
    REQUIRE(spirv.size() >= 20);
    std::uint32_t magic = 0;
    std::memcpy(&magic, spirv.data(), 4);
    CHECK(magic == 0x07230203u); // SPIR-V's magic number
    CHECK(readFile(portableShaderDir() / pass.at("hlsl").get<std::string>()).find("[numthreads(") !=
          std::string::npos);
    CHECK(readFile(portableShaderDir() / pass.at("msl").get<std::string>()).find("kernel void main0(") !=
          std::string::npos);
    const json& group = pass.at("workgroup_size");
    REQUIRE(group.size() == 3);
    CHECK(group[0].get<int>() * group[1].get<int>() * group[2].get<int>() >= 1);
  }
  for (const std::string& pass : passes) {
    CAPTURE(pass);
    CHECK(described.count(pass) == 1);
  }
  // The declared variants (glsl/portable_variants.txt): a library pass with defines, its files named
  // <pass>.<variant tag> beside the default's, in the same three forms.
  REQUIRE(resources.at("variants").size() >= 20);
  for (const json& variant : resources.at("variants")) {
    const std::string name = variant.at("name"), tag = variant.at("variant");
    CAPTURE(name);
    CAPTURE(tag);
    CHECK(passes.count(name) == 1);
    CHECK(tag.size() == 12);
    CHECK(!variant.at("defines").empty());
    const std::string stem = name.substr(std::string_view("passes/").size(),
                                         name.size() - std::string_view("passes/.comp").size());
    CHECK(variant.at("spirv") == "spirv/" + stem + "." + tag + ".spv");
    CHECK(variant.at("hlsl") == "hlsl/" + stem + "." + tag + ".hlsl");
    CHECK(variant.at("msl") == "msl/" + stem + "." + tag + ".metal");
    const std::string spirv = readFile(portableShaderDir() / variant.at("spirv").get<std::string>());
    REQUIRE(spirv.size() >= 20);
    std::uint32_t magic = 0;
    std::memcpy(&magic, spirv.data(), 4);
    CHECK(magic == 0x07230203u);
    CHECK(readFile(portableShaderDir() / variant.at("hlsl").get<std::string>()).find("[numthreads(") !=
          std::string::npos);
    CHECK(readFile(portableShaderDir() / variant.at("msl").get<std::string>()).find("kernel void main0(") !=
          std::string::npos);
  }
  CHECK(resources.at("descriptor_set") == 0);
  CHECK(resources.at("binding_bases").at("sampled_texture") == vulkanBindingBase("UNIT"));
  CHECK(resources.at("binding_bases").at("storage_image") == vulkanBindingBase("IMAGE"));
  CHECK(resources.at("binding_bases").at("uniform_buffer") == vulkanBindingBase("UNIFORM"));
  CHECK(resources.at("binding_bases").at("storage_buffer") == vulkanBindingBase("STORAGE"));
}

TEST_CASE("portable shaders: each resource's binding is its crep/bindings.h name plus the base of its kind") {
  const json resources = crep::test::portableShaderResources();
  const int kinds[] = {vulkanBindingBase("UNIT"), vulkanBindingBase("IMAGE"), vulkanBindingBase("UNIFORM"),
                       vulkanBindingBase("STORAGE")};
  REQUIRE((kinds[0] < kinds[1] && kinds[1] < kinds[2] && kinds[2] < kinds[3]));
  int checked = 0;
  for (const json* entry : shipped(resources)) {
    const json& pass = *entry;
    const std::string name = pass.at("name");
    const std::string text = preprocessed(pass);
    std::map<int, std::string> taken;
    for (const json& r : pass.at("resources")) {
      const std::string resource = r.at("name"), kind = r.at("kind");
      CAPTURE(name);
      CAPTURE(pass.value("variant", "default"));
      CAPTURE(resource);
      const int binding = r.at("binding"), base = baseOf(kind);
      CHECK(r.at("set") == 0);
      CHECK(r.at("gl_binding") == binding - base);
      // The GL number stays below the next kind's base, so two kinds never meet.
      int next = base + 8; // after the last kind: as wide as the one before
      for (int k : kinds)
        if (k > base) {
          next = k;
          break;
        }
      CHECK(binding < next);
      // Declared in the source with that GL number (a name of crep/bindings.h: HouseRulesTest). The one
      // block whose forms differ, the local light's (a storage block on Vulkan: "Bindings"), has it in its
      // Vulkan form.
      const bool vulkanForm = resource == "CrepLocalLightBlock" && kind == "storage_buffer";
      CHECK(declaredBinding(vulkanForm ? preprocessed(pass, true) : text, resource) == binding - base);
      CHECK_MESSAGE(taken.emplace(binding, resource).second, "binding " << binding << " taken twice");
      ++checked;
    }
  }
  CHECK(checked >= 300);
}

TEST_CASE("portable shaders: the HLSL registers and MSL indices in the files are resources.json's") {
  const json resources = crep::test::portableShaderResources();
  const std::regex hlslRegister(R"(register\(([tubs][0-9]+), space0\))");
  const std::regex mslIndex(R"(\[\[(buffer|texture|sampler)\(([0-9]+)\)\]\])");
  for (const json* entry : shipped(resources)) {
    const json& pass = *entry;
    const std::string name = pass.at("name");
    CAPTURE(name);
    CAPTURE(pass.value("variant", "default"));
    std::multiset<std::string> expectedHlsl, expectedMsl;
    for (const json& r : pass.at("resources")) {
      expectedHlsl.insert(r.at("hlsl_register").get<std::string>());
      const std::string kind = r.at("kind"), index = std::to_string(r.at("msl_index").get<int>());
      if (r.contains("hlsl_sampler_register")) {
        expectedHlsl.insert(r.at("hlsl_sampler_register").get<std::string>());
        expectedMsl.insert("sampler " + index);
      }
      expectedMsl.insert((kind == "sampled_texture" || kind == "storage_image" ? "texture " : "buffer ") +
                         index);
    }
    if (pass.contains("push_constants"))
      expectedMsl.insert("buffer " + std::to_string(pass.at("push_constants").at("msl_buffer").get<int>()));
    std::multiset<std::string> hlsl, msl;
    const std::string hlslText = readFile(portableShaderDir() / pass.at("hlsl").get<std::string>());
    for (std::sregex_iterator i(hlslText.begin(), hlslText.end(), hlslRegister), end; i != end; ++i)
      hlsl.insert((*i)[1].str());
    const std::string mslText = readFile(portableShaderDir() / pass.at("msl").get<std::string>());
    for (std::sregex_iterator i(mslText.begin(), mslText.end(), mslIndex), end; i != end; ++i)
      msl.insert((*i)[1].str() + " " + (*i)[2].str());
    CHECK(hlsl == expectedHlsl);
    // MSL leaves out what the kernel never reads (spirv-cross prunes its arguments); what it keeps is at
    // the stated indices.
    for (const std::string& index : msl) {
      CAPTURE(index);
      CHECK(expectedMsl.count(index) >= 1);
    }
    CHECK(msl.size() >= 1);
  }
}

TEST_CASE("portable shaders: push constants hold what the GL uniforms held, at offsets a host can write") {
  // The passes whose GL form has loose uniforms (glProgramUniform*) take them as push constants on
  // Vulkan: the members are the uniforms by name, 16-byte aligned vectors, inside the 128 bytes every
  // Vulkan implementation offers.
  const json resources = crep::test::portableShaderResources();
  int blocks = 0;
  for (const json* entry : shipped(resources)) {
    const json& pass = *entry;
    // A variant is checked for its block when it has one; the defaults check the rule both ways (a
    // glslangValidator run each).
    if (pass.contains("variant") && !pass.contains("push_constants")) continue;
    const std::string name = pass.at("name");
    CAPTURE(name);
    CAPTURE(pass.value("variant", "default"));
    const std::string text = preprocessed(pass);
    const bool hasUniforms =
        std::regex_search(text, std::regex(R"(layout\s*\(\s*location\s*=\s*[0-9]+\s*\)\s*uniform\b)"));
    CHECK(pass.contains("push_constants") == hasUniforms);
    if (!pass.contains("push_constants")) continue;
    ++blocks;
    const json& push = pass.at("push_constants");
    CHECK(push.at("size").get<int>() <= 128);
    for (const json& m : push.at("members")) {
      const std::string member = m.at("name"), type = m.at("type");
      CAPTURE(member);
      CHECK(std::regex_search(text, std::regex(R"(layout\s*\(\s*location\s*=\s*[0-9]+\s*\)\s*uniform\s+)" +
                                               type + R"(\s+)" + member)));
      if (type.find("vec4") != std::string::npos || type == "mat4")
        CHECK(m.at("offset").get<int>() % 16 == 0);
    }
  }
  CHECK(blocks >= 8);
}
