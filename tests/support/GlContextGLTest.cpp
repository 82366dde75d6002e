// The headless context and the GL helpers (crep/support/gl_context.h, crep/gpu/gl.h).
#include "common/gl_fixture.h"

#include <crep/core/error.h>
#include <crep/gpu/gl.h>
#include <crep/support/gl_context.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <utility>
#include <vector>

namespace {
bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}
} // namespace

TEST_CASE("GlContext: OpenGL 4.5 core debug context on EGL's surfaceless platform") {
  crep::GlContext& context = CREP_REQUIRE_GL();
  const std::string renderer = context.renderer();
  std::printf("GL_RENDERER: %s\nGL_VERSION: %s\n", renderer.c_str(), context.version().c_str());
  MESSAGE("GL_RENDERER: " << renderer << ", GL_VERSION: " << context.version());
  CHECK(!renderer.empty());

  GLint major = 0, minor = 0, profile = 0, flags = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
  glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
  CHECK((major > 4 || (major == 4 && minor >= 5)));
  CHECK((profile & GL_CONTEXT_CORE_PROFILE_BIT) != 0);
  CHECK((flags & GL_CONTEXT_FLAG_DEBUG_BIT) != 0);
  CHECK(context.isDebug());
  CHECK(glIsEnabled(GL_DEBUG_OUTPUT) == GL_TRUE);
  CHECK(glIsEnabled(GL_DEBUG_OUTPUT_SYNCHRONOUS) == GL_TRUE);
  CHECK(crep::test::glErrorCount() == 0);
}

TEST_CASE("GlContext: the debug callback reports a deliberate GL error and checkError drains it") {
  CREP_REQUIRE_GL();
  const int errorsBefore = crep::test::glErrorCount();
  std::vector<crep::GlDebugMessage> messages;
  {
    // A private callback, so the fixture's fail-on-error callback does not fail this test.
    crep::test::ScopedGlDebugCallback scoped([&](const crep::GlDebugMessage& m) {
      if (m.isError()) messages.push_back(m); // drivers may add notifications
    });
    glBindTexture(0x1234, 0); // not a texture target: GL_INVALID_ENUM
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].isError());
    CHECK(messages[0].type == GL_DEBUG_TYPE_ERROR);
    CHECK(messages[0].source == GL_DEBUG_SOURCE_API);
    CHECK(!messages[0].text.empty());
    MESSAGE("debug message: " << messages[0].text);
    try {
      crep::gl::checkError("the deliberate glBindTexture");
      FAIL("checkError did not throw");
    } catch (const crep::GlError& e) {
      CHECK(contains(e.what(), "GL_INVALID_ENUM"));
      CHECK(contains(e.what(), "the deliberate glBindTexture"));
    }
    CHECK(glGetError() == GL_NO_ERROR); // drained
    CHECK_NOTHROW(crep::gl::checkError("nothing"));
  }
  CHECK(crep::test::glErrorCount() == errorsBefore); // the fixture's callback saw nothing
}

TEST_CASE("GlContext: a second non-debug context and failures that name the step") {
  crep::GlContext& shared = CREP_REQUIRE_GL();
  {
    crep::GlContext plain; // becomes current
    CHECK(!plain.isDebug());
    GLint flags = 0;
    glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
    CHECK((flags & GL_CONTEXT_FLAG_DEBUG_BIT) == 0);
  }
  // The shared context is current again.
  GLint flags = 0;
  glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
  CHECK((flags & GL_CONTEXT_FLAG_DEBUG_BIT) != 0);
  CHECK(shared.isDebug());

  crep::GlContextOptions options;
  options.majorVersion = 9;
  options.minorVersion = 9;
  try {
    crep::GlContext impossible(options);
    FAIL("an OpenGL 9.9 context was created");
  } catch (const crep::GlUnavailable& e) {
    MESSAGE(std::string(e.what()));
    CHECK(contains(e.what(), "9.9"));
  }
  glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
  CHECK((flags & GL_CONTEXT_FLAG_DEBUG_BIT) != 0);

  options.majorVersion = 0;
  CHECK_THROWS_AS(crep::GlContext{options}, crep::InvalidArgument);
}

