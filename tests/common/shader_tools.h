// Shader tools the tests run as a user would (glslangValidator, glslc, spirv-val), and the portable
// shaders of the build (share/crepuscular/shaders once installed: docs/PORTABLE_SHADERS.md).
#pragma once

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include <crep/gpu/shader_library.h>

namespace crep::test {

/// The program's path if it is an executable in one of PATH's folders.
std::optional<std::filesystem::path> findInPath(const char* program);

struct RunResult {
  int exitCode = -1;  ///< -1 if it did not exit normally
  std::string output; ///< stdout + stderr
};

/// Runs `command` through the shell and captures its output.
RunResult runCommand(const std::string& command);

/// Writes `text` (an expanded compute shader) to the test output folder and compiles it for Vulkan 1.1
/// as the build does (glslc, the binding bases of crep/bindings.h), then validates the SPIR-V
/// (spirv-val). The result is the first failing step's, or spirv-val's.
RunResult compileComputeForVulkan(const std::string& name, const std::string& text);

/// Runs `text` (an expanded compute shader) through glslangValidator's preprocessor (-E): the GL form,
/// macros replaced, inactive branches gone; the output is the preprocessed text.
RunResult preprocessCompute(const std::string& name, const std::string& text);

/// CREP_VULKAN_<kind>_BASE of crep/bindings.h, kind "UNIT", "IMAGE", "UNIFORM" or "STORAGE".
int vulkanBindingBase(const std::string& kind);

/// True for a pass of the library (glsl/passes/ of the source tree), not one a tool or test registered.
bool isLibraryPass(std::string_view path);

/// The build's portable shaders folder (spirv/, hlsl/, msl/, resources.json).
std::filesystem::path portableShaderDir();

/// resources.json of the build, parsed.
nlohmann::json portableShaderResources();

/// The entry of `resources` (resources.json) that ships the program variant `path` with `defines`: its
/// "passes" entry for the default variant (no defines), else the "variants" entry with these defines in this
/// order; null if none.
const nlohmann::json* shippedVariant(const nlohmann::json& resources, std::string_view path,
                                     std::span<const ShaderDefine> defines);

} // namespace crep::test
