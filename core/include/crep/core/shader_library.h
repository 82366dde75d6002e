// The shader library: shader sources embedded into the binaries at build time (no file is read at run
// time). The runtime library serves its own files (glsl/: the public includes crep/*.glsl and the
// passes of its modules); a program adds its own embedded sets with addFiles() (cmake/EmbedGlsl.cmake
// generates them), and every registered file can include every other one. `#include "path"`
// directives are resolved here, relative to the including file first and then to the root of the
// paths; each file is included once per expansion. `#line` markers keep compiler messages pointing at
// the real file and line; variants are made by prepended #defines (shaders give defaults with #ifndef).
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
  /// Every registered file (the library's own and those added with addFiles()), sorted by path. The
  /// span stays valid for the life of the process, even after a later addFiles() (which makes a new
  /// table; files() then returns the new one).
  static std::span<const File> files();
  /// Registers more embedded files, e.g. an application's own shaders (cmake/EmbedGlsl.cmake). The
  /// views must stay valid for the life of the process (static storage, as generated). Paths are
  /// relative ("passes/scene.vert"), without "." or ".." segments; their includes may name any
  /// registered file, e.g. "crep/common.glsl". Registering a file again (same path, same source
  /// storage) does nothing, so a set may be registered by every user. Throws ShaderError for an
  /// invalid path or a path already registered with another source (files never shadow each other).
  /// Thread-safe.
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

/// Compiles and links a program from registered files (current context required). Throws ShaderError
/// whose message holds the translated compile or link log.
gl::Handle buildProgram(std::initializer_list<ShaderStageSource> stages);
gl::Handle buildProgram(std::span<const ShaderStageSource> stages);

} // namespace crep
