// Headless OpenGL 4.5 core context through EGL's surfaceless platform (Mesa), for the crep tool, the tests
// and the benchmarks; library passes never create one. Lifetime rules: support/README.md.
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
  /// Called synchronously for each debug message (debug contexts); must not throw. Default: errors to stderr.
  std::function<void(const GlDebugMessage&)> debugCallback;
};

/// An EGL display and a surfaceless context, current on the creating thread for its whole lifetime; not
/// copyable or movable. What destruction restores, and LeakSanitizer: README.
class GlContext {
public:
  /// Throws GlUnavailable naming the failing step. One-time: loads the driver.
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
