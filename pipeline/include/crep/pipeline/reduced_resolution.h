// Reduced-resolution evaluation (not in Klehm et al. 2014; asked for by users of froxel fog and volumetric
// passes on low-end GPUs): the scattering is evaluated on a camera image f times smaller in each axis
// (f = 2 or 4) and brought back to full resolution with a depth-aware (joint bilateral) upsample.
//
// Rules (CPU reference here in double, GL pass DepthAwareResamplePass in float, the same arithmetic):
//   Downsample: the full-resolution depth-buffer image (W x H, multiples of f) becomes W/f x H/f; low pixel
//     (i, j) takes the minimum depth of its f x f block where i + j is even and the maximum where it is odd
//     (a checkerboard of near and far surfaces, so both sides of a depth edge keep samples). The low image's
//     pixel (i, j) is evaluated with its own view ray (the low camera image's pixel centre) at that depth.
//   Upsample: full pixel (x, y) at low coordinate u = (x + 0.5) / f - 0.5 (and v) takes the four low pixels
//     of its bilinear footprint (indices clamped to the image) with weights b_k (bilinear) / (e + r_k),
//     r_k = |Z - Z_k| / Z the relative difference of view-space depths (Camera::linearDepth; the sky, depth
//     1, is the far plane) and e = 0.01; normalized. On a constant-depth image every r_k is 0 and the result
//     is exactly the bilinear upsample.
// RGB (in-scattering) and A (transmittance) are filtered alike.
#pragma once

#include <cstdint>

#include <crep/core/camera.h>
#include <crep/core/gl.h>
#include <crep/core/image.h>

namespace crep {

/// The relative-depth floor e of the upsample weights (see top).
inline constexpr double kUpsampleDepthEpsilon = 0.01;

/// Checkerboard min/max downsample of a depth-buffer image by `factor` (see top). Throws InvalidArgument
/// ("downsampleDepth.factor": not 2 or 4; "downsampleDepth.depth": empty, or a size not a multiple of it).
Image downsampleDepth(const Image& depth, int factor);

/// Depth-aware upsample (see top) of `low` (W/f x H/f, any channel count) to fullDepth's size. `lowDepth`
/// is downsampleDepth(fullDepth, f); `camera` converts depths to view space (near, far). Throws
/// InvalidArgument naming the parameter for inconsistent sizes.
Image depthAwareUpsample(const Image& low, const Image& lowDepth, const Image& fullDepth,
                         const Camera& camera, int factor);

/// The GL pass: downsample() and upsample() as above, compute shaders, for a fixed full size and factor.
/// Requires a current OpenGL 4.5 context; never creates or owns one. Leaves program 0, texture units 0-2
/// and image unit 0 unbound, and issues the barriers its outputs need.
class DepthAwareResamplePass {
public:
  struct CreateInfo {
    int width = 0, height = 0; ///< full resolution, pixels; multiples of factor
    int factor = 2;            ///< 2 or 4
  };
  /// Throws InvalidArgument naming the field ("DepthAwareResamplePass::CreateInfo.factor", ...).
  explicit DepthAwareResamplePass(const CreateInfo& info);
  ~DepthAwareResamplePass();
  /// Moved from: valid but empty (run() throws InvalidArgument naming "DepthAwareResamplePass", memoryBytes()
  /// is 0).
  DepthAwareResamplePass(DepthAwareResamplePass&&) noexcept;
  DepthAwareResamplePass& operator=(DepthAwareResamplePass&&) noexcept;
  DepthAwareResamplePass(const DepthAwareResamplePass&) = delete;
  DepthAwareResamplePass& operator=(const DepthAwareResamplePass&) = delete;

  int lowWidth() const noexcept { return info_.width / info_.factor; }
  int lowHeight() const noexcept { return info_.height / info_.factor; }

  /// fullDepth (width x height depth texture) -> lowDepth (R32F, lowWidth x lowHeight).
  void downsample(std::uint32_t fullDepth, std::uint32_t lowDepth);
  /// low (RGBA32F, low size), lowDepth, fullDepth -> output (RGBA32F, full size); the depths are read in
  /// `camera`'s depth convention (Camera::surfaceViewDepth).
  void upsample(std::uint32_t low, std::uint32_t lowDepth, std::uint32_t fullDepth, std::uint32_t output,
                const Camera& camera);
  /// The same for GL's default depth convention with near and far planes zNear and zFar.
  void upsample(std::uint32_t low, std::uint32_t lowDepth, std::uint32_t fullDepth, std::uint32_t output,
                double zNear, double zFar);

private:
  void upsample(std::uint32_t low, std::uint32_t lowDepth, std::uint32_t fullDepth, std::uint32_t output,
                const glm::vec4& depthMap);
  CreateInfo info_;
  gl::Handle downsampleProgram_, upsampleProgram_, sampler_;
};

} // namespace crep
