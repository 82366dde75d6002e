// The froxel fog on the GPU (Wronski 2014, "Volumetric Fog"): the passes of froxel_fog.h's rules 1-5 and the
// front door FroxelFog, each on the gpu::Backend of its CreateInfo (default: GL on the current OpenGL 4.5
// context, never owned). Volume format, GL state left, NaN inputs: postfx/README.md, "gpu_froxel_fog.h".
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/gpu/backend.h>
#include <crep/gpu/frame_timers.h>
#include <crep/gpu/gl.h>
#include <crep/postfx/froxel_fog.h>
#include <crep/scatter/froxel_grid.h>

namespace crep {
namespace gpu {

/// std140 twin of CrepFroxelCamera (glsl/crep/froxel.glsl): gpu::GpuCamera's vectors.
struct FroxelCamera {
  glm::vec4 position{0.0f}; ///< xyz world; w near
  glm::vec4 forward{0.0f};  ///< xyz unit; w integration far
  glm::vec4 right{0.0f};    ///< xyz right * half width at unit distance
  glm::vec4 up{0.0f};       ///< xyz up * half height at unit distance
  glm::vec4 center{0.0f};   ///< xyz the image centre's offset from forward
};
static_assert(sizeof(FroxelCamera) == 80, "std140 CrepFroxelCamera");

/// std140 block CrepFroxelBlock { CrepFroxelParams crep_froxel; } of every froxel and ESM pass.
struct FroxelParams {
  FroxelCamera camera;
  FroxelCamera previous;
  glm::vec4 cameraDepth{0.0f};    ///< near, projection far (0 = infinite), far, 1 = reversed-Z
  glm::vec4 range{0.0f};          ///< x near, y far of the volume; zw the previous frame's
  glm::ivec4 grid{0};             ///< xyz cells; w 1 = history valid
  glm::vec4 jitter{0.0f};         ///< xyz sample offset (cells); w history weight
  glm::vec4 lightDirection{0.0f}; ///< xyz
  glm::vec4 lightIrradiance{0.0f};
  glm::vec4 mieScattering{0.0f}; ///< rgb; w g
  glm::vec4 rayleighScattering{0.0f};
  glm::vec4 extinction{0.0f}; ///< rgb sigma_t; w sbar
  glm::vec4 ambient{0.0f};
  glm::vec4 density{0.0f};     ///< height base, height falloff, noise amplitude, noise frequency
  glm::vec4 noiseOffset{0.0f}; ///< xyz
  glm::vec4 esm{0.0f};         ///< x exponent c (depth-buffer units), y bias, z 1 = ESM shadowing on
  glm::ivec4 sizes{0};         ///< xy shadow map (ESM passes) or camera image (apply), zw ESM
  glm::ivec4 info{0};          ///< x downsample, y blur radius
  glm::mat4 lightClipFromWorld{1.0f};
};
static_assert(sizeof(FroxelParams) == 2 * 80 + 15 * 16 + 64, "std140 CrepFroxelParams");

/// The camera members of FroxelParams (gpuCamera's vectors).
FroxelCamera froxelCamera(const Camera& camera);

} // namespace gpu

/// Throws InvalidArgument naming `owner`.format unless `format` is GL_RGBA16F or GL_RGBA32F.
void validateFroxelFormat(std::uint32_t format, const char* owner);
/// A GL_TEXTURE_3D of the grid's size in `format` (InvalidArgument naming `owner`.grid.width / ...).
gl::Handle createFroxelVolume(const FroxelGrid& grid, std::uint32_t format, const char* owner);
/// The same as a 3D texture of `backend`.
gpu::Texture createFroxelVolume(gpu::Backend& backend, const FroxelGrid& grid, std::uint32_t format,
                                const char* owner);

/// Rule 1 on the GPU: the ESM of a standard shadow map. Owns two R32F textures. Per frame, O(map texels).
class EsmPass {
public:
  struct CreateInfo {
    EsmOptions options;
    gpu::Backend* backend = nullptr; ///< runs the pass (outlives it); null: a GL backend of its own
  };
  struct FrameAttribs {
    /// GL_TEXTURE_2D of depth-buffer values in [0, 1] (a depth format or GL_R32F), read with texelFetch
    std::uint32_t shadowMap = 0;
    glm::dmat4 lightClipFromWorld{1.0}; ///< its matrix (turns the exponent into depth units)
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "EsmPass::FrameAttribs") const;
  /// Throws InvalidArgument naming "EsmPass::CreateInfo.options.<field>".
  explicit EsmPass(const CreateInfo& info);
  void run(const FrameAttribs& frame);
  /// R32F, ceil(W / f) x ceil(H / f): log-space depths (rule 1)
  std::uint32_t esm() const noexcept { return esm_.id(); }
  int width() const noexcept { return width_; }
  int height() const noexcept { return height_; }
  std::size_t memoryBytes() const noexcept; ///< both R32F textures

private:
  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr;
  gpu::Buffer params_;
  gpu::Texture esm_, scratch_;
  int width_ = 0, height_ = 0;
};

/// Rule 2 on the GPU: the lighting volume.
class FroxelLightingPass {
public:
  struct CreateInfo {
    FroxelGrid grid;
    FroxelDensity density;
    glm::dvec3 ambient{0.0};
    EsmOptions esm;                  ///< exponent and bias of the test (the ESM's own build is EsmPass's)
    std::uint32_t format = 0x881A;   ///< GL_RGBA16F or GL_RGBA32F (0x8814)
    gpu::Backend* backend = nullptr; ///< runs the pass (outlives it); null: a GL backend of its own
  };
  struct FrameAttribs {
    const Camera* camera = nullptr;
    const DirectionalLight* light = nullptr;
    const Medium* medium = nullptr;
    std::uint32_t esm = 0; ///< EsmPass::esm(), or 0: every point lit
    glm::dmat4 lightClipFromWorld{1.0};
    glm::dvec3 jitter{0.0}; ///< cells, each in [-0.5, 0.5]
    glm::dvec3 noiseOffset{0.0};
    std::uint32_t output = 0; ///< GL_TEXTURE_3D, grid size, CreateInfo::format
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "FroxelLightingPass::FrameAttribs") const;
  explicit FroxelLightingPass(const CreateInfo& info);
  void run(const FrameAttribs& frame);

private:
  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr;
  gpu::Buffer params_;
  gpu::Texture unlit_; ///< a 1-texel stand-in bound when no ESM is given (never read)
};

/// Rule 3 on the GPU: the lighting volume integrated front to back, in place.
class FroxelAccumulatePass {
public:
  struct CreateInfo {
    FroxelGrid grid;
    std::uint32_t format = 0x881A;   ///< GL_RGBA16F or GL_RGBA32F
    gpu::Backend* backend = nullptr; ///< runs the pass (outlives it); null: a GL backend of its own
  };
  struct FrameAttribs {
    const Camera* camera = nullptr;
    const Medium* medium = nullptr; ///< its extinction ratios sigma_c / sbar
    glm::dvec3 jitter{0.0};         ///< the jitter the volume was lit with
    std::uint32_t volume = 0;       ///< GL_TEXTURE_3D, grid size, CreateInfo::format: read and written
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame,
                std::string_view owner = "FroxelAccumulatePass::FrameAttribs") const;
  explicit FroxelAccumulatePass(const CreateInfo& info);
  void run(const FrameAttribs& frame);

private:
  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr;
  gpu::Buffer params_;
};

/// Rule 5 on the GPU: the history reprojected, clamped and blended with the current volume.
class FroxelTemporalPass {
public:
  struct CreateInfo {
    FroxelGrid grid;
    std::uint32_t format = 0x881A;   ///< of the output (GL_RGBA16F or GL_RGBA32F)
    gpu::Backend* backend = nullptr; ///< runs the pass (outlives it); null: a GL backend of its own
  };
  struct FrameAttribs {
    const Camera* camera = nullptr;
    /// The camera of `history`; nullptr = no history (first frame, camera cut): the current volume with its
    /// non-finite values replaced.
    const Camera* previousCamera = nullptr;
    double historyWeight = 0.9; ///< in [0, 1)
    std::uint32_t current = 0;  ///< integrated GL_TEXTURE_3D, grid size
    std::uint32_t history = 0;  ///< last frame's output (grid size), or 0 with previousCamera nullptr
    std::uint32_t output = 0;   ///< GL_TEXTURE_3D, grid size, CreateInfo::format; not current or history
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "FroxelTemporalPass::FrameAttribs") const;
  explicit FroxelTemporalPass(const CreateInfo& info);
  void run(const FrameAttribs& frame);

private:
  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr;
  gpu::Buffer params_;
};

/// Rule 4 on the GPU: one trilinear fetch per pixel.
class FroxelApplyPass {
public:
  struct CreateInfo {
    FroxelGrid grid;
    gpu::Backend* backend = nullptr; ///< runs the pass (outlives it); null: a GL backend of its own
  };
  struct FrameAttribs {
    const Camera* camera = nullptr;
    std::uint32_t cameraDepth = 0; ///< GL_TEXTURE_2D of depth-buffer values; the image size is its size
    std::uint32_t volume = 0;      ///< integrated GL_TEXTURE_3D, grid size
    glm::dvec3 offset{0.0};        ///< the volume's sample offset (its jitter; 0 after the temporal pass)
    std::uint32_t output = 0;      ///< GL_RGBA32F, cameraDepth's size
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "FroxelApplyPass::FrameAttribs") const;
  explicit FroxelApplyPass(const CreateInfo& info);
  void run(const FrameAttribs& frame);

private:
  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr;
  gpu::Buffer params_;
};

/// The froxel fog of one view (Wronski 2014), one run() per frame: Esm mode (ESM, lighting, accumulation)
/// or Prefiltered mode (filled by crep::Scattering, Klehm et al. 2014); then temporal and apply (README).
/// Memory: 1 volume, 3 with temporal (8 or 16 bytes per cell), plus the ESM. Per frame, O(cells + pixels).
class FroxelFog {
public:
  enum class Mode { Esm, Prefiltered };
  struct TemporalOptions {
    /// Weight of the reprojected history in [0, 1); 0 = off (no jitter, no history volumes).
    double historyWeight = 0.9;
    /// Jitter the sample points by froxelJitter(frameIndex) when historyWeight > 0.
    bool jitter = true;
  };
  struct CreateInfo {
    FroxelGrid grid;
    EsmOptions esm;
    FroxelDensity density;
    glm::dvec3 ambient{0.0}; ///< isotropic ambient radiance per channel, >= 0 (default 0)
    TemporalOptions temporal;
    std::uint32_t format = 0x881A; ///< GL_RGBA16F (default) or GL_RGBA32F
    /// Per-stage GPU times by the backend's timer (GL_TIME_ELAPSED, Vulkan timestamps): timings().
    bool timings = false;
    /// With timings, wait for each stage's GPU time: a finish and a read per stage, which stall the
    /// pipeline; for tools (timings() the last run's). false: run() never waits for the GPU; timings() holds
    /// an earlier run's once its times have arrived.
    bool blockingTimings = false;
    gpu::Backend* backend = nullptr; ///< runs every pass (outlives it); null: a GL backend of its own
  };
  struct FrameAttribs {
    Mode mode = Mode::Esm;
    const Camera* camera = nullptr;
    const DirectionalLight* light = nullptr; ///< Esm mode
    const Medium* medium = nullptr;          ///< Esm mode
    std::uint32_t cameraDepth = 0;           ///< GL_TEXTURE_2D depth-buffer values (needed with output)
    std::uint32_t shadowMap = 0;             ///< Esm mode: the standard shadow map, or 0 = unshadowed
    glm::dmat4 lightClipFromWorld{1.0};      ///< its matrix
    std::uint32_t output = 0;                ///< GL_RGBA32F, cameraDepth's size, or 0 (volume only)
    int frameIndex = 0;                      ///< selects the jitter froxelJitter(frameIndex)
    /// Last frame's camera (reprojection); nullptr = no history this frame (first frame, camera cut).
    const Camera* previousCamera = nullptr;
    glm::dvec3 noiseOffset{0.0}; ///< Esm mode, world units (wind)
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "FroxelFog::FrameAttribs") const;
  /// Throws InvalidArgument naming "FroxelFog::CreateInfo.<field>" (grid, esm, density, ambient,
  /// temporal.historyWeight, format; a grid beyond GL_MAX_3D_TEXTURE_SIZE).
  explicit FroxelFog(const CreateInfo& info);
  /// Throws InvalidArgument naming "FroxelFog::FrameAttribs.<field>".
  void run(const FrameAttribs& frame);

