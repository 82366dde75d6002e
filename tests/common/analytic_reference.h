// References on the analytic setup (common/analytic_scene.h: a camera over a ground plane, an infinite plane
// occluder), for the tests of every module that marches or prefilters: closed-form single scattering that
// uses none of the code under test, the occluder's shadow map, synthetic maps, and image metrics.
#pragma once

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scenes/scene.h>
#include <crep/support/image_compare.h>

#include "common/analytic_scene.h"

#include <doctest/doctest.h>

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <string>

namespace crep::test {

/// A random camera: position in [-10, 10]^3, any orientation, fovY 30-100 degrees, aspect 0.6-2.5, near
/// 0.05-1, far 20-500.
inline Camera randomEpipolarCamera(std::mt19937_64& rng) {
  const auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  std::normal_distribution<double> n;
  const glm::dquat q(n(rng), n(rng), n(rng), n(rng));
  const glm::dvec3 position(uniform(-10, 10), uniform(-10, 10), uniform(-10, 10));
  const double fovY = glm::radians(uniform(30.0, 100.0)), aspect = uniform(0.6, 2.5),
               near = uniform(0.05, 1.0);
  return Camera(position, q, fovY, aspect, near, uniform(20.0, 500.0));
}

/// The shadow map of the half-space occluder for an orthographic or perspective light matrix: each texel
/// stores the depth-buffer value of the plane along the light ray through its centre (clamped like
/// GL_DEPTH_CLAMP; 1 where the ray misses the plane).
inline Image halfSpaceShadowMap(const HalfSpace& plane, const glm::dmat4& lightClipFromWorld, int size) {
  const glm::dmat4 worldFromClip = glm::inverse(lightClipFromWorld);
  Image d(size, size, 1, 1.0f);
  for (int j = 0; j < size; ++j)
    for (int i = 0; i < size; ++i) {
      const double x = 2.0 * (i + 0.5) / size - 1.0, y = 2.0 * (j + 0.5) / size - 1.0;
      const glm::dvec4 a = worldFromClip * glm::dvec4(x, y, -1.0, 1.0),
                       b = worldFromClip * glm::dvec4(x, y, 1.0, 1.0);
      const glm::dvec3 p0 = glm::dvec3(a) / a.w, p1 = glm::dvec3(b) / b.w;
      const double f0 = glm::dot(plane.normal, p0 - plane.point),
                   f1 = glm::dot(plane.normal, p1 - plane.point);
      if (f0 == f1) continue;
      const double t = f0 / (f0 - f1); // the hit p0 + t (p1 - p0), projected
      const glm::dvec4 q = lightClipFromWorld * glm::dvec4(p0 + t * (p1 - p0), 1.0);
      if (!(q.w > 0.0)) continue; // behind a perspective light
      d.at(i, j) = static_cast<float>(std::clamp(0.5 * q.z / q.w + 0.5, 0.0, 1.0));
    }
  return d;
}

/// A light matrix around the analytic scene's visible region (camera at y = 2, far 80, looking to -z).
inline glm::dmat4 analyticLightMatrix(const DirectionalLight& light) {
  return scenes::standardLightClipFromWorld(light, {-60.0, -1.0, -85.0}, {60.0, 40.0, 5.0});
}

/// (exp(-sigma a) - exp(-sigma b)) / sigma per channel.
inline glm::dvec3 segmentIntegral(const glm::dvec3& sigma, double a, double b) {
  glm::dvec3 r(0.0);
  if (!(b > a)) return r;
  for (int c = 0; c < 3; ++c)
    r[c] = (std::exp(-sigma[c] * a) - std::exp(-sigma[c] * b)) / sigma[c];
  return r;
}

/// Closed-form single scattering (Klehm et al. 2014, Eq. 1, 3) with an optional half-space shadow, per pixel
/// of a camera depth image (sky to the far plane), RGBA like the marches (A = grey transmittance).
inline Image closedForm(const Image& depth, const Camera& camera, const DirectionalLight& light,
                        const Medium& medium, const std::optional<HalfSpace>& plane) {
  Image out(depth.width(), depth.height(), 4);
  const glm::dvec3 sigma = medium.extinction();
  const double grey = (sigma.x + sigma.y + sigma.z) / 3.0;
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x) {
      const glm::dvec3 v =
          camera.rayDirection(2.0 * (x + 0.5) / depth.width() - 1.0, 2.0 * (y + 0.5) / depth.height() - 1.0);
      const double cosF = glm::dot(v, camera.forward());
      const double d = depth.at(x, y);
      const double s = (d >= 1.0 ? camera.far() : camera.linearDepth(d)) / cosF;
      double lo = 0.0, hi = s; // lit part
      if (plane) {
        const double f0 = glm::dot(plane->normal, camera.position() - plane->point),
                     fv = glm::dot(plane->normal, v);
        if (fv > 0.0)
          hi = std::min(s, -f0 / fv);
        else if (fv < 0.0)
          lo = std::max(0.0, -f0 / fv);
        else if (f0 > 0.0)
          hi = lo;
      }
      const glm::dvec3 C = light.irradiance() * medium.scatteringTimesPhase(glm::dot(light.direction(), -v));
      const glm::dvec3 L = C * segmentIntegral(sigma, lo, hi);
      for (int c = 0; c < 3; ++c)
        out.at(x, y, c) = static_cast<float>(L[c]);
      out.at(x, y, 3) = static_cast<float>(std::exp(-grey * s));
    }
  return out;
}

/// A synthetic W x H map: runs of random depths (like the rows of real scenes) with empty stretches (1).
inline Image randomRunsDepth(int W, int H, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  Image d(W, H, 1, 1.0f);
  for (int j = 0; j < H; ++j) {
    int i = 0;
    while (i < W) {
      const int run = 1 + static_cast<int>(uni(rng) * 40.0);
      const float v = uni(rng) < 0.4 ? 1.0f : static_cast<float>(uni(rng));
      const double slope = (uni(rng) - 0.5) * 0.01;
      for (int k = 0; k < run && i < W; ++k, ++i)
        d.at(i, j) = static_cast<float>(std::clamp(v + slope * k, 0.0, 1.0));
    }
  }
  return d;
}

/// Metrics over the RGB channels.
inline ImageMetrics rgbMetrics(const Image& actual, const Image& reference) {
  CompareOptions o;
  o.channels = 3;
  return compareImages(actual, reference, o);
}

inline void report(const std::string& what, const ImageMetrics& m) {
  MESSAGE(what << ": relative RMSE " << m.relativeRmse << ", PSNR " << m.psnr << " dB, max abs "
               << m.maxAbsError << " (peak " << m.peak << ")");
}

/// The RGB channels of an RGBA image (image checks on the radiance only; A is the same transmittance).
inline Image rgb(const Image& rgba) {
  Image out(rgba.width(), rgba.height(), 3);
  for (int y = 0; y < rgba.height(); ++y)
    for (int x = 0; x < rgba.width(); ++x)
      for (int c = 0; c < 3; ++c)
        out.at(x, y, c) = rgba.at(x, y, c);
  return out;
}

/// Largest relative difference |a - b| / max(|b|, floor) over the RGB channels.
inline double maxRelativeDifference(const Image& a, const Image& b, double floor) {
  double worst = 0.0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x)
      for (int c = 0; c < 3; ++c) {
        const double r = b.at(x, y, c);
        worst = std::max(worst, std::abs(a.at(x, y, c) - r) / std::max(std::abs(r), floor));
      }
  return worst;
}

} // namespace crep::test
