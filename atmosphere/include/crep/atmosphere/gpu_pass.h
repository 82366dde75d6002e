// The per-frame pass of the atmosphere: sky, aerial perspective and light shafts of one camera image, the
// rules of crep::atmosphereImage in float (atmosphere/README.md, "gpu_pass.h"), on a gpu::Backend. On OpenGL
// it needs a current 4.5 context and never creates or owns one; the FrameAttribs' textures and buffers are
// the caller's (ids of the pass's backend).
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include <crep/atmosphere/atmosphere.h>
#include <crep/atmosphere/gpu_tables.h>
#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/gpu/backend.h>
#include <crep/gpu/gl.h>
#include <crep/gpu/shader_library.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/gpu_layout_buffers.h>

namespace crep {

/// atmosphereImage on the GPU. On GL it leaves program 0 and every unit and binding it used unbound, and
/// issues the barriers its outputs need (gpu::GlBackend).
class AtmospherePass {
public:
  struct CreateInfo {
    AtmosphereShafts shafts = AtmosphereShafts::None; ///< one program per pass (options.shafts is ignored)
    /// (a): integrationSteps, skySteps in [1, 4096]; None, (b), (c): `single` and the view tables' sizes and
    /// steps (ViewTables: computed each run, 2.6 mebibytes at the defaults).
    AtmosphereRayOptions options;
    /// (a), (b): the rectified map's W x H texels (> 0, at most 16 tree levels); 0 for None and (c).
    int mapWidth = 0, mapHeight = 0;
    /// Runs the pass (must outlive it; the tables must be on it); null: a gpu::GlBackend of its own.
    gpu::Backend* backend = nullptr;
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
  ~AtmospherePass();
  /// Moved from: valid but empty (run() throws InvalidArgument naming "AtmospherePass").
  AtmospherePass(AtmospherePass&& other) noexcept;
  AtmospherePass& operator=(AtmospherePass&& other) noexcept;
  AtmospherePass(const AtmospherePass&) = delete;
  AtmospherePass& operator=(const AtmospherePass&) = delete;
  /// Per frame, O(pixels). Throws InvalidArgument naming the FrameAttribs field (README).
  void run(const FrameAttribs& frame);

  const CreateInfo& info() const noexcept { return info_; }
  /// The last run's view tables (RGB as crep::AtmosphereViewTables', RGBA32F 3D / 2D), 0 without them.
  std::uint32_t volumeRayleighTexture() const noexcept { return volumeRayleigh_.id(); }
  std::uint32_t volumeMieTexture() const noexcept { return volumeMie_.id(); }
  std::uint32_t skyRayleighTexture() const noexcept { return skyRayleigh_.id(); }
  std::uint32_t skyMieTexture() const noexcept { return skyMie_.id(); }

private:
  struct Plan;
  Plan plan(const FrameAttribs& frame, std::string_view owner) const;
  void uploadBlocks(const FrameAttribs& frame, const Plan& plan);
  void computeViewTables(const AtmosphereTablesPass& tables);
  void dispatchImage(const FrameAttribs& frame, const Plan& plan);
  std::vector<ShaderDefine> imageDefines(bool combinedMie, int layoutKind) const;

  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr; ///< null when moved from
  bool view_ = false;
  gpu::Texture volumeRayleigh_, volumeMie_, skyRayleigh_, skyMie_;
  gpu::LayoutBuffers layoutBuffers_;
  gpu::Buffer marchParams_, atmosphereParams_;
  gpu::Texture dummyTransmittance_;
  int dummyWidth_ = 0, dummyHeight_ = 0;
};

} // namespace crep
