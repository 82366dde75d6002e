// Reduced-resolution evaluation (not in Klehm et al. 2014): a checkerboard min/max depth downsample by f = 2
// or 4 and a depth-aware (joint bilateral) upsample; CPU reference in double, DepthAwareResamplePass in
// float, the same arithmetic. The rules: pipeline/README.md, "reduced_resolution.h".
#pragma once

#include <cstdint>

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/gpu/backend.h>
#include <crep/gpu/gl.h>

#include <memory>

namespace crep {

/// The relative-depth floor e of the upsample weights b_k / (e + r_k).
inline constexpr double kUpsampleDepthEpsilon = 0.01;

/// Checkerboard min/max downsample of a depth-buffer image by `factor` (2 or 4). Throws InvalidArgument
/// ("downsampleDepth.factor"; "downsampleDepth.depth": empty, or a size not a multiple of the factor).
Image downsampleDepth(const Image& depth, int factor);

/// Depth-aware upsample of `low` (W/f x H/f, any channels) to fullDepth's size; lowDepth = downsampleDepth(
/// fullDepth, f), `camera` gives view depths. Throws InvalidArgument naming the parameter for bad sizes.
Image depthAwareUpsample(const Image& low, const Image& lowDepth, const Image& fullDepth,
                         const Camera& camera, int factor);

/// The GPU pass (fixed full size and factor) on a gpu::Backend. On OpenGL it needs a current 4.5 context and
/// never owns one; it leaves program 0, texture units 0-2 and image unit 0 unbound.
class DepthAwareResamplePass {
public:
  struct CreateInfo {
    int width = 0, height = 0; ///< full resolution, pixels; multiples of factor
    int factor = 2;            ///< 2 or 4
    /// Runs the pass (must outlive it); null: a gpu::GlBackend of its own on the current GL context.
    gpu::Backend* backend = nullptr;
  };
  /// Throws InvalidArgument naming the field ("DepthAwareResamplePass::CreateInfo.factor", ...).
  explicit DepthAwareResamplePass(const CreateInfo& info);
  ~DepthAwareResamplePass();
  /// Moved from: valid but empty (downsample() and upsample() throw InvalidArgument naming the pass).
  DepthAwareResamplePass(DepthAwareResamplePass&&) noexcept;
  DepthAwareResamplePass& operator=(DepthAwareResamplePass&&) noexcept;
  DepthAwareResamplePass(const DepthAwareResamplePass&) = delete;
  DepthAwareResamplePass& operator=(const DepthAwareResamplePass&) = delete;

  int lowWidth() const noexcept { return info_.width / info_.factor; }
  int lowHeight() const noexcept { return info_.height / info_.factor; }

  /// fullDepth (width x height depth texture, or R32F) -> lowDepth (R32F, lowWidth x lowHeight). Per frame,
  /// O(pixels). Textures are ids of the backend (GL names on OpenGL).
  void downsample(std::uint32_t fullDepth, std::uint32_t lowDepth);
  /// low (RGBA32F), lowDepth, fullDepth -> output (RGBA32F, full size); depths in `camera`'s convention.
  void upsample(std::uint32_t low, std::uint32_t lowDepth, std::uint32_t fullDepth, std::uint32_t output,
                const Camera& camera);
  /// The same for GL's default depth convention with near and far planes zNear and zFar.
  void upsample(std::uint32_t low, std::uint32_t lowDepth, std::uint32_t fullDepth, std::uint32_t output,
                double zNear, double zFar);

private:
  void upsample(std::uint32_t low, std::uint32_t lowDepth, std::uint32_t fullDepth, std::uint32_t output,
                const glm::vec4& depthMap);
  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr; ///< null when moved from
};

} // namespace crep
