// Private helpers shared by the CPU marches (march.cpp) and the epipole block: the pixel rays and the
// integration rule of crep/epipolar/march.h ("Rays and output").
#pragma once

#include <crep/core/camera.h>
#include <crep/core/error.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/prefilter/prefilter.h>
#include <crep/prefilter/weights.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace crep::epipolar_detail {

// validateCameraDepth: crep::validateCameraDepth (prefilter.h), the same rule for every CPU path.

/// The view ray of pixel (x, y) and the distance s to its surface (far plane for the sky).
struct PixelRay {
  glm::dvec3 direction{0.0};
  double surface = 0.0;
};

inline PixelRay pixelRay(const Camera& camera, const Image& depth, int x, int y) {
  PixelRay r;
  const double ndcX = 2.0 * (x + 0.5) / depth.width() - 1.0;
  const double ndcY = 2.0 * (y + 0.5) / depth.height() - 1.0;
  r.direction = camera.rayDirection(ndcX, ndcY);
  const double cosForward = glm::dot(r.direction, camera.forward());
  const double d = depth.at(x, y, 0);
  r.surface = (d >= 1.0 ? camera.far() : camera.linearDepth(d)) / cosForward;
  return r;
}

/// (exp(-sigma ta) - exp(-sigma tb)) / sigma, finite as sigma -> 0 (seed 003 Eq. 3 on a section).
inline double sectionIntegral(double sigma, double ta, double tb) {
  const double len = tb - ta;
  if (!(len > 0.0)) return 0.0;
  return std::exp(-sigma * ta) * len * oneMinusExpOverX(sigma * len);
}

inline glm::dvec3 sectionIntegral(const glm::dvec3& sigma, double ta, double tb) {
  return {sectionIntegral(sigma.x, ta, tb), sectionIntegral(sigma.y, ta, tb),
          sectionIntegral(sigma.z, ta, tb)};
}

// C of Eq. 1 (crep::scatteringConstant), phi(x) (crep::oneMinusExpOverX) and the grey extinction of
// the alpha channel (crep::weightExtinction) come from prefilter/, so both methods integrate alike.
inline double greyExtinction(const Medium& medium) {
  return weightExtinction(medium);
}

inline void storePixel(Image& out, int x, int y, const glm::dvec3& L, double transmittance) {
  out.at(x, y, 0) = static_cast<float>(L.x);
  out.at(x, y, 1) = static_cast<float>(L.y);
  out.at(x, y, 2) = static_cast<float>(L.z);
  out.at(x, y, 3) = static_cast<float>(transmittance);
}

} // namespace crep::epipolar_detail
