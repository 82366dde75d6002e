// The rectified shadow pass (Klehm et al. 2014, Sec. 4.2): the engine's shadow casters drawn once per split
// of a projective rectification, each with its own matrix, into its own columns of one depth map. The pass
// sets what the rectification needs so that an integration cannot get it wrong:
//   - the whole map cleared to 1 once, before the first split (a glClear per split would wipe the splits
//     drawn before: glClear ignores the viewport);
//   - per split: the viewport of Rectification::splitViewport() and a scissor box equal to it, with the
//     scissor test on, so that even a clear inside the caller's callback stays inside its split;
//   - GL_DEPTH_TEST with GL_LESS and depth writes, GL_DEPTH_CLAMP (casters between the light and the view
//     frustum have a depth below 0 and must be kept at 0, not clipped), no face culling (the rectification
//     may mirror the winding).
// It also sets every other raster state the map depends on (clip control, depth range, polygon mode and
// offset, rasterizer discard, clip distances, ...) whatever the caller left, and restores the caller's
// values afterwards: docs/GL_STATE.md lists them (gl::DepthPassScope). The callback draws the casters with
// gl_Position = clipFromWorld * worldPosition (GL clip conventions, [-1, 1] depth) into the bound
// framebuffer and must leave that state as it found it (run() names a callback that does not).
// Requires a current OpenGL 4.5 context; never creates or owns one.
#pragma once

#include <cstdint>
#include <functional>
#include <string_view>

#include <glm/glm.hpp>

#include <crep/core/gl.h>
#include <crep/rectify/rectify.h>

namespace crep {

class RectifiedShadowPass {
public:
  struct CreateInfo {
    int mapWidth = 1024;  ///< map width W (a multiple of the split count)
    int mapHeight = 1024; ///< map height H (rows)
  };
  /// Draws the casters of split `split` with its rectClipFromWorld matrix.
  using DrawCasters = std::function<void(int split, const glm::dmat4& clipFromWorld)>;
  struct FrameAttribs {
    const Rectification* rectification = nullptr; ///< projective, SplitLayout::Regions
    DrawCasters drawCasters;                      ///< required
    /// Depth texture to render into (GL_TEXTURE_2D of mapWidth x mapHeight, a depth format: D32F recommended,
    /// D24 works since the depth is linear in the depth slope); 0 = the pass's own D32F texture.
    std::uint32_t depthTexture = 0;
  };
  /// Throws what run(frame) would before drawing: InvalidArgument naming the field after `owner` (a
  /// depthTexture of a colour format is found when run() attaches it).
  void validate(const FrameAttribs& frame,
                std::string_view owner = "RectifiedShadowPass::FrameAttribs") const;

  /// Throws InvalidArgument naming the field for sizes < 1 or beyond GL_MAX_TEXTURE_SIZE.
  explicit RectifiedShadowPass(const CreateInfo& info);
  ~RectifiedShadowPass();
  /// Moved from: valid but empty (run() throws InvalidArgument naming "RectifiedShadowPass", memoryBytes() is
  /// 0).
  RectifiedShadowPass(RectifiedShadowPass&&) noexcept;
  RectifiedShadowPass& operator=(RectifiedShadowPass&&) noexcept;
  RectifiedShadowPass(const RectifiedShadowPass&) = delete;
  RectifiedShadowPass& operator=(const RectifiedShadowPass&) = delete;

  /// Renders the map (see top). Throws InvalidArgument naming the FrameAttribs field: no rectification, a
  /// rectification that is not projective or uses SplitLayout::Layers, a width that is not a multiple of
  /// its split count, no callback, a callback that left the pass's raster state changed, a depth texture
  /// that is not a 2D texture of the map's size; GlError for an active transform feedback.
  void run(const FrameAttribs& frame);

  /// The pass's own D32F map (what run() renders into without FrameAttribs::depthTexture; created by the
  /// first such run, 0 before).
  std::uint32_t depthTexture() const noexcept { return texture_.get(); }
  const CreateInfo& createInfo() const noexcept { return info_; }
  /// GPU memory it owns, bytes (its D32F map, once created).
  std::size_t memoryBytes() const noexcept;

private:
  CreateInfo info_;
  gl::Handle texture_, framebuffer_;
};

} // namespace crep
