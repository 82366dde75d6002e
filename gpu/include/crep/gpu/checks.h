// A pass's checks of its inputs, on any backend and in the seam's own terms (gpu::TextureType, gpu::Format):
// what a texture or buffer an engine hands over is, and InvalidArgument naming the parameter when it is not
// what the pass reads or writes. On OpenGL they ask GL itself (an engine's texture may be in any GL format),
// so the messages are GL's there (gl::requireTexture2D and its siblings, crep/gpu/gl.h); on every other
// backend they use Backend::describe() and bufferBytes(), and no message names a GL type or enum.
#pragma once

#include <cstddef>
#include <initializer_list>
#include <optional>
#include <string>

#include <crep/gpu/backend.h>

namespace crep::gpu {

/// Level 0 of a texture as the checks see it.
struct TextureLevel {
  TextureType type = TextureType::Texture2D;
  int width = 0;  ///< texels
  int height = 0; ///< texels
  int depth = 1;  ///< layers (Texture2DArray), slices (Texture3D); 1 for Texture2D
  /// Its format when it is one of gpu::Format; empty for any other (on OpenGL an engine's texture may be,
  /// e.g., a 24-bit depth or a 16-bit float format).
  std::optional<Format> format;
  bool isDepth = false; ///< a depth format (Depth32F; on OpenGL any depth format)
};

/// The name of `format` in messages ("RGBA32F", ...).
const char* formatName(Format format);

/// A pass's check that it was not moved from (its backend pointer is then null): InvalidArgument naming
/// `owner` ("EvaluatePass", ...).
void requireNotMovedFrom(const Backend* backend, const char* owner);

/// InvalidArgument naming `parameter` for sizes <= 0 or beyond backend.maxTextureSize() (on OpenGL a
/// GlError naming GL_MAX_TEXTURE_SIZE, as gl::checkTextureSize).
void checkTextureSize(const Backend& backend, const char* parameter, int width, int height);

/// A request beyond a device limit: on OpenGL a GlError "<parameter> = <value> exceeds <glLimit> = <limit>"
/// (the limit as GL names it, e.g. GL_MAX_ARRAY_TEXTURE_LAYERS), elsewhere an InvalidArgument naming
/// `parameter` and the limit in the seam's words (`limitName`, e.g. "array layers").
[[noreturn]] void throwBeyondLimit(const Backend& backend, const std::string& parameter,
                                   const std::string& value, const std::string& glLimit,
                                   const std::string& limitName, long long limit);

/// InvalidArgument naming `parameter` unless `texture` is a 2D texture of the backend, width x height, in
/// one of `formats`.
void requireTexture(const Backend& backend, const char* parameter, TextureId texture, int width, int height,
                    std::initializer_list<Format> formats);

/// Level 0 of `texture`; InvalidArgument naming `parameter` if it is 0 or no texture of the backend.
TextureLevel textureLevelOf(const Backend& backend, const char* parameter, TextureId texture);
/// textureLevelOf(), and InvalidArgument naming `parameter` unless it is a 2D texture (any size).
TextureLevel requireTexture2DOf(const Backend& backend, const char* parameter, TextureId texture);
/// InvalidArgument naming `parameter` unless `texture` is a 2D texture of width x height (> 0) and, when
/// `format` is given, of that format.
void requireTexture2DOf(const Backend& backend, const char* parameter, TextureId texture, int width,
                        int height, std::optional<Format> format = std::nullopt);
/// InvalidArgument naming `parameter` unless `texture` reads as depth: a depth format (on OpenGL sampled as
/// depth) or R32F (camera depth, shadow and rectified maps).
void requireDepthFormatOf(const Backend& backend, const char* parameter, TextureId texture);
/// InvalidArgument naming `parameter` (with `requirement`) unless `buffer` is a buffer of the backend;
/// returns its size in bytes.
std::size_t requireBufferOf(const Backend& backend, const char* parameter, BufferId buffer,
                            const std::string& requirement);

} // namespace crep::gpu
