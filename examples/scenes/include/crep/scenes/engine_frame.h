// A built-in scene's frame as an engine hands it to crep::Scattering on any gpu::Backend: the camera depth
// and the shadow maps rendered once by GL and read back (renderEngineMaps), then uploaded to a backend as
// its depth textures (EngineFrame). How the backends are compared side by side: tests/vulkan/ and the
// bench's "backends" section.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include <crep/core/image.h>
#include <crep/gpu/backend.h>
#include <crep/pipeline/scattering.h>
#include <crep/scatter/gpu_light_texture.h>
#include <crep/scenes/scene.h>

namespace crep::scenes {

/// The engine's inputs of a frame, on the CPU (1 channel, depth-buffer values, row 0 at the bottom).
struct EngineMaps {
  Image cameraDepth;                ///< width x height, of scene.camera
  Image sunMap;                     ///< sunMapSize^2 with depth clamp; empty without a sun
  glm::dmat4 sunClipFromWorld{1.0}; ///< orthographicLightClipFromWorld of the camera's frustum
  std::vector<Image> spotMaps;      ///< one per scene spot (its lightClipFromWorld), localMapSize^2
  std::vector<Image> pointMaps;     ///< six per point light, face k of light i at 6 i + k
  double sunBias = 1e-4;            ///< Scattering::ShadowMap::bias of the sun's map (depth-buffer units)
  double localBias = 1e-4;          ///< the same for the local lights' maps
};

/// The RGBA floats a backend's RGBA32F texture takes of an image's RGB (channels 0-2 of 3 or 4), A = 1, row 0
/// at the bottom.
std::vector<float> rgbaTexels(const Image& rgb);

/// Renders the maps with GL (needs a current context). Sizes > 0.
EngineMaps renderEngineMaps(const Scene& scene, int width, int height, int sunMapSize, int localMapSize);

/// The maps as Depth32F textures of `backend` (kept for its lifetime), the scene's light texture (if any) as
/// an RGBA32F one, and the frame over them.
class EngineFrame {
public:
  EngineFrame(gpu::Backend& backend, const Scene& scene, const EngineMaps& maps);
  /// The frame's attributes writing `output` (RGBA32F, the camera depth's size, a texture of the backend):
  /// camera, sun and medium of the scene, the maps as shadowMap / spotShadowMaps / pointShadowMaps, the
  /// sun's light texture when the scene has one.
  Scattering::FrameAttribs attribs(std::uint32_t output) const;

private:
  const Scene& scene_;
  gpu::Texture depth_, sun_, window_;
  GpuLightTexture lightTexture_; ///< window_ and its projection; texture 0 without one
  std::vector<gpu::Texture> locals_;
  Scattering::ShadowMap sunMap_;
  std::vector<Scattering::ShadowMap> spotMaps_, pointMaps_;
};

} // namespace crep::scenes
