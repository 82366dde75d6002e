// Upload of any rectified layout's GPU description (crep/rectify/gpu_layout.h) into buffers of a
// gpu::Backend, for the passes that map pixels into a rectified map. Owns its buffers.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <crep/gpu/backend.h>
#include <crep/gpu/gl.h>
#include <crep/rectify/rectified_map.h>

namespace crep::gpu {

/// `layout`'s GPU description; throws InvalidArgument naming `parameter` when it has no GPU mapping.
GpuLayoutData requireGpuLayout(const RectifiedLayout& layout, const char* parameter = "layout");

class LayoutBuffers {
public:
  /// Buffers of `backend` (must outlive this); null: a gpu::GlBackend of its own on the current GL context,
  /// made at the first upload.
  explicit LayoutBuffers(Backend* backend = nullptr) : backend_(backend) {}
  /// Uploads `layout`'s block and row table for a map of `mapHeight` rows; returns its kind (CREP_LAYOUT).
  /// Throws InvalidArgument naming `parameter` (README). Per frame, O(rows).
  LayoutKind upload(const RectifiedLayout& layout, int mapHeight, const char* parameter = "layout");
  /// The same for a description already made with requireGpuLayout() (a layout is serialized once per run).
  LayoutKind upload(const GpuLayoutData& data, int mapHeight, const char* parameter = "layout");
  /// Throws InvalidArgument as upload() does for `data` and `mapHeight`, without uploading.
  static void requireUploadable(const GpuLayoutData& data, int mapHeight, const char* parameter = "layout");
  /// GL passes: binds the block at uniform buffer `blockBinding` and any row table at storage buffer
  /// `rowsBinding` (the GL backend's buffers).
  void bind(std::uint32_t blockBinding, std::uint32_t rowsBinding) const;
  /// Passes on the seam: the block at `blockBinding` and any row table at `rowsBinding`, appended to `out`.
  void appendResources(std::vector<Resource>& out, std::uint32_t blockBinding,
                       std::uint32_t rowsBinding) const;
  LayoutKind kind() const noexcept { return kind_; }

private:
  Backend* backend_ = nullptr;
  std::unique_ptr<Backend> ownBackend_;
  LayoutKind kind_ = LayoutKind::Projective;
  bool hasRows_ = false;
  Buffer block_, rows_;
};

} // namespace crep::gpu
