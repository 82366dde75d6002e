// gpu::Backend on the caller's current OpenGL 4.5 context (it never owns one). Ids are GL names, so an
// engine's own GL texture or buffer is used by its name. State left after each call: docs/BACKENDS.md.
#pragma once

#include <cstddef>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <crep/gpu/backend.h>
#include <crep/gpu/checks.h>
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
  /// GL_TIME_ELAPSED queries (some drivers measure nothing for compute work), one active at a time: spans do
  /// not nest, and the caller's own GL_TIME_ELAPSED query must not be active. cancelTimer() leaves none of
  /// ours active.
  void beginTimer() override;
  double endTimer() override;
  void cancelTimer() noexcept override;
  /// Ends the span's query (glEndQuery only); timerResult() polls GL_QUERY_RESULT_AVAILABLE and reads the
  /// result only once available (never glFinish, never a blocking read). A read query is reused.
  TimerId endTimerDeferred() override;
  std::optional<double> timerResult(TimerId id) override;
  /// Most deferred spans pending (ended, result not yet returned): ending one more drops the oldest, whose
  /// id then reads 0.0.
  static constexpr std::size_t kMaxPendingTimers = 1024;
  /// Deferred spans pending now, at most kMaxPendingTimers.
  std::size_t pendingTimers() const noexcept { return pending_.size(); }

private:
  gl::Handle nearest_, linear_;
  gl::Handle activeQuery_;                             ///< the span begun by beginTimer(); empty: none
  std::vector<gl::Handle> freeQueries_;                ///< GL_TIME_ELAPSED queries read, to reuse
  std::deque<std::pair<TimerId, gl::Handle>> pending_; ///< ended deferred spans, oldest (lowest id) first
  TimerId nextTimer_ = 1;
  std::map<std::string, gl::Handle> programs_; ///< by program and defines
  gl::Handle& program(const std::string& path, std::span<const ShaderDefine> defines);
};

/// The GL internal format of `format` (GL_R32F, ..., GL_DEPTH_COMPONENT32F).
std::uint32_t glInternalFormat(Format format);

/// Level 0 of a GL texture as the checks see it: its gpu::Format when it is one of them, isDepth for any
/// depth format.
TextureLevel textureLevelFromGl(const gl::TextureLevel& level);

/// `given`, or else a GlBackend made into `own` on the current GL context: the default backend of a pass.
Backend& givenOrGl(Backend* given, std::unique_ptr<Backend>& own);

} // namespace crep::gpu
