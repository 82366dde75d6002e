// GPU work lists (crep/scatter/gpu_sample_list.h).
#include <crep/core/error.h>
#include <crep/gpu/checks.h>
#include <crep/scatter/gpu_sample_list.h>

#include <crep/gpu/gl_backend.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <span>
#include <string>
#include <vector>

namespace crep::gpu {

gl::Handle createSampleListBuffer(int capacity) {
  if (capacity <= 0) throw InvalidArgument("SampleList.capacity", std::to_string(capacity), "must be > 0");
  gl::Handle buffer = gl::createBuffer();
  const GLsizeiptr bytes = kSampleListHeaderBytes + static_cast<GLsizeiptr>(capacity) * 4;
  glNamedBufferStorage(buffer.get(), bytes, nullptr, GL_DYNAMIC_STORAGE_BIT);
  clearSampleList(buffer.get());
  return buffer;
}

void clearSampleList(std::uint32_t buffer) {
  const std::array<GLuint, 4> header{0u, 1u, 1u, 0u};
  glNamedBufferSubData(buffer, 0, sizeof(header), header.data());
}

void dispatchSampleList(std::uint32_t buffer) {
  glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, buffer);
  glDispatchComputeIndirect(0);
  glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
}

int sampleListCount(std::uint32_t buffer) {
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  GLuint count = 0;
  glGetNamedBufferSubData(buffer, 12, sizeof(count), &count);
  return static_cast<int>(count);
}

Buffer createSampleListBuffer(Backend& backend, int capacity, std::string_view label) {
  if (capacity <= 0) throw InvalidArgument("SampleList.capacity", std::to_string(capacity), "must be > 0");
  Buffer buffer(backend, kSampleListHeaderBytes + static_cast<std::size_t>(capacity) * 4, label);
  clearSampleList(backend, buffer.id());
  return buffer;
}

void clearSampleList(Backend& backend, BufferId buffer) {
  const std::array<std::uint32_t, 4> header{0u, 1u, 1u, 0u}; // an empty list: x groups 0, y 1, z 1, count 0
  backend.writeBuffer(buffer, 0, std::as_bytes(std::span(header)));
}

int sampleListCount(Backend& backend, BufferId buffer) {
  const std::vector<std::byte> bytes = backend.readBuffer(buffer, 12, 4);
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data(), sizeof(count));
  return static_cast<int>(count);
}

void validateSampleList(const SampleList& list, const std::string& owner) {
  if (list.buffer == 0 || glIsBuffer(list.buffer) != GL_TRUE)
    throw InvalidArgument(owner + ".buffer", std::to_string(list.buffer),
                          "must name the list's buffer (gpu::createSampleListBuffer)");
  gl::requireTexture2D((owner + ".coordinates").c_str(), list.coordinates, list.width, list.height,
                       GL_RGBA32F);
  gl::requireTexture2D((owner + ".output").c_str(), list.output, list.width, list.height, GL_RGBA32F);
}

gpu::TextureLevel listImageSize(int imageWidth, int imageHeight, std::uint32_t cameraDepth,
                                const std::string& owner) {
  if (imageWidth == 0 && imageHeight == 0)
    return textureLevelFromGl(gl::requireTexture2D((owner + ".cameraDepth").c_str(), cameraDepth));
  if (imageWidth <= 0 || imageHeight <= 0)
    throw InvalidArgument(owner + ".imageWidth/imageHeight",
                          std::to_string(imageWidth) + " x " + std::to_string(imageHeight),
                          "must both be > 0 (or both 0: cameraDepth's size)");
  gpu::TextureLevel size;
  size.width = imageWidth;
  size.height = imageHeight;
  return size;
}

void validateSampleList(const Backend& backend, const SampleList& list, const std::string& owner) {
  if (backend.kind() == BackendKind::OpenGL) return validateSampleList(list, owner);
  const std::size_t bytes =
      requireBufferOf(backend, (owner + ".buffer").c_str(), list.buffer, "must name the list's buffer");
  const std::size_t needed = static_cast<std::size_t>(kSampleListHeaderBytes) +
                             static_cast<std::size_t>(std::max(list.capacity, 0)) * 4;
  if (list.capacity < 1 || bytes < needed)
    throw InvalidArgument(owner + ".buffer", std::to_string(list.buffer),
                          "must hold the header and capacity = " + std::to_string(list.capacity) +
                              " entries (capacity >= 1)");
  requireTexture2DOf(backend, (owner + ".coordinates").c_str(), list.coordinates, list.width, list.height,
                     gpu::Format::RGBA32F);
  requireTexture2DOf(backend, (owner + ".output").c_str(), list.output, list.width, list.height,
                     gpu::Format::RGBA32F);
}

gpu::TextureLevel listImageSize(const Backend& backend, int imageWidth, int imageHeight,
                                std::uint32_t cameraDepth, const std::string& owner) {
  if (backend.kind() == BackendKind::OpenGL || imageWidth != 0 || imageHeight != 0)
    return listImageSize(imageWidth, imageHeight, cameraDepth, owner);
  return requireTexture2DOf(backend, (owner + ".cameraDepth").c_str(), cameraDepth);
}

} // namespace crep::gpu
