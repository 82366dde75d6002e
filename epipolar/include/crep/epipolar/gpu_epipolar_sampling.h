// Yusov's epipolar sampling on the GPU (Yusov 2012, Sec. 6; Yusov 2013): the stage passes as compute
// shaders in float on a gpu::Backend, the samples to evaluate as GPU work lists
// (crep/scatter/gpu_sample_list.h). Stages, bindings, GL state left: epipolar/README.md,
// "crep/epipolar/gpu_epipolar_sampling.h". On OpenGL it needs a current 4.5 context (never owns one);
// FrameAttribs' textures are the caller's.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/epipolar/epipolar_sampling.h>
#include <crep/gpu/backend.h>
#include <crep/gpu/gl.h>
#include <crep/scatter/gpu_sample_list.h>

namespace crep {
namespace gpu {

/// std140 twin of CrepEpipolarSamplingParams (glsl/crep/epipolar_sampling.glsl, uniform binding 1).
/// Pixel coordinates, origin at the bottom-left.
struct EpipolarSamplingParams {
  /// xy: epipole e (pixels, full resolution); z: arcBegin, w: arcLength (border pixels)
  glm::vec4 epipole{0.0f};
  /// x: W, y: H (full resolution), z: perimeter P = 2 (W + H), w: 1 = epipole on screen
  glm::vec4 border{0.0f};
  glm::ivec4 counts{0}; ///< x: slices N, y: samples Ns, z: initial step S, w: downscale F
  /// xy: target size (W / F, H / F); z: 1 = depth criterion, w: 1 = scattering criterion
  glm::ivec4 target{0};
  glm::vec4 thresholds{0.0f}; ///< x: depth threshold, y: scattering threshold, z: bilateral threshold; w: 0
};
static_assert(sizeof(EpipolarSamplingParams) == 16 * 5, "std140 CrepEpipolarSamplingParams");

/// std430 element of CrepEpipolarLinesBlock { CrepEpipolarLine crep_lines[]; } (storage binding 0): one line.
struct EpipolarSamplingLine {
  glm::vec4 ends{0.0f};         ///< xy: entry, zw: exit (pixels)
  glm::ivec4 info{-1, 0, 1, 0}; ///< x: lastValid (-1: no valid sample); y: samples with the denser initial
                                ///< step (EpipolarLines::denseEnd), z: that step; w: 0
};
static_assert(sizeof(EpipolarSamplingLine) == 32, "std430 CrepEpipolarLine");

/// The block of a frame's lines and options (floats of the lines' doubles).
EpipolarSamplingParams makeEpipolarSamplingParams(const EpipolarLines& lines,
                                                  const EpipolarSamplingOptions& options);

} // namespace gpu

/// Epipolar sampling on the GPU: one object per camera image size and options.
class EpipolarSamplingPass {
public:
  struct CreateInfo {
    int width = 0, height = 0; ///< W x H camera image (multiples of options.downscale)
    EpipolarSamplingOptions options;
    /// Runs the pass (must outlive it); null: a gpu::GlBackend of its own on the current GL context.
    gpu::Backend* backend = nullptr;
    /// epipolarLines' lineOffset, in [0, 0.5]: the lines moved along the border by this fraction of their
    /// spacing (crep::Scattering: epipolarLineOffset of its map's rows, so no line lies on a row boundary).
    double lineOffset = 0.0;
  };
  /// Per-frame inputs: non-owning.
  struct FrameAttribs {
    const Camera* camera = nullptr;
    const DirectionalLight* light = nullptr;
    const Medium* medium = nullptr;
    /// GL_TEXTURE_2D W x H of depth-buffer values of `camera` (a depth format or GL_R32F)
    std::uint32_t cameraDepth = 0;
    std::uint32_t output = 0; ///< GL_RGBA32F W x H: the in-scattering (RGB) and transmittance (A)
  };
  /// Throws what placeSamples, unwarp and upscale would for `frame` (InvalidArgument naming the field).
  void validate(const FrameAttribs& frame,
                std::string_view owner = "EpipolarSamplingPass::FrameAttribs") const;
  /// Throws InvalidArgument naming the field ("EpipolarSamplingPass::CreateInfo.width", ...), GlError
  /// beyond the backend's limits (README) or ShaderError. One-time: builds five programs, O(Ns N + W H)
  /// memory.
  explicit EpipolarSamplingPass(const CreateInfo& info);
  ~EpipolarSamplingPass();
  /// Moved from: valid but empty (the stages throw InvalidArgument naming "EpipolarSamplingPass").
  EpipolarSamplingPass(EpipolarSamplingPass&& other) noexcept;
  EpipolarSamplingPass& operator=(EpipolarSamplingPass&& other) noexcept;

