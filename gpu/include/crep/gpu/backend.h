// The seam between the passes and a graphics API: a pass describes each dispatch (program and defines,
// resources at their crep/bindings.h numbers, push-constant bytes, group counts) and a Backend runs it.
// GlBackend (crep/gpu/gl_backend.h) runs on the caller's OpenGL 4.5 context, VulkanBackend
// (crep/vulkan/vulkan_backend.h) on a Vulkan device; an engine's RHI implements the same interface.
// Rules and what an implementation must guarantee: docs/BACKENDS.md.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include <crep/gpu/shader_library.h>

namespace crep::gpu {

enum class TextureType : std::uint8_t { Texture2D, Texture2DArray, Texture3D };

/// Texel formats of the passes' textures. Depth32F is sampled only (a depth map's red channel); RGBA8 is
/// unsigned normalized (floats in [0, 1] through the Backend); RG32I is signed integer (storage images only,
/// integer floats through the Backend, exact within +-2^24).
enum class Format : std::uint8_t { R32F, RG32F, RGBA32F, RGBA16F, Depth32F, RGBA8, RG32I };

/// Components per texel of `format` (1, 2 or 4) as read and written through the Backend (floats).
int componentCount(Format format);

/// The IEEE half-float bits of `f`, rounded to the nearest, ties to even (overflow: infinity). Backends store
/// RGBA16F uploads with it, so every backend rounds alike.
std::uint16_t halfBits(float f);
/// `f` rounded to the nearest half-float value (as a float, exact).
float roundedToHalf(float f);

struct TextureDesc {
  TextureType type = TextureType::Texture2D;
  Format format = Format::RGBA32F;
  int width = 0;     ///< texels, > 0
  int height = 0;    ///< texels, > 0
  int depth = 1;     ///< layers (Texture2DArray) or slices (Texture3D), > 0; 1 for Texture2D
  std::string label; ///< debug name shown by the API's tools
};

struct ComputeLimits {
  int groupSize[3] = {0, 0, 0};  ///< GL_MAX_COMPUTE_WORK_GROUP_SIZE, maxComputeWorkGroupSize
  int groupCount[3] = {0, 0, 0}; ///< GL_MAX_COMPUTE_WORK_GROUP_COUNT, maxComputeWorkGroupCount
  int invocations = 0;           ///< GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS, maxComputeWorkGroupInvocations
};

/// A backend's texture or buffer: an id it issued (create*) or imported (GlBackend: the GL object's
/// name). 0 is none.
using TextureId = std::uint32_t;
using BufferId = std::uint32_t;
/// A span of GPU time ended without waiting (Backend::endTimerDeferred); each span its own id, never
/// reused; 0 is none.
using TimerId = std::uint64_t;

enum class ResourceKind : std::uint8_t { SampledTexture, StorageImage, UniformBuffer, StorageBuffer };
enum class Filter : std::uint8_t { Nearest, Linear }; ///< sampled textures; always clamped to the edge
enum class Access : std::uint8_t { ReadOnly, WriteOnly, ReadWrite };

/// One resource of a dispatch at its GL binding number (crep/bindings.h); the backend maps it (Vulkan:
/// the number plus the base of its kind, set 0).
struct Resource {
  ResourceKind kind = ResourceKind::SampledTexture;
  std::uint32_t binding = 0;
  TextureId texture = 0;             ///< SampledTexture, StorageImage
  Filter filter = Filter::Nearest;   ///< SampledTexture
  Access access = Access::ReadWrite; ///< StorageImage
  BufferId buffer = 0;               ///< UniformBuffer, StorageBuffer
  std::size_t offset = 0;            ///< bytes into the buffer
  std::size_t size = 0;              ///< bytes from offset; 0: to the end of the buffer

