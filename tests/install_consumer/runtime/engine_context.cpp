#include "engine_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdio>
#include <string_view>

namespace {

bool hasExtension(const char* list, std::string_view name) {
  if (list == nullptr) return false;
  std::string_view rest(list);
  while (!rest.empty()) {
    const std::size_t end = rest.find(' ');
    if (rest.substr(0, end) == name) return true;
    if (end == std::string_view::npos) break;
    rest.remove_prefix(end + 1);
  }
  return false;
}

bool fail(const char* step) {
  std::fprintf(stderr, "consumer: no GL context: %s failed (EGL error 0x%x)\n", step,
               static_cast<unsigned>(eglGetError()));
  return false;
}

} // namespace

bool EngineContext::create() {
  const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!hasExtension(clientExtensions, "EGL_MESA_platform_surfaceless"))
    return fail("EGL_MESA_platform_surfaceless support");
  EGLDisplay dpy = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (dpy == EGL_NO_DISPLAY) return fail("eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA)");
  display = dpy;
  EGLint major = 0, minor = 0;
  if (eglInitialize(dpy, &major, &minor) != EGL_TRUE) {
    display = nullptr;
    return fail("eglInitialize");
  }
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) return fail("eglBindAPI(EGL_OPENGL_API)");
  const char* displayExtensions = eglQueryString(dpy, EGL_EXTENSIONS);
  EGLConfig config = nullptr; // EGL_NO_CONFIG_KHR
  if (!hasExtension(displayExtensions, "EGL_KHR_no_config_context")) {
    const EGLint configAttribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLint count = 0;
    if (eglChooseConfig(dpy, configAttribs, &config, 1, &count) != EGL_TRUE || count < 1)
      return fail("eglChooseConfig");
  }
  const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                            4,
                            EGL_CONTEXT_MINOR_VERSION,
                            5,
                            EGL_CONTEXT_OPENGL_PROFILE_MASK,
                            EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                            EGL_NONE};
  EGLContext ctx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, attribs);
  if (ctx == EGL_NO_CONTEXT) return fail("eglCreateContext(OpenGL 4.5 core)");
  context = ctx;
  if (eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx) != EGL_TRUE)
    return fail("eglMakeCurrent(no surface)");
  return true;
}

EngineContext::~EngineContext() {
  if (context != nullptr) {
    eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display, context);
  }
  if (display != nullptr) eglTerminate(display);
}
