// Upload of a layout's GPU description (crep/scatter/gpu_layout_buffers.h).
#include <crep/core/error.h>
#include <crep/gpu/gl_backend.h>
#include <crep/scatter/gpu_layout_buffers.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <string>
#include <utility>

namespace crep::gpu {

namespace {
// The uniform block is sized for the largest layout block the GLSL declares.
constexpr std::size_t kMaxBlockBytes = 16 * (16 + kMaxLayoutRegions);
} // namespace

GpuLayoutData requireGpuLayout(const RectifiedLayout& layout, const char* parameter) {
  std::optional<GpuLayoutData> data = layout.gpuLayoutData();
  if (!data)
    throw InvalidArgument(parameter, "a RectifiedLayout without GPU mapping",
                          "must be a ProjectiveLayout or an EpipolarLayout");
  return std::move(*data);
}

LayoutKind LayoutBuffers::upload(const RectifiedLayout& layout, int mapHeight, const char* parameter) {
  return upload(requireGpuLayout(layout, parameter), mapHeight, parameter);
}

void LayoutBuffers::requireUploadable(const GpuLayoutData& d, int mapHeight, const char* parameter) {
  if (d.regionCount > kMaxLayoutRegions)
    throw InvalidArgument(parameter, "regionCount() " + std::to_string(d.regionCount),
                          "must be <= " + std::to_string(kMaxLayoutRegions) + " on the GPU");
  if (d.rowCount != 0 && d.rowCount != mapHeight)
    throw InvalidArgument("mapHeight", std::to_string(mapHeight),
                          "must be the layout's row count " + std::to_string(d.rowCount) +
                              " (an EpipolarLayout's slice count)");
  if (d.block.size() > kMaxBlockBytes)
    throw InvalidArgument(parameter, std::to_string(d.block.size()) + " bytes of layout block",
                          "must be <= " + std::to_string(kMaxBlockBytes));
}

LayoutKind LayoutBuffers::upload(const GpuLayoutData& d, int mapHeight, const char* parameter) {
  requireUploadable(d, mapHeight, parameter);
  if (backend_ == nullptr) backend_ = &givenOrGl(nullptr, ownBackend_); // at the first upload: GL is current
  if (!block_) block_ = Buffer(*backend_, kMaxBlockBytes, "LayoutBuffers: layout block");
  backend_->writeBuffer(block_.id(), 0, std::as_bytes(std::span(d.block)));
  hasRows_ = !d.rows.empty();
  if (hasRows_) {
    // An epipolar layout's slice count changes per frame.
    writeGrowing(*backend_, rows_, d.rows, "LayoutBuffers: row table");
  }
  kind_ = d.kind;
  return kind_;
}

void LayoutBuffers::bind(std::uint32_t blockBinding, std::uint32_t rowsBinding) const {
  glBindBufferBase(GL_UNIFORM_BUFFER, blockBinding, block_.id());
  if (hasRows_) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, rowsBinding, rows_.id());
}

void LayoutBuffers::appendResources(std::vector<Resource>& out, std::uint32_t blockBinding,
                                    std::uint32_t rowsBinding) const {
  out.push_back(Resource::uniform(blockBinding, block_.id()));
  if (hasRows_) out.push_back(Resource::storage(rowsBinding, rows_.id())); // the whole buffer, as bind()
}

} // namespace crep::gpu
