// Blocks shared between the epipolar/ GPU passes (gpu_march.h, resample.h) and their shaders. Each struct
// has a GLSL twin with the same name prefixed "Crep" in glsl/crep/layout.glsl, laid out by std140 (uniform
// blocks) or std430 (storage buffers): 16-byte vectors and matrices only, int instead of bool, a
// static_assert on the size. tests/epipolar/EpipolarGLTest.cpp ("uniform and storage blocks match their C++
// structs") compares every member offset with the offsets the driver reports for the linked shaders.
//
// A shader of an engine that maps pixels into a rectified map (e.g. to evaluate the prefiltered scattering
// on the epipolar fallback layout) includes "crep/layout.glsl" with CREP_LAYOUT set, and binds a uniform
// buffer holding makeProjectiveLayoutParams(layout) or makeEpipolarLayoutParams(layout) at
// CREP_LAYOUT_BINDING (plus, for the epipolar layout, a storage buffer holding makeEpipolarSlices(layout) at
// CREP_SLICES_BINDING); gpu::LayoutBuffers (crep/scatter/gpu_layout_buffers.h) does both for any layout.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/rectify/gpu_layout.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/gpu_world_march.h>

namespace crep {
class EpipolarLayout; // crep/epipolar/epipolar.h
} // namespace crep

namespace crep::gpu {

/// std140 block CrepEpipolarLayoutBlock { CrepEpipolarLayoutParams crep_epipolar; } (CREP_LAYOUT 1): the
/// geometry of crep::EpipolarLayout (epipolar.h); the per-slice bounds are in the storage buffer below.
struct EpipolarLayoutParams {
  glm::vec4 origin{
      0.0f}; ///< xyz: camera position (world); w: D = |light - camera| (local light), 0 (directional)
  glm::vec4 towardLight{0.0f, 1.0f, 0.0f, 0.0f}; ///< xyz: m = -light direction (unit); w: 0
  glm::vec4 imageX{
      1.0f, 0.0f, 0.0f,
      0.0f}; ///< xyz: camera right / (tan(fovY / 2) aspect): NDC x = dot(w, imageX) / dot(w, forward)
  glm::vec4 imageY{0.0f, 1.0f, 0.0f, 0.0f};   ///< xyz: camera up / tan(fovY / 2)
  glm::vec4 forward{0.0f, 0.0f, -1.0f, 0.0f}; ///< xyz: camera forward (unit); w: 0
  glm::vec4 cameraTan{1.0f};                  ///< x: tan(fovY / 2) aspect, y: tan(fovY / 2); zw: 0
  glm::vec4 border{0.0f};                     ///< x: screen width, y: height (pixels), z: perimeter P, w: 0
  glm::vec4 arc{
      0.0f}; ///< x: arcBegin, y: arcLength (border pixels), z: 1 = exit at the larger psi, 0 = smaller
  glm::ivec4 counts{0}; ///< x: slices H, y: regions K; zw: 0
  /// Region boundary f_k (b / bMax, EpipolarLayout::regionFractions()) in element k / 4, component k % 4,
  /// k = 0..K.
  glm::vec4 regionFractions[kMaxLayoutRegions / 4 + 1]{};
};
static_assert(sizeof(EpipolarLayoutParams) == 16 * (9 + kMaxLayoutRegions / 4 + 1),
              "std140 CrepEpipolarLayoutParams");

/// std430 element of CrepEpipolarSlicesBlock { CrepEpipolarSlice crep_slices[]; }: one slice (texel row).
struct EpipolarSlice {
  /// x: bMax (world units; local light: thetaMax, radians), y: g(psiMin), z: g(psiMax) (the depth warp), w: 0
  glm::vec4 bounds{0.0f};
};
static_assert(sizeof(EpipolarSlice) == 16, "std430 CrepEpipolarSlice");

/// The block and the slice table of an epipolar layout.
EpipolarLayoutParams makeEpipolarLayoutParams(const EpipolarLayout& layout);
std::vector<EpipolarSlice> makeEpipolarSlices(const EpipolarLayout& layout);

/// Which GLSL layout implements `layout` (its gpuLayoutData().kind); throws InvalidArgument ("layout") for
/// a RectifiedLayout without GPU mapping.
LayoutKind layoutKind(const RectifiedLayout& layout);

/// The check every pass that reads a W x H map of `layout` makes: W a multiple of the layout's region count,
/// and H its slice count for an EpipolarLayout. Throws InvalidArgument naming `parameter` (e.g.
/// "RectifiedMarchPass::CreateInfo.mapWidth/mapHeight") otherwise.
void requireMapSize(const RectifiedLayout& layout, int width, int height, const std::string& parameter);

} // namespace crep::gpu
