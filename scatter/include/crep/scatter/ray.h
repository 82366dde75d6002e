// The single-scattering integrand along camera view rays, shared by every method (Klehm et al. 2014,
// Eq. 1 and 3; Yusov 2012, Eq. 15-16): the pixel rays of a camera depth image, the scattering constant
// C of Eq. 1, the transmittance integral of a ray section and the output convention. The prefiltered
// evaluation (prefilter/), the marches (this module, epipolar/) and the closed form below all use these
// functions, so every method is compared on identical rays with identical integration rules.
//
// ---------------------------------------------------------------------------------------------------
// Rays and output. Per camera pixel (x, y) of a w x h depth image (row 0 at the bottom):
//   ndc = (2 (x + 0.5) / w - 1, 2 (y + 0.5) / h - 1), v = camera.rayDirection(ndc) (unit);
//   s = linearDepth(depth) / dot(v, forward) (surface distance, world units); sky (depth >= 1):
//   s = far / dot(v, forward) (the maps cover the frustum up to the far plane, nothing beyond).
//   The integration starts at the camera (t = 0), or, with the near-plane correction (Klehm et al. 2014,
//   Sec. 3.1), at t_n = min(near / dot(v, forward), s).
//   C = light.irradiance() * medium.scatteringTimesPhase(dot(light.direction(), -v)) per channel;
//   L = C sum_{lit sections [ta, tb]} (exp(-sigma ta) - exp(-sigma tb)) / sigma   (sigma = extinction per
//       channel; evaluated as exp(-sigma ta) (tb - ta) phi(sigma (tb - ta)), finite as sigma -> 0).
//   Output RGBA: RGB = L, A = exp(-sbar s), sbar = weightExtinction(medium), the grey transmittance to the
//   surface (composite: surface * A + L; per-channel transmittance is exp(-sigma_c s)).
#pragma once

#include <span>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>

namespace crep {

/// Options of the CPU marches and of the closed form (rules at the top).
struct MarchOptions {
  /// CPU worker threads: 0 = std::thread::hardware_concurrency(). Never changes the result.
  int threads = 0;
  /// Klehm et al. 2014, Sec. 3.1: integrate from the near plane instead of the camera.
  bool nearPlaneCorrection = false;
};

/// Throws InvalidArgument naming the field ("MarchOptions.threads").
void validate(const MarchOptions& options);

/// What a march produces.
struct MarchResult {
  Image scattering; ///< RGBA, the camera image's size: RGB in-scattered radiance, A grey transmittance
  Image steps;      ///< 1 channel, same size: steps of the pixel's march (defined by each march)
  double meanSteps() const; ///< mean of `steps` over all pixels (0 for an empty result)
  double maxSteps() const;  ///< max of `steps`
};

/// The view ray of one camera pixel and its integration range (rules at the top).
struct PixelRay {
  glm::dvec3 direction{0.0}; ///< v: unit, from the camera
  double surface = 0.0;      ///< s: distance to the surface (far plane for the sky), world units
  double start = 0.0;        ///< 0, or t_n with the near-plane correction
};

/// The ray of pixel (x, y) of the depth image `depth` (channel 0; validated by validateCameraDepth):
/// screenRay at the pixel centre (x + 0.5, y + 0.5) with the pixel's depth-buffer value (bit-identical).
PixelRay pixelRay(const Camera& camera, const Image& depth, int x, int y, bool nearPlaneCorrection = false);

/// The ray through the continuous position (x, y) of a width x height camera image (pixel coordinates,
/// origin at the bottom-left corner, pixel centres at + 0.5: ndc = 2 (x, y) / (width, height) - 1) ending
/// at the surface of depth-buffer value `depthValue` (camera.surfaceViewDepth: >= 1 is the sky, far()):
/// pixelRay's rule at any point of the screen (Yusov 2012, Sec. 6.1: epipolar samples lie between pixel
/// centres). Not validated (width, height > 0 and a finite position are the caller's).
PixelRay screenRay(const Camera& camera, int width, int height, double x, double y, double depthValue,
                   bool nearPlaneCorrection = false);

/// A point of the camera image to evaluate: its ray is screenRay(camera, width, height, x, y, depth).
struct ScreenSample {
  double x = 0, y = 0; ///< pixel coordinates (origin bottom-left, pixel centres at + 0.5)
  double depth = 1;    ///< depth-buffer value of the ray's surface, in [0, 1]
};

/// Throws InvalidArgument ("samples[i]", with the value) unless every sample has a finite position and a
/// depth-buffer value in [0, 1] (NaN included); "width" / "height" unless both are > 0.
void validateScreenSamples(std::span<const ScreenSample> samples, int width, int height);

/// Throws InvalidArgument ("cameraDepth", naming the pixel and value) unless `depth` is non-empty and
/// every value of its first channel is a depth-buffer value in [0, 1] (NaN included).
void validateCameraDepth(const Image& depth);

/// C of Eq. 1 per channel for a view direction v (unit, from the camera): irradiance *
/// medium.scatteringTimesPhase(dot(light.direction(), -v)) (radiance per world unit).
glm::dvec3 scatteringConstant(const DirectionalLight& light, const Medium& medium,
                              const glm::dvec3& viewDirection);

/// The grey extinction sbar: the mean of medium.extinction() over R, G, B (1/world unit). The alpha
/// channel of every output and the scalar extinction of the prefilter weights.
double weightExtinction(const Medium& medium);

/// phi(x) = (1 - exp(-x)) / x for x >= 0, phi(0) = 1 (series below 1e-5). +inf -> 0.
double oneMinusExpOverX(double x);

/// (exp(-sigma ta) - exp(-sigma tb)) / sigma = exp(-sigma ta) (tb - ta) phi(sigma (tb - ta)) (Eq. 3 on one
/// section), tb - ta for sigma = 0; 0 when tb <= ta.
double transmittanceIntegral(double sigma, double ta, double tb);
/// The same per channel.
glm::dvec3 transmittanceIntegral(const glm::dvec3& sigma, double ta, double tb);

/// Writes RGB = L, A = transmittance into pixel (x, y) of an RGBA image.
void storeScattering(Image& out, int x, int y, const glm::dvec3& L, double transmittance);

/// Closed-form single scattering of the homogeneous medium without occluders (Eq. 1 with V = 1, Eq. 3):
/// L_c = C_c (exp(-sigma_c t_a) - exp(-sigma_c s)) / sigma_c on the rays at the top. Ground truth for tests
/// and the value of pixels a layout cannot map. Throws InvalidArgument ("cameraDepth", options).
Image unshadowedScattering(const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                           const Medium& medium, const MarchOptions& options = {});

} // namespace crep
