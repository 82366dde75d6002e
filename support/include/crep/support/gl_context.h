// Headless OpenGL 4.5 core context through EGL's surfaceless platform (Mesa), for the crep tool,
// the tests and the benchmarks. Library passes never create or own a context: an engine calls them
// with its own context current.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace crep {

/// One KHR_debug message.
struct GlDebugMessage {
  std::uint32_t source = 0, type = 0, id = 0, severity = 0; // GLenum values
  std::string text;
  bool isError() const; ///< type == GL_DEBUG_TYPE_ERROR
};

struct GlContextOptions {
  int majorVersion = 4; ///< requested OpenGL version (core profile)
  int minorVersion = 5;
  /// Debug context with synchronous KHR_debug output; messages go to `debugCallback`.
  bool debug = false;
  /// Called for each debug message (debug contexts only), synchronously inside the GL call that
  /// caused it; must not throw (an exception is caught and reported on stderr). Default: GL errors
  /// are printed to stderr.
  std::function<void(const GlDebugMessage&)> debugCallback;
};

/// Owns an EGL display connection and a surfaceless OpenGL context, current on the creating thread
/// for its whole lifetime. Not copyable, not movable. A GlContext created while another context is
/// current makes that one current again when it is destroyed; the EGL display is terminated when
/// the last GlContext of the process is destroyed. Terminating the display unloads Mesa's driver;
/// under LeakSanitizer the driver's own allocations are then reported from "<unknown module>", so
/// sanitized programs keep one context for the process lifetime (as the crep tool and the tests do).
class GlContext {
public:
  /// Throws GlUnavailable with a message naming the failing step (no EGL, no surfaceless platform,
  /// no OpenGL 4.5 core context).
  explicit GlContext(const GlContextOptions& options = {});
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  std::string renderer() const; ///< GL_RENDERER
  std::string version() const;  ///< GL_VERSION
  bool isDebug() const;
  /// Replaces the debug callback (debug contexts only).
  void setDebugCallback(std::function<void(const GlDebugMessage&)> callback);

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace crep
