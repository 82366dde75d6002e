// `crep render --backend vulkan`: the frame's crep::Scattering on gpu::VulkanBackend, the scene's maps
// rendered by GL and handed over as an engine on Vulkan would (crep/scenes/engine_frame.h).
#pragma once

#include "methods.h"
#include "scene_frame.h"

#include <string>

namespace crep::tool {

/// The backends --backend takes ("opengl", "vulkan"; "vulkan" only in a build with the Vulkan backend).
std::string backendNames();
/// UsageError unless `backend` is one of backendNames() and, for Vulkan, `method` runs there (prefilter,
/// minmax) and the settings are those the Vulkan frame supports (--scale 1).
void requireBackend(const std::string& backend, const std::string& method, const MethodSettings& settings);
/// `method` (prefilter or minmax) on a Vulkan device: stages by the wall clock, the output copied into a GL
/// texture for the composite. Throws VulkanError when no Vulkan device answers.
MethodOutput runOnVulkan(const SceneFrame& frame, const std::string& method, const MethodSettings& settings);

} // namespace crep::tool
