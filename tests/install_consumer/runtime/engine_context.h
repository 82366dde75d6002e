// The engine's own headless OpenGL 4.5 core context: EGL on Mesa's surfaceless platform
// (EGL_MESA_platform_surfaceless), no window, no surface. Kept apart from the GL code because libEGL's
// headers and libepoxy's GL header both define the Khronos types.
#pragma once

struct EngineContext {
  /// Creates the context and makes it current; prints the failing step and returns false if there is
  /// no GL.
  bool create();
  ~EngineContext();

  void* display = nullptr; ///< EGLDisplay
  void* context = nullptr; ///< EGLContext
};