TEST_CASE("gl::checkTextureSize names the parameter and the limit") {
  CREP_REQUIRE_GL();
  const int limit = crep::gl::maxTextureSize();
  CHECK(limit >= 16384); // OpenGL 4.5 minimum
  CHECK(crep::gl::maxArrayTextureLayers() >= 2048);
  CHECK_NOTHROW(crep::gl::checkTextureSize("Test.size", 1, 1));
  CHECK_NOTHROW(crep::gl::checkTextureSize("Test.size", limit, limit));

  for (const auto& [w, h] : {std::pair{0, 16}, std::pair{16, 0}, std::pair{-1, 16}, std::pair{16, -1}}) {
    CAPTURE(w);
    CAPTURE(h);
    try {
      crep::gl::checkTextureSize("Test.size", w, h);
      FAIL("no exception");
    } catch (const crep::InvalidArgument& e) {
      CHECK(e.parameter() == "Test.size");
      CHECK(contains(e.what(), "Test.size"));
      CHECK(contains(e.what(), std::to_string(w) + " x " + std::to_string(h)));
    }
  }
  for (const auto& [w, h] : {std::pair{limit + 1, 16}, std::pair{16, limit + 1}}) {
    try {
      crep::gl::checkTextureSize("Test.size", w, h);
      FAIL("no exception");
    } catch (const crep::GlError& e) {
      CHECK(contains(e.what(), "Test.size"));
      CHECK(contains(e.what(), "GL_MAX_TEXTURE_SIZE = " + std::to_string(limit)));
    }
  }
}

TEST_CASE("gl::GpuTimer measures a finite, non-negative time") {
  CREP_REQUIRE_GL();
  crep::gl::GpuTimer timer;
  CHECK_THROWS_AS(timer.milliseconds(), crep::GlError);
  CHECK_THROWS_AS(timer.end(), crep::GlError);
  const crep::gl::Handle texture = crep::gl::createTexture(GL_TEXTURE_2D);
  glTextureStorage2D(texture.get(), 1, GL_RGBA32F, 256, 256);
  timer.begin();
  CHECK_THROWS_AS(timer.begin(), crep::GlError);
  const float value[4] = {1, 2, 3, 4};
  glClearTexImage(texture.get(), 0, GL_RGBA, GL_FLOAT, value);
  timer.end();
  const double ms = timer.milliseconds();
  MESSAGE("clear of a 256x256 RGBA32F texture: " << ms << " ms");
  CHECK(std::isfinite(ms));
  CHECK(ms >= 0.0);
  // A timer can be reused.
  timer.begin();
  timer.end();
  CHECK(std::isfinite(timer.milliseconds()));
}

