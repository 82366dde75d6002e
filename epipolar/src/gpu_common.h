// Private GL helpers of the epipolar/ passes: samplers, buffers, input checks, the layout upload, state
// reset (the contract of crep/epipolar/gpu_march.h).
#pragma once

#include <crep/core/error.h>
#include <crep/core/gl.h>
#include <crep/epipolar/gpu_layout.h>
#include <crep/rectify/rectified_map.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <string>

namespace crep::epipolar_detail {

/// Size of the layout uniform buffer: the largest layout block.
inline constexpr std::size_t kLayoutBlockSize =
    std::max(sizeof(gpu::ProjectiveLayoutParams), sizeof(gpu::EpipolarLayoutParams));

/// Nearest filtering, clamp to edge, no depth comparison: texelFetch reads the raw depth values.
inline gl::Handle createNearestSampler() {
  gl::Handle s = gl::createSampler();
  glSamplerParameteri(s.get(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glSamplerParameteri(s.get(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glSamplerParameteri(s.get(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(s.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(s.get(), GL_TEXTURE_COMPARE_MODE, GL_NONE);
  return s;
}

inline gl::Handle createUniformBuffer(std::size_t bytes) {
  gl::Handle b = gl::createBuffer();
  glNamedBufferStorage(b.get(), static_cast<GLsizeiptr>(bytes), nullptr, GL_DYNAMIC_STORAGE_BIT);
  return b;
}

/// Throws InvalidArgument naming `parameter` unless `texture` is a 2D texture of width x height (and of
/// internal format `format` when it is not 0).
inline void requireTexture(const char* parameter, std::uint32_t texture, int width, int height,
                           GLenum format = 0) {
  if (width <= 0 || height <= 0)
    throw InvalidArgument(parameter, std::to_string(width) + " x " + std::to_string(height),
                          "size must be > 0");
  if (texture == 0 || !glIsTexture(texture))
    throw InvalidArgument(parameter, std::to_string(texture), "must be the name of an existing texture");
  GLint w = 0, h = 0, f = 0;
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_WIDTH, &w);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_HEIGHT, &h);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_INTERNAL_FORMAT, &f);
  if (w != width || h != height)
    throw InvalidArgument(parameter, "texture of " + std::to_string(w) + " x " + std::to_string(h),
                          "must be " + std::to_string(width) + " x " + std::to_string(height));
  if (format != 0 && static_cast<GLenum>(f) != format)
    throw InvalidArgument(
        parameter,
        "internal format 0x" +
            [f] {
              char buf[16];
              std::snprintf(buf, sizeof(buf), "%x", static_cast<unsigned>(f));
              return std::string(buf);
            }(),
        format == GL_RGBA32F ? "must be GL_RGBA32F" : "must be GL_R32F");
}

/// A GL_R32F texture of at least width x height owned by the pass, for a steps output the caller does
/// not want.
inline GLuint dummyR32F(gl::Handle& texture, int& w, int& h, int width, int height) {
  if (!texture || w < width || h < height) {
    w = std::max(w, width);
    h = std::max(h, height);
    texture = gl::createTexture(GL_TEXTURE_2D);
    glTextureStorage2D(texture.get(), 1, GL_R32F, w, h);
  }
  return texture.get();
}

/// Uploads the layout block (and, for the epipolar layout, the per-slice table) of `layout`.
void uploadLayout(const RectifiedLayout& layout, gpu::LayoutKind kind, int mapHeight, gl::Handle& block,
                  gl::Handle& slices);

inline void outputBarrier() {
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                  GL_TEXTURE_UPDATE_BARRIER_BIT | GL_PIXEL_BUFFER_BARRIER_BIT |
                  GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

/// The state the passes leave behind (gpu_march.h).
inline void unbindAll() {
  glUseProgram(0);
  for (GLuint unit = 0; unit < 2; ++unit) {
    glBindTextureUnit(unit, 0);
    glBindSampler(unit, 0);
    glBindImageTexture(unit, 0, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
    glBindBufferBase(GL_UNIFORM_BUFFER, unit, 0);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, unit, 0);
  }
}

} // namespace crep::epipolar_detail
