// A pass's checks of its inputs on any backend (crep/gpu/checks.h): GL's own queries on the GL backend,
// Backend::describe() / bufferBytes() elsewhere.
#include <crep/core/error.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/gl.h>
#include <crep/gpu/gl_backend.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <string>

namespace crep::gpu {

namespace {

bool onGl(const Backend& backend) {
  return backend.kind() == BackendKind::OpenGL;
}

std::string sizeText(int width, int height) {
  return std::to_string(width) + " x " + std::to_string(height);
}

} // namespace

const char* formatName(Format format) {
  switch (format) {
  case Format::R32F:
    return "R32F";
  case Format::RG32F:
    return "RG32F";
  case Format::RGBA32F:
    return "RGBA32F";
  case Format::RGBA16F:
    return "RGBA16F";
  case Format::Depth32F:
    return "Depth32F";
  case Format::RGBA8:
    return "RGBA8";
  case Format::RG32I:
    return "RG32I";
  }
  return "unknown";
}

void requireNotMovedFrom(const Backend* backend, const char* owner) {
  if (backend == nullptr)
    throw InvalidArgument(owner, "a moved-from object",
                          "owns no GPU objects: assign a constructed one first");
}

void checkTextureSize(const Backend& backend, const char* parameter, int width, int height) {
  if (onGl(backend)) return gl::checkTextureSize(parameter, width, height);
  if (width <= 0 || height <= 0)
    throw InvalidArgument(parameter, sizeText(width, height), "width and height must be > 0");
  const int limit = backend.maxTextureSize();
  if (width > limit || height > limit)
    throw InvalidArgument(parameter, sizeText(width, height),
                          "must not exceed the " + std::string(backend.name()) +
                              " device's maximum texture size " + std::to_string(limit));
}

void throwBeyondLimit(const Backend& backend, const std::string& parameter, const std::string& value,
                      const std::string& glLimit, const std::string& limitName, long long limit) {
  if (onGl(backend))
    throw GlError(parameter + " = " + value + " exceeds " + glLimit + " = " + std::to_string(limit));
  throw InvalidArgument(parameter, value,
                        "exceeds the " + std::string(backend.name()) + " device's " + limitName + " (" +
                            std::to_string(limit) + ")");
}

void requireTexture(const Backend& backend, const char* parameter, TextureId texture, int width, int height,
                    std::initializer_list<Format> formats) {
  if (texture == 0) throw InvalidArgument(parameter, "0", "must be a texture");
  const TextureDesc d = backend.describe(texture);
  if (d.type != TextureType::Texture2D || d.width != width || d.height != height)
    throw InvalidArgument(parameter, sizeText(d.width, d.height),
                          "must be a 2D texture of " + sizeText(width, height));
  if (std::find(formats.begin(), formats.end(), d.format) == formats.end())
    throw InvalidArgument(parameter, std::string("format ") + formatName(d.format),
                          "has a format the pass cannot read");
}

TextureLevel textureLevelOf(const Backend& backend, const char* parameter, TextureId texture) {
  if (onGl(backend)) return textureLevelFromGl(gl::textureLevel(parameter, texture));
  if (texture == 0) throw InvalidArgument(parameter, "0", "must be a texture");
  TextureDesc d;
  try {
    d = backend.describe(texture);
  } catch (const InvalidArgument&) {
    throw InvalidArgument(parameter, std::to_string(texture),
                          "must be a texture of the pass's " + std::string(backend.name()) + " backend");
  }
  TextureLevel level;
  level.type = d.type;
  level.width = d.width;
  level.height = d.height;
  level.depth = d.depth;
  level.format = d.format;
  level.isDepth = d.format == Format::Depth32F;
  return level;
}

TextureLevel requireTexture2DOf(const Backend& backend, const char* parameter, TextureId texture) {
  if (onGl(backend)) return textureLevelFromGl(gl::requireTexture2D(parameter, texture));
  const TextureLevel level = textureLevelOf(backend, parameter, texture);
  requireTexture2DOf(backend, parameter, texture, level.width, level.height);
  return level;
}

void requireTexture2DOf(const Backend& backend, const char* parameter, TextureId texture, int width,
                        int height, std::optional<Format> format) {
  if (onGl(backend))
    return gl::requireTexture2D(parameter, texture, width, height, format ? glInternalFormat(*format) : 0u);
  if (width <= 0 || height <= 0)
    throw InvalidArgument(parameter, sizeText(width, height), "size must be > 0");
  const TextureLevel level = textureLevelOf(backend, parameter, texture);
  if (level.type != TextureType::Texture2D)
    throw InvalidArgument(parameter, "texture " + std::to_string(texture), "must be a 2D texture");
  if (level.width != width || level.height != height)
    throw InvalidArgument(parameter, "texture of " + sizeText(level.width, level.height),
                          "must be " + sizeText(width, height));
  if (format && level.format != format)
    throw InvalidArgument(parameter, "texture " + std::to_string(texture),
                          std::string("must be ") + formatName(*format));
}

void requireDepthFormatOf(const Backend& backend, const char* parameter, TextureId texture) {
  if (onGl(backend)) return gl::requireDepthFormat(parameter, texture);
  const TextureLevel level = textureLevelOf(backend, parameter, texture);
  if (!level.isDepth && level.format != Format::R32F)
    throw InvalidArgument(parameter, "texture " + std::to_string(texture),
                          "must be a depth (Depth32F) or R32F texture");
}

std::size_t requireBufferOf(const Backend& backend, const char* parameter, BufferId buffer,
                            const std::string& requirement) {
  if (onGl(backend)) return static_cast<std::size_t>(gl::requireBuffer(parameter, buffer, requirement));
  if (buffer == 0) throw InvalidArgument(parameter, "0", requirement);
  try {
    return backend.bufferBytes(buffer);
  } catch (const InvalidArgument&) {
    throw InvalidArgument(parameter, std::to_string(buffer),
                          requirement + " (a buffer of the pass's " + std::string(backend.name()) +
                              " backend)");
  }
}

} // namespace crep::gpu
