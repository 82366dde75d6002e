// Blocks shared between the GPU prefilter / evaluation passes (gpu_pass.h) and their shaders. Each
// struct here has a GLSL twin with the same name prefixed "Crep" in glsl/crep/scattering_structs.glsl,
// laid out by std140 (uniform blocks) or std430 (the storage buffer): only 16-byte vectors and 4-byte
// scalars, explicit padding, int instead of bool, a static_assert on the size. The GL test
// tests/prefilter/PrefilterGpuStructsGLTest.cpp compares every member offset with the offsets the driver
// reports for the linked shaders (glGetProgramResourceiv).
//
// An engine that evaluates the scattering in its own shader (#include "crep/scattering.glsl") fills a
// ScatteringParams with makeScatteringParams() (gpu_pass.h) and uploads it to a uniform buffer bound at
// CREP_SCATTERING_BINDING.
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

namespace crep::gpu {

/// Largest number of layout regions (splits) the scattering block holds (= RectifyOptions::kMaxSplits).
inline constexpr int kMaxSplits = 64;

/// std140 uniform block CrepScatteringBlock { CrepScatteringParams crep_scattering; } of
/// crep/scattering.glsl: everything the per-pixel evaluation (Listing 4, Appendix A) needs besides the
/// filtered-basis texture. World units are those of the rectification; coefficients per world unit.
struct ScatteringParams {
  glm::vec4 frameOrigin{0.0f}; ///< xyz: rectification origin = camera position (world); w: 0
  glm::vec4 frameAxisX{1.0f, 0.0f, 0.0f,
                       0.0f}; ///< xyz: projection axis (unit); w: rho = 1/|c - L| (0: directional)
  glm::vec4 frameAxisY{0.0f, 1.0f, 0.0f, 0.0f}; ///< xyz: axisZ x axisX (unit); w: 0
  glm::vec4 frameAxisZ{0.0f, 0.0f, 1.0f, 0.0f}; ///< xyz: direction light travels at the camera (unit); w: 0
  /// x: row slope min, y: 1 / (row slope max - min), z: depth slope min, w: 1 / (depth slope max - min)
  glm::vec4 slopes{0.0f, 1.0f, 0.0f, 1.0f};
  glm::vec4 extinction{0.0f};         ///< rgb: sigma_t per channel (1/world unit); w: weight extinction s
  glm::vec4 mieScattering{0.0f};      ///< rgb: sigma_s of the Henyey-Greenstein part (1/world unit); w: g
  glm::vec4 rayleighScattering{0.0f}; ///< rgb: sigma_s of the Rayleigh part (1/world unit); w: 0
  glm::vec4 lightIrradiance{0.0f};    ///< rgb: irradiance of the directional light (linear); w: 0
  glm::vec4 lightDirection{0.0f, 0.0f, -1.0f, 0.0f}; ///< xyz: direction the light travels (unit); w: 0
  glm::ivec4 mapSize{
      0}; ///< x: map width W, y: height H (texels), z: prefilter regions R, w: layout regions K
  glm::ivec4 basisInfo{0};     ///< x: bases M, y: layers ceil(M / 4), z: regions per split P, w: WeightMode
  glm::vec4 depthMargin{0.0f}; ///< x: depth margin m of fourier.h; yzw: 0
  /// Split k < K: x = zetaBegin, y = zetaEnd (column parameter at its near / far edge, 1/world unit); zw: 0.
  glm::vec4 splitZeta[kMaxSplits]{};
};
static_assert(sizeof(ScatteringParams) == 16 * (13 + kMaxSplits), "std140 layout of CrepScatteringParams");

/// std430 element of the storage buffer CrepRegionWeightsBlock { CrepRegionWeights crep_regionWeights[]; }:
/// the reference-ray distances of one row and prefilter region (index row * R + region), reduced to the
/// numbers the weight mode needs (weights.h; computed in double on the CPU from referenceProfiles()).
/// tau(u) is the distance from the region's start at column u in [0, 1] of the region (n texels):
///   Exact:         tau(u) = u scale / (c + d u)   (scale = (b c - a d) / c of the DistanceProfile)
///   ConstantStep:  tau(u) = u n scale             (scale = the step D = (t(1) - t(0)) / n)
///   ConstantRatio: tau(u) = scale expm1(u n c)    (c = log r, scale = D0 / expm1(c)); u n scale if c = 0;
///                  d = D0, the first texel's length
///   AverageVisibility: unused.
struct RegionWeights {
  float scale = 0.0f;     ///< world units (see above)
  float c = 1.0f;         ///< Exact: c of the profile (1/world unit scale-free); ConstantRatio: log r
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

/// std140 uniform block CrepLocalLightBlock { CrepLocalLightParams crep_localLight; } of the local-light
/// variants of the prefilter and evaluation passes (CREP_LOCAL_LIGHT 1): a spot light or one point-light
/// face (crep::LocalLight) and the medium's phase coefficients, for the light-side factor of the weights
/// (crep::LocalLight::weightFactor) and the view rays' in-scattering (crep::RayScattering).
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

/// std430 element of the storage buffer CrepRegionRaysBlock { vec4 crep_regionRays[]; } of the local-light
/// prefilter (index row * R + region): xyz the region's reference ray direction (unit), w its distance from
/// the camera at the region's start, t(0) of the region's DistanceProfile (+inf -> -1: beyond the horizon).
using RegionRay = glm::vec4;

/// std140 uniform block CrepEvaluateBlock of passes/prefilter/evaluate.comp: the camera whose depth buffer is
/// read.
struct EvaluateParams {
  glm::vec4 cameraPosition{0.0f};                   ///< xyz: world; w: near plane distance (world units)
  glm::vec4 cameraForward{0.0f, 0.0f, -1.0f, 0.0f}; ///< xyz: unit view direction; w: far plane distance
  glm::vec4 cameraRight{1.0f, 0.0f, 0.0f, 0.0f};    ///< xyz: right * tan(fovY / 2) * aspect; w: 0
  glm::vec4 cameraUp{0.0f, 1.0f, 0.0f, 0.0f};       ///< xyz: up * tan(fovY / 2); w: 0
  glm::ivec4 imageSize{0};                          ///< xy: output size (pixels); zw: 0
  /// xyz: (cx right + cy up) for an off-centre image (Camera::tangents' centre); w: 0
  glm::vec4 cameraCenter{0.0f};
  /// The camera's depth convention (crep_cameraViewDepth): x near, y projection far (0 = infinite), z
  /// integration far, w 1 = reversed-Z
  glm::vec4 cameraDepth{0.0f};
};
static_assert(sizeof(EvaluateParams) == 112, "std140 layout of CrepEvaluateParams");

} // namespace crep::gpu
