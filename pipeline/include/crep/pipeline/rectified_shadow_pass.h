// The rectified shadow pass (Klehm et al. 2014, Sec. 4.2): the engine's casters drawn once per split of a
// projective rectification into that split's columns of one depth map, every raster state the map depends on
// set and then restored (pipeline/README.md, "rectified_shadow_pass.h"; docs/GL_STATE.md).
// Requires a current OpenGL 4.5 context; never creates or owns one.
#pragma once

#include <cstdint>
#include <functional>
#include <string_view>

#include <glm/glm.hpp>

#include <crep/gpu/gl.h>
#include <crep/rectify/rectify.h>

namespace crep {

class RectifiedShadowPass {
public:
  struct CreateInfo {
    int mapWidth = 1024;  ///< map width W (a multiple of the split count)
    int mapHeight = 1024; ///< map height H (rows)
  };
  /// Draws split `split`'s casters with gl_Position = clipFromWorld * world; leaves the GL state as found.
  using DrawCasters = std::function<void(int split, const glm::dmat4& clipFromWorld)>;
  struct FrameAttribs {
    const Rectification* rectification = nullptr; ///< projective, SplitLayout::Regions
    DrawCasters drawCasters;                      ///< required
    /// GL_TEXTURE_2D depth texture of mapWidth x mapHeight (D32F, or D24) to render into; 0 = its own D32F.
    std::uint32_t depthTexture = 0;
  };
  /// Throws what run(frame) would before drawing: InvalidArgument naming the field after `owner` (a
  /// depthTexture of a colour format is found when run() attaches it).
  void validate(const FrameAttribs& frame,
                std::string_view owner = "RectifiedShadowPass::FrameAttribs") const;

  /// Throws InvalidArgument naming the field for sizes < 1 or beyond GL_MAX_TEXTURE_SIZE.
  explicit RectifiedShadowPass(const CreateInfo& info);
  ~RectifiedShadowPass();
  /// Moved from: valid, empty: run() throws InvalidArgument naming "RectifiedShadowPass", memoryBytes() is 0.
  RectifiedShadowPass(RectifiedShadowPass&&) noexcept;
  RectifiedShadowPass& operator=(RectifiedShadowPass&&) noexcept;
  RectifiedShadowPass(const RectifiedShadowPass&) = delete;
  RectifiedShadowPass& operator=(const RectifiedShadowPass&) = delete;

  /// Renders the map (per frame, one draw callback per split). Throws InvalidArgument naming the FrameAttribs
  /// field (README), GlError for an active transform feedback.
  void run(const FrameAttribs& frame);

  /// Its own D32F map, used by run() without FrameAttribs::depthTexture (0 before the first such run).
  std::uint32_t depthTexture() const noexcept { return texture_.get(); }
  const CreateInfo& createInfo() const noexcept { return info_; }
  /// GPU memory it owns, bytes (its D32F map, once created).
  std::size_t memoryBytes() const noexcept;

private:
  CreateInfo info_;
  gl::Handle texture_, framebuffer_;
};

} // namespace crep
