// The GL pass of the world-space reference march (crep/scatter/world_march.h: its CPU reference and
// rule) and the std140 block MarchParams shared by every march and resampling pass of the library
// (this one, the rectified marches and the resampling of epipolar/). Float precision.
//
// The block has a GLSL twin with the same name prefixed "Crep" in glsl/crep/march.glsl: 16-byte vectors
// and matrices only, int instead of bool, a static_assert on the size; the GL tests compare every member
// offset with the offsets the driver reports.
//
// The pass requires a current OpenGL 4.5 context and never creates or owns one. It owns its program,
// buffer and sampler (RAII); the textures of FrameAttribs are the caller's (non-owning GL names). Depth
// textures hold depth-buffer values in [0, 1] (GL_DEPTH_COMPONENT32F or GL_R32F, read with texelFetch
// through the pass's own nearest sampler, so their compare mode does not matter); outputs are
// GL_RGBA32F (scattering: RGB radiance, A grey transmittance) and GL_R32F (steps per pixel). It leaves
// program 0, texture units 0-1 with no texture and no sampler, image units 0-1, uniform and storage
// buffer bindings 0-1 unbound (gl::unbindPassState), and issues gl::passOutputBarrier(). A NaN camera
// depth is treated as the sky (far plane), a NaN shadow-map texel as empty (lit): checking would cost a
// readback. The CPU reference rejects NaN with InvalidArgument.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/gl.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/scatter/gpu_light_texture.h>
#include <crep/scatter/ray_scattering.h>
#include <crep/scatter/world_march.h>

namespace crep {
namespace gpu {

/// std140 block CrepMarchBlock { CrepMarchParams crep_march; } of the march and resampling passes.
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
  // The local light of the world march (appended: the members above keep their offsets; zeros = a
  // directional light, what every other pass of the block leaves them at).
  glm::vec4 lightPosition{0.0f};  ///< xyz: world; w: 1 = local light (spot or point face), 0 = directional
  glm::vec4 lightAxis{0.0f};      ///< xyz: unit spot axis or point-face axis; w: point face index, or -1
  glm::vec4 lightCone{0.0f};      ///< x cosInner, y cosOuter, z near plane, w 1 = the spot falloff applies
  glm::vec4 lightIntensity{0.0f}; ///< rgb: radiant intensity (on the axis for a spot); w: 0
};
static_assert(sizeof(MarchParams) == 16 * 24, "std140 CrepMarchParams");

/// The camera vectors of the GPU blocks (MarchParams, gpu::EvaluateParams): a pixel at NDC (x, y) looks
/// along forward + center + x right + y up (right and up scaled by the image's half extents at unit
/// distance), and its depth-buffer value maps to a distance with `depth` (crep_cameraViewDepth).
struct GpuCamera {
  glm::vec4 position;  ///< xyz; w near
  glm::vec4 forward;   ///< xyz unit; w integration far
  glm::vec4 right, up; ///< xyz; w 0
  glm::vec4 center;    ///< xyz; w 0
  glm::vec4 depth;     ///< near, projection far (0 = infinite), integration far, reversed (1 / 0)
};
GpuCamera gpuCamera(const Camera& camera);
/// Sets the camera members of a GPU block (MarchParams, gpu::EvaluateParams: cameraPosition, cameraForward,
/// cameraRight, cameraUp, cameraCenter, cameraDepth) from gpuCamera(camera).
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

/// The resources of every march pass's shader (this module's and epipolar/'s): `program` current,
/// MarchParams buffer `params` at uniform binding 0, the camera depth at texture unit 0 and the map it
/// marches at unit 1 (both through `sampler`), the scattering output (GL_RGBA32F) at image unit 0 and
/// the steps output (GL_R32F) at image unit 1. The caller binds its own extra blocks after this.
void bindMarchResources(std::uint32_t program, std::uint32_t params, std::uint32_t cameraDepth,
                        std::uint32_t map, std::uint32_t sampler, std::uint32_t scattering,
                        std::uint32_t steps);
/// The dispatch rectangle of a march over a width x height image: the whole image (blockRadius < 0), or
/// the bounding box of the disc of blockRadius pixels around blockCenter (pixel coordinates, origin at the
/// bottom-left corner) clipped to it, with MarchParams::block set so the shader writes only the pixels
/// whose centre is in the disc. Returns false when the disc misses the image (nothing to dispatch).
/// Throws InvalidArgument naming `owner` + ".blockCenter/blockRadius" for non-finite values.
bool setMarchRegion(MarchParams& params, int width, int height, const glm::dvec2& blockCenter,
                    double blockRadius, const std::string& owner);
/// Dispatches 8 x 8 workgroups over width x height pixels (local size of the march shaders), then issues
/// gl::passOutputBarrier(), unbinds (gl::unbindPassState(2)) and checks GL errors under `what`.
void dispatchMarch(int width, int height, const char* what);

} // namespace gpu

/// The world-space reference march (world_march.h) against a standard shadow map; optionally only the
/// pixels within a radius of a point: the epipole block of Klehm et al. 2014, Fig. 8 (its other pixels
/// are not written).
class WorldMarchPass {
public:
  struct CreateInfo {
    /// steps and refinements are compiled in; bias and threads are not used by the pass (bias is a
    /// per-frame attribute, FrameAttribs::bias).
    WorldMarchOptions options;
  };
  struct FrameAttribs {
    const Camera* camera = nullptr;
    /// The light: exactly one of `light` (directional) and `localLight` (a spot light,
    /// LocalLight::spot, or one face of a point light, LocalLight::pointFace: march each face with its
    /// own map and add the outputs) is set. For a local light, lightClipFromWorld is its perspective
    /// shadow map's matrix (SpotLight::lightClipFromWorld, PointLight::faceClipFromWorld), points with
    /// clip w <= 0 count as lit, each lit part is integrated with crep_localSegment
    /// (glsl/crep/local_light.glsl, the float counterpart of RayScattering::segment) and the output RGB is
    /// the radiance itself, as worldSpaceMarch with a LocalLight.
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
    /// Epipole block: when blockRadius >= 0, only pixels whose centre is within blockRadius pixels of
    /// blockCenter (pixel coordinates, origin at the bottom-left corner of the image) are marched.
    glm::dvec2 blockCenter{0.0};
    double blockRadius = -1.0;
    /// Light textures (crep/scatter/light_texture.h): texture 0 = none (the untextured program, nothing
    /// more bound); else each lit part times the texture's colour at its midpoint (worldSpaceMarch with a
    /// LightTexture), the CREP_LIGHT_TEXTURE program built on first use, the texture at texture unit 2 and
    /// its block at uniform binding 1 (unbound afterwards). The projection must follow the light's rays
    /// (InvalidArgument naming "WorldMarchPass::FrameAttribs.lightTexture.textureClipFromWorld").
    GpuLightTexture lightTexture;
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "WorldMarchPass::FrameAttribs") const;
  /// Throws InvalidArgument ("WorldMarchOptions.steps" / ".refinements") for bad values.
  explicit WorldMarchPass(const CreateInfo& info);
  /// Throws InvalidArgument naming the FrameAttribs field ("WorldMarchPass::FrameAttribs.light/localLight"
  /// when both or neither are set).
  void run(const FrameAttribs& frame);

private:
  struct Plan;
  Plan plan(const FrameAttribs& frame, std::string_view owner) const;

  CreateInfo info_;
  gl::Handle program_, params_, sampler_, dummySteps_;
  gl::Handle texturedProgram_, textureParams_; ///< light textures, on first use
  int dummyWidth_ = 0, dummyHeight_ = 0;
};

} // namespace crep
