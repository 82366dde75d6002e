// gpu::Backend on the caller's OpenGL 4.5 context (crep/gpu/gl_backend.h).
#include <crep/core/error.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/gl_state.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <utility>
#include <vector>

namespace crep::gpu {

namespace {

GLenum pixelFormat(GLint internal) {
  switch (internal) {
  case GL_R32F:
  case GL_R16F:
    return GL_RED;
  case GL_RG32F:
  case GL_RG16F:
    return GL_RG;
  case GL_RG32I:
    return GL_RG_INTEGER;
  case GL_DEPTH_COMPONENT32F:
  case GL_DEPTH_COMPONENT24:
  case GL_DEPTH_COMPONENT16:
  case GL_DEPTH_COMPONENT32:
    return GL_DEPTH_COMPONENT;
  default:
    return GL_RGBA;
  }
}

int channels(GLenum pixel) {
  return pixel == GL_RGBA ? 4 : pixel == GL_RG || pixel == GL_RG_INTEGER ? 2 : 1;
}

/// What a GL texture is, from the driver (ids may be the engine's own textures).
struct TextureInfo {
  GLint target = 0, internal = 0, width = 0, height = 0, depth = 0;
};
TextureInfo query(GLuint texture) {
  TextureInfo t;
  glGetTextureParameteriv(texture, GL_TEXTURE_TARGET, &t.target);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_INTERNAL_FORMAT, &t.internal);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_WIDTH, &t.width);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_HEIGHT, &t.height);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_DEPTH, &t.depth);
  return t;
}

GLenum access(Access a) {
  return a == Access::ReadOnly ? GL_READ_ONLY : a == Access::WriteOnly ? GL_WRITE_ONLY : GL_READ_WRITE;
}

void setUniform(GLuint program, const PushValue& v) {
  const GLint l = static_cast<GLint>(v.location);
  const auto* i = reinterpret_cast<const GLint*>(v.bits.data());
  const auto* f = reinterpret_cast<const GLfloat*>(v.bits.data());
  switch (v.type) {
  case PushValue::Type::Int:
    glProgramUniform1iv(program, l, 1, i);
    break;
  case PushValue::Type::IVec2:
    glProgramUniform2iv(program, l, 1, i);
    break;
  case PushValue::Type::IVec4:
    glProgramUniform4iv(program, l, 1, i);
    break;
  case PushValue::Type::Float:
    glProgramUniform1fv(program, l, 1, f);
    break;
  case PushValue::Type::Vec2:
    glProgramUniform2fv(program, l, 1, f);
    break;
  case PushValue::Type::Vec4:
    glProgramUniform4fv(program, l, 1, f);
    break;
  case PushValue::Type::Mat4:
    glProgramUniformMatrix4fv(program, l, 1, GL_FALSE, f);
    break;
  }
}

} // namespace

std::uint32_t glInternalFormat(Format f) {
  switch (f) {
  case Format::R32F:
    return GL_R32F;
  case Format::RG32F:
    return GL_RG32F;
  case Format::RGBA32F:
    return GL_RGBA32F;
  case Format::RGBA16F:
    return GL_RGBA16F;
  case Format::Depth32F:
    return GL_DEPTH_COMPONENT32F;
  case Format::RGBA8:
    return GL_RGBA8;
  case Format::RG32I:
    return GL_RG32I;
  }
  return GL_RGBA32F;
}

TextureLevel textureLevelFromGl(const gl::TextureLevel& l) {
  TextureLevel level;
  level.type = l.target == GL_TEXTURE_2D_ARRAY ? TextureType::Texture2DArray
               : l.target == GL_TEXTURE_3D     ? TextureType::Texture3D
                                               : TextureType::Texture2D;
  level.width = l.width;
  level.height = l.height;
  level.depth = std::max(l.depth, 1);
  for (Format f : {Format::R32F, Format::RG32F, Format::RGBA32F, Format::RGBA16F, Format::Depth32F,
                   Format::RGBA8, Format::RG32I})
    if (glInternalFormat(f) == l.internalFormat) level.format = f;
  switch (l.internalFormat) {
  case GL_DEPTH_COMPONENT16:
  case GL_DEPTH_COMPONENT24:
  case GL_DEPTH_COMPONENT32:
  case GL_DEPTH_COMPONENT32F:
  case GL_DEPTH24_STENCIL8:
  case GL_DEPTH32F_STENCIL8:
    level.isDepth = true;
    break;
  default:
    break;
  }
  return level;
}

GlBackend::GlBackend() {
  nearest_ = gl::createClampSampler(GL_NEAREST);
  linear_ = gl::createClampSampler(GL_LINEAR);
}

