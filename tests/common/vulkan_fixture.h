// The Vulkan tests' device (tests/vulkan/): gpu::VulkanBackend with the validation layer on, and the check
// that the layer said nothing. Header-only: only the tests that link crep::vulkan include it.
#pragma once

#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <string>
#include <vector>

namespace crep::test {

/// A VulkanBackend's CreateInfo with VK_LAYER_KHRONOS_validation on.
inline gpu::VulkanBackend::CreateInfo validatedVulkan() {
  gpu::VulkanBackend::CreateInfo info;
  info.validation = true;
  return info;
}

/// No warning or error of the validation layer so far (every message printed on failure).
inline void checkNoValidationMessages(const gpu::VulkanBackend& vk) {
  const std::vector<std::string> messages = vk.validationMessages();
  std::string all;
  for (const std::string& m : messages)
    all += "\n" + m;
  CHECK_MESSAGE(messages.empty(), messages.size() << " validation messages:" << all);
}

} // namespace crep::test