  static Resource sampled(std::uint32_t binding, TextureId t, Filter f = Filter::Nearest);
  static Resource image(std::uint32_t binding, TextureId t, Access a = Access::ReadWrite);
  static Resource uniform(std::uint32_t binding, BufferId b, std::size_t offset = 0, std::size_t size = 0);
  static Resource storage(std::uint32_t binding, BufferId b, std::size_t offset = 0, std::size_t size = 0);
};

/// One value of a pass's push-constant block, given in the block's member order: GlBackend sets it at
/// `location` (the GL form's uniform), Vulkan at the next std430 offset of its type
/// (docs/PORTABLE_SHADERS.md, "Push constants").
struct PushValue {
  enum class Type : std::uint8_t { Int, IVec2, IVec4, Float, Vec2, Vec4, Mat4 };
  std::uint32_t location = 0;
  Type type = Type::Int;
  std::array<std::uint32_t, 16> bits{}; ///< the 4-byte components (column-major for Mat4)

  static PushValue of(std::uint32_t location, int v);
  static PushValue of(std::uint32_t location, const glm::ivec2& v);
  static PushValue of(std::uint32_t location, const glm::ivec4& v);
  static PushValue of(std::uint32_t location, float v);
  static PushValue of(std::uint32_t location, const glm::vec2& v);
  static PushValue of(std::uint32_t location, const glm::vec4& v);
  static PushValue of(std::uint32_t location, const glm::mat4& v);
};

/// The push-constant block's bytes: each value at the next offset std430 gives its type (int and float
/// at 4, ivec2 and vec2 at 8, ivec4, vec4 and mat4 at 16).
std::vector<std::byte> packPushConstants(std::span<const PushValue> values);

/// One compute dispatch, the same for every backend.
struct Dispatch {
  std::string label;   ///< for errors and the API's tools, e.g. "MinMaxTreePass"
  std::string program; ///< a ShaderLibrary compute shader, e.g. "passes/epipolar/minmax_build.comp"
  std::vector<ShaderDefine> defines; ///< the variant
  std::vector<Resource> resources;   ///< every resource the variant reads or writes
  std::vector<PushValue> push;       ///< the push-constant block (at most 128 bytes packed)
  glm::uvec3 groups{1, 1, 1};        ///< work groups; a zero count dispatches nothing
  /// Non-zero: an indirect dispatch, the three uint32 group counts read from this buffer at
  /// indirectOffset (written by an earlier dispatch; a GPU work list), `groups` unused.
  BufferId indirect = 0;
  std::size_t indirectOffset = 0; ///< bytes, a multiple of 4
};

/// A program variant's key for a backend's caches: the path, then each define as "NAME=value".
std::string variantKey(std::string_view program, std::span<const ShaderDefine> defines);

/// Which API a backend drives. The passes ask it only where OpenGL differs: the GL backend's own checks and
/// messages (an engine's GL texture may be in any GL format), and the barrier a GL caller's own dispatches
/// need. An engine's backend is Other.
enum class BackendKind : std::uint8_t { OpenGL, Vulkan, Other };

/// What a pass needs of a graphics API. Every call is in order: a dispatch sees the writes of every call
/// before it (writes, dispatches), a read sees every call before it. Not thread-safe.
class Backend {
public:
  virtual ~Backend() = default;
  virtual std::string_view name() const = 0; ///< for messages: "OpenGL", "Vulkan", an engine's own
  virtual BackendKind kind() const { return BackendKind::Other; }
  /// The largest width or height of a 2D texture (GL_MAX_TEXTURE_SIZE, maxImageDimension2D).
  virtual int maxTextureSize() const = 0;
  /// The most layers of a 2D array texture (GL_MAX_ARRAY_TEXTURE_LAYERS, maxImageArrayLayers).
  virtual int maxArrayLayers() const = 0;
  /// The largest side of a 3D texture (GL_MAX_3D_TEXTURE_SIZE, maxImageDimension3D). Default: 256, the
  /// least Vulkan guarantees; a backend of your own returns its device's.
  virtual int max3DTextureSize() const { return 256; }
  /// Compute limits: work-group size per axis, work groups per dispatch per axis, invocations per group.
  virtual ComputeLimits computeLimits() const = 0;
  /// What `texture` is (size, format, type; label empty). InvalidArgument if it is no texture of this
  /// backend.
  virtual TextureDesc describe(TextureId texture) const = 0;
  /// The size of `buffer` in bytes. InvalidArgument if it is no buffer of this backend.
  virtual std::size_t bufferBytes(BufferId buffer) const = 0;
  /// Compiles a program ahead of its first dispatch, so that a ShaderError comes at a pass's creation.
  virtual void prepareProgram(const std::string& program, std::span<const ShaderDefine> defines) = 0;