int GlBackend::maxTextureSize() const {
  return gl::maxTextureSize();
}

int GlBackend::maxArrayLayers() const {
  return gl::maxArrayTextureLayers();
}

void GlBackend::beginTimer() {
  cancelTimer(); // spans do not nest
  if (freeQueries_.empty()) {
    activeQuery_ = gl::createQuery(GL_TIME_ELAPSED);
  } else {
    activeQuery_ = std::move(freeQueries_.back());
    freeQueries_.pop_back();
  }
  glBeginQuery(GL_TIME_ELAPSED, activeQuery_.get());
}

double GlBackend::endTimer() {
  if (!activeQuery_) {
    finish();
    return 0.0;
  }
  glEndQuery(GL_TIME_ELAPSED);
  gl::Handle query = std::move(activeQuery_);
  finish();
  GLuint64 nanoseconds = 0;
  glGetQueryObjectui64v(query.get(), GL_QUERY_RESULT, &nanoseconds);
  freeQueries_.push_back(std::move(query));
  return static_cast<double>(nanoseconds) * 1e-6;
}

void GlBackend::cancelTimer() noexcept {
  if (!activeQuery_) return;
  glEndQuery(GL_TIME_ELAPSED);
  activeQuery_.reset(); // its result is never read: deleted rather than reused while it may be pending
}

TimerId GlBackend::endTimerDeferred() {
  if (!activeQuery_) return 0;
  glEndQuery(GL_TIME_ELAPSED);
  const TimerId id = nextTimer_++;
  pending_.emplace_back(id, std::move(activeQuery_));
  if (pending_.size() > kMaxPendingTimers) pending_.pop_front(); // dropped: its id reads 0.0
  return id;
}

std::optional<double> GlBackend::timerResult(TimerId id) {
  const auto it = std::lower_bound(pending_.begin(), pending_.end(), id,
                                   [](const auto& span, TimerId key) { return span.first < key; });
  if (it == pending_.end() || it->first != id) return 0.0; // 0, unknown, returned before or dropped
  GLuint available = GL_FALSE;
  glGetQueryObjectuiv(it->second.get(), GL_QUERY_RESULT_AVAILABLE, &available);
  if (available != GL_TRUE) return std::nullopt;
  GLuint64 nanoseconds = 0;
  glGetQueryObjectui64v(it->second.get(), GL_QUERY_RESULT_NO_WAIT, &nanoseconds);
  freeQueries_.push_back(std::move(it->second));
  pending_.erase(it);
  return static_cast<double>(nanoseconds) * 1e-6;
}

int GlBackend::max3DTextureSize() const {
  GLint v = 0;
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &v);
  return v;
}

ComputeLimits GlBackend::computeLimits() const {
  ComputeLimits l;
  for (GLuint axis = 0; axis < 3; ++axis) {
    glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_SIZE, axis, &l.groupSize[axis]);
    glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, axis, &l.groupCount[axis]);
  }
  glGetIntegerv(GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS, &l.invocations);
  return l;
}

TextureDesc GlBackend::describe(TextureId texture) const {
  if (texture == 0 || glIsTexture(texture) != GL_TRUE)
    throw InvalidArgument("gpu::GlBackend texture", std::to_string(texture), "must be a GL texture name");
  const TextureInfo t = query(texture);
  const TextureLevel level = textureLevelFromGl({static_cast<std::uint32_t>(t.target), t.width, t.height,
                                                 t.depth, static_cast<std::uint32_t>(t.internal)});
  TextureDesc d;
  d.type = level.type;
  // A format outside gpu::Format reads as the one its components are read as.
  d.format = level.format                                    ? *level.format
             : pixelFormat(t.internal) == GL_DEPTH_COMPONENT ? Format::Depth32F
                                                             : Format::RGBA32F;
  d.width = level.width;
  d.height = level.height;
  d.depth = level.depth;
  return d;
}

std::size_t GlBackend::bufferBytes(BufferId buffer) const {
  return static_cast<std::size_t>(
      gl::requireBuffer("gpu::GlBackend buffer", buffer, "must be a GL buffer name"));
}

gl::Handle& GlBackend::program(const std::string& path, std::span<const ShaderDefine> defines) {
  gl::Handle& p = programs_[variantKey(path, defines)];
  if (!p)
    p = buildProgram(
        std::vector<ShaderStageSource>{{ShaderStage::Compute, path, {defines.begin(), defines.end()}}});
  return p;
}

