// Small GL helpers shared by the passes, the scenes and the tests; GL names and enums are std::uint32_t (no
// loader header). Every function requires a current OpenGL 4.5 context (the caller's or GlContext).
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>

#include <crep/core/image.h>
#include <crep/gpu/shader_library.h>

namespace crep::gl {

enum class ObjectType {
  Texture,
  Buffer,
  Framebuffer,
  Renderbuffer,
  VertexArray,
  Program,
  Shader,
  Query,
  Sampler
};

/// Move-only owner of one GL object name; deletes it with the matching glDelete* on destruction.
class Handle {
public:
  Handle() = default;
  Handle(ObjectType type, std::uint32_t name) noexcept : type_(type), name_(name) {}
  ~Handle();
  Handle(Handle&& other) noexcept;
  Handle& operator=(Handle&& other) noexcept;
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  std::uint32_t get() const noexcept { return name_; }
  explicit operator bool() const noexcept { return name_ != 0; }
  std::uint32_t release() noexcept; ///< gives up ownership
  void reset() noexcept;            ///< deletes the object now

private:
  ObjectType type_ = ObjectType::Texture;
  std::uint32_t name_ = 0;
};

/// Throws InvalidArgument naming `owner` when `handle` is empty because its pass was moved from: a moved-from
/// pass is valid but empty (memoryBytes() 0), and its run() refuses to work.
void requireNotMovedFrom(const Handle& handle, const char* owner);

/// glCreate* wrappers (DSA). `target` is a GLenum such as GL_TEXTURE_2D or GL_TIME_ELAPSED.
Handle createTexture(std::uint32_t target);
Handle createBuffer();
Handle createFramebuffer();
Handle createVertexArray();
Handle createQuery(std::uint32_t target);
Handle createSampler();

/// A GL_TEXTURE_2D with one level of `internalFormat` (a GLenum such as GL_RGBA32F or
/// GL_DEPTH_COMPONENT32F), nearest filtering, clamp to edge. Checks the size first
/// (checkTextureSize(parameter, ...)).
Handle createTexture2D(std::uint32_t internalFormat, int width, int height,
                       const char* parameter = "texture size");

/// A sampler with `filter` (GL_NEAREST or GL_LINEAR) for minification and magnification, clamp to edge in
/// s, t and r, no depth comparison: texelFetch / texture read the raw values whatever the texture's compare
/// mode.
Handle createClampSampler(std::uint32_t filter);
/// A buffer of `bytes` bytes with GL_DYNAMIC_STORAGE_BIT (filled with glNamedBufferSubData).
Handle createDynamicBuffer(std::size_t bytes);
/// An owned texture of at least width x height in `internalFormat`, (re)allocated when smaller: scratch
/// output for a pass whose caller does not want that output. `capacityWidth/Height` track its size.
std::uint32_t scratchTexture2D(Handle& texture, int& capacityWidth, int& capacityHeight,
                               std::uint32_t internalFormat, int width, int height);

/// Level 0 of a caller's texture as GL reports it.
struct TextureLevel {
  std::uint32_t target = 0; ///< GL_TEXTURE_2D, GL_TEXTURE_2D_ARRAY, ...
  int width = 0, height = 0, depth = 0;
  std::uint32_t internalFormat = 0;
};
/// The target, size and format of `texture`'s level 0 (how the passes learn sizes); InvalidArgument naming
/// `parameter` if `texture` is 0 or not an existing texture.
TextureLevel textureLevel(const char* parameter, std::uint32_t texture);
/// textureLevel(), and InvalidArgument naming `parameter` unless the target is GL_TEXTURE_2D.
TextureLevel requireTexture2D(const char* parameter, std::uint32_t texture);

/// Throws InvalidArgument naming `parameter` unless `texture` names an existing GL_TEXTURE_2D whose level 0
/// is width x height (sizes > 0) and, when `internalFormat` is not 0, of that internal format.
void requireTexture2D(const char* parameter, std::uint32_t texture, int width, int height,
                      std::uint32_t internalFormat = 0);

/// GL_BUFFER_SIZE of `buffer` in bytes; InvalidArgument naming `parameter` if it is 0 or not a buffer.
long long requireBuffer(const char* parameter, std::uint32_t buffer, const std::string& requirement);

/// Throws InvalidArgument naming `parameter` unless `texture` reads as depth: a depth format sampled as
/// depth, or GL_R32F (camera depth, shadow and rectified maps).
void requireDepthFormat(const char* parameter, std::uint32_t texture);
/// Throws InvalidArgument naming `parameter` unless `texture` has a colour format read as float (float or
/// normalized; not depth, stencil or integer): light textures.
void requireColorFormat(const char* parameter, std::uint32_t texture);

/// The state the compute passes of the library leave behind: program 0; texture units, samplers, image
/// units, uniform and storage buffer bindings 0 .. units - 1 unbound.
void unbindPassState(int units);
/// glMemoryBarrier for every way a pass output is read afterwards: texture fetches, image loads,
/// texture and buffer updates and readback, storage buffer reads.
void passOutputBarrier();

/// What readTexture() reads: RGBA (4 channels), the red channel, or depth (1 channel each).
enum class TexelData { Rgba, Red, Depth };
/// Reads level 0 of a 2D texture, or layer `layer` of a 2D array, as a float image (row 0 = bottom).
Image readTexture(std::uint32_t texture, int width, int height, TexelData data, int layer = 0);

/// Implementation limits.
int maxTextureSize();        ///< GL_MAX_TEXTURE_SIZE
int maxArrayTextureLayers(); ///< GL_MAX_ARRAY_TEXTURE_LAYERS

/// Throws InvalidArgument naming `parameter` when width/height are <= 0, and GlError when they
/// exceed GL_MAX_TEXTURE_SIZE (the message gives the limit).
void checkTextureSize(const char* parameter, int width, int height);

/// Throws GlError naming `what` when glGetError() reports an error (drains all pending errors).
void checkError(const char* what);
/// Pops every pending GL error (at most 32: a lost context reports one forever) and returns their names,
/// comma separated ("" when none).
std::string drainErrors() noexcept;

/// Measures GPU time between begin() and end() with a GL_TIME_ELAPSED query. Only one
/// GL_TIME_ELAPSED query can be active at a time, so timers do not nest.
class GpuTimer {
public:
  GpuTimer();
  void begin();
  void end();
  /// Waits for the result. Milliseconds of GPU time between the last begin() and end(). Throws
  /// GlError when called before a begin()/end() pair has completed.
  double milliseconds();
  /// Ends a running query without a result (a stage that threw): the context is left without an active
  /// GL_TIME_ELAPSED query and the timer can begin() again. No-op otherwise.
  void cancel() noexcept;

private:
  enum class State { Idle, Running, Ended };
  Handle query_;
  State state_ = State::Idle;
};

} // namespace crep::gl

namespace crep {

/// Compiles and links a program from registered files (current context required). Throws ShaderError
/// whose message holds the translated compile or link log.
gl::Handle buildProgram(std::initializer_list<ShaderStageSource> stages);
gl::Handle buildProgram(std::span<const ShaderStageSource> stages);

} // namespace crep
