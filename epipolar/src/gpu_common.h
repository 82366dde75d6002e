// Private GL helper of the epipolar/ passes: the layout upload. Samplers, buffers, input checks and the
// state reset are core's (crep/core/gl.h).
#pragma once

#include <crep/core/error.h>
#include <crep/core/gl.h>
#include <crep/epipolar/gpu_layout.h>
#include <crep/rectify/rectified_map.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <cstddef>

namespace crep::epipolar_detail {

/// Size of the layout uniform buffer: the largest layout block.
inline constexpr std::size_t kLayoutBlockSize =
    std::max(sizeof(gpu::ProjectiveLayoutParams), sizeof(gpu::EpipolarLayoutParams));

/// Uploads the layout block (and, for the epipolar layout, the per-slice table) of `layout`.
void uploadLayout(const RectifiedLayout& layout, gpu::LayoutKind kind, int mapHeight, gl::Handle& block,
                  gl::Handle& slices);

} // namespace crep::epipolar_detail
