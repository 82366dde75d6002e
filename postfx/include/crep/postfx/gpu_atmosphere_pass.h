// The per-frame GL pass of the atmosphere: the sky, aerial perspective and light shafts of one camera image
// (crep::atmosphereImage in crep/postfx/atmosphere.h is its CPU reference and holds the rules; this pass
// follows them in float). One compute shader, glsl/passes/atmosphere.comp, with a variant per
// AtmosphereShafts mode (CREP_ATMOSPHERE_SHAFTS 0..3) and per rectified layout kind; it reads the tables of
// an AtmosphereTablesPass (crep/postfx/gpu_atmosphere.h) through glsl/crep/atmosphere.glsl and, for the
// shafts (a) and (b), walks the min/max trees of the scene's rectified shadow map with
// glsl/crep/minmax_walk.glsl (the walk of RectifiedMarchPass, crep/epipolar/gpu_march.h).
//
// The pass requires a current OpenGL 4.5 context and never creates or owns one. It owns its programs,
// buffers and samplers (RAII); the textures and buffers of FrameAttribs are the caller's (non-owning GL
// names). Depth textures hold depth-buffer values in [0, 1] (read with texelFetch through the pass's own
// nearest sampler); a camera depth value >= 1 (or NaN) is the sky. It leaves program 0, texture units 0-11
// with no texture and no sampler, image units 0-1, uniform buffer bindings 0-2 and storage buffer bindings
// 0-1 unbound (gl::unbindPassState) and issues gl::passOutputBarrier().
#pragma once

#include <cstdint>
#include <string_view>

#include <crep/core/camera.h>
#include <crep/core/gl.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/postfx/atmosphere.h>
#include <crep/postfx/gpu_atmosphere.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/gpu_layout_buffers.h>

namespace crep {

/// The atmosphere's in-scattering and transmittance of every pixel of a camera image (atmosphereImage on
/// the GPU), with the light shafts of AtmosphereRayOptions::shafts.
class AtmospherePass {
public:
  struct CreateInfo {
    /// The shafts mode (one program per pass; AtmosphereRayOptions::shafts of `options` is ignored).
    AtmosphereShafts shafts = AtmosphereShafts::None;
    /// The steps of (a): integrationSteps and skySteps, each in [1, 4096] (InvalidArgument
    /// "AtmospherePass::CreateInfo.options.integrationSteps" / ".skySteps"); uniforms, not compiled in.
    /// None, (b), (c): `single` (default ViewTables: crep::atmosphereViewTables computed on the GPU each
    /// run, two volumeSize 3D and two skyViewSize 2D RGBA32F textures: 2.6 mebibytes at the defaults),
    /// volumeSize, volumeSteps, skyViewSize, skyViewSteps (InvalidArgument naming the field).
    AtmosphereRayOptions options;
    /// (a), (b): the rectified map's size W x H in texels (> 0, <= GL_MAX_TEXTURE_SIZE, at most 16 tree
    /// levels); ignored (may be 0) for None and (c).
    int mapWidth = 0, mapHeight = 0;
  };
  /// Per-frame inputs: non-owning; the pointers are not stored.
  struct FrameAttribs {
    /// The tables (computed or uploaded); their parameters are the atmosphere's.
    const AtmosphereTablesPass* tables = nullptr;
    const AtmospherePlacement* placement = nullptr; ///< validated against the tables' parameters
    const Camera* camera = nullptr;
    const DirectionalLight* sun = nullptr; ///< its direction and irradiance
    /// GL_TEXTURE_2D of depth-buffer values of `camera` (its convention; 1 = sky); the image size is its
    /// size.
    std::uint32_t cameraDepth = 0;
    /// (a), (b): the rectified shadow map as RectifiedMarchPass::FrameAttribs takes it: its layout (a
    /// ProjectiveLayout or an EpipolarLayout), the mapWidth x mapHeight depth texture and
    /// MinMaxTreePass::treeBuffer() of it. Not read by None and (c).
    const RectifiedLayout* layout = nullptr;
    std::uint32_t rectifiedDepth = 0;
    std::uint32_t minMaxBuffer = 0;
    /// (c): the prefiltered (or any shadowed) homogeneous-medium result of `sun` in `proxyMedium` for this
    /// camera (crep::Scattering / EvaluatePass output: GL_TEXTURE_2D, RGB radiance, the size of
    /// cameraDepth), and that medium; the visibility of each pixel is prefilteredVisibility of its texel.
    /// Not read by the other modes.
    std::uint32_t prefiltered = 0;
    const Medium* proxyMedium = nullptr;
    /// GL_RGBA32F, the size of cameraDepth: RGB the in-scattered radiance, A the mean RGB transmittance
    /// (AtmosphereImage::inscattering).
    std::uint32_t output = 0;
    /// GL_RGBA32F, the size of cameraDepth: RGB the transmittance (AtmosphereImage::transmittance), A 1;
    /// or 0 (not written).
    std::uint32_t transmittanceOutput = 0;
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "AtmospherePass::FrameAttribs") const;

  /// Validates (InvalidArgument "AtmospherePass::CreateInfo.options.integrationSteps", ".skySteps",
  /// ".mapWidth/mapHeight"; GlError beyond the GL limits) and builds the program.
  explicit AtmospherePass(const CreateInfo& info);
  /// Throws InvalidArgument naming the field of FrameAttribs ("AtmospherePass::FrameAttribs.tables", ...)
  /// for a null pointer or zero name the mode reads, sizes that do not match, wrong output formats, a
  /// layout with no GPU mapping, an invalid placement.
  void run(const FrameAttribs& frame);

  const CreateInfo& info() const noexcept { return info_; }
  /// The view tables of the last run, RGB crep::AtmosphereViewTables' volumeRayleigh / volumeMie
  /// (GL_TEXTURE_3D RGBA32F) and skyRayleigh / skyMie (GL_TEXTURE_2D RGBA32F), A 0; 0 without them (shafts
  /// (a), or options.single Table4D).
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
  /// [combinedMie][layout kind] ((a), (b)); [.][0] for None and (c)
  gl::Handle programs_[2][2];
  gl::Handle marchParams_, atmosphereParams_, nearest_, linear_, dummyTransmittance_;
  int dummyWidth_ = 0, dummyHeight_ = 0;
};

} // namespace crep
