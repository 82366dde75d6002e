// Blocks shared by the GPU prefilter / evaluation passes (gpu_pass.h) and their shaders: each has a std140 /
// std430 GLSL twin prefixed "Crep" in glsl/crep/scattering_structs.glsl, its offsets checked against the
// driver's by a GL test (prefilter/README.md, "gpu_structs.h").
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

namespace crep::gpu {

/// Largest number of layout regions (splits) the scattering block holds (= RectifyOptions::kMaxSplits).
inline constexpr int kMaxSplits = 64;

/// std140 CrepScatteringBlock { CrepScatteringParams crep_scattering; } of crep/scattering.glsl: the
/// evaluation's inputs (Listing 4, Appendix A) besides the basis; world units of the rectification.
struct ScatteringParams {
  glm::vec4 frameOrigin{0.0f};                  ///< xyz: rectification origin = camera position (world); w: 0
  glm::vec4 frameAxisX{1.0f, 0.0f, 0.0f, 0.0f}; ///< xyz: projection axis (unit); w: rho = 1/|c - L| (0: sun)
  glm::vec4 frameAxisY{0.0f, 1.0f, 0.0f, 0.0f}; ///< xyz: axisZ x axisX (unit); w: 0
  glm::vec4 frameAxisZ{0.0f, 0.0f, 1.0f, 0.0f}; ///< xyz: direction light travels at the camera (unit); w: 0
  /// x: row slope min, y: 1 / (row slope max - min), z: depth slope min, w: 1 / (depth slope max - min)
  glm::vec4 slopes{0.0f, 1.0f, 0.0f, 1.0f};
  glm::vec4 extinction{0.0f};         ///< rgb: sigma_t per channel (1/world unit); w: weight extinction s
  glm::vec4 mieScattering{0.0f};      ///< rgb: sigma_s of the Henyey-Greenstein part (1/world unit); w: g
  glm::vec4 rayleighScattering{0.0f}; ///< rgb: sigma_s of the Rayleigh part (1/world unit); w: 0
  glm::vec4 lightIrradiance{0.0f};    ///< rgb: irradiance of the directional light (linear); w: 0
  glm::vec4 lightDirection{0.0f, 0.0f, -1.0f, 0.0f}; ///< xyz: direction the light travels (unit); w: 0
  glm::ivec4 mapSize{0};       ///< x: map width W, y: height H (texels), z: prefilter regions R, w: K
  glm::ivec4 basisInfo{0};     ///< x: bases M, y: layers ceil(M / 4), z: regions per split P, w: WeightMode
  glm::vec4 depthMargin{0.0f}; ///< x: depth margin m of fourier.h; yzw: 0
  /// Split k < K: x = zetaBegin, y = zetaEnd (column parameter at its near / far edge, 1/world unit); zw: 0.
  glm::vec4 splitZeta[kMaxSplits]{};
};
static_assert(sizeof(ScatteringParams) == 16 * (13 + kMaxSplits), "std140 layout of CrepScatteringParams");

/// std430 element of CrepRegionWeightsBlock (index row * R + region): a region's reference-ray distances
/// tau(u) as the weight mode needs them (gpuRegionWeights(); the formulas: README).
struct RegionWeights {
  float scale = 0.0f;     ///< world units (README)
  float c = 1.0f;         ///< Exact: c of the profile; ConstantRatio: log r
  float d = 0.0f;         ///< Exact: d of the profile; ConstantRatio: D0 (world units)
  std::int32_t valid = 1; ///< 0: the distances are not finite (beyond a spot light's horizon): no weight
};
static_assert(sizeof(RegionWeights) == 16, "std430 layout of CrepRegionWeights");

/// std140 uniform block CrepPrefilterBlock of passes/prefilter.comp.
struct PrefilterParams {
  glm::ivec4 mapSize{0};   ///< x: W, y: H (texels), z: prefilter regions R, w: texels per region n = W / R
  glm::ivec4 basisInfo{0}; ///< x: bases M, y: bases per invocation, z: WeightMode, w: 0
  glm::vec4 weights{0.0f}; ///< x: weight extinction s (1/world unit), y: depth margin m, zw: 0
};
static_assert(sizeof(PrefilterParams) == 48, "std140 layout of CrepPrefilterParams");

/// std140 CrepLocalLightBlock { CrepLocalLightParams crep_localLight; } (CREP_LOCAL_LIGHT 1): a spot or a
/// point-light face (crep::LocalLight) and the medium's phase coefficients.
struct LocalLightParams {
  glm::vec4 origin{0.0f};   ///< xyz: camera position = rectification origin; w: grey extinction s
  glm::vec4 position{0.0f}; ///< xyz: light position; w: near plane (d is clamped below at it)
  glm::vec4 axis{0.0f};     ///< xyz: spot axis or face axis (unit); w: point face 0-5, -1 none
  glm::vec4 cone{0.0f}; ///< x: cos inner, y: cos outer, z: 1 = spot falloff, w: LocalLightWeights (0, 1, 2)
  glm::vec4 intensity{0.0f};          ///< rgb: radiant intensity (on the axis for a spot); w: 0
  glm::vec4 mieScattering{0.0f};      ///< rgb: sigma_s of the Henyey-Greenstein part; w: g
  glm::vec4 rayleighScattering{0.0f}; ///< rgb: sigma_s of the Rayleigh part; w: 0
};
static_assert(sizeof(LocalLightParams) == 16 * 7, "std140 layout of CrepLocalLightParams");

/// std430 element of CrepRegionRaysBlock (local-light prefilter, index row * R + region): xyz the reference
/// ray's unit direction, w its t(0) (world units; -1: beyond the horizon).
using RegionRay = glm::vec4;

/// std140 CrepEvaluateBlock of passes/prefilter/evaluate.comp: the camera whose depth buffer is read.
struct EvaluateParams {
  glm::vec4 cameraPosition{0.0f};                   ///< xyz: world; w: near plane distance (world units)
  glm::vec4 cameraForward{0.0f, 0.0f, -1.0f, 0.0f}; ///< xyz: unit view direction; w: far plane distance
  glm::vec4 cameraRight{1.0f, 0.0f, 0.0f, 0.0f};    ///< xyz: right * tan(fovY / 2) * aspect; w: 0
  glm::vec4 cameraUp{0.0f, 1.0f, 0.0f, 0.0f};       ///< xyz: up * tan(fovY / 2); w: 0
  glm::ivec4 imageSize{0};                          ///< xy: output size (pixels); zw: 0
  /// xyz: (cx right + cy up) for an off-centre image (Camera::tangents' centre); w: 0
  glm::vec4 cameraCenter{0.0f};
  /// Depth convention: x near, y projection far (0 = infinite), z integration far, w 1 = reversed-Z
  glm::vec4 cameraDepth{0.0f};
};
static_assert(sizeof(EvaluateParams) == 112, "std140 layout of CrepEvaluateParams");

} // namespace crep::gpu
