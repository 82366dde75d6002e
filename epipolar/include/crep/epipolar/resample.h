// Resampling of a standard shadow map into a rectified map (Klehm et al. 2014, Sec. 4.1): the epipolar
// fallback's map, or a projective one for an unchanged shadow pass. CPU reference (double) and GL pass.
// The rule, blocker clamping, local lights: epipolar/README.md, "crep/epipolar/resample.h".
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>

#include <glm/glm.hpp>

#include <crep/core/image.h>
#include <crep/gpu/backend.h>
#include <crep/gpu/gl.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/gpu_layout_buffers.h>

namespace crep {

struct ResampleOptions {
  int threads = 0; ///< CPU worker threads: 0 = hardware concurrency (never changes the result)
};

/// Throws InvalidArgument ("lightClipFromWorld") unless the matrix is an orthographic shadow matrix
/// looking along `lightDirection` (finite, affine, invertible; tolerances: README).
void validateLightMatrix(const glm::dmat4& lightClipFromWorld, const glm::dvec3& lightDirection);

/// Throws InvalidArgument ("lightClipFromWorld") unless the matrix is a finite, invertible perspective
/// projection centred at `lightPosition` (SpotLight::lightClipFromWorld, PointLight::faceClipFromWorld).
void validateLocalLightMatrix(const glm::dmat4& lightClipFromWorld, const glm::dvec3& lightPosition);

/// The light position of a layout whose light is local (ProjectiveLayout with inverseLightDistance > 0, a
/// local EpipolarLayout), else nullopt (directional layouts, any other layout).
std::optional<glm::dvec3> localLightPosition(const RectifiedLayout& layout);

/// validateLocalLightMatrix for a local light, else validateLightMatrix along the layout's light.
void validateLayoutLightMatrix(const RectifiedLayout& layout, const glm::dmat4& lightClipFromWorld);

/// The CPU reference. Throws InvalidArgument for a null layout, bad sizes ("resampleShadowMap.size"), a
/// bad shadow map ("shadowDepth") or light matrix (validateLayoutLightMatrix). O(W H).
RectifiedMap resampleShadowMap(std::shared_ptr<const RectifiedLayout> layout, int width, int height,
                               const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                               const ResampleOptions& options = {});

/// The GL pass of the same rule (float; a NaN texel is empty). Requires a current OpenGL 4.5 context.
class ShadowResamplePass {
public:
  struct CreateInfo {
    int mapWidth = 0;  ///< W texels of the rectified maps it writes (> 0, <= the backend's maximum)
    int mapHeight = 0; ///< H texels (for an EpipolarLayout: its sliceCount())
    /// Runs the pass (must outlive it); null: a gpu::GlBackend of its own on the current GL context.
    gpu::Backend* backend = nullptr;
  };
  struct FrameAttribs {
    const RectifiedLayout* layout = nullptr; ///< ProjectiveLayout or EpipolarLayout (not stored)
    /// standard shadow map: 2D depth (or R32F) texture, any size (a GL name, or a texture id of the backend)
    std::uint32_t shadowMap = 0;
    /// the matrix it was rendered with (validateLayoutLightMatrix)
    glm::dmat4 lightClipFromWorld{1.0};
    std::uint32_t output = 0; ///< R32F mapWidth x mapHeight texture (written)
    /// 0, or a MinMaxTreePass::treeBuffer() (mapWidth > 64) whose low tree levels the pass also writes
    /// (Yusov 2012, Sec. 6.3; README).
    std::uint32_t minMaxBuffer = 0;
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "ShadowResamplePass::FrameAttribs") const;
  /// Throws InvalidArgument ("ShadowResamplePass::CreateInfo.mapWidth/mapHeight") for sizes <= 0, GlError
  /// beyond GL_MAX_TEXTURE_SIZE.
  explicit ShadowResamplePass(const CreateInfo& info);
  /// Throws InvalidArgument naming the FrameAttribs field. Per frame, O(W H).
  void run(const FrameAttribs& frame);

private:
  struct Plan;
  Plan plan(const FrameAttribs& frame, std::string_view owner) const;

  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr;
  gpu::LayoutBuffers layoutBuffers_;
  gpu::Buffer params_;
};

} // namespace crep
