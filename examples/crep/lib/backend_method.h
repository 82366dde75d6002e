// `--backend vulkan` of crep render, compare and bench: the frame's crep::Scattering on gpu::VulkanBackend,
// the scene's maps rendered by GL and handed over as an engine on Vulkan would (crep/scenes/engine_frame.h).
#pragma once

#include "methods.h"
#include "scene_frame.h"

#include <crep/gpu/backend.h>

#include <memory>
#include <string>

namespace crep::tool {

/// The backends --backend takes ("opengl", "vulkan"; "vulkan" only in a build with the Vulkan backend).
std::string backendNames();
/// The methods that run on another backend: crep::Scattering's (prefilter, minmax, epipolar-sampling,
/// epipolar-prefilter).
bool runsOnBackend(const std::string& method);
/// UsageError unless `backend` is one of backendNames().
void requireBackend(const std::string& backend);
/// The same, and for Vulkan `method` must run there.
void requireBackend(const std::string& backend, const std::string& method);
/// A Vulkan device (gpu::VulkanBackend) to keep across runs: its pipelines stay built. UsageError in a build
/// without the Vulkan backend; VulkanError when no Vulkan device answers.
std::unique_ptr<gpu::Backend> makeVulkanBackend();
/// `method` (runsOnBackend) on `vulkan` (makeVulkanBackend(); null: a device of its own, made and dropped
/// here): stages by the wall clock, the output copied into a GL texture for the composite.
MethodOutput runOnVulkan(const SceneFrame& frame, const std::string& method, const MethodSettings& settings,
                         gpu::Backend* vulkan = nullptr);

} // namespace crep::tool
