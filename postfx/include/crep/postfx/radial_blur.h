// Volumetric light scattering as a screen-space post-process (Mitchell 2007, GPU Gems 3 ch. 13): a radial
// blur of an occlusion source toward the sun's screen position; a heuristic. CPU reference in double
// (RadialBlurPass on the GPU). Fade, source, blur, modes: postfx/README.md, "crep/postfx/radial_blur.h".
#pragma once

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>

namespace crep {

/// What the radial sum accumulates.
enum class RadialBlurMode {
  SourceRadiance,    ///< Mitchell 2007, Eq. 3-4: the source's radiance (the sky's in-scattering)
  OcclusionFraction, ///< Mitchell 2007, Eq. 2: the sky fraction times the pixel's own in-scattering
};

/// The knobs of Mitchell 2007, Eq. 4 and Sec. 13.3.1, and the fade. The defaults are the physically
/// anchored setting; Mitchell's artistic settings (decay < 1, weight, exposure) scale it.
struct RadialBlurOptions {
  double exposure = 1.0;   ///< overall scale, finite, >= 0
  double decay = 1.0;      ///< per-sample attenuation decay^i away from the pixel, in (0, 1]
  double weight = 1.0;     ///< per-sample scale, finite, >= 0
  double density = 1.0;    ///< fraction of the pixel-to-sun segment covered by the samples, finite, > 0
  int samples = 64;        ///< n in [1, 1024]: n + 1 samples per pixel
  int sourceScale = 1;     ///< k in [1, 16]: the source image is downsampled by k (box filter)
  double fadeMargin = 0.5; ///< NDC units outside the screen where the fade reaches 0, finite, > 0
  int threads = 0;         ///< CPU worker threads (reference only), 0 = hardware concurrency, >= 0
  RadialBlurMode mode = RadialBlurMode::OcclusionFraction;
};

/// Throws InvalidArgument naming `owner` + ".exposure" etc.
void validate(const RadialBlurOptions& options, const char* owner = "RadialBlurOptions");

/// The sun's screen position and fade.
struct RadialLight {
  glm::dvec2 uv{0.0}; ///< texture coordinates of the image; meaningful when inFront
  double fade = 0.0;  ///< in [0, 1]: 0 behind the camera, 1 on screen
  bool inFront = false;
};

/// The sun's screen position and fade for `camera`. InvalidArgument ("RadialBlurOptions.fadeMargin").
RadialLight radialLight(const Camera& camera, const DirectionalLight& light, double fadeMargin);

/// Size of the source image for a w x h camera image and sourceScale k: ceil(w / k) x ceil(h / k).
glm::ivec2 radialSourceSize(int width, int height, int sourceScale);

/// The occlusion source image: RGBA, radialSourceSize(...). InvalidArgument ("cameraDepth", options).
Image radialBlurSource(const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                       const Medium& medium, const RadialBlurOptions& options = {});

/// Bilinear, clamp-to-edge read of `source` (<= 4 channels) at texel coordinate (sx, sy); RGBA.
glm::dvec4 radialBilinear(const Image& source, double sx, double sy);

/// The radial blur: RGBA of cameraDepth's size. Throws InvalidArgument ("cameraDepth",
/// "RadialBlurOptions.<field>"). O(pixels x samples).
Image radialBlur(const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                 const Medium& medium, const RadialBlurOptions& options = {});

} // namespace crep