  // The stages of one frame in order; the caller evaluates each list between them. Per frame.
  /// Lines on the CPU (epipolarLines), uploaded; the coordinates pass. Throws InvalidArgument naming the
  /// FrameAttribs field.
  void placeSamples(const FrameAttribs& frame);
  /// The refinement pass (Yusov 2012, Sec. 6.2): sourcesTexture() and sampleList().
  void refine();
  /// coordinates = coordinatesTexture() (Ns x N), output = sampleTexture() (Ns x N).
  const gpu::SampleList& sampleList() const noexcept { return sampleList_; }
  /// Interpolates the samples that were not marched, in place in sampleTexture() (Yusov 2012, Sec. 6.5).
  void interpolate();
  /// Unwarps (Yusov 2012, Sec. 6.6) into FrameAttribs::output (F = 1) or targetTexture() (F > 1).
  void unwarp(const FrameAttribs& frame);
  /// coordinates = targetCoordinatesTexture(), output = the unwarp's target.
  const gpu::SampleList& correctionList() const noexcept { return correctionList_; }
  /// F > 1 only: bilateral upscale into FrameAttribs::output (Yusov 2012, Sec. 6.8).
  void upscale(const FrameAttribs& frame);
  /// coordinates = a W x H texture (written at the entries only), output = FrameAttribs::output.
  const gpu::SampleList& upscaleCorrectionList() const noexcept { return upscaleList_; }

  /// All stages with one evaluator, called with each list in turn.
  void run(const FrameAttribs& frame, const std::function<void(const gpu::SampleList&)>& evaluate);

  struct Statistics {
    int validSamples = 0, marchedSamples = 0, correctedPixels = 0, correctedFullPixels = 0;
  };
  /// Reads back the list counts of the last frame (a GPU sync): for tests and tools. Textures and buffers
  /// below are ids of the backend (GL names on OpenGL).
  Statistics statistics() const;
  const EpipolarLines& lines() const noexcept { return lines_; } ///< this frame's lines (CPU)
  const CreateInfo& info() const noexcept { return info_; }

  /// Ns x N RGBA32F (x, y, d, z) of every sample; (-1, -1, -1, -1) for invalid samples
  std::uint32_t coordinatesTexture() const noexcept { return coordinates_.id(); }
  /// Ns x N R32F: U, the luminance of each sample's unshadowed in-scattering (0 invalid)
  std::uint32_t unshadowedTexture() const noexcept { return unshadowed_.id(); }
  /// Ns x N RG32I: sources (left, right); (k, k) marched, (-1, -1) invalid
  std::uint32_t sourcesTexture() const noexcept { return sources_.id(); }
  /// Ns x N RGBA32F: the evaluator's values at the marched samples, then interpolated (invalid: 0)
  std::uint32_t sampleTexture() const noexcept { return samples_.id(); }
  /// (W/F) x (H/F) RGBA32F, F > 1 (0 for F = 1: the unwarp writes the output)
  std::uint32_t targetTexture() const noexcept { return target_.id(); }
  /// (W/F) x (H/F) RGBA32F (c.x, c.y, d, z) of every target pixel
  std::uint32_t targetCoordinatesTexture() const noexcept { return targetCoordinates_.id(); }
  /// W x H RGBA32F, F > 1 (0 for F = 1)
  std::uint32_t fullCoordinatesTexture() const noexcept { return fullCoordinates_.id(); }
  /// GPU memory it owns, bytes (textures, lists, line table, blocks).
  std::size_t memoryBytes() const noexcept;

private:
  void evaluatorBarrier() const;
  void dispatch(const char* stage, std::vector<gpu::Resource> resources, unsigned groupsX, unsigned groupsY);

  CreateInfo info_;
  int targetWidth_ = 0, targetHeight_ = 0;
  EpipolarLines lines_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr; ///< ownBackend_ or CreateInfo::backend
  gpu::Buffer params_, samplingParams_, lineBuffer_;
  gpu::Texture coordinates_, unshadowed_, sources_, samples_, target_, targetCoordinates_, fullCoordinates_;
  gpu::Buffer sampleBuffer_, correctionBuffer_, upscaleBuffer_;
  gpu::SampleList sampleList_, correctionList_, upscaleList_;
};

} // namespace crep
