// gpu::Backend on a Vulkan 1.1 device (Mesa's lavapipe here, any conformant driver elsewhere): the library's
// passes from the same descriptions as on GL, their shaders compiled from the same GLSL to SPIR-V at run
// time (shaderc), bindings as in docs/PORTABLE_SHADERS.md. Rules and limits: docs/BACKENDS.md.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <crep/core/error.h>
#include <crep/core/gpu_backend.h>

namespace crep::gpu {

/// A Vulkan call failed, or no device or queue could serve the backend.
class VulkanError : public Error {
public:
  using Error::Error;
};

class VulkanBackend final : public Backend {
public:
  struct CreateInfo {
    /// Turns on VK_LAYER_KHRONOS_validation (Debian package vulkan-validationlayers) and records each of
    /// its warnings and errors (validationMessages()). Default off: a cost for every call.
    bool validation = false;
    /// A part of the physical device's name to pick it by; empty: the first with a compute queue.
    std::string deviceName;
  };
  /// Creates its own instance, device and compute queue. VulkanError when there is no Vulkan driver, no
  /// matching device, or (with validation) no validation layer.
  explicit VulkanBackend(const CreateInfo& info);
  VulkanBackend(); ///< default CreateInfo
  ~VulkanBackend() override;
  VulkanBackend(const VulkanBackend&) = delete;
  VulkanBackend& operator=(const VulkanBackend&) = delete;

  std::string_view name() const override { return "Vulkan"; }
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
  void dispatch(const Dispatch& dispatch) override;
  void finish() override;
  /// Timestamp queries on the compute queue (0 where its family has no timestamp bits).
  void beginTimer() override;
  double endTimer() override;
  void cancelTimer() noexcept override;

  std::string deviceName() const; ///< the physical device's name
  /// The validation layer's warnings and errors so far (CreateInfo::validation), oldest first.
  std::vector<std::string> validationMessages() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace crep::gpu