TEST_CASE("gl::Handle owns exactly one object") {
  CREP_REQUIRE_GL();
  using crep::gl::Handle;

  SUBCASE("move construction and assignment transfer ownership; reset deletes") {
    Handle a = crep::gl::createTexture(GL_TEXTURE_2D);
    const GLuint name = a.get();
    REQUIRE(name != 0);
    CHECK(glIsTexture(name) == GL_TRUE);
    Handle b(std::move(a));
    CHECK(!a); // NOLINT(bugprone-use-after-move): moved-from is empty by contract
    CHECK(a.get() == 0);
    CHECK(b.get() == name);
    Handle c;
    c = std::move(b);
    CHECK(!b); // NOLINT(bugprone-use-after-move)
    CHECK(c.get() == name);
    CHECK(glIsTexture(name) == GL_TRUE);
    c.reset();
    CHECK(!c);
    CHECK(glIsTexture(name) == GL_FALSE);
    // The moved-from handles delete nothing, even when the name has been reused meanwhile.
    Handle d = crep::gl::createTexture(GL_TEXTURE_2D);
    const GLuint reused = d.get();
    a = Handle();
    b.reset();
    CHECK(glIsTexture(reused) == GL_TRUE);
  }
  SUBCASE("assignment deletes the previous object; self-move is harmless") {
    Handle a = crep::gl::createBuffer();
    const GLuint first = a.get();
    a = crep::gl::createBuffer();
    CHECK(glIsBuffer(first) == GL_FALSE);
    CHECK(glIsBuffer(a.get()) == GL_TRUE);
    Handle& self = a;
    a = std::move(self);
    CHECK(glIsBuffer(a.get()) == GL_TRUE);
  }
  SUBCASE("release gives up ownership") {
    GLuint name = 0;
    {
      Handle a = crep::gl::createSampler();
      name = a.release();
      CHECK(!a);
    }
    CHECK(glIsSampler(name) == GL_TRUE);
    glDeleteSamplers(1, &name);
  }
  SUBCASE("every create* wrapper and every object type is deleted by its destructor") {
    GLuint texture = 0, buffer = 0, framebuffer = 0, vertexArray = 0, query = 0, sampler = 0, program = 0,
           shader = 0, renderbuffer = 0;
    {
      const Handle t = crep::gl::createTexture(GL_TEXTURE_2D_ARRAY);
      const Handle b = crep::gl::createBuffer();
      const Handle f = crep::gl::createFramebuffer();
      const Handle v = crep::gl::createVertexArray();
      const Handle q = crep::gl::createQuery(GL_TIME_ELAPSED);
      const Handle s = crep::gl::createSampler();
      const Handle p(crep::gl::ObjectType::Program, glCreateProgram());
      const Handle sh(crep::gl::ObjectType::Shader, glCreateShader(GL_COMPUTE_SHADER));
      GLuint rb = 0;
      glCreateRenderbuffers(1, &rb);
      const Handle r(crep::gl::ObjectType::Renderbuffer, rb);
      texture = t.get(), buffer = b.get(), framebuffer = f.get(), vertexArray = v.get(), query = q.get();
      sampler = s.get(), program = p.get(), shader = sh.get(), renderbuffer = r.get();
      CHECK(glIsTexture(texture) == GL_TRUE);
      CHECK(glIsBuffer(buffer) == GL_TRUE);
      CHECK(glIsFramebuffer(framebuffer) == GL_TRUE);
      CHECK(glIsVertexArray(vertexArray) == GL_TRUE);
      CHECK(glIsQuery(query) == GL_TRUE);
      CHECK(glIsSampler(sampler) == GL_TRUE);
      CHECK(glIsProgram(program) == GL_TRUE);
      CHECK(glIsShader(shader) == GL_TRUE);
      CHECK(glIsRenderbuffer(renderbuffer) == GL_TRUE);
    }
    CHECK(glIsTexture(texture) == GL_FALSE);
    CHECK(glIsBuffer(buffer) == GL_FALSE);
    CHECK(glIsFramebuffer(framebuffer) == GL_FALSE);
    CHECK(glIsVertexArray(vertexArray) == GL_FALSE);
    CHECK(glIsQuery(query) == GL_FALSE);
    CHECK(glIsSampler(sampler) == GL_FALSE);
    CHECK(glIsProgram(program) == GL_FALSE);
    CHECK(glIsShader(shader) == GL_FALSE);
    CHECK(glIsRenderbuffer(renderbuffer) == GL_FALSE);
  }
}

namespace {
/// Runs this test executable again with `arguments` (a shell fragment); returns the exit code and
/// fills `output` with stdout + stderr.
int runSelf(const std::string& arguments, std::string& output) {
  char exe[4096] = {};
  const ssize_t n = ::readlink("/proc/self/exe", exe, sizeof exe - 1);
  REQUIRE(n > 0);
  const std::string command = arguments.substr(0, arguments.find('|')) + " '" + std::string(exe) + "' " +
                              arguments.substr(arguments.find('|') + 1) + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  char buffer[1024];
  std::size_t got;
  while ((got = std::fread(buffer, 1, sizeof buffer, pipe)) > 0)
    output.append(buffer, got);
  const int status = ::pclose(pipe);
  REQUIRE(WIFEXITED(status));
  return WEXITSTATUS(status);
}
} // namespace

TEST_CASE("GL tests are skipped, not failed, without OpenGL (CREP_TEST_FORCE_NO_GL)") {
  // Runs the first test case in a child process, as ctest would on a machine without OpenGL. Needs
  // no context itself.
  std::string output;
  const int code =
      runSelf("CREP_TEST_FORCE_NO_GL=1|--test-case='GlContext: OpenGL 4.5 core debug context*'", output);
  CAPTURE(output);
  CHECK(code == 77);
  CHECK(contains(output, "skipped: CREP_TEST_FORCE_NO_GL"));
}

// Run only by the next test case, in a child process (skipped otherwise): a GL error that no test
// asked for.
TEST_CASE("GL fixture self-test: an unexpected GL error" * doctest::skip()) {
  CREP_REQUIRE_GL();
  glBindTexture(0x1234, 0);
  glGetError();
}

TEST_CASE("The GL fixture turns an unexpected GL error into a test failure") {
  std::string output;
  const int code = runSelf("|--no-skip --test-case='GL fixture self-test: an unexpected GL error'", output);
  CAPTURE(output);
  if (code == 77) {
    std::printf("skipped: %s\n", output.c_str());
    std::exit(77);
  }
  CHECK(code == 1);
  CHECK(contains(output, "GL error (KHR_debug id"));
  CHECK(contains(output, "GL_INVALID_ENUM"));
  CHECK(contains(output, "1 failed"));
}
