// The library's GL state contract (docs/GL_STATE.md has the whole of it: what each pass sets, restores
// and requires of the caller). Two scopes, used by every pass that rasterizes or transfers pixels:
//   - DepthPassScope: the fixed-function state a depth-only pass depends on, whatever the engine left
//     (reversed-Z clip control, a polygon offset, a scissor box, rasterizer discard, ...): saved, set to
//     the contract's values, restored on destruction;
//   - PixelStoreScope: the pack/unpack state and pixel buffer bindings of texture uploads and readbacks.
// GL names and enums are std::uint32_t / int (no loader header here). Requires a current OpenGL 4.5
// context. GPU note: each scope reads ~40 values with glGet*; drivers that run GL on a worker thread
// (NVIDIA's threaded optimization) may synchronise on them, once per scope, not per draw.
#pragma once

#include <cstdint>
#include <string>

namespace crep::gl {

/// The raster state of the contract that decides what a depth-only pass writes: the values GL holds for
/// viewport / scissor / depth range index 0 and the global ones. Single-sampled, depth-only targets make
/// the colour, blend, stencil and multisample state irrelevant (GL 4.5 core, Sec. 14.3.1, 17.3), so it is
/// not part of it.
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

/// Scope of a depth-only pass into `framebuffer` (a single-sampled depth attachment). The constructor
/// throws GlError when the caller left a state that cannot be overridden (requireNoActiveTransformFeedback),
/// saves the caller's RasterState and sets the contract's: `framebuffer` as the draw
/// framebuffer; clip control GL_LOWER_LEFT / GL_NEGATIVE_ONE_TO_ONE; depth range (0, 1); depth test on
/// with GL_LESS and writes; depth clamp per `state`; GL_FILL without polygon offset or smoothing; culling
/// per `state`; rasterizer discard, clip distances, depth bounds test and conservative rasterization off;
/// scissor test on with the scissor box equal to the viewport (setViewport). The destructor restores the
/// caller's values, also when an exception leaves the scope.
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

/// Saves the pixel pack and unpack state (alignment, row length, skip pixels/rows/images, image height,
/// swap bytes, LSB first) and the GL_PIXEL_PACK_BUFFER / GL_PIXEL_UNPACK_BUFFER bindings, sets GL's
/// defaults with alignment 1 and no pixel buffer bound (client memory is tightly packed), restores them on
/// destruction. Used around every glTextureSubImage* / glGetTextureSubImage of the library.
class PixelStoreScope {
public:
  PixelStoreScope();
  ~PixelStoreScope();
  PixelStoreScope(const PixelStoreScope&) = delete;
  PixelStoreScope& operator=(const PixelStoreScope&) = delete;

private:
  int pack_[8] = {}, unpack_[8] = {}, packBuffer_ = 0, unpackBuffer_ = 0;
};

/// Throws GlError naming `owner` when a transform feedback is active and not paused: it would capture the
/// library's draws and makes every glUseProgram of its passes fail; the library cannot set it aside without
/// changing what the engine records.
void requireNoActiveTransformFeedback(const char* owner);

/// Throws GlError naming `owner` and the errors when GL errors are pending before a call of the library
/// (the caller's earlier GL calls raised them; glGetError() pops them, so they are reported here rather
/// than blamed on the library's first check).
void requireNoPendingError(const char* owner);

/// GL_TIME_ELAPSED queries do not nest: throws GlError naming `owner` when the caller has one active (the
/// library's stage timers would fail part way through a frame).
void requireNoActiveTimerQuery(const char* owner);

} // namespace crep::gl
