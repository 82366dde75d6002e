// crepuscular in the Vulkan engine of engine.h: the whole integration. A gpu::VulkanBackend on the engine's
// device, the engine's images imported where they are (camera depth, shadow maps, output), and a
// crep::Scattering frame recorded into the engine's command buffer between its depth passes and its
// submission. docs/VULKAN_STATE.md is the contract it relies on.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <crep/pipeline/scattering.h>
#include <crep/vulkan/vulkan_backend.h>

#include "engine.h"

namespace vkengine {

/// The engine's images the volumetrics read and write. The sun map may be null (a night frame); one spot
/// map per spot light of the frames.
struct VolumetricImages {
  const DepthImage* cameraDepth = nullptr;
  const DepthImage* sunMap = nullptr;
  std::vector<const DepthImage*> spotMaps;
  const ColorImage* output = nullptr; ///< RGB in-scattering, A transmittance
};

/// A frame's lights and medium. The shadow matrices are in OpenGL's clip conventions, as crepuscular takes
/// them; the engine rasterizes each map with zeroToOne(matrix).
struct VolumetricLights {
  const crep::DirectionalLight* sun = nullptr;
  glm::dmat4 sunClipFromWorld{1.0};
  std::span<const crep::SpotLight> spots; ///< spot i's map is VolumetricImages::spotMaps[i]
  std::vector<glm::dmat4> spotClipFromWorld;
  const crep::Medium* medium = nullptr;
  double bias = 1e-4; ///< added to the stored depth by the world-space marches (depth-buffer units)
};

class Volumetrics {
public:
  /// `settings`: crep::Scattering's CreateInfo but its backend (the size is the camera depth's).
  /// `loader`: the Vulkan loader's entry point the backend resolves every function through (the engine's).
  Volumetrics(const Engine& engine, const VolumetricImages& images, crep::Scattering::CreateInfo settings,
              PFN_vkGetInstanceProcAddr loader = vkGetInstanceProcAddr);

  /// Records the frame into `frame.commandBuffer`, after the engine's depth passes and before its
  /// submission: no submission and no wait. The GPU times of earlier frames come back in
  /// FrameResult::gpuTimes once those frames have completed.
  crep::Scattering::FrameResult record(const Engine::Frame& frame, const crep::Camera& camera,
                                       const VolumetricLights& lights);

  crep::gpu::VulkanBackend& backend() { return backend_; }

private:
  crep::gpu::VulkanBackend backend_;
  crep::gpu::TextureId cameraDepth_ = 0, sunMap_ = 0, output_ = 0;
  std::vector<crep::gpu::TextureId> spotMaps_;
  crep::Scattering scattering_;
};

} // namespace vkengine
