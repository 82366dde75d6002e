// The backend-independent parts of the seam (crep/gpu/backend.h): resource and push-constant
// helpers, and the owning handles.
#include <crep/core/error.h>
#include <crep/gpu/backend.h>

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

namespace crep::gpu {

int componentCount(Format format) {
  switch (format) {
  case Format::R32F:
  case Format::Depth32F:
    return 1;
  case Format::RG32F:
  case Format::RG32I:
    return 2;
  case Format::RGBA32F:
  case Format::RGBA16F:
  case Format::RGBA8:
    return 4;
  }
  return 4;
}

// Round to nearest, ties to even, by bits: glm::packHalf1x16 and Mesa 22.3's GL upload truncate instead (one
// unit in the last place off on about half the values).
std::uint16_t halfBits(float f) {
  std::uint32_t x = 0;
  std::memcpy(&x, &f, sizeof x);
  const std::uint32_t sign = (x >> 16) & 0x8000u, magnitude = x & 0x7fffffffu;
  if (magnitude >= 0x7f800000u) // infinity, NaN (kept quiet)
    return static_cast<std::uint16_t>(sign | 0x7c00u | (magnitude > 0x7f800000u ? 0x200u : 0u));
  if (magnitude >= 0x477ff000u) return static_cast<std::uint16_t>(sign | 0x7c00u); // rounds to >= 65520
  if (magnitude < 0x38800000u) { // below 2^-14: a subnormal half, in steps of 2^-24 (exact scaling)
    float v = 0.0f;
    std::memcpy(&v, &magnitude, sizeof v);
    return static_cast<std::uint16_t>(sign | static_cast<std::uint32_t>(std::nearbyint(v * 16777216.0f)));
  }
  std::uint32_t h = ((((magnitude >> 23) - 112u) << 10) | ((magnitude & 0x7fffffu) >> 13));
  const std::uint32_t rest = magnitude & 0x1fffu;
  if (rest > 0x1000u || (rest == 0x1000u && (h & 1u))) ++h; // a carry moves into the exponent, as it should
  return static_cast<std::uint16_t>(sign | h);
}

float roundedToHalf(float f) {
  return glm::unpackHalf1x16(halfBits(f));
}

Resource Resource::sampled(std::uint32_t binding, TextureId t, Filter f) {
  Resource r;
  r.kind = ResourceKind::SampledTexture;
  r.binding = binding;
  r.texture = t;
  r.filter = f;
  return r;
}

Resource Resource::image(std::uint32_t binding, TextureId t, Access a) {
  Resource r;
  r.kind = ResourceKind::StorageImage;
  r.binding = binding;
  r.texture = t;
  r.access = a;
  return r;
}

Resource Resource::uniform(std::uint32_t binding, BufferId b, std::size_t offset, std::size_t size) {
  Resource r;
  r.kind = ResourceKind::UniformBuffer;
  r.binding = binding;
  r.buffer = b;
  r.offset = offset;
  r.size = size;
  return r;
}

Resource Resource::storage(std::uint32_t binding, BufferId b, std::size_t offset, std::size_t size) {
  Resource r = uniform(binding, b, offset, size);
  r.kind = ResourceKind::StorageBuffer;
  return r;
}

namespace {
template <class T>
PushValue make(std::uint32_t location, PushValue::Type type, const T* components, int n) {
  static_assert(sizeof(T) == 4);
  PushValue p;
  p.location = location;
  p.type = type;
  std::memcpy(p.bits.data(), components, static_cast<std::size_t>(n) * 4);
  return p;
}

/// std430 size and alignment of a push value's type, bytes.
std::pair<std::size_t, std::size_t> sizeAndAlignment(PushValue::Type type) {
  switch (type) {
  case PushValue::Type::Int:
  case PushValue::Type::Float:
    return {4, 4};
  case PushValue::Type::IVec2:
  case PushValue::Type::Vec2:
    return {8, 8};
  case PushValue::Type::IVec4:
  case PushValue::Type::Vec4:
    return {16, 16};
  case PushValue::Type::Mat4:
    return {64, 16};
  }
  return {4, 4};
}
} // namespace

PushValue PushValue::of(std::uint32_t location, int v) {
  return make(location, Type::Int, &v, 1);
}
PushValue PushValue::of(std::uint32_t location, const glm::ivec2& v) {
  return make(location, Type::IVec2, &v.x, 2);
}
PushValue PushValue::of(std::uint32_t location, const glm::ivec4& v) {
  return make(location, Type::IVec4, &v.x, 4);
}
PushValue PushValue::of(std::uint32_t location, float v) {
  return make(location, Type::Float, &v, 1);
}
PushValue PushValue::of(std::uint32_t location, const glm::vec2& v) {
  return make(location, Type::Vec2, &v.x, 2);
}
PushValue PushValue::of(std::uint32_t location, const glm::vec4& v) {
  return make(location, Type::Vec4, &v.x, 4);
}
PushValue PushValue::of(std::uint32_t location, const glm::mat4& v) {
  return make(location, Type::Mat4, &v[0][0], 16);
}

std::string variantKey(std::string_view program, std::span<const ShaderDefine> defines) {
  std::string key(program);
  for (const ShaderDefine& d : defines)
    key += "\n" + d.name + "=" + d.value;
  return key;
}

std::vector<std::byte> packPushConstants(std::span<const PushValue> values) {
  std::vector<std::byte> out;
  for (const PushValue& v : values) {
    const auto [size, alignment] = sizeAndAlignment(v.type);
    const std::size_t offset = (out.size() + alignment - 1) / alignment * alignment;
    out.resize(offset + size);
    std::memcpy(out.data() + offset, v.bits.data(), size);
  }
  if (out.size() > 128)
    throw InvalidArgument("gpu::Dispatch.push", std::to_string(out.size()) + " bytes",
                          "must pack into at most 128 bytes");
  return out;
}

void writeGrowing(Backend& backend, Buffer& buffer, std::span<const std::byte> bytes,
                  std::string_view label) {
  if (buffer.bytes() < bytes.size()) {
    std::size_t capacity = 256;
    while (capacity < bytes.size())
      capacity *= 2;
    buffer = Buffer(backend, capacity, label);
  }
  backend.writeBuffer(buffer.id(), 0, bytes);
}

Texture& Texture::operator=(Texture&& o) noexcept {
  if (this != &o) {
    if (backend_ != nullptr && id_ != 0) backend_->destroyTexture(id_);
    backend_ = o.backend_;
    id_ = std::exchange(o.id_, 0);
  }
  return *this;
}

Texture::~Texture() {
  if (backend_ != nullptr && id_ != 0) backend_->destroyTexture(id_);
}

Buffer& Buffer::operator=(Buffer&& o) noexcept {
  if (this != &o) {
    if (backend_ != nullptr && id_ != 0) backend_->destroyBuffer(id_);
    backend_ = o.backend_;
    id_ = std::exchange(o.id_, 0);
    bytes_ = o.bytes_;
  }
  return *this;
}

Buffer::~Buffer() {
  if (backend_ != nullptr && id_ != 0) backend_->destroyBuffer(id_);
}

} // namespace crep::gpu
