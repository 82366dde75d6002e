// `--backend vulkan` of crep render, compare and bench: the frame's crep::Scattering on gpu::VulkanBackend,
// its camera depth and its plan's shadow maps rasterized on Vulkan by the Vulkan engine example's engine
// (examples/vulkan_engine), as an engine on Vulkan does: the same method as on OpenGL, no GL map read back.
#pragma once

#include "methods.h"
#include "scene_frame.h"

#include <crep/gpu/backend.h>

#include <memory>
#include <string>
#include <vector>

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
/// One built-in scene on Vulkan, to keep across runs of that scene (its pipelines and depth images stay
/// built): the Vulkan engine example's engine (its own instance and device, the scene's mesh, its depth-only
/// graphics pipeline) and a gpu::VulkanBackend on the engine's device. UsageError in a build without the
/// Vulkan backend; an error naming the failed call when no Vulkan device answers.
class VulkanSession {
public:
  /// `validation`: the engine's instance with VK_LAYER_KHRONOS_validation (synchronization validation on).
  explicit VulkanSession(const scenes::Scene& scene, bool validation = false);
  ~VulkanSession();
  VulkanSession(const VulkanSession&) = delete;
  VulkanSession& operator=(const VulkanSession&) = delete;
  /// The layer's warnings and errors so far (empty without validation).
  std::vector<std::string> validationMessages() const;
  std::string deviceName() const;

  struct Impl;
  Impl& impl() { return *impl_; }

private:
  std::unique_ptr<Impl> impl_;
};
/// `method` (runsOnBackend) on Vulkan: the engine rasterizes the camera depth and the plan's shadow maps
/// (Scattering::plan, ClipConvention::Vulkan: rectified maps, standard maps of lights in view, point-light
/// faces; the sun's fallback reads the frame's standard map, rendered there too, as the OpenGL method does),
/// then crep::Scattering runs on the backend. `session`: one of this scene kept across runs (null: one of its
/// own, made and dropped here). Stages by the wall clock, the output copied into a GL texture for the
/// composite.
MethodOutput runOnVulkan(const SceneFrame& frame, const std::string& method, const MethodSettings& settings,
                         VulkanSession* session = nullptr);

} // namespace crep::tool
