// One frame's inputs on the GPU, shared by the tool's commands and the benchmark: camera depth,
// standard shadow map, camera, light, medium, and the rectified map a method needs (made on first use,
// then shared between methods: `crep compare` runs several methods on one frame).
#pragma once

#include "timings.h"

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/gpu/gl.h>
#include <crep/pipeline/scattering.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/gpu_light_texture.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace crep::scenes {
class SceneRenderer;
} // namespace crep::scenes

namespace crep::tool {

/// The options of the methods (command-line options shared by render, compare, scatter and bench).
struct MethodSettings {
  int mapSize = 1024; ///< rectified map, mapSize x mapSize texels
  /// M, storage format, regions per split, ... of the prefiltered method (crep::Scattering's defaults)
  PrefilterOptions prefilter = Scattering::CreateInfo{}.prefilter;
  RectifyOptions rectify = Scattering::CreateInfo{}.rectify; ///< splits (logarithmic; Scattering's defaults)
  int steps = 256;    ///< world-space reference march: sections per pixel
  double scale = 1.0; ///< prefiltered method: Scattering::CreateInfo::evaluationScale (1, 0.5 or 0.25)
  /// epipolar-sampling, epipolar-prefilter: Scattering::CreateInfo::epipolarSampling
  EpipolarSamplingOptions sampling;
  /// prefilter, epipolar-prefilter: Scattering::CreateInfo::epipoleBlockMethod and epipoleBlockRadius
  Scattering::EpipoleBlockMethod epipoleBlock = Scattering::CreateInfo{}.epipoleBlockMethod;
  double epipoleBlockRadius = Scattering::CreateInfo{}.epipoleBlockRadius;
  int epipoleBlockMaxPixels = Scattering::CreateInfo{}.epipoleBlockMaxPixels;
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

/// A local light's perspective shadow map on the GPU: one per spot light, one per point-light face.
struct LocalShadowMap {
  gl::Handle texture; ///< depth-buffer values of lightClipFromWorld (R32F or depth)
  int width = 0, height = 0;
  glm::dmat4 lightClipFromWorld{1.0}; ///< perspective, centred at the light (GL conventions)
  double bias = 0.0;                  ///< added to the stored depth by the world-space marches
  Image image;                        ///< CPU copy (users' data; else empty)
};

/// A light texture on the GPU (frame_json.h "Light textures"; crep/scatter/light_texture.h): the texture
/// and its projection. texture 0 = none.
struct LightTextureMap {
  gl::Handle texture; ///< GL_RGBA32F, RGB the texture (A = 1), row 0 at the bottom (v = 0)
  glm::dmat4 textureClipFromWorld{1.0};
  Image image; ///< CPU copy, RGB
  bool present() const { return texture.get() != 0; }
  GpuLightTexture gpu() const { return {texture.get(), textureClipFromWorld}; }
};
/// Uploads an RGB(A) image (channels 0-2) as a LightTextureMap; `parameter` names it in size errors.
LightTextureMap makeLightTextureMap(Image rgb, const glm::dmat4& textureClipFromWorld, const char* parameter);

/// One frame's inputs: what every method reads. GL names are owned here.
struct FrameInputs {
  FrameInputs(const Camera& c, const DirectionalLight& l, const Medium& m) : camera(c), light(l), medium(m) {}

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
  /// false: no directional light (a night frame with local lights only; `light` and the standard shadow
  /// map are then unused)
  bool directional = true;
  /// Local lights (Klehm et al. 2014, Sec. 3.2), added to the directional light's result by every method,
  /// with their perspective shadow maps: spotShadows[i] for spotLights[i], pointShadows[6 i + k] for face k
  /// (+X, -X, +Y, -Y, +Z, -Z) of pointLights[i].
  std::vector<SpotLight> spotLights;
  std::vector<PointLight> pointLights;
  std::vector<LocalShadowMap> spotShadows, pointShadows;
  bool hasLocalLights() const { return !spotLights.empty() || !pointLights.empty(); }
  /// Light textures (crep/scatter/light_texture.h): the directional light's (texture 0 = none), and empty
  /// or one per spot light (texture 0 = that spot has none).
  LightTextureMap lightTexture;
  std::vector<LightTextureMap> spotTextures;
  /// The texture of spot i, or nullptr.
  const LightTextureMap* spotTexture(std::size_t i) const {
    return i < spotTextures.size() && spotTextures[i].present() ? &spotTextures[i] : nullptr;
  }
  bool textured() const {
    if (lightTexture.present()) return true;
    for (const LightTextureMap& t : spotTextures)
      if (t.present()) return true;
    return false;
  }

  /// The rectified map for these settings (made on first use, then shared while the map size and the
  /// rectify options stay the same), or nullptr when the rectification is not projective (`rect` then
  /// says why). Timings of its stages go to `timings`.
  const RectifiedGpuMap* rectified(const MethodSettings& settings, StageTimings& timings,
                                   Rectification* rect = nullptr);

private:
  std::optional<RectifiedGpuMap> rectified_;
  std::optional<Rectification> rect_;
  int rectifiedSize_ = 0;
  RectifyOptions rectifiedOptions_;
};

} // namespace crep::tool
