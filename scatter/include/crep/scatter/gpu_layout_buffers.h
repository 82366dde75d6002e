// Upload of any rectified layout's GPU description (crep/rectify/gpu_layout.h) into GL buffers, for the
// passes that map pixels into a rectified map. Requires a current OpenGL 4.5 context; owns its buffers.
#pragma once

#include <cstdint>

#include <crep/core/gl.h>
#include <crep/rectify/rectified_map.h>

namespace crep::gpu {

/// `layout`'s GPU description; throws InvalidArgument naming `parameter` when it has no GPU mapping.
GpuLayoutData requireGpuLayout(const RectifiedLayout& layout, const char* parameter = "layout");

class LayoutBuffers {
public:
  /// Uploads `layout`'s block and row table for a map of `mapHeight` rows; returns its kind (CREP_LAYOUT).
  /// Throws InvalidArgument naming `parameter` (README). Per frame, O(rows).
  LayoutKind upload(const RectifiedLayout& layout, int mapHeight, const char* parameter = "layout");
  /// The same for a description already made with requireGpuLayout() (a layout is serialized once per run).
  LayoutKind upload(const GpuLayoutData& data, int mapHeight, const char* parameter = "layout");
  /// Throws InvalidArgument as upload() does for `data` and `mapHeight`, without uploading.
  static void requireUploadable(const GpuLayoutData& data, int mapHeight, const char* parameter = "layout");
  /// Binds the block at uniform buffer `blockBinding` and any row table at storage buffer `rowsBinding`.
  void bind(std::uint32_t blockBinding, std::uint32_t rowsBinding) const;
  LayoutKind kind() const noexcept { return kind_; }

private:
  LayoutKind kind_ = LayoutKind::Projective;
  bool hasRows_ = false;
  gl::Handle block_, rows_;
  std::size_t rowsCapacity_ = 0;
};

} // namespace crep::gpu
