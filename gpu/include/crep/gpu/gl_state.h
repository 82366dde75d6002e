// The library's GL state contract (docs/GL_STATE.md): DepthPassScope for depth-only passes, PixelStoreScope
// for uploads and readbacks; each saves, sets and restores the state (gpu/README.md, "gl_state.h"). GL names
// and enums are std::uint32_t / int. Requires a current OpenGL 4.5 context.
#pragma once

#include <cstdint>
#include <string>

namespace crep::gl {

/// The raster state that decides what a depth-only pass writes (index 0 of viewport, scissor and depth
/// range, and the global state; colour, blend, stencil and multisample state do not matter).
struct RasterState {
  int drawFramebuffer = 0;
  float viewport[4] = {0, 0, 0, 0}; ///< index 0
  int scissorBox[4] = {0, 0, 0, 0}; ///< index 0
  bool scissorTest = false;         ///< index 0
  double depthRange[2] = {0, 1};    ///< index 0
  std::uint32_t clipOrigin = 0, clipDepthMode = 0;
  std::uint32_t depthFunc = 0;
  bool depthMask = true, depthTest = false, depthClamp = false;
  std::uint32_t polygonMode = 0; ///< GL_FILL, GL_LINE, GL_POINT (core: front and back alike)
  bool polygonOffsetFill = false, polygonOffsetLine = false, polygonOffsetPoint = false;
  bool polygonSmooth = false;
  bool cullFace = false;
  std::uint32_t cullFaceMode = 0, frontFace = 0;
  bool rasterizerDiscard = false;
  std::uint32_t clipDistances = 0; ///< bit i: GL_CLIP_DISTANCEi enabled (i < GL_MAX_CLIP_DISTANCES)
  bool depthBoundsTest = false;    ///< GL_EXT_depth_bounds_test, where supported
  bool conservativeRaster = false; ///< GL_NV/INTEL_conservative_rasterization, where supported

  /// The current values.
  static RasterState read();
  /// Makes them current.
  void apply() const;
  /// "" if equal, else the first field that differs, as "GL_CLIP_DEPTH_MODE = GL_ZERO_TO_ONE (expected
  /// GL_NEGATIVE_ONE_TO_ONE)" with this object's value second.
  std::string firstDifference(const RasterState& actual) const;
};

/// What a depth-only pass asks of the contract beyond its fixed values.
struct DepthPassState {
  bool depthClamp = true;     ///< GL_DEPTH_CLAMP: shadow maps keep casters in front of the near plane at 0
  bool cullBackFaces = false; ///< GL_CULL_FACE (GL_BACK, GL_CCW); off: a rectification may mirror winding
};

/// Scope of a depth-only pass into `framebuffer`: saves the caller's RasterState, sets the contract's, and
/// restores it on destruction, also on an exception. GlError for an active transform feedback.
class DepthPassScope {
public:
  DepthPassScope(std::uint32_t framebuffer, int width, int height, const DepthPassState& state = {});
  ~DepthPassScope();
  DepthPassScope(const DepthPassScope&) = delete;
  DepthPassScope& operator=(const DepthPassScope&) = delete;

  /// Viewport 0 and scissor box 0 to (x, y, width, height): a clear inside a callback stays inside it.
  void setViewport(int x, int y, int width, int height);
  /// Throws InvalidArgument naming `callback` when the current state differs from the contract's (a
  /// callback changed the framebuffer, viewport, clip control, depth state, ... and left it changed).
  void requireUnchanged(const char* callback) const;

private:
  RasterState saved_, set_;
};

/// Saves the pixel pack / unpack state and pixel buffer bindings, sets GL's defaults with alignment 1 and no
/// pixel buffer (tightly packed client memory), restores them on destruction; around every transfer.
class PixelStoreScope {
public:
  PixelStoreScope();
  ~PixelStoreScope();
  PixelStoreScope(const PixelStoreScope&) = delete;
  PixelStoreScope& operator=(const PixelStoreScope&) = delete;

private:
  int pack_[8] = {}, unpack_[8] = {}, packBuffer_ = 0, unpackBuffer_ = 0;
};

/// Throws GlError naming `owner` when a transform feedback is active and not paused (it cannot be set aside).
void requireNoActiveTransformFeedback(const char* owner);

/// Throws GlError naming `owner` and the errors when GL errors are pending before a call of the library.
void requireNoPendingError(const char* owner);

/// Throws GlError naming `owner` when the caller has a GL_TIME_ELAPSED query active (they do not nest).
void requireNoActiveTimerQuery(const char* owner);

} // namespace crep::gl
