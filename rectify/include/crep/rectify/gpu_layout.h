// The GPU description of a rectified layout (glsl/crep/layout.glsl, CREP_LAYOUT = LayoutKind): a std140
// block and an optional std430 row table, uploaded without knowing the layout (rectify/README.md,
// "gpu_layout.h").
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace crep {

class ProjectiveLayout; // crep/rectify/rectified_map.h

namespace gpu {

/// Largest number of layout regions the blocks hold (= RectifyOptions::kMaxSplits).
inline constexpr int kMaxLayoutRegions = 64;

/// The value of CREP_LAYOUT in glsl/crep/layout.glsl.
enum class LayoutKind : std::int32_t {
  Projective = 0, ///< crep::ProjectiveLayout
  Epipolar = 1,   ///< crep::EpipolarLayout
};

/// std140 block CrepProjectiveLayoutBlock { CrepProjectiveLayoutParams crep_projective; } (CREP_LAYOUT 0).
struct ProjectiveLayoutParams {
  glm::vec4 origin{0.0f}; ///< xyz: camera position (world); w: rho = 1 / |camera - light| (0: directional)
  glm::vec4 axisX{1.0f, 0.0f, 0.0f, 0.0f};  ///< xyz: projection axis (unit); w: 0
  glm::vec4 axisY{0.0f, 1.0f, 0.0f, 0.0f};  ///< xyz: axisZ x axisX; w: 0
  glm::vec4 axisZ{0.0f, 0.0f, 1.0f, 0.0f};  ///< xyz: direction light travels at the camera; w: 0
  glm::vec4 slopes{0.0f, 1.0f, 0.0f, 1.0f}; ///< row slope min, max, depth slope min, max
  glm::ivec4 counts{1, 0, 0, 0};            ///< x: layout regions (splits) K; yzw: 0
  glm::vec4 splitZeta[kMaxLayoutRegions]{}; ///< split k < K: x zetaBegin, y zetaEnd (1/world unit); zw 0
};
static_assert(sizeof(ProjectiveLayoutParams) == 16 * (6 + kMaxLayoutRegions),
              "std140 CrepProjectiveLayoutParams");

/// The block of a projective layout; InvalidArgument "ProjectiveLayout.regionCount" beyond kMaxLayoutRegions.
ProjectiveLayoutParams makeProjectiveLayoutParams(const ProjectiveLayout& layout);

} // namespace gpu

/// A layout serialized for the GPU (RectifiedLayout::gpuLayoutData()).
struct GpuLayoutData {
  gpu::LayoutKind kind = gpu::LayoutKind::Projective;
  std::vector<std::byte> block; ///< the std140 layout block (CREP_LAYOUT_BINDING)
  std::vector<std::byte> rows;  ///< std430 per-row table (CREP_SLICES_BINDING), empty if the layout has none
  int rowCount = 0;             ///< rows of the table: the map height the layout requires, 0 = any
  int regionCount = 0;          ///< the layout's regionCount()
};

} // namespace crep
