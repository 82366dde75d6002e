// A built-in scene (crep/scenes) rendered into a FrameInputs: the standard shadow pass and the lit camera
// pass.
#pragma once

#include "frame.h"
#include "timings.h"

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/gpu/gl.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace crep::scenes {
class SceneRenderer;
struct Scene;
} // namespace crep::scenes

namespace crep::tool {

struct SceneFrame {
  std::unique_ptr<scenes::Scene> scene;
  std::unique_ptr<scenes::SceneRenderer> renderer;
  std::unique_ptr<FrameInputs> frame;
  gl::Handle color; ///< lit surfaces, RGBA32F width x height
  SceneFrame();
  ~SceneFrame();
  SceneFrame(SceneFrame&&) noexcept;
  SceneFrame& operator=(SceneFrame&&) noexcept;
};

/// Depth bias of the built-in scenes' local-light perspective maps (depth-buffer units; crep::Scattering's
/// ownShadowMapBias).
inline constexpr double kLocalShadowBias = 1e-4;

/// What a command changes in a built-in scene before rendering it (`crep render --method atmosphere`).
struct SceneOverrides {
  std::optional<DirectionalLight> sun; ///< the sun of the shadow pass, the methods and the shading
  std::optional<Camera> camera;        ///< the camera (its aspect must be the image's)
  /// The surfaces' shading: the sun's irradiance at the ground (e.g. after the atmosphere's extinction)
  /// and the ambient irradiance (SceneRenderer::ShadeInputs' ambient) instead of the sun's and the default.
  std::optional<glm::dvec3> shadeIrradiance, shadeAmbient;
};

/// Every built-in scene name makeScene accepts: the sunlit, local-light and light-texture scenes.
std::vector<std::string> builtInSceneNames();
/// UsageError naming `option` (e.g. "--scene") and listing the scenes when `name` is not a built-in scene:
/// checked before any output path (the default --out is crep-<scene>) and before any GL work.
void requireSceneName(const std::string& name, const std::string& option = "--scene");

/// Builds scene `name` for a width x height camera and renders its passes (stages to `timings`).
SceneFrame makeSceneFrame(const std::string& name, int width, int height, int shadowMapSize,
                          StageTimings& timings, const SceneOverrides& overrides = {});

} // namespace crep::tool
