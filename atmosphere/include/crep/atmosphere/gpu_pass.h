// The per-frame GL pass of the atmosphere: sky, aerial perspective and light shafts of one camera image, the
// rules of crep::atmosphereImage in float (atmosphere/README.md, "gpu_pass.h"). Requires a current OpenGL 4.5
// context, never creates or owns one; the FrameAttribs' textures and buffers are the caller's.
#pragma once

#include <cstdint>
#include <string_view>

#include <crep/atmosphere/atmosphere.h>
#include <crep/atmosphere/gpu_tables.h>
#include <crep/core/camera.h>
#include <crep/core/gl.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/gpu_layout_buffers.h>

namespace crep {

/// atmosphereImage on the GPU. Leaves program 0, texture units 0-11, image units 0-1, uniform buffers 0-2
/// and storage buffers 0-1 unbound, and issues gl::passOutputBarrier().
class AtmospherePass {
public:
  struct CreateInfo {
    AtmosphereShafts shafts = AtmosphereShafts::None; ///< one program per pass (options.shafts is ignored)
    /// (a): integrationSteps, skySteps in [1, 4096]; None, (b), (c): `single` and the view tables' sizes and
    /// steps (ViewTables: computed each run, 2.6 mebibytes at the defaults).
    AtmosphereRayOptions options;
    /// (a), (b): the rectified map's W x H texels (> 0, at most 16 tree levels); 0 for None and (c).
    int mapWidth = 0, mapHeight = 0;
  };
  /// Per-frame inputs: non-owning; the pointers are not stored.
  struct FrameAttribs {
    const AtmosphereTablesPass* tables = nullptr;   ///< computed or uploaded; their parameters rule
    const AtmospherePlacement* placement = nullptr; ///< validated against the tables' parameters
    const Camera* camera = nullptr;
    const DirectionalLight* sun = nullptr; ///< its direction and irradiance
    /// GL_TEXTURE_2D of depth-buffer values of `camera` (>= 1 or NaN: sky); its size is the image's.
    std::uint32_t cameraDepth = 0;
    /// (a), (b): the rectified map as RectifiedMarchPass takes it: layout, depth texture, min/max trees.
    const RectifiedLayout* layout = nullptr;
    std::uint32_t rectifiedDepth = 0;
    std::uint32_t minMaxBuffer = 0;
    /// (c): crep::Scattering's output for this camera and `sun` in `proxyMedium` (cameraDepth's size).
    std::uint32_t prefiltered = 0;
    const Medium* proxyMedium = nullptr;
    /// GL_RGBA32F of cameraDepth's size: AtmosphereImage::inscattering.
    std::uint32_t output = 0;
    /// GL_RGBA32F of cameraDepth's size: RGB AtmosphereImage::transmittance, A 1; or 0 (not written).
    std::uint32_t transmittanceOutput = 0;
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "AtmospherePass::FrameAttribs") const;

  /// One-time: validates (InvalidArgument naming the field; GlError beyond GL limits), builds the program.
  explicit AtmospherePass(const CreateInfo& info);
  /// Per frame, O(pixels). Throws InvalidArgument naming the FrameAttribs field (README).
  void run(const FrameAttribs& frame);

  const CreateInfo& info() const noexcept { return info_; }
  /// The last run's view tables (RGB as crep::AtmosphereViewTables', RGBA32F 3D / 2D), 0 without them.
  std::uint32_t volumeRayleighTexture() const noexcept { return volumeRayleigh_.get(); }
  std::uint32_t volumeMieTexture() const noexcept { return volumeMie_.get(); }
  std::uint32_t skyRayleighTexture() const noexcept { return skyRayleigh_.get(); }
  std::uint32_t skyMieTexture() const noexcept { return skyMie_.get(); }

private:
  struct Plan;
  Plan plan(const FrameAttribs& frame, std::string_view owner) const;
  void uploadBlocks(const FrameAttribs& frame, const Plan& plan);
  void computeViewTables(const AtmosphereTablesPass& tables);
  void dispatchImage(const FrameAttribs& frame, const Plan& plan, std::uint32_t program);

  CreateInfo info_;
  bool view_ = false;
  gl::Handle volumeProgram_, skyViewProgram_, volumeRayleigh_, volumeMie_, skyRayleigh_, skyMie_;
  gpu::LayoutBuffers layoutBuffers_;
  gl::Handle programs_[2][2]; ///< [combinedMie][layout kind] ((a), (b)); [.][0] for None and (c)
  gl::Handle marchParams_, atmosphereParams_, nearest_, linear_, dummyTransmittance_;
  int dummyWidth_ = 0, dummyHeight_ = 0;
};

} // namespace crep
