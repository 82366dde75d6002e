// Volumetric light scattering as a screen-space post-process (Mitchell 2007, GPU Gems 3 ch. 13): a radial
// blur of an occlusion source image toward the sun's screen position. CPU reference in double; the GL pass
// of the same rule is RadialBlurPass (crep/postfx/gpu_radial_blur.h). A heuristic: it sees only what is
// on screen, treats every occluder as if it were in front of the sky behind it (Mitchell 2007, Sec. 13.6)
// and knows nothing of the shadows' depth; compare it with the world-space reference to see how far off.
//
// ---------------------------------------------------------------------------------------------------
// The sun on screen (radialLight). The sun is the point at infinity in direction l = -light.direction();
// q = camera.clipFromWorld() (l, 0) (a direction: w = 0). q.w > 0: in front of the camera, screen position
// uv = (q.xy / q.w) * 0.5 + 0.5 (texture coordinates of the image, row 0 at the bottom; outside [0, 1]^2
// when the sun is off screen). Fade (Mitchell 2007, Sec. 13.6: "faded toward the perpendicular"):
//   q.w <= 0 (the sun behind the camera or in its image plane): fade = 0 exactly, nothing is added;
//   else e = max(|ndc.x| - 1, |ndc.y| - 1, 0) (how far outside the screen, in NDC units: 1 = half the
//   screen's width or height), t = min(e / fadeMargin, 1), fade = 1 - t^2 (3 - 2 t).
// So fade = 1 whenever the sun projects onto the screen, falls smoothly (C1) to 0 at fadeMargin outside
// it, and is 0 long before the sun reaches the perpendicular (where the screen position goes to infinity
// and the samples would spread without bound, Sec. 13.6); the blur only runs with the sun within
// fadeMargin of the screen, which is Mitchell's guard band.
//
// The source image (radialBlurSource; the occlusion pre-pass of Sec. 13.5.1 with a physical bright value):
// per camera pixel, sky (the cleared depth value, the rule of Camera::surfaceViewDepth: t = 1 - d, or d
// reversed-Z, not > 0, NaN included) -> the unshadowed in-scattering of that pixel's view ray to the far
// plane, i.e. crep::unshadowedScattering (crep/scatter/ray.h; Mitchell 2007, Eq. 1 without the L0 term);
// geometry -> 0 (drawn black). RGB = that radiance, A = 1 for sky, 0 for geometry. With sourceScale k > 1
// (Mitchell 2007, Sec. 13.3.1 and 13.8: a downsampled source) the source is ceil(w / k) x ceil(h / k), each
// texel the mean of the pixels of its k x k block that lie in the image (a box filter).
//
// The blur (radialBlur; Mitchell 2007, Eq. 4 and Sec. 13.4). Output pixel (x, y) of the w x h image:
// p = ((x + 0.5) / w, (y + 0.5) / h), delta = (p - uv) density / n (n = samples), for i = 0 .. n the sample
// p_i = p - i delta (i = 0 is the pixel itself; with density 1, i = n is the sun), read bilinearly from the
// source (source texel coordinate p_i (w, h) / k - 0.5, texel indices clamped to the image: GL's
// CLAMP_TO_EDGE), and
//   RGB = fade exposure weight / (n + 1) sum_{i=0}^{n} decay^i source(p_i),
//   A   = exp(-sbar s), s the pixel ray's surface distance and sbar = weightExtinction (crep::pixelRay,
//         the transmittance every method of the library writes, so surface * A + RGB composites the same).
// Eq. 4 divides its n + 1 terms by n; here they are averaged (n + 1), so that with exposure = weight =
// decay = density = 1 the RGB is the visible (sky) fraction of the screen segment from the pixel to the
// sun times the sky's unshadowed in-scattering along it (Mitchell 2007, Eq. 2-3): exactly the unshadowed
// in-scattering of the sky when nothing occludes a uniform sky. The in-scattering of a geometry pixel is
// the sky's along its segment, not its own shorter ray's (the method's bias near the camera).
// Mode OcclusionFraction (Mitchell 2007, Eq. 2 with the occlusion D estimated as in Sec. 13.3 by the
// proportion of samples that reach the bright region): the same sum over the source's A (the sky
// fraction) instead of its RGB, times the pixel's own unshadowed in-scattering U(x, y) (the closed form of
// crep::unshadowedScattering on its own ray, to its surface):
//   RGB = fade exposure weight / (n + 1) sum_{i=0}^{n} decay^i a(p_i) U(x, y), a = the source's A.
// With the defaults: the visible fraction of the screen segment times the pixel's own in-scattering, so
// geometry pixels keep their shorter rays' in-scattering instead of the sky's.
// Only the directional light; local lights and light textures are not modelled.
#pragma once

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>

namespace crep {

/// What the radial sum accumulates (rules at the top).
enum class RadialBlurMode {
  SourceRadiance,    ///< Mitchell 2007, Eq. 3-4: the source's radiance (the sky's in-scattering)
  OcclusionFraction, ///< Mitchell 2007, Eq. 2: the sky fraction times the pixel's own in-scattering
};

/// The knobs of Mitchell 2007, Eq. 4 and Sec. 13.3.1, and the fade. The defaults are the physically
/// anchored setting (the blur is the sky-fraction estimate of Eq. 2 times the pixel's own unshadowed
/// in-scattering: 26% relative RMSE against the world-space reference on the sun-in-view scene, where
/// SourceRadiance, the sky's in-scattering summed as in Eq. 3-4, is 77% off); Mitchell's artistic
/// settings (decay < 1, weight and exposure tuned by eye) scale it.
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

/// Throws InvalidArgument naming `owner` + ".exposure" etc. (e.g. owner
/// "RadialBlurPass::CreateInfo.options" -> "RadialBlurPass::CreateInfo.options.decay").
void validate(const RadialBlurOptions& options, const char* owner = "RadialBlurOptions");

/// The sun's screen position and fade (rule at the top).
struct RadialLight {
  glm::dvec2 uv{0.0}; ///< texture coordinates of the image; meaningful when inFront
  double fade = 0.0;  ///< in [0, 1]: 0 behind the camera, 1 on screen
  bool inFront = false;
};

/// The sun's screen position and fade for `camera` (rule at the top). Throws InvalidArgument
/// ("RadialBlurOptions.fadeMargin") for a margin that is not finite and > 0.
RadialLight radialLight(const Camera& camera, const DirectionalLight& light, double fadeMargin);

/// Size of the source image for a w x h camera image and sourceScale k: ceil(w / k) x ceil(h / k).
glm::ivec2 radialSourceSize(int width, int height, int sourceScale);

/// The occlusion source image (rule at the top): RGBA, radialSourceSize(...). Throws InvalidArgument for a
/// bad camera depth ("cameraDepth") or options.
Image radialBlurSource(const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                       const Medium& medium, const RadialBlurOptions& options = {});

/// Bilinear read of `source` (any channel count <= 4) at source texel coordinate (sx, sy) (texel centres at
/// integers), indices clamped to the image (rule at the top). Returns RGBA (missing channels 0).
glm::dvec4 radialBilinear(const Image& source, double sx, double sy);

/// The radial blur (rule at the top): RGBA of cameraDepth's size. Throws InvalidArgument for a bad camera
/// depth ("cameraDepth") or options ("RadialBlurOptions.<field>").
Image radialBlur(const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                 const Medium& medium, const RadialBlurOptions& options = {});

} // namespace crep