  /// Throws InvalidArgument naming `desc` fields beyond the device's limits or <= 0.
  virtual TextureId createTexture(const TextureDesc& desc) = 0;
  virtual void destroyTexture(TextureId texture) = 0;
  /// A buffer of `bytes` (> 0), for uniform and storage use, contents undefined.
  virtual BufferId createBuffer(std::size_t bytes, std::string_view label) = 0;
  virtual void destroyBuffer(BufferId buffer) = 0;

  virtual void writeBuffer(BufferId buffer, std::size_t offset, std::span<const std::byte> bytes) = 0;
  /// Replaces the whole texture: componentCount(format) floats per texel, layers or slices after each other.
  virtual void writeTexture(TextureId texture, std::span<const float> texels) = 0;
  virtual std::vector<std::byte> readBuffer(BufferId buffer, std::size_t offset, std::size_t bytes) = 0;
  /// The whole texture, as writeTexture takes it.
  virtual std::vector<float> readTexture(TextureId texture) = 0;

  virtual void dispatch(const Dispatch& dispatch) = 0;
  /// Waits for every call so far (timing; the API's own queue otherwise runs ahead).
  virtual void finish() = 0;

  /// GPU time of a span of calls (stage timings): beginTimer(), the calls, then endTimer(), which finishes
  /// and returns the GPU milliseconds between the two (0 where the device measures none). cancelTimer()
  /// ends a span without a result (a stage that threw). Default: no GPU timer (endTimer() finishes, 0).
  /// Spans do not nest: beginTimer() during a span cancels it.
  virtual void beginTimer() {}
  virtual double endTimer() {
    finish();
    return 0.0;
  }
  virtual void cancelTimer() noexcept {}
  /// Ends the span begun by beginTimer() without waiting (no finish, no read): its id for timerResult(), 0
  /// where the backend measures none (no span begun included). Default: cancelTimer(), 0.
  virtual TimerId endTimerDeferred() {
    cancelTimer();
    return 0;
  }
  /// Never waits: the span's GPU milliseconds once they are available, std::nullopt while pending. A
  /// result is forgotten once returned; 0, an unknown id, one returned before or one the backend dropped
  /// (it may keep a bounded number pending) give 0.0. Default: 0.0.
  virtual std::optional<double> timerResult(TimerId) { return 0.0; }
};

class Buffer;
/// Writes `bytes` at offset 0 of `buffer`, first replacing it by a buffer of `backend` of the next power of
/// two >= bytes.size() (at least 256) when it is smaller: per-frame tables whose size changes.
void writeGrowing(Backend& backend, Buffer& buffer, std::span<const std::byte> bytes, std::string_view label);

/// A texture or buffer of a Backend, destroyed with it. Move-only.
class Texture {
public:
  Texture() = default;
  Texture(Backend& backend, const TextureDesc& desc) : backend_(&backend), id_(backend.createTexture(desc)) {}
  Texture(Texture&& o) noexcept : backend_(o.backend_), id_(o.id_) { o.id_ = 0; }
  Texture& operator=(Texture&& o) noexcept;
  Texture(const Texture&) = delete;
  Texture& operator=(const Texture&) = delete;
  ~Texture();
  TextureId id() const noexcept { return id_; }
  explicit operator bool() const noexcept { return id_ != 0; }

private:
  Backend* backend_ = nullptr;
  TextureId id_ = 0;
};

class Buffer {
public:
  Buffer() = default;
  Buffer(Backend& backend, std::size_t bytes, std::string_view label)
      : backend_(&backend), id_(backend.createBuffer(bytes, label)), bytes_(bytes) {}
  Buffer(Buffer&& o) noexcept : backend_(o.backend_), id_(o.id_), bytes_(o.bytes_) { o.id_ = 0; }
  Buffer& operator=(Buffer&& o) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  ~Buffer();
  BufferId id() const noexcept { return id_; }
  std::size_t bytes() const noexcept { return bytes_; }
  explicit operator bool() const noexcept { return id_ != 0; }

private:
  Backend* backend_ = nullptr;
  BufferId id_ = 0;
  std::size_t bytes_ = 0;
};

} // namespace crep::gpu
