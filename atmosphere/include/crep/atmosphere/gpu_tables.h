// The atmosphere's tables on the GPU (crep/atmosphere/atmosphere.h: the CPU reference and its rules), in
// float; glsl/crep/atmosphere.glsl reads them (public: engines include it). Runs on a gpu::Backend; on
// OpenGL it needs a current 4.5 context and never creates or owns one (atmosphere/README.md, "gpu_tables.h").
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include <crep/atmosphere/atmosphere.h>
#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/gpu/backend.h>
#include <crep/gpu/gl.h>
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
  glm::vec4 multipleScattering{0.0f}; ///< x: ground albedo; y: Psi_ms texels per side; z: its steps; w: 0
};
static_assert(sizeof(AtmosphereParams) == 128, "std140 CrepAtmosphereParams");

/// The block of (p, o, placement).
AtmosphereParams atmosphereParams(const AtmosphereParameters& p, const AtmospherePrecomputeOptions& o,
                                  const AtmospherePlacement& placement = {});

} // namespace gpu

/// The tables on the GPU, in textures the pass owns, sized by CreateInfo (formats, memory: README). The 4D
/// tables take 16 bytes per texel (8 with halfFloatTables).
class AtmosphereTablesPass {
public:
  struct CreateInfo {
    AtmosphereParameters parameters;
    AtmospherePrecomputeOptions options; ///< keepOrders is ignored
    /// The 4D tables as RGBA16F: half the memory, each value rounded once (relative 2^-11).
    bool halfFloatTables = false;
    /// Runs the pass (must outlive it); null: a gpu::GlBackend of its own on the current GL context.
    gpu::Backend* backend = nullptr;
  };
  /// Validates (InvalidArgument naming the field, also beyond the backend's limits), allocates.
  explicit AtmosphereTablesPass(const CreateInfo& info);
  ~AtmosphereTablesPass();
  AtmosphereTablesPass(AtmosphereTablesPass&& other) noexcept;
  AtmosphereTablesPass& operator=(AtmosphereTablesPass&& other) noexcept;
  AtmosphereTablesPass(const AtmosphereTablesPass&) = delete;
  AtmosphereTablesPass& operator=(const AtmosphereTablesPass&) = delete;

  /// One-time per atmosphere: computes every table (atmosphere.h's steps, in float); stageTimes() then
  /// holds the wall-clock milliseconds per stage.
  void compute();
  /// Uploads CPU or cached tables matching CreateInfo (InvalidArgument
  /// "AtmosphereTablesPass::upload.tables").
  void upload(const AtmosphereTables& tables);
  /// Reads every table back (orders stays empty).
  AtmosphereTables download() const;

  const CreateInfo& info() const noexcept { return info_; }
  /// The backend the tables live on; null when moved from (the calls then throw InvalidArgument).
  gpu::Backend* backend() const noexcept { return backend_; }
  /// The tables: ids of the backend (GL names on OpenGL); 0 for a table the options do not make.
  std::uint32_t opticalDepthTexture() const noexcept { return opticalDepth_.id(); }
  std::uint32_t singleTexture() const noexcept { return single_.id(); }
  std::uint32_t singleMieTexture() const noexcept { return singleMie_.id(); }
  std::uint32_t higherOrdersTexture() const noexcept { return higher_.id(); }
  std::uint32_t ambientTexture() const noexcept { return ambient_.id(); }
  std::uint32_t multipleScatteringLutTexture() const noexcept { return msLut_.id(); }
  const std::vector<std::pair<std::string, double>>& stageTimes() const noexcept { return times_; }

private:
  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr; ///< null when moved from
  gpu::Texture opticalDepth_, single_, singleMie_, higher_, ambient_, msLut_;
  std::vector<std::pair<std::string, double>> times_;
};

} // namespace crep
