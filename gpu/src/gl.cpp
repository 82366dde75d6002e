#include <crep/core/error.h>
#include <crep/gpu/gl.h>
#include <crep/gpu/gl_state.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <cstdio>
#include <string>

namespace crep::gl {

namespace {

void deleteObject(ObjectType type, GLuint name) {
  switch (type) {
  case ObjectType::Texture:
    glDeleteTextures(1, &name);
    break;
  case ObjectType::Buffer:
    glDeleteBuffers(1, &name);
    break;
  case ObjectType::Framebuffer:
    glDeleteFramebuffers(1, &name);
    break;
  case ObjectType::Renderbuffer:
    glDeleteRenderbuffers(1, &name);
    break;
  case ObjectType::VertexArray:
    glDeleteVertexArrays(1, &name);
    break;
  case ObjectType::Program:
    glDeleteProgram(name);
    break;
  case ObjectType::Shader:
    glDeleteShader(name);
    break;
  case ObjectType::Query:
    glDeleteQueries(1, &name);
    break;
  case ObjectType::Sampler:
    glDeleteSamplers(1, &name);
    break;
  }
}

std::string hex(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04X", v);
  return buf;
}

std::string errorName(GLenum error) {
  switch (error) {
  case GL_INVALID_ENUM:
    return "GL_INVALID_ENUM";
  case GL_INVALID_VALUE:
    return "GL_INVALID_VALUE";
  case GL_INVALID_OPERATION:
    return "GL_INVALID_OPERATION";
  case GL_INVALID_FRAMEBUFFER_OPERATION:
    return "GL_INVALID_FRAMEBUFFER_OPERATION";
  case GL_OUT_OF_MEMORY:
    return "GL_OUT_OF_MEMORY";
  case GL_STACK_UNDERFLOW:
    return "GL_STACK_UNDERFLOW";
  case GL_STACK_OVERFLOW:
    return "GL_STACK_OVERFLOW";
  case GL_CONTEXT_LOST:
    return "GL_CONTEXT_LOST";
  default:
    return hex(error);
  }
}

Handle checked(ObjectType type, GLuint name, const char* function, const std::string& args = {}) {
  if (name == 0) throw GlError(std::string("crep: ") + function + "(" + args + ") created no object");
  return Handle(type, name);
}

int getInteger(GLenum pname) {
  GLint value = 0;
  glGetIntegerv(pname, &value);
  return value;
}

} // namespace

Handle::~Handle() {
  reset();
}

Handle::Handle(Handle&& other) noexcept : type_(other.type_), name_(other.release()) {}

Handle& Handle::operator=(Handle&& other) noexcept {
  if (this != &other) {
    reset();
    type_ = other.type_;
    name_ = other.release();
  }
  return *this;
}

std::uint32_t Handle::release() noexcept {
  const std::uint32_t name = name_;
  name_ = 0;
  return name;
}

void Handle::reset() noexcept {
  if (name_ != 0) deleteObject(type_, name_);
  name_ = 0;
}

void requireNotMovedFrom(const Handle& handle, const char* owner) {
  if (!handle)
    throw InvalidArgument(owner, "a moved-from object", "owns no GL objects: assign a constructed one first");
}

Handle createTexture(std::uint32_t target) {
  GLuint name = 0;
  glCreateTextures(target, 1, &name);
  return checked(ObjectType::Texture, name, "glCreateTextures", "target=" + hex(target));
}

Handle createBuffer() {
  GLuint name = 0;
  glCreateBuffers(1, &name);
  return checked(ObjectType::Buffer, name, "glCreateBuffers");
}

Handle createFramebuffer() {
  GLuint name = 0;
  glCreateFramebuffers(1, &name);
  return checked(ObjectType::Framebuffer, name, "glCreateFramebuffers");
}

Handle createVertexArray() {
  GLuint name = 0;
  glCreateVertexArrays(1, &name);
  return checked(ObjectType::VertexArray, name, "glCreateVertexArrays");
}

Handle createQuery(std::uint32_t target) {
  GLuint name = 0;
  glCreateQueries(target, 1, &name);
  return checked(ObjectType::Query, name, "glCreateQueries", "target=" + hex(target));
}

Handle createTexture2D(std::uint32_t internalFormat, int width, int height, const char* parameter) {
  checkTextureSize(parameter, width, height);
  Handle tex = createTexture(GL_TEXTURE_2D);
  glTextureStorage2D(tex.get(), 1, internalFormat, width, height);
  glTextureParameteri(tex.get(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(tex.get(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureParameteri(tex.get(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(tex.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  checkError("createTexture2D");
  return tex;
}

Image readTexture(std::uint32_t texture, int width, int height, TexelData data, int layer) {
  Image image(width, height, data == TexelData::Rgba ? 4 : 1);
  const GLenum format = data == TexelData::Rgba  ? GL_RGBA
                        : data == TexelData::Red ? GL_RED
                                                 : GL_DEPTH_COMPONENT;
  const PixelStoreScope pixelStore; // tightly packed rows, no pixel pack buffer: whatever the caller left
  glGetTextureSubImage(texture, 0, 0, 0, layer, width, height, 1, format, GL_FLOAT,
                       static_cast<GLsizei>(image.data().size_bytes()), image.data().data());
  checkError("readTexture");
  return image;
}

Handle createSampler() {
  GLuint name = 0;
  glCreateSamplers(1, &name);
  return checked(ObjectType::Sampler, name, "glCreateSamplers");
}

int maxTextureSize() {
  return getInteger(GL_MAX_TEXTURE_SIZE);
}
int maxArrayTextureLayers() {
  return getInteger(GL_MAX_ARRAY_TEXTURE_LAYERS);
}

void checkTextureSize(const char* parameter, int width, int height) {
  const std::string value = std::to_string(width) + " x " + std::to_string(height);
  if (width <= 0 || height <= 0) throw InvalidArgument(parameter, value, "width and height must be > 0");
  const int limit = maxTextureSize();
  if (width > limit || height > limit)
    throw GlError(std::string("crep: ") + parameter + " = " + value + " exceeds GL_MAX_TEXTURE_SIZE = " +
                  std::to_string(limit) + " of this OpenGL implementation");
}

std::string drainErrors() noexcept {
  std::string errors;
  try {
    // A lost context can report GL_CONTEXT_LOST forever: bound the loop.
    for (int i = 0; i < 32; ++i) {
      const GLenum error = glGetError();
      if (error == GL_NO_ERROR) break;
      errors += (errors.empty() ? "" : ", ") + errorName(error);
    }
  } catch (...) { // std::bad_alloc of the message: the errors are popped all the same
  }
  return errors;
}

void checkError(const char* what) {
  const std::string errors = drainErrors();
  if (!errors.empty()) throw GlError(std::string("crep: GL error in ") + what + ": " + errors);
}

GpuTimer::GpuTimer() : query_(createQuery(GL_TIME_ELAPSED)) {}

void GpuTimer::begin() {
  if (state_ == State::Running) throw GlError("crep: GpuTimer::begin() called twice without end()");
  glBeginQuery(GL_TIME_ELAPSED, query_.get());
  state_ = State::Running;
}

void GpuTimer::end() {
  if (state_ != State::Running) throw GlError("crep: GpuTimer::end() called without begin()");
  glEndQuery(GL_TIME_ELAPSED);
  state_ = State::Ended;
}

void GpuTimer::cancel() noexcept {
  if (state_ == State::Running) glEndQuery(GL_TIME_ELAPSED);
  state_ = State::Idle;
}

double GpuTimer::milliseconds() {
  if (state_ != State::Ended)
    throw GlError("crep: GpuTimer::milliseconds() needs a completed begin()/end() pair");
  GLuint64 nanoseconds = 0;
  glGetQueryObjectui64v(query_.get(), GL_QUERY_RESULT, &nanoseconds);
  return static_cast<double>(nanoseconds) * 1e-6;
}

Handle createClampSampler(std::uint32_t filter) {
  Handle s = createSampler();
  glSamplerParameteri(s.get(), GL_TEXTURE_MIN_FILTER, static_cast<GLint>(filter));
  glSamplerParameteri(s.get(), GL_TEXTURE_MAG_FILTER, static_cast<GLint>(filter));
  glSamplerParameteri(s.get(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(s.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(s.get(), GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(s.get(), GL_TEXTURE_COMPARE_MODE, GL_NONE);
  return s;
}

Handle createDynamicBuffer(std::size_t bytes) {
  Handle b = createBuffer();
  glNamedBufferStorage(b.get(), static_cast<GLsizeiptr>(bytes), nullptr, GL_DYNAMIC_STORAGE_BIT);
  return b;
}

std::uint32_t scratchTexture2D(Handle& texture, int& w, int& h, std::uint32_t internalFormat, int width,
                               int height) {
  if (!texture || w < width || h < height) {
    w = std::max(w, width);
    h = std::max(h, height);
    texture = createTexture(GL_TEXTURE_2D);
    glTextureStorage2D(texture.get(), 1, internalFormat, w, h);
  }
  return texture.get();
}

TextureLevel textureLevel(const char* parameter, std::uint32_t texture) {
  if (texture == 0 || glIsTexture(texture) != GL_TRUE)
    throw InvalidArgument(parameter, std::to_string(texture), "must be the name of an existing texture");
  GLint target = 0, w = 0, h = 0, d = 0, f = 0;
  glGetTextureParameteriv(texture, GL_TEXTURE_TARGET, &target);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_WIDTH, &w);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_HEIGHT, &h);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_DEPTH, &d);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_INTERNAL_FORMAT, &f);
  return {static_cast<std::uint32_t>(target), w, h, d, static_cast<std::uint32_t>(f)};
}

TextureLevel requireTexture2D(const char* parameter, std::uint32_t texture) {
  const TextureLevel level = textureLevel(parameter, texture);
  if (level.target != GL_TEXTURE_2D)
    throw InvalidArgument(parameter, "texture " + std::to_string(texture) + " of target " + hex(level.target),
                          "must be a GL_TEXTURE_2D");
  if (level.width <= 0 || level.height <= 0)
    throw InvalidArgument(parameter, "texture " + std::to_string(texture),
                          "has no storage (level 0 is " + std::to_string(level.width) + " x " +
                              std::to_string(level.height) + ")");
  return level;
}

void requireTexture2D(const char* parameter, std::uint32_t texture, int width, int height,
                      std::uint32_t format) {
  if (width <= 0 || height <= 0)
    throw InvalidArgument(parameter, std::to_string(width) + " x " + std::to_string(height),
                          "size must be > 0");
  if (texture == 0 || !glIsTexture(texture))
    throw InvalidArgument(parameter, std::to_string(texture), "must be the name of an existing texture");
  GLint target = 0, w = 0, h = 0, f = 0;
  glGetTextureParameteriv(texture, GL_TEXTURE_TARGET, &target);
  if (target != GL_TEXTURE_2D) // 3D, array and multisample textures are read as garbage by sampler2D
    throw InvalidArgument(parameter, "texture " + std::to_string(texture) + " of target " + hex(target),
                          "must be a GL_TEXTURE_2D");
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_WIDTH, &w);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_HEIGHT, &h);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_INTERNAL_FORMAT, &f);
  if (w != width || h != height)
    throw InvalidArgument(parameter, "texture of " + std::to_string(w) + " x " + std::to_string(h),
                          "must be " + std::to_string(width) + " x " + std::to_string(height));
  if (format != 0 && static_cast<GLenum>(f) != format)
    throw InvalidArgument(parameter, "internal format " + hex(static_cast<std::uint32_t>(f)),
                          "must be " + hex(format) +
                              (format == GL_RGBA32F ? " (GL_RGBA32F)"
                               : format == GL_R32F  ? " (GL_R32F)"
                                                    : ""));
}

long long requireBuffer(const char* parameter, std::uint32_t buffer, const std::string& requirement) {
  if (buffer == 0 || glIsBuffer(buffer) != GL_TRUE) invalid(parameter, std::to_string(buffer), requirement);
  GLint64 size = 0;
  glGetNamedBufferParameteri64v(buffer, GL_BUFFER_SIZE, &size);
  return static_cast<long long>(size);
}

void unbindPassState(int units) {
  glUseProgram(0);
  for (GLuint unit = 0; unit < static_cast<GLuint>(units); ++unit) {
    glBindTextureUnit(unit, 0);
    glBindSampler(unit, 0);
    glBindImageTexture(unit, 0, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
    glBindBufferBase(GL_UNIFORM_BUFFER, unit, 0);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, unit, 0);
  }
}

void passOutputBarrier() {
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                  GL_TEXTURE_UPDATE_BARRIER_BIT | GL_PIXEL_BUFFER_BARRIER_BIT |
                  GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

} // namespace crep::gl

namespace crep::gl {

namespace {
GLint levelParameter(std::uint32_t texture, GLenum pname) {
  GLint v = 0;
  glGetTextureLevelParameteriv(texture, 0, pname, &v);
  return v;
}
std::string formatText(std::uint32_t texture) {
  return "texture " + std::to_string(texture) + " of internal format " +
         hex(static_cast<std::uint32_t>(levelParameter(texture, GL_TEXTURE_INTERNAL_FORMAT)));
}
} // namespace

void requireDepthFormat(const char* parameter, std::uint32_t texture) {
  const GLint format = levelParameter(texture, GL_TEXTURE_INTERNAL_FORMAT);
  if (format == GL_R32F) return;
  if (levelParameter(texture, GL_TEXTURE_DEPTH_TYPE) == GL_NONE)
    throw InvalidArgument(parameter, formatText(texture),
                          "must have a depth format (GL_DEPTH_COMPONENT32F, GL_DEPTH24_STENCIL8, "
                          "GL_DEPTH_COMPONENT24, ...) or GL_R32F");
  GLint mode = GL_DEPTH_COMPONENT;
  glGetTextureParameteriv(texture, GL_DEPTH_STENCIL_TEXTURE_MODE, &mode);
  if (mode != GL_DEPTH_COMPONENT)
    throw InvalidArgument(parameter,
                          formatText(texture) + " with GL_DEPTH_STENCIL_TEXTURE_MODE = " +
                              hex(static_cast<std::uint32_t>(mode)),
                          "must be sampled as depth (GL_DEPTH_STENCIL_TEXTURE_MODE = GL_DEPTH_COMPONENT)");
}

void requireColorFormat(const char* parameter, std::uint32_t texture) {
  const GLint red = levelParameter(texture, GL_TEXTURE_RED_TYPE);
  if (levelParameter(texture, GL_TEXTURE_DEPTH_TYPE) != GL_NONE ||
      (red != GL_FLOAT && red != GL_UNSIGNED_NORMALIZED && red != GL_SIGNED_NORMALIZED))
    throw InvalidArgument(parameter, formatText(texture),
                          "must have a colour format read as float (GL_RGBA8, GL_SRGB8_ALPHA8, GL_RGBA16F, "
                          "GL_RGBA32F, ...), not depth, stencil or integer");
}

} // namespace crep::gl
