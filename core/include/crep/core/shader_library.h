// The shader library: every file of glsl/ is embedded into the library at build time (no file is
// read at run time). `#include "path"` directives are resolved here, relative to the including file
// first and then to the glsl/ root; each file is included once per expansion. `#line` markers keep
// compiler messages pointing at the real file and line; variants are made by prepended #defines
// (shaders give defaults with #ifndef).
#pragma once

#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <crep/core/gl.h>

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
  /// path (relative to glsl/) of that file. Number 0 is the top-level file.
  std::vector<std::string> files;
  /// Rewrites a driver log ("0:12(3): error ..." or "ERROR: 0:12: ...") into "path:12(3): error ...".
  std::string translateLog(std::string_view log) const;
};

class ShaderLibrary {
public:
  struct File {
    std::string_view path; ///< relative to glsl/, e.g. "crep/common.glsl"
    std::string_view source;
  };
  /// Every embedded file, sorted by path.
  static std::span<const File> files();
  /// Source of one file. Throws ShaderError for an unknown path.
  static std::string_view source(std::string_view path);
  /// Expands `path`: `#version` line (the file's own, or "#version 450 core"), then `defines`, then
  /// the file with its includes resolved. Throws ShaderError for a missing include or an include cycle.
  static ExpandedShader expand(std::string_view path, std::span<const ShaderDefine> defines = {});
};

enum class ShaderStage : std::uint32_t { Vertex, Fragment, Compute };

struct ShaderStageSource {
  ShaderStage stage;
  std::string path; ///< embedded file, relative to glsl/
  std::vector<ShaderDefine> defines;
};

/// Compiles and links a program from embedded files (current context required). Throws ShaderError
/// whose message holds the translated compile or link log.
gl::Handle buildProgram(std::initializer_list<ShaderStageSource> stages);
gl::Handle buildProgram(std::span<const ShaderStageSource> stages);

} // namespace crep
