// The single-scattering integrand along camera view rays, shared by every method (Klehm et al. 2014,
// Eq. 1 and 3; Yusov 2012, Eq. 15-16): pixel rays, the scattering constant C, transmittance integrals, the
// output convention. The rules: scatter/README.md, "crep/scatter/ray.h" ("Rays and output").
#pragma once

#include <span>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>

namespace crep {

/// Options of the CPU marches and of the closed form.
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

/// The view ray of one camera pixel and its integration range.
struct PixelRay {
  glm::dvec3 direction{0.0}; ///< v: unit, from the camera
  double surface = 0.0;      ///< s: distance to the surface (far plane for the sky), world units
  double start = 0.0;        ///< 0, or t_n with the near-plane correction
};

/// The ray of pixel (x, y) of `depth` (channel 0): screenRay at the pixel centre, bit for bit.
PixelRay pixelRay(const Camera& camera, const Image& depth, int x, int y, bool nearPlaneCorrection = false);

/// The ray through pixel point (x, y) of a width x height image (origin bottom-left) to the surface of
/// `depthValue` (Yusov 2012, Sec. 6.1). Not validated: width, height > 0 and finite x, y are the caller's.
PixelRay screenRay(const Camera& camera, int width, int height, double x, double y, double depthValue,
                   bool nearPlaneCorrection = false);

/// A point of the camera image to evaluate: its ray is screenRay(camera, width, height, x, y, depth).
struct ScreenSample {
  double x = 0, y = 0; ///< pixel coordinates (origin bottom-left, pixel centres at + 0.5)
  double depth = 1;    ///< depth-buffer value of the ray's surface, in [0, 1]
};

/// InvalidArgument ("samples[i]") unless positions are finite and depths in [0, 1]; "width" / "height" > 0.
void validateScreenSamples(std::span<const ScreenSample> samples, int width, int height);

/// InvalidArgument ("cameraDepth", with the pixel) unless non-empty and channel 0 is in [0, 1]. O(pixels).
void validateCameraDepth(const Image& depth);

/// C of Eq. 1 per channel for a unit view direction v, radiance per world unit.
glm::dvec3 scatteringConstant(const DirectionalLight& light, const Medium& medium,
                              const glm::dvec3& viewDirection);

/// The grey extinction sbar: mean of medium.extinction() over R, G, B (1/world unit).
double weightExtinction(const Medium& medium);

/// phi(x) = (1 - exp(-x)) / x for x >= 0, phi(0) = 1 (series below 1e-5). +inf -> 0.
double oneMinusExpOverX(double x);

/// (exp(-sigma ta) - exp(-sigma tb)) / sigma (Eq. 3 on one section); tb - ta for sigma = 0; 0 if tb <= ta.
double transmittanceIntegral(double sigma, double ta, double tb);
/// The same per channel.
glm::dvec3 transmittanceIntegral(const glm::dvec3& sigma, double ta, double tb);

/// Writes RGB = L, A = transmittance into pixel (x, y) of an RGBA image.
void storeScattering(Image& out, int x, int y, const glm::dvec3& L, double transmittance);

/// Closed-form single scattering without occluders (Eq. 1 with V = 1, Eq. 3). Throws InvalidArgument
/// ("cameraDepth", options). O(pixels).
Image unshadowedScattering(const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                           const Medium& medium, const MarchOptions& options = {});

} // namespace crep
