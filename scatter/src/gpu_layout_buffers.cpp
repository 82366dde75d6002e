// Upload of a layout's GPU description (crep/scatter/gpu_layout_buffers.h).
#include <crep/core/error.h>
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

LayoutKind LayoutBuffers::upload(const GpuLayoutData& d, int mapHeight, const char* parameter) {
  const GpuLayoutData* data = &d;
  if (data->regionCount > kMaxLayoutRegions)
    throw InvalidArgument(parameter, "regionCount() " + std::to_string(data->regionCount),
                          "must be <= " + std::to_string(kMaxLayoutRegions) + " on the GPU");
  if (data->rowCount != 0 && data->rowCount != mapHeight)
    throw InvalidArgument("mapHeight", std::to_string(mapHeight),
                          "must be the layout's row count " + std::to_string(data->rowCount) +
                              " (an EpipolarLayout's slice count)");
  if (data->block.size() > kMaxBlockBytes)
    throw InvalidArgument(parameter, std::to_string(data->block.size()) + " bytes of layout block",
                          "must be <= " + std::to_string(kMaxBlockBytes));
  if (!block_) block_ = gl::createDynamicBuffer(kMaxBlockBytes);
  glNamedBufferSubData(block_.get(), 0, static_cast<GLsizeiptr>(data->block.size()), data->block.data());
  hasRows_ = !data->rows.empty();
  if (hasRows_) {
    gl::uploadGrowingBuffer(rows_, rowsCapacity_, data->rows.data(), data->rows.size());
  }
  kind_ = data->kind;
  return kind_;
}

void LayoutBuffers::bind(std::uint32_t blockBinding, std::uint32_t rowsBinding) const {
  glBindBufferBase(GL_UNIFORM_BUFFER, blockBinding, block_.get());
  if (hasRows_) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, rowsBinding, rows_.get());
}

} // namespace crep::gpu
