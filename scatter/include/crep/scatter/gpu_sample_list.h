// GPU work lists: texels to evaluate, produced on the GPU by one pass and consumed by another through an
// indirect dispatch (no read-back). Epipolar sampling (Yusov 2012, Sec. 6.4 and 6.7) selects its ray-marching
// samples and the pixels to correct this way; any evaluator (the min/max march of epipolar/, the prefiltered
// evaluation of prefilter/) then runs on exactly those texels. Yusov marks them in a stencil buffer; a
// compacted list is the compute-shader equivalent and keeps a real GPU's waves full (no idle lanes for
// texels that are not selected). GLSL twin: glsl/crep/sample_list.glsl.
//
// Buffer layout (GL_SHADER_STORAGE_BUFFER, std430):
//   uint x, y, z groups              glDispatchComputeIndirect arguments at offset 0 (groups of
//                                    kSampleListGroupSize threads; y = z = 1)
//   uint count                       entries appended
//   uint entries[capacity]           texel x | y << 16 of `coordinates` and `output`
// Texels: `coordinates` (GL_RGBA32F, width x height) holds per texel (x, y: the camera-image pixel
// coordinates of the point to evaluate, origin at the bottom-left corner, pixel centres at + 0.5; d: the
// depth-buffer value of the ray's surface; z: its view depth); the evaluator writes texel (x, y) of each
// entry of `output` (GL_RGBA32F, the same size: RGB in-scattered radiance, A grey transmittance,
// crep/scatter/ray.h's convention) and nothing else.
#pragma once

#include <cstdint>
#include <string>

#include <crep/core/gl.h>

namespace crep::gpu {

/// Threads per work group of a list consumer (and the unit of the header's x group count).
inline constexpr int kSampleListGroupSize = 64;
/// Bytes of the header (the three group counts and the entry count).
inline constexpr int kSampleListHeaderBytes = 16;

/// A list of texels to evaluate (see top). Non-owning GL names.
struct SampleList {
  std::uint32_t buffer = 0;      ///< the list (layout at the top)
  std::uint32_t coordinates = 0; ///< GL_RGBA32F width x height: (x, y, d, z) per texel
  std::uint32_t output = 0;      ///< GL_RGBA32F width x height: written at the entries
  int width = 0, height = 0;     ///< of coordinates and output (each <= 65535)
  int capacity = 0;              ///< entries the buffer holds (width * height)
};

/// A buffer for `capacity` entries (> 0), header cleared.
gl::Handle createSampleListBuffer(int capacity);
/// Resets the header to (0, 1, 1, 0): an empty list, before the producer's pass.
void clearSampleList(std::uint32_t buffer);
/// Binds `buffer` as GL_DISPATCH_INDIRECT_BUFFER, issues glDispatchComputeIndirect(0) for the bound
/// program and unbinds it. The producer must have issued GL_COMMAND_BARRIER_BIT |
/// GL_SHADER_STORAGE_BARRIER_BIT.
void dispatchSampleList(std::uint32_t buffer);
/// Reads `count` back (a GPU sync: for tests and statistics).
int sampleListCount(std::uint32_t buffer);
/// A consumer's check of the list it is given (e.g. owner = "EvaluatePass::FrameAttribs.list"): throws
/// InvalidArgument naming owner + ".buffer" unless the buffer is an existing buffer object, owner +
/// ".coordinates" / ".output" unless those are GL_RGBA32F textures of width x height.
void validateSampleList(const SampleList& list, const std::string& owner);
/// The camera image size a list consumer maps its entries with: imageWidth x imageHeight when either is
/// set (both must be > 0: InvalidArgument owner + ".imageWidth/imageHeight"), else the size of the
/// cameraDepth texture (gl::requireTexture2D, owner + ".cameraDepth").
gl::TextureLevel listImageSize(int imageWidth, int imageHeight, std::uint32_t cameraDepth,
                               const std::string& owner);

} // namespace crep::gpu