void GlBackend::prepareProgram(const std::string& path, std::span<const ShaderDefine> defines) {
  program(path, defines);
}

TextureId GlBackend::createTexture(const TextureDesc& desc) {
  gl::checkTextureSize("gpu::TextureDesc.width/height", desc.width, desc.height);
  if (desc.depth < 1 || (desc.type == TextureType::Texture2D && desc.depth != 1))
    throw InvalidArgument("gpu::TextureDesc.depth", std::to_string(desc.depth),
                          "must be >= 1 (1 for a Texture2D)");
  const GLenum target = desc.type == TextureType::Texture2D        ? GL_TEXTURE_2D
                        : desc.type == TextureType::Texture2DArray ? GL_TEXTURE_2D_ARRAY
                                                                   : GL_TEXTURE_3D;
  gl::Handle t = gl::createTexture(target);
  if (target == GL_TEXTURE_2D)
    glTextureStorage2D(t.get(), 1, glInternalFormat(desc.format), desc.width, desc.height);
  else
    glTextureStorage3D(t.get(), 1, glInternalFormat(desc.format), desc.width, desc.height, desc.depth);
  // Linear and clamped by the texture's own state too: an engine's shader may sample it without a sampler
  // object (a pass binds its own).
  glTextureParameteri(t.get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(t.get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(t.get(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(t.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTextureParameteri(t.get(), GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
  if (!desc.label.empty())
    glObjectLabel(GL_TEXTURE, t.get(), static_cast<GLsizei>(desc.label.size()), desc.label.data());
  gl::checkError("gpu::GlBackend::createTexture");
  return t.release();
}

void GlBackend::destroyTexture(TextureId texture) {
  const GLuint name = texture;
  glDeleteTextures(1, &name);
}

BufferId GlBackend::createBuffer(std::size_t bytes, std::string_view label) {
  if (bytes == 0) throw InvalidArgument("gpu::Backend::createBuffer bytes", "0", "must be > 0");
  gl::Handle b = gl::createBuffer();
  glNamedBufferStorage(b.get(), static_cast<GLsizeiptr>(bytes), nullptr, GL_DYNAMIC_STORAGE_BIT);
  if (!label.empty()) glObjectLabel(GL_BUFFER, b.get(), static_cast<GLsizei>(label.size()), label.data());
  gl::checkError("gpu::GlBackend::createBuffer");
  return b.release();
}

void GlBackend::destroyBuffer(BufferId buffer) {
  const GLuint name = buffer;
  glDeleteBuffers(1, &name);
}

void GlBackend::writeBuffer(BufferId buffer, std::size_t offset, std::span<const std::byte> bytes) {
  if (!bytes.empty())
    glNamedBufferSubData(buffer, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes.size()),
                         bytes.data());
}

void GlBackend::writeTexture(TextureId texture, std::span<const float> texels) {
  const TextureInfo t = query(texture);
  const GLenum pixel = pixelFormat(t.internal);
  const std::size_t needed = static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height) *
                             static_cast<std::size_t>(std::max(t.depth, 1)) *
                             static_cast<std::size_t>(channels(pixel));
  if (texels.size() != needed)
    throw InvalidArgument("gpu::Backend::writeTexture texels", std::to_string(texels.size()),
                          "must hold " + std::to_string(needed) + " floats (the whole texture)");
  const gl::PixelStoreScope pixels;
  // Half-float textures take floats already rounded to their nearest half (GL drivers may truncate: Mesa
  // 22.3 does), so every backend stores the same halves.
  std::vector<float> rounded;
  if (t.internal == GL_RGBA16F || t.internal == GL_RG16F || t.internal == GL_R16F) {
    rounded.resize(texels.size());
    std::transform(texels.begin(), texels.end(), rounded.begin(), roundedToHalf);
    texels = rounded;
  }
  // Integer textures take GL_INT texels: the floats converted (exact within +-2^24).
  const bool integer = pixel == GL_RG_INTEGER;
  std::vector<GLint> ints(integer ? texels.size() : 0);
  std::transform(texels.begin(), texels.begin() + static_cast<std::ptrdiff_t>(ints.size()), ints.begin(),
                 [](float v) { return static_cast<GLint>(std::lround(v)); });
  const GLenum type = integer ? GL_INT : GL_FLOAT;
  const void* data = integer ? static_cast<const void*>(ints.data()) : texels.data();
  if (t.target == GL_TEXTURE_2D)
    glTextureSubImage2D(texture, 0, 0, 0, t.width, t.height, pixel, type, data);
  else
    glTextureSubImage3D(texture, 0, 0, 0, 0, t.width, t.height, t.depth, pixel, type, data);
}

std::vector<std::byte> GlBackend::readBuffer(BufferId buffer, std::size_t offset, std::size_t bytes) {
  std::vector<std::byte> out(bytes);
  if (bytes > 0)
    glGetNamedBufferSubData(buffer, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes),
                            out.data());
  gl::checkError("gpu::GlBackend::readBuffer");
  return out;
}

std::vector<float> GlBackend::readTexture(TextureId texture) {
  const TextureInfo t = query(texture);
  const GLenum pixel = pixelFormat(t.internal);
  std::vector<float> out(static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height) *
                         static_cast<std::size_t>(std::max(t.depth, 1)) *
                         static_cast<std::size_t>(channels(pixel)));
  const gl::PixelStoreScope pixels;
  if (pixel == GL_RG_INTEGER) {
    std::vector<GLint> ints(out.size());
    glGetTextureImage(texture, 0, pixel, GL_INT, static_cast<GLsizei>(ints.size() * sizeof(GLint)),
                      ints.data());
    std::transform(ints.begin(), ints.end(), out.begin(), [](GLint v) { return static_cast<float>(v); });
  } else {
    glGetTextureImage(texture, 0, pixel, GL_FLOAT, static_cast<GLsizei>(out.size() * sizeof(float)),
                      out.data());
  }
  gl::checkError("gpu::GlBackend::readTexture");
  return out;
}

void GlBackend::dispatch(const Dispatch& d) {
  const gl::Handle& program = this->program(d.program, d.defines);
  glUseProgram(program.get());
  for (const PushValue& v : d.push)
    setUniform(program.get(), v);
  for (const Resource& r : d.resources) {
    switch (r.kind) {
    case ResourceKind::SampledTexture:
      glBindTextureUnit(r.binding, r.texture);
      glBindSampler(r.binding, (r.filter == Filter::Linear ? linear_ : nearest_).get());
      break;
    case ResourceKind::StorageImage: {
      const TextureInfo t = query(r.texture);
      const GLboolean layered = t.target == GL_TEXTURE_2D ? GL_FALSE : GL_TRUE;
      glBindImageTexture(r.binding, r.texture, 0, layered, 0, access(r.access),
                         static_cast<GLenum>(t.internal));
      break;
    }
    case ResourceKind::UniformBuffer:
    case ResourceKind::StorageBuffer: {
      const GLenum target =
          r.kind == ResourceKind::UniformBuffer ? GL_UNIFORM_BUFFER : GL_SHADER_STORAGE_BUFFER;
      if (r.offset == 0 && r.size == 0)
        glBindBufferBase(target, r.binding, r.buffer);
      else {
        GLint64 total = 0;
        glGetNamedBufferParameteri64v(r.buffer, GL_BUFFER_SIZE, &total);
        const std::size_t size = r.size != 0 ? r.size : static_cast<std::size_t>(total) - r.offset;
        glBindBufferRange(target, r.binding, r.buffer, static_cast<GLintptr>(r.offset),
                          static_cast<GLsizeiptr>(size));
      }
      break;
    }
    }
  }
  if (d.indirect != 0) {
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, d.indirect);
    glDispatchComputeIndirect(static_cast<GLintptr>(d.indirectOffset));
    glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, 0);
  } else if (d.groups.x > 0 && d.groups.y > 0 && d.groups.z > 0)
    glDispatchCompute(d.groups.x, d.groups.y, d.groups.z);
  // Every later use of what the dispatch wrote (a choice for simplicity: a GPU driver may stall on a full
  // barrier where the passes' own narrower bits would not; the next dispatch's reads decide on real
  // hardware).
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  for (const Resource& r : d.resources) {
    switch (r.kind) {
    case ResourceKind::SampledTexture:
      glBindSampler(r.binding, 0);
      glBindTextureUnit(r.binding, 0);
      break;
    case ResourceKind::StorageImage:
      glBindImageTexture(r.binding, 0, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
      break;
    case ResourceKind::UniformBuffer:
      glBindBufferBase(GL_UNIFORM_BUFFER, r.binding, 0);
      break;
    case ResourceKind::StorageBuffer:
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, r.binding, 0);
      break;
    }
  }
  glUseProgram(0);
  gl::checkError(d.label.c_str());
}

Backend& givenOrGl(Backend* given, std::unique_ptr<Backend>& own) {
  if (given != nullptr) return *given;
  if (!own) own = std::make_unique<GlBackend>();
  return *own;
}

void GlBackend::finish() {
  glFinish();
}

} // namespace crep::gpu
