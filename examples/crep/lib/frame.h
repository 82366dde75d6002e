// The frame pipeline shared by `crep render`, `crep compare`, `crep scatter` and `crep bench`: one
// frame's inputs on the GPU (camera depth, standard shadow map, camera, light, medium), and a small
// registry of scattering methods, each a function that runs on those inputs and reports its stages.
//
// Adding a method is one entry in methodRegistry() (frame.cpp): a name, a one-line summary and a
// function Frame -> MethodOutput. The rectified map a method needs comes from Frame::rectified(),
// which rasterizes the scene's casters with the split matrices (built-in scenes) or resamples the
// standard shadow map into the projective layout (users' data), once per frame.
#pragma once

#include "timings.h"

#include <crep/core/camera.h>
#include <crep/core/gl.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace crep::scenes {
class SceneRenderer;
struct Scene;
} // namespace crep::scenes

namespace crep::tool {

/// The options of the methods (command-line options shared by render, compare and scatter).
struct MethodSettings {
  int mapSize = 1024;                          ///< rectified map, mapSize x mapSize texels
  int bases = kDefaultBases;                   ///< M
  StorageFormat format = StorageFormat::RGBA8; ///< filtered-basis storage
  RectifyOptions rectify;                      ///< splits (logarithmic)
  int steps = 256;                             ///< reference march: samples per pixel
};

/// A rectified depth map on the GPU with its rectification (projective).
struct RectifiedGpuMap {
  Rectification rect;
  std::shared_ptr<const ProjectiveLayout> layout;
  gl::Handle texture; ///< mapSize x mapSize, channel r = depth-buffer value of the split matrices
  int size = 0;
  std::string source; ///< how it was made, e.g. "rasterized" or "resampled (CPU)"
  /// Stages it cost when it was made (replayed into every method that uses it, so each method's
  /// timings stand alone even when compare shares the map between methods).
  std::vector<StageTimings::Row> cost;
};

/// One frame's inputs: what every method reads. GL names are owned here.
struct Frame {
  Frame(const Camera& c, const DirectionalLight& l, const Medium& m) : camera(c), light(l), medium(m) {}

  Camera camera;
  DirectionalLight light;
  Medium medium;
  int width = 0, height = 0; ///< camera image, pixels
  gl::Handle cameraDepth;    ///< width x height, depth-buffer values of `camera` in [0, 1]
  gl::Handle shadowMap;      ///< standard shadow map (depth-buffer values), shadowWidth x shadowHeight
  int shadowWidth = 0, shadowHeight = 0;
  glm::dmat4 lightClipFromWorld{1.0}; ///< the matrix the standard shadow map was rendered with
  double shadowBias = 2e-4;           ///< added to the stored depth by the reference march
  Image shadowImage;                  ///< CPU copy of the standard shadow map (users' data; else empty)
  scenes::SceneRenderer* renderer = nullptr; ///< built-in scene: rasterize rectified maps (not owned)

  /// The rectified map for these settings (made on first use, then shared), or nullopt when the
  /// rectification is not projective (`rect` then says why). Timings of its stages go to `timings`.
  const RectifiedGpuMap* rectified(const MethodSettings& settings, StageTimings& timings,
                                   Rectification* rect = nullptr);

private:
  std::optional<RectifiedGpuMap> rectified_;
  std::optional<Rectification> rect_;
  int rectifiedSize_ = 0, rectifiedSplits_ = 0;
};

/// What one method produced.
struct MethodOutput {
  gl::Handle scattering; ///< GL_RGBA32F width x height: RGB in-scattered radiance, A grey transmittance
  std::string used;      ///< the method actually run (a fallback may differ from the one asked)
  std::string detail;    ///< its parameters, for the report
  StageTimings timings;  ///< its stages (wall clock, each ends with glFinish)
};

/// One registry entry.
struct Method {
  std::string name;
  std::string summary;
  bool reference = false; ///< the reference of `crep compare`
  std::function<MethodOutput(Frame&, const MethodSettings&)> run;
};

/// Every method available in this build, the reference first.
const std::vector<Method>& methodRegistry();
/// The entry called `name`; throws UsageError naming `option` and listing the names otherwise.
const Method& findMethod(const std::string& name, const std::string& option = "--method");
/// "prefilter | reference | ..." for help texts and errors.
std::string methodNames();

/// Runs `name` and, when the rectification is not projective and the method needs it, the fallback
/// (announced on stderr by the method).
MethodOutput runMethod(const std::string& name, Frame& frame, const MethodSettings& settings);

// ---------------------------------------------------------------------------------------------------
// GL helpers of the tool.

/// The process-wide GL context of the tool (created on first call; never destroyed, see render.cpp's
/// history: LeakSanitizer and Mesa). `debug`: a debug context whose GL errors are recorded and
/// reported by checkGlErrors(). Prints the renderer on stderr under `command`.
void ensureGlContext(const std::string& command, bool debug, StageTimings& timings);
/// GL_RENDERER of the tool's context ("" before ensureGlContext).
std::string glRenderer();
/// Throws GlError when the debug context reported an error since the last call.
void checkGlErrors(const char* what);

/// A GL_R32F texture holding channel 0 of `image` (nearest, clamp to edge); `parameter` names the
/// input in size errors.
gl::Handle uploadR32F(const Image& image, const char* parameter);
/// Reads an RGBA texture back (row 0 = bottom).
Image readRgba(std::uint32_t texture, int width, int height);
/// surface * exp(-sigma_t s) + in-scattering (examples/glsl/passes/composite.comp), a new RGBA32F texture.
gl::Handle compositeImage(const Frame& frame, std::uint32_t surfaceColor, std::uint32_t scattering);

/// Throws crep::Error when `image` holds NaN or infinity (refuse to write a silently wrong image).
void requireFinite(const Image& image, const std::string& what);

// ---------------------------------------------------------------------------------------------------
// Built-in scenes as frames.

/// A built-in scene rendered into a Frame: standard shadow pass (mapSize^2) and lit camera pass.
struct SceneFrame {
  std::unique_ptr<scenes::Scene> scene;
  std::unique_ptr<scenes::SceneRenderer> renderer;
  std::unique_ptr<Frame> frame;
  gl::Handle color; ///< lit surfaces, RGBA32F width x height
  SceneFrame();
  ~SceneFrame();
  SceneFrame(SceneFrame&&) noexcept;
  SceneFrame& operator=(SceneFrame&&) noexcept;
};
/// Builds scene `name` for a width x height camera and renders its passes (stages to `timings`).
SceneFrame makeSceneFrame(const std::string& name, int width, int height, int shadowMapSize,
                          StageTimings& timings);

} // namespace crep::tool
