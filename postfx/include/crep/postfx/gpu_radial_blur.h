// RadialBlurPass, Mitchell 2007's radial blur on the GPU (rule and CPU reference: radial_blur.h): a source
// pre-pass, then the blur, in float. Requires a current OpenGL 4.5 context (never owns one). Shaders, GL
// state left: postfx/README.md, "crep/postfx/gpu_radial_blur.h".
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/gpu/backend.h>
#include <crep/gpu/gl.h>
#include <crep/postfx/radial_blur.h>

namespace crep {
namespace gpu {

/// std140 twin of CrepRadialBlurParams (glsl/crep/radial_blur.glsl).
struct RadialBlurParams {
  glm::vec4 light{
      0.0f}; ///< xy the sun's screen position (texture coordinates), z fade, w exposure weight / (n+1)
  glm::vec4 shape{0.0f}; ///< x decay, y density / n, zw 0
  glm::ivec4 info{0};    ///< x samples n, y sourceScale k, zw source size (texels)
};
static_assert(sizeof(RadialBlurParams) == 48, "std140 CrepRadialBlurParams");

/// The block for `options` (validated by the caller), the sun `sun` and a w x h camera image.
RadialBlurParams makeRadialBlurParams(const RadialBlurOptions& options, const RadialLight& sun, int width,
                                      int height);

} // namespace gpu

/// Mitchell 2007's radial blur on the GPU: crep::radialBlur's rule.
class RadialBlurPass {
public:
  struct CreateInfo {
    /// The blur's knobs; `threads` is unused, `mode` is compiled in.
    RadialBlurOptions options;
    /// Invocations per workgroup: workgroupSize^2, in [1, 32]; 8 suits every GPU's SIMD width (README).
    int workgroupSize = 8;
    /// Runs the pass (must outlive it); null: a gpu::GlBackend of its own on the current GL context.
    gpu::Backend* backend = nullptr;
  };
  struct FrameAttribs {
    const Camera* camera = nullptr;
    const DirectionalLight* light = nullptr; ///< the sun (local lights are not modelled by the blur)
    const Medium* medium = nullptr;
    /// GL_TEXTURE_2D of `camera`'s depth-buffer values (a depth format or GL_R32F); the image size.
    std::uint32_t cameraDepth = 0;
    std::uint32_t output = 0; ///< GL_RGBA32F, the size of cameraDepth: RGB radial sum, A transmittance
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "RadialBlurPass::FrameAttribs") const;
  /// Throws InvalidArgument naming "RadialBlurPass::CreateInfo.options.<field>" or
  /// "RadialBlurPass::CreateInfo.workgroupSize".
  explicit RadialBlurPass(const CreateInfo& info);
  /// Throws InvalidArgument naming the FrameAttribs field; GlError when the source exceeds the GL limit.
  /// Per frame, O(pixels x samples).
  void run(const FrameAttribs& frame);

  const CreateInfo& createInfo() const noexcept { return info_; }
  /// The source texture of the last run (RGBA32F, radialSourceSize of that run's image), 0 before any.
  std::uint32_t sourceTexture() const noexcept { return source_.id(); }
  /// The sun of the last run (screen position and fade).
  const RadialLight& lastLight() const noexcept { return lastLight_; }

private:
  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr;
  gpu::Buffer marchParams_, radialParams_;
  gpu::Texture source_; ///< the occlusion pre-pass (RGBA32F, cameraDepth / sourceScale)
  int sourceWidth_ = 0, sourceHeight_ = 0;
  RadialLight lastLight_;
};

} // namespace crep
