// std140 / std430 blocks of the epipolar layout, twins of glsl/crep/layout.glsl ("Crep" prefix; offsets
// checked by a GL test). How an engine shader binds them: epipolar/README.md, "crep/epipolar/gpu_layout.h".
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

/// std140 twin of CrepEpipolarLayoutParams (CREP_LAYOUT 1): crep::EpipolarLayout's geometry.
struct EpipolarLayoutParams {
  glm::vec4 origin{
      0.0f}; ///< xyz: camera position (world); w: D = |light - camera| (local light), 0 (directional)
  glm::vec4 towardLight{0.0f, 1.0f, 0.0f, 0.0f}; ///< xyz: m = -light direction (unit); w: 0
  glm::vec4 imageX{1.0f, 0.0f, 0.0f, 0.0f};      ///< xyz: camera right / (tan(fovY / 2) aspect)
  glm::vec4 imageY{0.0f, 1.0f, 0.0f, 0.0f};      ///< xyz: camera up / tan(fovY / 2)
  glm::vec4 forward{0.0f, 0.0f, -1.0f, 0.0f};    ///< xyz: camera forward (unit); w: 0
  glm::vec4 cameraTan{1.0f};                     ///< x: tan(fovY / 2) aspect, y: tan(fovY / 2); zw: 0
  glm::vec4 border{0.0f}; ///< x: screen width, y: height (pixels), z: perimeter P, w: 0
  glm::vec4 arc{
      0.0f}; ///< x: arcBegin, y: arcLength (border pixels), z: 1 = exit at the larger psi, 0 = smaller
  glm::ivec4 counts{0}; ///< x: slices H, y: regions K; zw: 0
  /// f_k (EpipolarLayout::regionFractions()) in element k / 4, component k % 4, k = 0..K.
  glm::vec4 regionFractions[kMaxLayoutRegions / 4 + 1]{};
};
static_assert(sizeof(EpipolarLayoutParams) == 16 * (9 + kMaxLayoutRegions / 4 + 1),
              "std140 CrepEpipolarLayoutParams");

/// std430 twin of CrepEpipolarSlice: one slice (texel row).
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

/// Throws InvalidArgument naming `parameter` unless W is a multiple of the layout's region count and,
/// for an EpipolarLayout, H its slice count.
void requireMapSize(const RectifiedLayout& layout, int width, int height, const std::string& parameter);

} // namespace crep::gpu
