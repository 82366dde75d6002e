// WorldMarchPass, the GL pass of the world-space reference march (world_march.h), and gpu::MarchParams, the
// std140 block of every march and resampling pass (twin: glsl/crep/march.glsl). Requires a current
// OpenGL 4.5 context. GL state left, NaN inputs: scatter/README.md, "crep/scatter/gpu_world_march.h".
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/gpu/gl.h>
#include <crep/scatter/gpu_light_texture.h>
#include <crep/scatter/ray_scattering.h>
#include <crep/scatter/world_march.h>

namespace crep {
namespace gpu {

/// std140 twin of CrepMarchParams (glsl/crep/march.glsl).
struct MarchParams {
  glm::vec4 cameraPosition{0.0f};                    ///< xyz: world; w: near plane distance
  glm::vec4 cameraForward{0.0f, 0.0f, -1.0f, 0.0f};  ///< xyz: unit view direction; w: far plane distance
  glm::vec4 cameraRight{1.0f, 0.0f, 0.0f, 0.0f};     ///< xyz: right * tan(fovY / 2) * aspect; w: 0
  glm::vec4 cameraUp{0.0f, 1.0f, 0.0f, 0.0f};        ///< xyz: up * tan(fovY / 2); w: 0
  glm::vec4 lightDirection{0.0f, -1.0f, 0.0f, 0.0f}; ///< xyz: direction the light travels; w: 0
  glm::vec4 lightIrradiance{0.0f};                   ///< rgb: irradiance; w: 0
  glm::vec4 mieScattering{0.0f};      ///< rgb: sigma_s of the Henyey-Greenstein part (1/world unit); w: g
  glm::vec4 rayleighScattering{0.0f}; ///< rgb: sigma_s of the Rayleigh part; w: 0
  glm::vec4 extinction{0.0f};         ///< rgb: sigma_t; w: grey extinction (weightExtinction)
  /// march: xy camera image (pixels), zw rectified map (texels); world march: zw standard shadow map;
  /// resampling: xy standard shadow map, zw rectified map
  glm::ivec4 sizes{0};
  glm::ivec4 info{0};   ///< march: x tree levels L, y tree row stride; world march: x steps N, y refinements
  glm::vec4 bias{0.0f}; ///< world march: x shadow bias (depth-buffer units)
  glm::vec4 block{0.0f, 0.0f, -1.0f,
                  0.0f}; ///< world and rectified marches: xy centre, z radius (pixels; < 0: all)
  glm::ivec4 region{
      0}; ///< world and rectified marches: first pixel of the dispatch, its size (makeMarchParams: the image)
  glm::mat4 lightClipFromWorld{1.0f}; ///< world march / resampling: the standard shadow map's matrix
  glm::vec4 cameraCenter{0.0f};       ///< xyz: the image centre's offset from forward (off-centre); w: 0
  /// The camera's depth convention: x near, y projection far (0 = infinite), z integration far, w 1 =
  /// reversed
  glm::vec4 cameraDepth{0.0f};
  // The world march's local light (appended; zeros = a directional light).
  glm::vec4 lightPosition{0.0f};  ///< xyz: world; w: 1 = local light (spot or point face), 0 = directional
  glm::vec4 lightAxis{0.0f};      ///< xyz: unit spot axis or point-face axis; w: point face index, or -1
  glm::vec4 lightCone{0.0f};      ///< x cosInner, y cosOuter, z near plane, w 1 = the spot falloff applies
  glm::vec4 lightIntensity{0.0f}; ///< rgb: radiant intensity (on the axis for a spot); w: 0
};
static_assert(sizeof(MarchParams) == 16 * 24, "std140 CrepMarchParams");

/// The camera vectors of the GPU blocks (MarchParams, gpu::EvaluateParams): a pixel at NDC (x, y) looks
/// along forward + center + x right + y up (README).
struct GpuCamera {
  glm::vec4 position;  ///< xyz; w near
  glm::vec4 forward;   ///< xyz unit; w integration far
  glm::vec4 right, up; ///< xyz; w 0
  glm::vec4 center;    ///< xyz; w 0
  glm::vec4 depth;     ///< near, projection far (0 = infinite), integration far, reversed (1 / 0)
};
GpuCamera gpuCamera(const Camera& camera);
/// Sets the camera members of a GPU block (MarchParams, gpu::EvaluateParams) from gpuCamera(camera).
template <class Block>
void assignCamera(Block& block, const Camera& camera) {
  const GpuCamera c = gpuCamera(camera);
  block.cameraPosition = c.position;
  block.cameraForward = c.forward;
  block.cameraRight = c.right;
  block.cameraUp = c.up;
  block.cameraCenter = c.center;
  block.cameraDepth = c.depth;
}

/// The camera, light and medium part of MarchParams for a w x h camera image and a W x H map.
MarchParams makeMarchParams(const Camera& camera, const DirectionalLight& light, const Medium& medium,
                            int width, int height, int mapWidth, int mapHeight);
/// The same for a local light (lightPosition, lightAxis, lightCone, lightIntensity; the directional
/// members stay zero).
MarchParams makeMarchParams(const Camera& camera, const LocalLight& light, const Medium& medium, int width,
                            int height, int mapWidth, int mapHeight);

/// Binds the resources of every march pass's shader (uniform 0, texture units 0-1, image units 0-1;
/// README); the caller binds its own extra blocks after this.
void bindMarchResources(std::uint32_t program, std::uint32_t params, std::uint32_t cameraDepth,
                        std::uint32_t map, std::uint32_t sampler, std::uint32_t scattering,
                        std::uint32_t steps);
/// The dispatch rectangle: the image, or the disc of blockRadius >= 0 pixels around blockCenter; false
/// when it misses the image. InvalidArgument naming `owner` + ".blockCenter/blockRadius" if non-finite.
bool setMarchRegion(MarchParams& params, int width, int height, const glm::dvec2& blockCenter,
                    double blockRadius, const std::string& owner);
/// Dispatches 8 x 8 workgroups over width x height pixels, barrier, unbinds, checks GL errors (`what`).
void dispatchMarch(int width, int height, const char* what);

} // namespace gpu

/// The world-space reference march against a standard shadow map; optionally only a disc of pixels (the
/// epipole block of Klehm et al. 2014, Fig. 8). Per frame, O(pixels x steps).
class WorldMarchPass {
public:
  struct CreateInfo {
    /// steps and refinements are compiled in; bias and threads are unused (FrameAttribs::bias).
    WorldMarchOptions options;
    /// Runs the pass (must outlive it); null: a gpu::GlBackend of its own on the current GL context.
    gpu::Backend* backend = nullptr;
  };
  struct FrameAttribs {
    const Camera* camera = nullptr;
    /// Exactly one of `light` and `localLight` (a spot, or one point-light face with its own map: add the
    /// faces' outputs; README).
    const DirectionalLight* light = nullptr;
    const LocalLight* localLight = nullptr;
    const Medium* medium = nullptr;
    /// GL_TEXTURE_2D of depth-buffer values of `camera` (its convention); the image size is its size
    std::uint32_t cameraDepth = 0;
    std::uint32_t shadowMap =
        0; ///< standard shadow map (GL_TEXTURE_2D depth) rendered with lightClipFromWorld
    glm::dmat4 lightClipFromWorld{1.0};
    double bias = 0.0;             ///< added to the stored depth (depth-buffer units)
    std::uint32_t output = 0;      ///< GL_RGBA32F, the size of cameraDepth
    std::uint32_t stepsOutput = 0; ///< GL_R32F, the size of cameraDepth, or 0
    /// blockRadius >= 0 (pixels): march only the disc around blockCenter (origin bottom-left); -1 = all.
    glm::dvec2 blockCenter{0.0};
    double blockRadius = -1.0;
    /// A light texture (texture 0 = none): each lit part times its colour at the part's midpoint.
    GpuLightTexture lightTexture;
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "WorldMarchPass::FrameAttribs") const;
  /// Throws InvalidArgument ("WorldMarchOptions.steps" / ".refinements") for bad values.
  explicit WorldMarchPass(const CreateInfo& info);
  /// Throws InvalidArgument naming the FrameAttribs field (e.g. ".light/localLight": both or neither).
  void run(const FrameAttribs& frame);

private:
  struct Plan;
  Plan plan(const FrameAttribs& frame, std::string_view owner) const;

  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr;
  gpu::Buffer params_, textureParams_; ///< the march block; the light texture's, on first use
  gpu::Texture dummySteps_;            ///< R32F: the step counts when FrameAttribs::stepsOutput is 0
  int dummyWidth_ = 0, dummyHeight_ = 0;
};

} // namespace crep
