// ToneMapPass: auto exposure from a GPU log-average reduction, light adaptation kept on the GPU, and the
// operators of tone_mapping.h (its CPU reference), in float. Requires a current OpenGL 4.5 context (never
// owns one). Stages, GL state left: postfx/README.md, "crep/postfx/gpu_tone_mapping.h".
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>

#include <glm/glm.hpp>

#include <crep/gpu/backend.h>
#include <crep/gpu/gl.h>
#include <crep/gpu/shader_library.h>
#include <crep/postfx/tone_mapping.h>

namespace crep {
namespace gpu {

/// std140 twin of CrepToneMapParams (glsl/crep/tone_mapping.glsl).
struct ToneMapParams {
  glm::vec4 curve{0.0f};      ///< x middleGrey, y whitePoint, z saturation, w manual exposure
  glm::vec4 adaptation{0.0f}; ///< x 1 - exp(-dt / tau) (double on the CPU, then float); yzw 0
  glm::ivec4 flags{0};        ///< x 1 = auto exposure, y 1 = reset adaptation, z partial sums; w 0
  glm::ivec4 sizes{0};        ///< xy input size (pixels), zw workgroups of the reduction
};
static_assert(sizeof(ToneMapParams) == 64, "std140 CrepToneMapParams");

/// std430 element of the reduction's storage buffer (CrepLuminancePartial): one 64 x 64 block.
struct LuminancePartial {
  float logSum = 0.0f;     ///< sum of log(kLogAverageDelta + Y) over its finite pixels
  std::uint32_t count = 0; ///< its finite pixels
};
static_assert(sizeof(LuminancePartial) == 8, "std430 CrepLuminancePartial");

/// std430 twin of CrepToneMapState: ToneMapPass::stateBuffer(), bindable by an engine's shaders.
struct ToneMapState {
  float adaptedLuminance = 0.0f; ///< La, the luminance the exposure follows
  float targetLuminance = 0.0f;  ///< the last frame's log-average (La when it had no finite pixel)
  float exposureScale = 0.0f;    ///< middleGrey / La
  std::int32_t valid = 0;        ///< 0 until a frame with a finite pixel was reduced (then 1)
};
static_assert(sizeof(ToneMapState) == 16, "std430 CrepToneMapState");

} // namespace gpu

/// Tone mapping with auto exposure and light adaptation on the GPU.
class ToneMapPass {
public:
  /// Edge of the input block one reduction workgroup sums (16 x 16 invocations x 4 x 4 pixels).
  static constexpr int kReductionTile = 64;

  struct CreateInfo {
    /// Operator and knobs (validated: InvalidArgument naming "ToneMapPass::CreateInfo.options.<field>").
    ToneMapOptions options;
    /// Write values encoded by crep_srgbEncode (IEC 61966-2-1) instead of linear.
    bool encodeSrgb = false;
    /// Runs the pass (must outlive it); null: a gpu::GlBackend of its own on the current GL context.
    gpu::Backend* backend = nullptr;
  };
  struct FrameAttribs {
    /// GL_TEXTURE_2D, GL_RGBA32F or GL_RGBA16F: linear HDR RGB (A ignored); its size is the frame's.
    std::uint32_t input = 0;
    /// GL_TEXTURE_2D, GL_RGBA8 or GL_RGBA32F, the input's size, not the input: display RGB, A = 1.
    std::uint32_t output = 0;
    /// Seconds since the previous frame (finite, >= 0): the adaptation step.
    double dt = 0.0;
    /// Forget the adaptation state: jump to this frame's log-average (e.g. a camera cut).
    bool resetAdaptation = false;
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "ToneMapPass::FrameAttribs") const;

  explicit ToneMapPass(const CreateInfo& info);
  /// Tone-maps one frame. Throws InvalidArgument naming the FrameAttribs field. Per frame, O(pixels).
  void run(const FrameAttribs& frame);

  /// Changes the knobs between frames (InvalidArgument naming "ToneMapPass::options"); state kept.
  void setOptions(const ToneMapOptions& options);
  const ToneMapOptions& options() const { return info_.options; }

  /// The storage buffer holding gpu::ToneMapState (owned by the pass; a GL name on the GL backend).
  std::uint32_t stateBuffer() const { return state_.id(); }
  /// Reads the state back (a pipeline stall; for tests and debugging).
  gpu::ToneMapState readState() const;

private:
  ShaderStageSource toneMapStage(bool rgba8) const;

  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr;
  gpu::Buffer params_, partials_,
      state_; ///< the block, the per-tile luminance partials, the adaptation state
};

} // namespace crep
