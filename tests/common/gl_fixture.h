// The GL context of the GL tests (tests/**/*GLTest.cpp).
//
// Every GL test starts with CREP_REQUIRE_GL(): it creates (once per process) a debug OpenGL 4.5 core
// context through EGL's surfaceless platform (Mesa llvmpipe without a GPU). When no context can be
// created, it prints "skipped: <reason>" and exits the process with code 77, which ctest reports as
// "skipped" (SKIP_RETURN_CODE 77; ctest runs each test case as its own process). Setting the
// environment variable CREP_TEST_FORCE_NO_GL=1 simulates a machine without OpenGL.
//
// The context's synchronous KHR_debug callback turns every GL_DEBUG_TYPE_ERROR message from the API
// (a GL call that failed) into a doctest failure of the running test. Shader compiler messages are
// not: buildProgram() reports compile errors as crep::ShaderError. A test that provokes GL errors on
// purpose installs its own callback with ScopedGlDebugCallback.
#pragma once

#include <crep/support/gl_context.h>

#include <functional>
#include <string>

namespace crep::test {

/// The process-wide debug context, created on first use (current on the calling thread) and never
/// destroyed (see gl_fixture.cpp); nullptr when OpenGL is unavailable (see glUnavailableReason()).
GlContext* sharedGlContext();
/// Why sharedGlContext() returned nullptr (empty otherwise).
std::string glUnavailableReason();
/// Number of GL_DEBUG_TYPE_ERROR messages the default callback has received in this process.
int glErrorCount();
/// The default callback: GL API errors fail the running doctest test case and are counted.
void failOnGlError(const GlDebugMessage& message);
/// Ensures the shared context exists; otherwise prints "skipped: <reason>" and exits with code 77.
GlContext& requireGl();

/// Replaces the shared context's debug callback for the current scope, restoring failOnGlError().
class ScopedGlDebugCallback {
public:
  explicit ScopedGlDebugCallback(std::function<void(const GlDebugMessage&)> callback);
  ~ScopedGlDebugCallback();
  ScopedGlDebugCallback(const ScopedGlDebugCallback&) = delete;
  ScopedGlDebugCallback& operator=(const ScopedGlDebugCallback&) = delete;
};

} // namespace crep::test

/// First statement of every GL test case: skips the test (exit code 77) without a GL context.
#define CREP_REQUIRE_GL() ::crep::test::requireGl()
