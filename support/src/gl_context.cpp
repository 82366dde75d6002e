// Headless OpenGL context through EGL's surfaceless platform (EGL_MESA_platform_surfaceless): no
// window system, no config, no surface. Every step that can fail throws GlUnavailable naming it.
#include <crep/core/error.h>
#include <crep/support/gl_context.h>

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstdio>
#include <mutex>
#include <string>
#include <string_view>
#include <utility>

namespace crep {

namespace {

/// True when `list` (a space-separated EGL extension string, may be null) contains `name` as a token.
bool hasToken(const char* list, std::string_view name) {
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

std::string eglErrorName(EGLint error) {
  switch (error) {
  case EGL_SUCCESS:
    return "EGL_SUCCESS";
  case EGL_NOT_INITIALIZED:
    return "EGL_NOT_INITIALIZED";
  case EGL_BAD_ACCESS:
    return "EGL_BAD_ACCESS";
  case EGL_BAD_ALLOC:
    return "EGL_BAD_ALLOC";
  case EGL_BAD_ATTRIBUTE:
    return "EGL_BAD_ATTRIBUTE";
  case EGL_BAD_CONFIG:
    return "EGL_BAD_CONFIG";
  case EGL_BAD_CONTEXT:
    return "EGL_BAD_CONTEXT";
  case EGL_BAD_CURRENT_SURFACE:
    return "EGL_BAD_CURRENT_SURFACE";
  case EGL_BAD_DISPLAY:
    return "EGL_BAD_DISPLAY";
  case EGL_BAD_MATCH:
    return "EGL_BAD_MATCH";
  case EGL_BAD_NATIVE_PIXMAP:
    return "EGL_BAD_NATIVE_PIXMAP";
  case EGL_BAD_NATIVE_WINDOW:
    return "EGL_BAD_NATIVE_WINDOW";
  case EGL_BAD_PARAMETER:
    return "EGL_BAD_PARAMETER";
  case EGL_BAD_SURFACE:
    return "EGL_BAD_SURFACE";
  case EGL_CONTEXT_LOST:
    return "EGL_CONTEXT_LOST";
  default: {
    char buf[32];
    std::snprintf(buf, sizeof buf, "0x%x", static_cast<unsigned>(error));
    return buf;
  }
  }
}

[[noreturn]] void fail(const std::string& step) {
  throw GlUnavailable("crep: no OpenGL context: " + step);
}
[[noreturn]] void failEgl(const std::string& step) {
  fail(step + " failed (" + eglErrorName(eglGetError()) + ")");
}

/// eglTerminate acts on the whole display, which is shared by every context of the process (the
/// surfaceless display is a singleton), so the last GlContext alive terminates it.
std::mutex gDisplayMutex;
int gDisplayUsers = 0;

void defaultDebugCallback(const GlDebugMessage& message) {
  if (message.isError())
    std::fprintf(stderr, "crep: GL error (id %u): %s\n", message.id, message.text.c_str());
}

} // namespace

bool GlDebugMessage::isError() const {
  return type == GL_DEBUG_TYPE_ERROR;
}

struct GlContext::Impl {
  EGLDisplay display = EGL_NO_DISPLAY;
  bool initialized = false;
  EGLContext context = EGL_NO_CONTEXT;
  // Context current on this thread before ours (nested lifetimes): made current again when ours dies.
  EGLDisplay previousDisplay = EGL_NO_DISPLAY;
  EGLContext previousContext = EGL_NO_CONTEXT;
  EGLSurface previousDraw = EGL_NO_SURFACE, previousRead = EGL_NO_SURFACE;
  bool debug = false;
  std::function<void(const GlDebugMessage&)> callback;

  Impl() = default;
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  ~Impl() {
    if (context != EGL_NO_CONTEXT) {
      if (eglGetCurrentContext() == context) {
        if (debug) glDebugMessageCallback(nullptr, nullptr);
        eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (previousContext != EGL_NO_CONTEXT)
          eglMakeCurrent(previousDisplay, previousDraw, previousRead, previousContext);
      }
      eglDestroyContext(display, context);
    }
    if (initialized) {
      const std::lock_guard lock(gDisplayMutex);
      if (--gDisplayUsers == 0) eglTerminate(display);
    }
  }

  // Called by the driver inside GL calls, i.e. from C code: nothing may propagate out of it.
  static void GLAPIENTRY onDebugMessage(GLenum source, GLenum type, GLuint id, GLenum severity,
                                        GLsizei length, const GLchar* text, const void* user) {
    const Impl* self = static_cast<const Impl*>(user);
    try {
      GlDebugMessage message;
      message.source = source;
      message.type = type;
      message.id = id;
      message.severity = severity;
      message.text = length >= 0 ? std::string(text, static_cast<std::size_t>(length)) : std::string(text);
      if (self->callback) self->callback(message);
    } catch (...) {
      std::fprintf(stderr, "crep: the GL debug callback threw an exception (ignored): %s\n", text);
    }
  }
};

GlContext::GlContext(const GlContextOptions& options) : impl_(std::make_unique<Impl>()) {
  if (options.majorVersion < 1 || options.minorVersion < 0)
    throw InvalidArgument("GlContextOptions.majorVersion/minorVersion",
                          std::to_string(options.majorVersion) + "." + std::to_string(options.minorVersion),
                          "must be a valid OpenGL version");
  Impl& impl = *impl_;

  // libepoxy aborts the process when an EGL entry point is called and libEGL cannot be loaded.
  if (!epoxy_has_egl()) fail("libEGL could not be loaded (install libegl1 and Mesa's libegl-mesa0)");

  const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!hasToken(clientExtensions, "EGL_EXT_platform_base"))
    fail("EGL client extension EGL_EXT_platform_base is not supported");
  if (!hasToken(clientExtensions, "EGL_MESA_platform_surfaceless"))
    fail("EGL client extension EGL_MESA_platform_surfaceless is not supported (Mesa's EGL is needed)");