  /// The integrated volume's sample offset of frame `frameIndex` in cells (for Mode::Prefiltered's fill):
  /// froxelJitter(frameIndex) across the image, 0 in depth; 0 without temporal jitter.
  glm::dvec3 jitter(int frameIndex) const;
  /// Where Mode::Esm lights each cell: froxelJitter(frameIndex) in all three axes, or 0 (README).
  glm::dvec3 lightingJitter(int frameIndex) const;
  /// The volume the lighting and accumulation (or crep::Scattering's fill) write: GL_TEXTURE_3D.
  std::uint32_t currentVolume() const noexcept { return current_.id(); }
  /// The integrated volume of the last run() (blended with temporal), sample offset 0, for the engine.
  std::uint32_t volume() const noexcept { return volume_; }
  std::size_t memoryBytes() const noexcept;
  /// GPU milliseconds of one run's stages (0 for stages not run, or where the backend measures none).
  struct Timings {
    std::uint64_t run = 0; ///< the run they belong to: the run() calls before it
    double esm = 0.0, lighting = 0.0, accumulate = 0.0, temporal = 0.0, apply = 0.0;
  };
  /// CreateInfo::timings: with blockingTimings the last run's; without, those of the latest earlier run
  /// whose times have all arrived (never waited for; kept until a later run's arrive), std::nullopt until
  /// one has. std::nullopt without timings.
  const std::optional<Timings>& timings() const noexcept { return timings_; }
  /// run() calls so far (those that threw included): the next run's Timings::run.
  std::uint64_t runCount() const noexcept { return runs_; }

private:
  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr;
  EsmPass esm_;
  FroxelLightingPass lighting_;
  FroxelAccumulatePass accumulate_;
  FroxelTemporalPass temporal_;
  FroxelApplyPass apply_;
  gpu::Texture current_;
  std::array<gpu::Texture, 2> history_;
  int latest_ = -1; ///< index of history_ written last, -1 = none
  std::uint32_t volume_ = 0;
  std::optional<Timings> timings_;
  std::uint64_t runs_ = 0;
  gpu::FrameTimers timers_; ///< timings without blockingTimings: the runs waiting for their GPU times
  /// Without blockingTimings: this run's spans (esm, lighting, accumulate, temporal, apply; 0 = not run)
  /// wait, and the latest earlier run whose times have all arrived becomes timings().
  void reportTimes(std::uint64_t run, const std::array<gpu::TimerId, 5>& spans);
};

} // namespace crep
