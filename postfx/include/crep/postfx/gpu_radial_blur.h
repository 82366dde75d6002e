// The GL pass of Mitchell 2007's radial blur (GPU Gems 3 ch. 13; the rule and its CPU reference are in
// crep/postfx/radial_blur.h). Two compute shaders per frame: the occlusion pre-pass
// (glsl/passes/radial_source.comp) into a source texture the pass owns (RGBA32F, radialSourceSize of the
// camera image and options.sourceScale), then the blur (glsl/passes/radial_blur.comp) into the caller's
// output. Float precision; the source is read with the hardware bilinear filter.
//
// The pass requires a current OpenGL 4.5 context and never creates or owns one. It owns its programs,
// buffers, sampler and source texture (RAII); the textures of FrameAttribs are the caller's (non-owning GL
// names). It leaves program 0, texture units 0-1 with no texture and no sampler, image unit 0 and uniform
// buffer bindings 0-1 unbound (gl::unbindPassState(2)), and issues gl::passOutputBarrier(). A NaN camera
// depth is treated as the sky (checking would cost a readback; the CPU reference rejects it).
#pragma once

#include <cstdint>
#include <string_view>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/gl.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/postfx/radial_blur.h>

namespace crep {
namespace gpu {

/// std140 block CrepRadialBlurBlock { CrepRadialBlurParams crep_radial; } (glsl/crep/radial_blur.glsl).
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
    /// The blur's knobs (crep/postfx/radial_blur.h); `threads` is not used by the pass; `mode` is compiled
    /// in (OcclusionFraction: the CREP_RADIAL_FRACTION variant of the blur shader).
    RadialBlurOptions options;
    /// Both shaders run workgroupSize x workgroupSize invocations per workgroup, in [1, 32]. 8 (64
    /// invocations) is a multiple of every GPU's SIMD width (32 / 64); neighbouring pixels' samples read
    /// neighbouring source texels, which the texture cache shares within a group.
    int workgroupSize = 8;
  };
  struct FrameAttribs {
    const Camera* camera = nullptr;
    const DirectionalLight* light = nullptr; ///< the sun (local lights are not modelled by the blur)
    const Medium* medium = nullptr;
    /// GL_TEXTURE_2D of depth-buffer values of `camera` (its convention): GL_DEPTH_COMPONENT16/24/32/32F,
    /// GL_DEPTH24_STENCIL8, GL_DEPTH32F_STENCIL8 (read as depth) or GL_R32F; the image size is its size.
    std::uint32_t cameraDepth = 0;
    std::uint32_t output = 0; ///< GL_RGBA32F, the size of cameraDepth: RGB radial sum, A transmittance
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "RadialBlurPass::FrameAttribs") const;
  /// Throws InvalidArgument naming "RadialBlurPass::CreateInfo.options.<field>" or
  /// "RadialBlurPass::CreateInfo.workgroupSize".
  explicit RadialBlurPass(const CreateInfo& info);
  /// Throws InvalidArgument naming the FrameAttribs field (null pointers, missing textures, wrong formats
  /// or sizes); GlError when the source would exceed GL_MAX_TEXTURE_SIZE.
  void run(const FrameAttribs& frame);

  const CreateInfo& createInfo() const noexcept { return info_; }
  /// The source texture of the last run (RGBA32F, radialSourceSize of that run's image), 0 before any.
  std::uint32_t sourceTexture() const noexcept { return source_.get(); }
  /// The sun of the last run (screen position and fade).
  const RadialLight& lastLight() const noexcept { return lastLight_; }

private:
  CreateInfo info_;
  gl::Handle sourceProgram_, blurProgram_, marchParams_, radialParams_, nearest_, linear_, source_;
  int sourceWidth_ = 0, sourceHeight_ = 0;
  RadialLight lastLight_;
};

} // namespace crep
