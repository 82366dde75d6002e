// crepuscular in the Vulkan engine of engine.h: the whole integration. A gpu::VulkanBackend on the engine's
// device, the engine's images imported where they are (camera depth, shadow maps, output), and per frame
// the three steps of a crep::Scattering frame: plan() (CPU: the shadow passes crepuscular needs, in Vulkan's
// clip conventions), the engine's shadow passes rasterized from that plan with its own pipeline into its own
// depth images, then record() (crepuscular's compute passes into the engine's command buffer, between its
// depth passes and its submission). docs/VULKAN_STATE.md is the contract it relies on.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <crep/pipeline/scattering.h>
#include <crep/vulkan/vulkan_backend.h>

#include "engine.h"

namespace vkengine {

/// The engine's images the volumetrics read and write every frame besides the shadow maps.
struct VolumetricImages {
  const DepthImage* cameraDepth = nullptr;
  const ColorImage* output = nullptr; ///< RGB in-scattering, A transmittance
};

/// A frame's lights and medium. Their shadow maps are the plan's (Volumetrics::plan).
struct VolumetricLights {
  const crep::DirectionalLight* sun = nullptr; ///< null: a night frame (the spots alone)
  std::span<const crep::SpotLight> spots;
  const crep::Medium* medium = nullptr;
};

/// One shadow pass of the frame's plan as the engine draws it: the depth image, the raster state and the
/// draws (one per split of a rectified map, one for a standard map).
struct ShadowPassTarget {
  const crep::ShadowPass* pass = nullptr; ///< the plan's pass
  const DepthImage* image = nullptr;      ///< the engine's image of the pass's size
  DepthPassState state;
  std::vector<DepthDraw> draws;
};

/// A gpu::VulkanBackend's CreateInfo on the engine's instance, device and queue, resolving Vulkan through
/// `loader`.
crep::gpu::VulkanBackend::CreateInfo
backendOnEngine(const Engine& engine, PFN_vkGetInstanceProcAddr loader = vkGetInstanceProcAddr);

/// Imports an engine image into the backend where it is (VulkanBackend::importTexture), in its home layout.
crep::gpu::TextureId importImage(crep::gpu::VulkanBackend& backend, const DepthImage& image,
                                 const char* label);
crep::gpu::TextureId importImage(crep::gpu::VulkanBackend& backend, const ColorImage& image,
                                 const char* label);

/// The engine's depth images for shadow maps, each imported into the backend once and reused frame after
/// frame (the render pass's dependencies order a frame's depth pass after the previous frame's reads).
class DepthImagePool {
public:
  DepthImagePool(Engine& engine, crep::gpu::VulkanBackend& backend) : engine_(engine), backend_(backend) {}
  struct Entry {
    const DepthImage* image = nullptr;
    crep::gpu::TextureId texture = 0; ///< the image in the backend
  };
  /// Every image free again: at the start of a frame's planning.
  void release() { taken_.assign(entries_.size(), false); }
  /// A free image of that size, made (and imported) when there is none.
  Entry acquire(std::uint32_t width, std::uint32_t height);

private:
  Engine& engine_;
  crep::gpu::VulkanBackend& backend_;
  std::vector<Entry> entries_;
  std::vector<bool> taken_;
};

/// A plan pass (ClipConvention::Vulkan) as the engine's depth pass into `image` (its size): the pass's clear
/// value, compare and depth clamp; per split its matrix, its viewport as it is (a positive height, no y flip)
/// and its scissor.
ShadowPassTarget targetOf(const crep::ShadowPass& pass, const DepthImage& image);

/// The depth images of a plan's maps, taken from `pool` (after its release() for the frame).
struct PlannedMaps {
  std::vector<std::uint32_t> planMaps; ///< FrameAttribs::planMaps: one per plan pass, 0 where none is needed
  std::vector<ShadowPassTarget> targets; ///< the passes that need a map, in the plan's order
};
PlannedMaps acquireMaps(const crep::ShadowPassPlan& plan, DepthImagePool& pool);

class Volumetrics {
public:
  /// `settings`: crep::Scattering's CreateInfo but its backend (the size is the camera depth's).
  /// `loader`: the Vulkan loader's entry point the backend resolves every function through (the engine's).
  Volumetrics(Engine& engine, const VolumetricImages& images, crep::Scattering::CreateInfo settings,
              PFN_vkGetInstanceProcAddr loader = vkGetInstanceProcAddr);

  /// Step 1 of a frame, before its shadow passes: crepuscular's plan for this camera and these lights
  /// (Scattering::plan, CPU only), each pass that needs a map given a depth image of its size from a pool
  /// kept across frames (made and imported on first need). Valid until the next plan().
  const std::vector<ShadowPassTarget>& plan(const crep::Camera& camera, const VolumetricLights& lights);
  /// Step 2 is the engine's: Engine::drawDepthPass(frame, *t.image, t.state, t.draws) for each target.
  /// Step 3: records the frame into `frame.commandBuffer`, after the engine's depth passes and before its
  /// submission: no submission and no wait. The same camera and lights as plan(). The GPU times of earlier
  /// frames come back in FrameResult::gpuTimes once those frames have completed.
  crep::Scattering::FrameResult record(const Engine::Frame& frame, const crep::Camera& camera,
                                       const VolumetricLights& lights);

  const crep::ShadowPassPlan& currentPlan() const { return plan_; }
  const std::vector<ShadowPassTarget>& currentTargets() const { return maps_.targets; }
  crep::gpu::VulkanBackend& backend() { return backend_; }

private:
  crep::Scattering::FrameAttribs attribs(const crep::Camera& camera, const VolumetricLights& lights) const;

  crep::gpu::VulkanBackend backend_;
  crep::gpu::TextureId cameraDepth_ = 0, output_ = 0;
  crep::Scattering scattering_;
  DepthImagePool shadowMaps_;
  crep::ShadowPassPlan plan_;
  PlannedMaps maps_; ///< plan_'s
};

} // namespace vkengine
