#include "common/shader_tools.h"

#include <crep/gpu/shader_library.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sys/wait.h>
#include <unistd.h>

namespace crep::test {

std::optional<std::filesystem::path> findInPath(const char* program) {
  const char* pathEnv = std::getenv("PATH");
  std::string_view rest = pathEnv != nullptr ? pathEnv : "";
  while (!rest.empty()) {
    const std::size_t colon = rest.find(':');
    const std::filesystem::path candidate = std::filesystem::path(rest.substr(0, colon)) / program;
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
    if (colon == std::string_view::npos) break;
    rest.remove_prefix(colon + 1);
  }
  return std::nullopt;
}

RunResult runCommand(const std::string& command) {
  RunResult result;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  REQUIRE_MESSAGE(pipe != nullptr, "cannot run " << command);
  std::array<char, 4096> buffer;
  std::size_t n;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    result.output.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

int vulkanBindingBase(const std::string& kind) {
  const std::string text(ShaderLibrary::source("crep/bindings.h"));
  std::smatch m;
  const std::regex define("#define CREP_VULKAN_" + kind + "_BASE +([0-9]+)");
  REQUIRE_MESSAGE(std::regex_search(text, m, define),
                  "crep/bindings.h has no CREP_VULKAN_" << kind << "_BASE");
  return std::stoi(m[1].str());
}

namespace {
/// Writes `text` to <dir>/<flat>.<pid>.comp: tests of one binary run as parallel processes (ctest -j)
/// and may take the same pass, so each process writes its own file.
std::filesystem::path writeScratch(const std::filesystem::path& dir, const std::string& flat,
                                   const std::string& text) {
  const std::filesystem::path source = dir / (flat + "." + std::to_string(::getpid()) + ".comp");
  std::ofstream out(source, std::ios::binary);
  out << text;
  out.close();
  REQUIRE_MESSAGE(out.good(), "cannot write " << source.string());
  return source;
}
std::filesystem::path requireTool(const char* program, const char* package) {
  const std::optional<std::filesystem::path> path = findInPath(program);
  REQUIRE_MESSAGE(path.has_value(), program << " not found in PATH: install " << package
                                            << " (part of the README's set-up command)");
  return *path;
}
} // namespace

RunResult compileComputeForVulkan(const std::string& name, const std::string& text) {
  const std::filesystem::path glslc = requireTool("glslc", "glslc"),
                              val = requireTool("spirv-val", "spirv-tools");
  const std::filesystem::path dir = std::filesystem::path(CREP_TEST_OUTPUT_DIR) / "vulkan";
  std::filesystem::create_directories(dir);
  std::string flat = name;
  std::replace(flat.begin(), flat.end(), '/', '_');
  const std::filesystem::path source = writeScratch(dir, flat, text),
                              spirv = dir / (flat + "." + std::to_string(::getpid()) + ".spv");
  const std::string unit = std::to_string(vulkanBindingBase("UNIT"));
  RunResult r = runCommand("'" + glslc.string() + "' --target-env=vulkan1.1 -Werror -ftexture-binding-base " +
                           unit + " -fsampler-binding-base " + unit + " -fimage-binding-base " +
                           std::to_string(vulkanBindingBase("IMAGE")) + " -fubo-binding-base " +
                           std::to_string(vulkanBindingBase("UNIFORM")) + " -fssbo-binding-base " +
                           std::to_string(vulkanBindingBase("STORAGE")) + " -o '" + spirv.string() + "' '" +
                           source.string() + "'");
  if (r.exitCode != 0) return r;
  return runCommand("'" + val.string() + "' --target-env vulkan1.1 '" + spirv.string() + "'");
}

RunResult preprocessCompute(const std::string& name, const std::string& text) {
  const std::filesystem::path validator = requireTool("glslangValidator", "glslang-tools");
  const std::filesystem::path dir = std::filesystem::path(CREP_TEST_OUTPUT_DIR) / "preprocessed";
  std::filesystem::create_directories(dir);
  std::string flat = name;
  std::replace(flat.begin(), flat.end(), '/', '_');
  const std::filesystem::path source = writeScratch(dir, flat, text);
  RunResult r = runCommand("'" + validator.string() + "' -E '" + source.string() + "'");
  std::error_code ignored;
  std::filesystem::remove(source, ignored);
  return r;
}

bool isLibraryPass(std::string_view path) {
  return path.starts_with("passes/") && path.ends_with(".comp") &&
         std::filesystem::exists(std::filesystem::path(CREP_SOURCE_DIR) / "glsl" / path);
}

std::filesystem::path portableShaderDir() {
  return CREP_SHADER_OUTPUT_DIR;
}

nlohmann::json portableShaderResources() {
  const std::filesystem::path file = portableShaderDir() / "resources.json";
  std::ifstream in(file);
  REQUIRE_MESSAGE(in.good(),
                  "cannot read " << file.string() << " (built by the crep_portable_shaders target)");
  return nlohmann::json::parse(in);
}

const nlohmann::json* shippedVariant(const nlohmann::json& resources, std::string_view path,
                                     std::span<const ShaderDefine> defines) {
  const auto sameDefines = [&](const nlohmann::json& entry) {
    const nlohmann::json& listed = entry.at("defines");
    if (listed.size() != defines.size()) return false;
    for (std::size_t i = 0; i < defines.size(); ++i)
      if (listed[i].at("name") != defines[i].name || listed[i].at("value") != defines[i].value) return false;
    return true;
  };
  if (defines.empty()) {
    for (const nlohmann::json& pass : resources.at("passes"))
      if (pass.at("name") == path) return &pass;
    return nullptr;
  }
  if (!resources.contains("variants")) return nullptr;
  for (const nlohmann::json& variant : resources.at("variants"))
    if (variant.at("name") == path && sameDefines(variant)) return &variant;
  return nullptr;
}

} // namespace crep::test
