// GPU work lists (Yusov 2012, Sec. 6.4 and 6.7): texels to evaluate, produced on the GPU by one pass and
// consumed by another through an indirect dispatch, no read-back. GLSL twin: glsl/crep/sample_list.glsl.
// Buffer layout and texel conventions: scatter/README.md, "crep/scatter/gpu_sample_list.h".
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include <crep/gpu/backend.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/gl.h>

namespace crep::gpu {

/// Threads per work group of a list consumer (and the unit of the header's x group count).
inline constexpr int kSampleListGroupSize = 64;
/// Bytes of the header (the three group counts and the entry count).
inline constexpr int kSampleListHeaderBytes = 16;

/// A list of texels to evaluate. Non-owning GL names.
struct SampleList {
  std::uint32_t buffer = 0;      ///< the list (std430 layout: README)
  std::uint32_t coordinates = 0; ///< GL_RGBA32F width x height: (x, y, d, z) per texel
  std::uint32_t output = 0;      ///< GL_RGBA32F width x height: written at the entries
  int width = 0, height = 0;     ///< of coordinates and output (each <= 65535)
  int capacity = 0;              ///< entries the buffer holds (width * height)
};

/// A buffer for `capacity` entries (> 0), header cleared.
gl::Handle createSampleListBuffer(int capacity);
/// Resets the header to (0, 1, 1, 0): an empty list, before the producer's pass.
void clearSampleList(std::uint32_t buffer);
/// glDispatchComputeIndirect of the bound program over the list. The producer must have issued
/// GL_COMMAND_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT.
void dispatchSampleList(std::uint32_t buffer);
/// Reads `count` back (a GPU sync: for tests and statistics).
int sampleListCount(std::uint32_t buffer);
/// The three above on any backend: a list buffer of `backend` (header cleared), its clear (in order with
/// the dispatches), and its count (a read-back: a GPU sync).
Buffer createSampleListBuffer(Backend& backend, int capacity, std::string_view label);
void clearSampleList(Backend& backend, BufferId buffer);
int sampleListCount(Backend& backend, BufferId buffer);
/// A consumer's check: InvalidArgument naming owner + ".buffer", ".coordinates" or ".output".
void validateSampleList(const SampleList& list, const std::string& owner);
/// The camera image size a consumer maps entries with: imageWidth x imageHeight when set (both > 0),
/// else cameraDepth's size. InvalidArgument naming owner + ".imageWidth/imageHeight" or ".cameraDepth".
gpu::TextureLevel listImageSize(int imageWidth, int imageHeight, std::uint32_t cameraDepth,
                                const std::string& owner);
/// The two checks above for a list of `backend`'s objects (on a GlBackend, the same checks); the buffer
/// must also hold the header and `capacity` entries.
void validateSampleList(const Backend& backend, const SampleList& list, const std::string& owner);
gpu::TextureLevel listImageSize(const Backend& backend, int imageWidth, int imageHeight,
                                std::uint32_t cameraDepth, const std::string& owner);

} // namespace crep::gpu
