#include "common/gl_fixture.h"

#include <crep/core/error.h>

#include <doctest/doctest.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <string_view>
#include <utility>

namespace crep::test {

namespace {

// KHR_debug values (no GL loader header in the test support).
constexpr std::uint32_t kDebugSourceShaderCompiler = 0x8248; // GL_DEBUG_SOURCE_SHADER_COMPILER

std::atomic<int> gErrorCount{0};

struct SharedState {
  // Never destroyed: destroying the last context terminates the EGL display, which unloads Mesa's
  // driver, and LeakSanitizer then reports a one-time allocation of the driver (128 bytes from a
  // pthread_once in an "<unknown module>") as leaked. Process exit reclaims everything anyway.
  GlContext* context = nullptr;
  std::string unavailable;
  bool attempted = false;
};

SharedState& state() {
  static SharedState s;
  return s;
}

bool forcedNoGl() {
  const char* v = std::getenv("CREP_TEST_FORCE_NO_GL");
  return v != nullptr && std::string_view(v) != "" && std::string_view(v) != "0";
}

} // namespace

void failOnGlError(const GlDebugMessage& message) {
  if (!message.isError() || message.source == kDebugSourceShaderCompiler) return;
  ++gErrorCount;
  if (doctest::is_running_in_test) {
    FAIL_CHECK("GL error (KHR_debug id " << message.id << "): " << message.text);
  } else {
    std::fprintf(stderr, "GL error outside a test case (KHR_debug id %u): %s\n", message.id,
                 message.text.c_str());
  }
}

GlContext* sharedGlContext() {
  SharedState& s = state();
  if (!s.attempted) {
    s.attempted = true;
    if (forcedNoGl()) {
      s.unavailable = "CREP_TEST_FORCE_NO_GL is set";
    } else {
      try {
        GlContextOptions options;
        options.debug = true;
        options.debugCallback = failOnGlError;
        s.context = new GlContext(options);
      } catch (const GlUnavailable& e) {
        s.unavailable = e.what();
      }
    }
  }
  return s.context;
}

std::string glUnavailableReason() {
  return state().unavailable;
}

int glErrorCount() {
  return gErrorCount.load();
}

GlContext& requireGl() {
  GlContext* context = sharedGlContext();
  if (context == nullptr) {
    std::printf("skipped: %s\n", glUnavailableReason().c_str());
    std::fflush(stdout);
    std::exit(77);
  }
  return *context;
}

ScopedGlDebugCallback::ScopedGlDebugCallback(std::function<void(const GlDebugMessage&)> callback) {
  requireGl().setDebugCallback(std::move(callback));
}

ScopedGlDebugCallback::~ScopedGlDebugCallback() {
  if (GlContext* context = sharedGlContext()) context->setDebugCallback(failOnGlError);
}

} // namespace crep::test
