// gpu::Backend on the caller's current OpenGL 4.5 context (it never owns one). Ids are GL names, so an
// engine's own GL texture or buffer is used by its name. State left after each call: docs/BACKENDS.md.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>

#include <crep/gpu/backend.h>
#include <crep/gpu/gl.h>

namespace crep::gpu {

class GlBackend final : public Backend {
public:
  /// Needs a current context; creates two sampler objects (nearest and linear, clamped).
  GlBackend();
  std::string_view name() const override { return "OpenGL"; }
  BackendKind kind() const override { return BackendKind::OpenGL; }
  int maxTextureSize() const override;
  int maxArrayLayers() const override;
  int max3DTextureSize() const override;
  ComputeLimits computeLimits() const override;
  TextureDesc describe(TextureId texture) const override;
  std::size_t bufferBytes(BufferId buffer) const override;
  void prepareProgram(const std::string& program, std::span<const ShaderDefine> defines) override;

  TextureId createTexture(const TextureDesc& desc) override;
  void destroyTexture(TextureId texture) override;
  BufferId createBuffer(std::size_t bytes, std::string_view label) override;
  void destroyBuffer(BufferId buffer) override;
  void writeBuffer(BufferId buffer, std::size_t offset, std::span<const std::byte> bytes) override;
  void writeTexture(TextureId texture, std::span<const float> texels) override;
  std::vector<std::byte> readBuffer(BufferId buffer, std::size_t offset, std::size_t bytes) override;
  std::vector<float> readTexture(TextureId texture) override;
  /// Binds, dispatches, issues a barrier for every later use of what it wrote, then leaves program 0 and
  /// every unit and binding it used unbound (what the library's GL passes leave).
  void dispatch(const Dispatch& dispatch) override;
  void finish() override;
  /// GL_TIME_ELAPSED (some drivers measure nothing for compute work).
  void beginTimer() override;
  double endTimer() override;
  void cancelTimer() noexcept override;

private:
  gl::Handle nearest_, linear_;
  std::optional<gl::GpuTimer> timer_;
  bool timing_ = false;
  std::map<std::string, gl::Handle> programs_; ///< by program and defines
  gl::Handle& program(const std::string& path, std::span<const ShaderDefine> defines);
};

/// The GL internal format of `format` (GL_R32F, ..., GL_DEPTH_COMPONENT32F).
std::uint32_t glInternalFormat(Format format);

/// `given`, or else a GlBackend made into `own` on the current GL context: the default backend of a pass.
Backend& givenOrGl(Backend* given, std::unique_ptr<Backend>& own);

} // namespace crep::gpu
