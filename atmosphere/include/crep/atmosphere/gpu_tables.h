// The GL passes of the atmosphere (crep/atmosphere/atmosphere.h: the CPU reference, its conventions and
// rules): AtmosphereTablesPass computes (or uploads) the precomputed tables, AtmospherePass evaluates the
// sky, aerial perspective and light shafts of one camera image per frame. Float precision; the look-ups are
// glsl/crep/atmosphere.glsl (public: an engine includes it to read the tables in its own shaders, e.g. the
// sun's transmittance and the ambient sky light of its terrain shading).
//
// The passes require a current OpenGL 4.5 context and never create or own one. They own their programs,
// buffers and table textures (RAII); the textures of FrameAttribs are the caller's (non-owning GL names).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include <crep/atmosphere/atmosphere.h>
#include <crep/core/camera.h>
#include <crep/core/gl.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/rectify/rectified_map.h>

namespace crep {
namespace gpu {

/// std140 block CrepAtmosphereBlock { CrepAtmosphereParams crep_atmosphere; } (glsl/crep/atmosphere.glsl).
struct AtmosphereParams {
  glm::vec4 radii{0.0f};              ///< x: R, y: R + H_Atm, z: H_Atm, w: kOccludedDensity
  glm::vec4 rayleighScattering{0.0f}; ///< rgb: beta_R; w: H_R
  glm::vec4 mieScattering{0.0f};      ///< rgb: beta_M; w: H_M
  glm::vec4 mieExtinction{0.0f};      ///< rgb: beta_M + mieAbsorption; w: g
  glm::ivec4 tableSize{0};            ///< N_h, N_alpha, N_phi, N_theta
  glm::ivec4 auxSizes{0}; ///< optical depth width (altitude), height (zenith); ambient size; orders
  glm::vec4 placement{1.0f, 0.0f, 0.0f, 0.0f}; ///< x: metersPerUnit; y: originAltitude; zw: 0
  /// x: ground albedo; y: Psi_ms texels per side; z: Psi_ms steps per ray (sizes exact in float); w: 0
  glm::vec4 multipleScattering{0.0f};
};
static_assert(sizeof(AtmosphereParams) == 128, "std140 CrepAtmosphereParams");

/// The block of (p, o, placement).
AtmosphereParams atmosphereParams(const AtmosphereParameters& p, const AtmospherePrecomputeOptions& o,
                                  const AtmospherePlacement& placement = {});

} // namespace gpu

/// The tables on the GPU: textures owned by the pass, sized by CreateInfo.
///   opticalDepthTexture(): GL_TEXTURE_2D GL_RG32F, opticalDepthHeight x opticalDepthZenith;
///   single/singleMie/higherOrdersTexture(): GL_TEXTURE_3D GL_RGBA32F (GL_RGBA16F with halfFloatTables),
///     N_h x N_alpha x (N_phi N_theta)
///     (the packing of atmosphere.h: single scattering without its phase functions, `single` RGB Rayleigh
///     and A Mie's red, `singleMie` RGB Mie; singleMieTexture() is 0 with options.combinedMie), linear
///     filtering, clamp to edge;
///   ambientTexture(): GL_TEXTURE_2D GL_RGBA32F, ambientSize x 1;
///   multipleScatteringLutTexture(): GL_TEXTURE_2D GL_RGBA32F, multipleScatteringSize^2, linear, clamp to
///     edge (Psi_ms; 0 unless usesMultipleScatteringLut).
/// 4D tables take 16 bytes per texel (8 with halfFloatTables): 4 mebibytes each at the default size, 64 at
/// Yusov's 32 x 128 x 64 x 16 (three, two with combinedMie, plus two of the same size while computing more
/// than one order, and three more with halfFloatTables).
class AtmosphereTablesPass {
public:
  struct CreateInfo {
    AtmosphereParameters parameters;
    AtmospherePrecomputeOptions options; ///< keepOrders is ignored
    /// The three 4D tables as GL_RGBA16F: half the memory, each value rounded once to half precision
    /// (relative 2^-11) after compute() in RGBA32F or in upload(); download() returns the rounded values.
    bool halfFloatTables = false;
  };
  /// Validates both (InvalidArgument naming the field; sizes beyond the GL limits name the size field) and
  /// allocates the textures. Throws GlError when allocation fails.
  explicit AtmosphereTablesPass(const CreateInfo& info);

  /// Computes every table on the GPU (the steps of atmosphere.h's top, in float). Wall-clock milliseconds
  /// per stage ("optical depth", "single scattering", "order 2: J", "order 2: L", ..., "ambient") are in
  /// stageTimes() afterwards.
  void compute();
  /// Uploads tables computed on the CPU or loaded from a cache (sizes and parameters must match CreateInfo:
  /// InvalidArgument "AtmosphereTablesPass::upload.tables" otherwise).
  void upload(const AtmosphereTables& tables);
  /// Reads every table back (orders stays empty).
  AtmosphereTables download() const;

  const CreateInfo& info() const noexcept { return info_; }
  std::uint32_t opticalDepthTexture() const noexcept { return opticalDepth_.get(); }
  std::uint32_t singleTexture() const noexcept { return single_.get(); }
  std::uint32_t singleMieTexture() const noexcept { return singleMie_.get(); }
  std::uint32_t higherOrdersTexture() const noexcept { return higher_.get(); }
  std::uint32_t ambientTexture() const noexcept { return ambient_.get(); }
  std::uint32_t multipleScatteringLutTexture() const noexcept { return msLut_.get(); }
  const std::vector<std::pair<std::string, double>>& stageTimes() const noexcept { return times_; }

private:
  CreateInfo info_;
  gl::Handle opticalDepth_, single_, singleMie_, higher_, ambient_, msLut_;
  std::vector<std::pair<std::string, double>> times_;
};

} // namespace crep
