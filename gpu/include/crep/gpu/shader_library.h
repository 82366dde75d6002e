// The shader library: GLSL sources embedded at build time (no file read at run time), the library's own and
// those a program adds with addFiles(); `#include "path"` resolved, `#line` markers kept, variants by
// prepended #defines. Rules: gpu/README.md, "shader_library.h".
#pragma once

#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace crep {

struct ShaderDefine {
  std::string name;
  std::string value; ///< may be empty: `#define NAME`
};

/// A fully expanded shader source ready for glShaderSource.
struct ExpandedShader {
  /// Line k of files[n] is numbered n * kLineStride + k in the `#line` markers, so the line number
  /// alone identifies the file: Mesa reports source-string number 0 for many errors in included files.
  static constexpr int kLineStride = 100000;

  std::string text;
  /// Source-string numbers used in the `#line <line> <number>` markers: files[number] is the
  /// path of that file in the shader library. Number 0 is the top-level file.
  std::vector<std::string> files;
  /// Rewrites a driver log ("0:12(3): error ..." or "ERROR: 0:12: ...") into "path:12(3): error ...".
  std::string translateLog(std::string_view log) const;
};

class ShaderLibrary {
public:
  struct File {
    std::string_view path; ///< relative to its set's root, e.g. "crep/common.glsl" (glsl/crep/common.glsl)
    std::string_view source;
  };
  /// Every registered file, sorted by path; the span stays valid for the life of the process.
  static std::span<const File> files();
  /// Registers more embedded files (cmake/EmbedGlsl.cmake); the views must live as long as the process.
  /// Thread-safe. ShaderError for a bad path or one already registered with another source.
  static void addFiles(std::span<const File> files);
  /// Source of one file. Throws ShaderError for an unknown path.
  static std::string_view source(std::string_view path);
  /// Expands `path`: `#version` line (the file's own, or "#version 450 core"), then `defines`, then
  /// the file with its includes resolved. Throws ShaderError for a missing include or an include cycle.
  static ExpandedShader expand(std::string_view path, std::span<const ShaderDefine> defines = {});
};

enum class ShaderStage : std::uint32_t { Vertex, Fragment, Compute };

struct ShaderStageSource {
  ShaderStage stage;
  std::string path; ///< registered file of the ShaderLibrary, e.g. "passes/prefilter/prefilter.comp"
  std::vector<ShaderDefine> defines;
};

/// Every distinct stage (path and defines) gl::buildProgram (crep/gpu/gl.h) compiled in this process, in
/// first-use order: the variants an engine's frames use, to precompile for another API
/// (docs/PORTABLE_SHADERS.md). Thread-safe.
std::vector<ShaderStageSource> programVariantsBuilt();

} // namespace crep