  impl.display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (impl.display == EGL_NO_DISPLAY) failEgl("eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA)");
  EGLint eglMajor = 0, eglMinor = 0;
  {
    const std::lock_guard lock(gDisplayMutex);
    if (!eglInitialize(impl.display, &eglMajor, &eglMinor))
      failEgl("eglInitialize on the surfaceless display");
    impl.initialized = true;
    ++gDisplayUsers;
  }

  const char* displayExtensions = eglQueryString(impl.display, EGL_EXTENSIONS);
  const bool egl15 = eglMajor > 1 || (eglMajor == 1 && eglMinor >= 5);
  if (!egl15 && !hasToken(displayExtensions, "EGL_KHR_create_context"))
    fail("EGL " + std::to_string(eglMajor) + "." + std::to_string(eglMinor) +
         " without EGL_KHR_create_context cannot create a versioned core-profile context");
  if (!hasToken(displayExtensions, "EGL_KHR_surfaceless_context"))
    fail("EGL display extension EGL_KHR_surfaceless_context is not supported");

  if (!eglBindAPI(EGL_OPENGL_API)) failEgl("eglBindAPI(EGL_OPENGL_API)");

  EGLConfig config = EGL_NO_CONFIG_KHR;
  if (!hasToken(displayExtensions, "EGL_KHR_no_config_context") &&
      !hasToken(displayExtensions, "EGL_MESA_configless_context")) {
    const EGLint configAttribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLint count = 0;
    if (!eglChooseConfig(impl.display, configAttribs, &config, 1, &count) || count < 1)
      failEgl("eglChooseConfig (EGL_OPENGL_BIT)");
  }

  // The EGL 1.5 names and the EGL_KHR_create_context names share their values for version and
  // profile; only the debug flag differs.
  EGLint attribs[16];
  int n = 0;
  attribs[n++] = EGL_CONTEXT_MAJOR_VERSION_KHR;
  attribs[n++] = options.majorVersion;
  attribs[n++] = EGL_CONTEXT_MINOR_VERSION_KHR;
  attribs[n++] = options.minorVersion;
  attribs[n++] = EGL_CONTEXT_OPENGL_PROFILE_MASK_KHR;
  attribs[n++] = EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT_KHR;
  if (options.debug) {
    if (egl15) {
      attribs[n++] = EGL_CONTEXT_OPENGL_DEBUG;
      attribs[n++] = EGL_TRUE;
    } else {
      attribs[n++] = EGL_CONTEXT_FLAGS_KHR;
      attribs[n++] = EGL_CONTEXT_OPENGL_DEBUG_BIT_KHR;
    }
  }
  attribs[n++] = EGL_NONE;

  const std::string requested = "OpenGL " + std::to_string(options.majorVersion) + "." +
                                std::to_string(options.minorVersion) + " core" +
                                (options.debug ? " debug" : "");
  impl.previousDisplay = eglGetCurrentDisplay();
  impl.previousContext = eglGetCurrentContext();
  impl.previousDraw = eglGetCurrentSurface(EGL_DRAW);
  impl.previousRead = eglGetCurrentSurface(EGL_READ);
  impl.context = eglCreateContext(impl.display, config, EGL_NO_CONTEXT, attribs);
  if (impl.context == EGL_NO_CONTEXT) failEgl("eglCreateContext(" + requested + ")");
  if (!eglMakeCurrent(impl.display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl.context))
    failEgl("eglMakeCurrent(no surface)");

  GLint major = 0, minor = 0, profile = 0, flags = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
  glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
  if (major < options.majorVersion || (major == options.majorVersion && minor < options.minorVersion))
    fail(requested + " requested but the context is " + std::to_string(major) + "." + std::to_string(minor) +
         " (" + version() + ", " + renderer() + ")");
  if ((options.majorVersion > 3 || (options.majorVersion == 3 && options.minorVersion >= 2)) &&
      (profile & GL_CONTEXT_CORE_PROFILE_BIT) == 0)
    fail(requested + " requested but the context is not a core profile (" + version() + ")");

  impl.debug = (flags & GL_CONTEXT_FLAG_DEBUG_BIT) != 0;
  if (options.debug) {
    if (!impl.debug) fail(requested + " requested but the context has no GL_CONTEXT_FLAG_DEBUG_BIT");
    impl.callback = options.debugCallback ? options.debugCallback : defaultDebugCallback;
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
    glDebugMessageCallback(&Impl::onDebugMessage, &impl);
  }
}

GlContext::~GlContext() = default;

std::string GlContext::renderer() const {
  const GLubyte* s = glGetString(GL_RENDERER);
  return s != nullptr ? reinterpret_cast<const char*>(s) : "";
}

std::string GlContext::version() const {
  const GLubyte* s = glGetString(GL_VERSION);
  return s != nullptr ? reinterpret_cast<const char*>(s) : "";
}

bool GlContext::isDebug() const {
  return impl_->debug;
}

void GlContext::setDebugCallback(std::function<void(const GlDebugMessage&)> callback) {
  impl_->callback = callback ? std::move(callback) : defaultDebugCallback;
}

} // namespace crep
