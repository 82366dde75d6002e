// Resampling of a standard shadow map into a rectified map (Klehm et al. 2014, Sec. 4.1): the epipolar
// fallback's map, and, with the same code, a projective rectified map for engines that cannot change
// their shadow pass (directional light: an orthographic map; spot light or point-light face: the light's
// perspective map). CPU reference (double) and GL compute pass.
//
// Rule, for texel (i, j) of a W x H map of `layout` (column (i + 0.5) / W, row (j + 0.5) / H):
//   ray = layout.lightRay(column, row); the projected point p = ray.origin for a directional light (every
//   point of the ray projects alike: the matrix must be an orthographic projection along the light
//   direction), p = ray.origin + ray.direction / rho for a local light (ray.origin is the light position,
//   the matrix's centre of projection; rho = 1 / |camera - light|, so p lies on the ray in front of the
//   light, at the camera's distance from it); (x, y) = NDC of p under lightClipFromWorld (a local light
//   also needs clip w > 0 there, else the ray is behind the map);
//   outside [-1, 1]^2 -> 1 (no information: nothing casts); else d = shadowDepth(floor(u Ws), floor(v Hs))
//   (nearest texel, "point-resampled"), u = (x + 1) / 2, v = (y + 1) / 2;
//   d >= 1 -> 1 (nothing on that light ray); else the occluder p = lightClipFromWorld^-1 (x, y, 2 d - 1, 1)
//   (on the ray: the inverse maps NDC (x, y) to the ray through the centre of projection),
//   stored depth = clamp(layout.toRectified(p).depth, 0, 1).
// A layout's light is local when it is a ProjectiveLayout of rectify(camera, SpotLight) or a face of
// rectifyPointLight (RectifiedFrame::inverseLightDistance > 0, its lightPosition the light's), or an
// EpipolarLayout built for a light position (EpipolarLayout::localLight(), 1 / rho = lightDistance()); the
// other epipolar layouts and rectify(camera, DirectionalLight) are directional.
// Blocker clamping (Sec. 4.1): an occluder between the light and the camera frustum has a depth < 0 in the
// slice's bounds and is clamped to 0, so it still shadows every view ray of the texel (like GL_DEPTH_CLAMP
// for the projective matrices); one behind the frustum clamps to 1 (lit).
// For an EpipolarLayout the map height must be its sliceCount(); the width W a multiple of regionCount().
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>

#include <glm/glm.hpp>

#include <crep/core/gl.h>
#include <crep/core/image.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/gpu_layout_buffers.h>

namespace crep {

struct ResampleOptions {
  int threads = 0; ///< CPU worker threads: 0 = hardware concurrency (never changes the result)
};

/// Throws InvalidArgument ("lightClipFromWorld") unless the matrix is finite, affine (last row 0 0 0 w),
/// invertible, and maps the light direction to a pure depth increase (clip (0, 0, > 0), up to 1e-3 of the
/// matrix scale so that matrices stored in float pass): an orthographic shadow matrix looking along it.
void validateLightMatrix(const glm::dmat4& lightClipFromWorld, const glm::dvec3& lightDirection);

/// Throws InvalidArgument ("lightClipFromWorld") unless the matrix is finite, invertible and a perspective
/// projection whose centre is lightPosition: clip x, y and w of (lightPosition, 1) are 0 up to 1e-4 of the
/// magnitude of the terms they sum (|row.xyz| |lightPosition| + |row.w| for each of those rows), so that
/// matrices stored in float (rounding ~1e-7 of it) pass and a centre more than about 2e-4 |lightPosition|
/// away from the light does not. A spot light's or point-light face's shadow matrix
/// (SpotLight::lightClipFromWorld, PointLight::faceClipFromWorld, an engine's cube-map face matrices).
void validateLocalLightMatrix(const glm::dmat4& lightClipFromWorld, const glm::dvec3& lightPosition);

/// The light position of a layout whose light is local (ProjectiveLayout with inverseLightDistance > 0, a
/// local EpipolarLayout), else nullopt (directional layouts, any other layout).
std::optional<glm::dvec3> localLightPosition(const RectifiedLayout& layout);

/// The check resampleShadowMap and ShadowResamplePass apply to a matrix for `layout`'s light:
/// validateLocalLightMatrix for a local light, else validateLightMatrix along the layout's light direction.
void validateLayoutLightMatrix(const RectifiedLayout& layout, const glm::dmat4& lightClipFromWorld);

/// The CPU reference (rule at the top). Throws InvalidArgument for a null layout, sizes <= 0 or a width
/// that is not a multiple of regionCount() ("resampleShadowMap.size"), an EpipolarLayout whose sliceCount()
/// differs from the height, an empty / multi-channel shadow map or a NaN texel ("shadowDepth"), a bad
/// light matrix (validateLayoutLightMatrix: orthographic along the layout's light direction for a
/// directional light, perspective centred at the light for a local one).
RectifiedMap resampleShadowMap(std::shared_ptr<const RectifiedLayout> layout, int width, int height,
                               const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                               const ResampleOptions& options = {});

/// The GL compute pass of the same rule (float precision; a NaN shadow-map texel counts as empty). Owns
/// its program, buffers and sampler; the textures are the caller's. GL state left as in gpu_march.h.
class ShadowResamplePass {
public:
  struct CreateInfo {
    int mapWidth = 0;  ///< W texels of the rectified maps it writes (> 0, <= GL_MAX_TEXTURE_SIZE)
    int mapHeight = 0; ///< H texels (for an EpipolarLayout: its sliceCount())
  };
  struct FrameAttribs {
    const RectifiedLayout* layout = nullptr; ///< ProjectiveLayout or EpipolarLayout (not stored)
    /// standard shadow map: GL_TEXTURE_2D depth (or GL_R32F) texture, any size (read from the texture)
    std::uint32_t shadowMap = 0;
    /// the matrix it was rendered with (validateLayoutLightMatrix: orthographic for a directional light,
    /// perspective centred at the light for a spot light or point-light face)
    glm::dmat4 lightClipFromWorld{1.0};
    std::uint32_t output = 0; ///< GL_R32F mapWidth x mapHeight texture (written)
    /// 0, or the MinMaxTreePass::treeBuffer() of a mapWidth x mapHeight map (mapWidth > 64): the pass also
    /// writes levels 1..MinMaxTreePass::lowLevels(mapWidth) of the output's 1D min/max trees (Yusov 2012,
    /// Sec. 6.3) from the texels it resamples, one work group per row, and issues the storage barrier;
    /// MinMaxTreePass::completeUpperLevels() then builds the rest (the nodes of MinMaxTreePass::run()).
    /// The map is read once instead of twice: for crep::Scattering's tree-marched epipole block.
    std::uint32_t minMaxBuffer = 0;
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "ShadowResamplePass::FrameAttribs") const;
  /// Throws InvalidArgument ("ShadowResamplePass::CreateInfo.mapWidth/mapHeight") for sizes <= 0, GlError
  /// beyond GL_MAX_TEXTURE_SIZE.
  explicit ShadowResamplePass(const CreateInfo& info);
  /// Throws InvalidArgument naming the FrameAttribs field.
  void run(const FrameAttribs& frame);

private:
  struct Plan;
  Plan plan(const FrameAttribs& frame, std::string_view owner) const;

  CreateInfo info_;
  gpu::LayoutBuffers layoutBuffers_;
  gl::Handle programs_[2][2], params_, sampler_; ///< [layout kind][with the trees' low levels]
};

} // namespace crep
