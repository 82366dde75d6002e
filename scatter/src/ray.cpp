// The single-scattering integrand on camera pixel rays (Klehm et al. 2014, Eq. 1 and 3); the rules are
// at the top of crep/scatter/ray.h.
#include <crep/core/error.h>
#include <crep/core/parallel.h>
#include <crep/scatter/ray.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace crep {

void validate(const MarchOptions& o) {
  if (o.threads < 0)
    throw InvalidArgument("MarchOptions.threads", detail::formatValue(o.threads), "must be >= 0");
}

double MarchResult::meanSteps() const {
  if (steps.empty()) return 0.0;
  double sum = 0.0;
  for (float v : steps.data())
    sum += v;
  return sum / static_cast<double>(steps.sampleCount());
}

double MarchResult::maxSteps() const {
  double m = 0.0;
  for (float v : steps.data())
    m = std::max(m, static_cast<double>(v));
  return m;
}

// crep/scatter/ray.h "Rays and output" at a pixel centre (Klehm et al. 2014, Eq. 1 per pixel).
PixelRay pixelRay(const Camera& camera, const Image& depth, int x, int y, bool nearPlaneCorrection) {
  return screenRay(camera, depth.width(), depth.height(), x + 0.5, y + 0.5, depth.at(x, y, 0),
                   nearPlaneCorrection);
}

// The same rule at a continuous screen position (Yusov 2012, Sec. 6.1: samples along epipolar lines).
PixelRay screenRay(const Camera& camera, int width, int height, double x, double y, double depthValue,
                   bool nearPlaneCorrection) {
  PixelRay r;
  const double ndcX = 2.0 * x / width - 1.0;
  const double ndcY = 2.0 * y / height - 1.0;
  r.direction = camera.rayDirection(ndcX, ndcY);
  const double cosForward = glm::dot(r.direction, camera.forward());
  const double viewDepth = camera.surfaceViewDepth(depthValue); // the sky (cleared value) integrates to far()
  r.surface = viewDepth / cosForward;
  r.start = nearPlaneCorrection ? std::min(camera.near() / cosForward, r.surface) : 0.0;
  return r;
}

void validateScreenSamples(std::span<const ScreenSample> samples, int width, int height) {
  if (width <= 0) throw InvalidArgument("width", detail::formatValue(width), "must be > 0");
  if (height <= 0) throw InvalidArgument("height", detail::formatValue(height), "must be > 0");
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const ScreenSample& s = samples[i];
    const std::string name = "samples[" + std::to_string(i) + "]";
    if (!std::isfinite(s.x) || !std::isfinite(s.y))
      throw InvalidArgument(name, "(" + detail::formatValue(s.x) + ", " + detail::formatValue(s.y) + ")",
                            "the position must be finite");
    if (!(s.depth >= 0.0 && s.depth <= 1.0))
      throw InvalidArgument(name, "depth " + detail::formatValue(s.depth),
                            "must be a depth-buffer value in [0, 1]");
  }
}

void validateCameraDepth(const Image& depth) {
  if (depth.empty()) throw InvalidArgument("cameraDepth", "empty", "must be a depth-buffer image");
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x) {
      const float v = depth.at(x, y, 0);
      if (!(v >= 0.0f && v <= 1.0f))
        throw InvalidArgument("cameraDepth",
                              "pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                                  ") = " + detail::formatValue(v),
                              "depth-buffer values must be in [0, 1]");
    }
}

glm::dvec3 scatteringConstant(const DirectionalLight& light, const Medium& medium,
                              const glm::dvec3& viewDirection) {
  return light.irradiance() * medium.scatteringTimesPhase(glm::dot(light.direction(), -viewDirection));
}

double weightExtinction(const Medium& medium) {
  const glm::dvec3 e = medium.extinction();
  return (e.x + e.y + e.z) / 3.0;
}

double oneMinusExpOverX(double x) {
  if (x == std::numeric_limits<double>::infinity()) return 0.0;
  if (std::abs(x) < 1e-5) return 1.0 - x * (0.5 - x / 6.0); // error < x^3 / 24 < 1e-16
  return -std::expm1(-x) / x;
}

double transmittanceIntegral(double sigma, double ta, double tb) {
  const double len = tb - ta;
  if (!(len > 0.0)) return 0.0;
  return std::exp(-sigma * ta) * len * oneMinusExpOverX(sigma * len);
}

glm::dvec3 transmittanceIntegral(const glm::dvec3& sigma, double ta, double tb) {
  return {transmittanceIntegral(sigma.x, ta, tb), transmittanceIntegral(sigma.y, ta, tb),
          transmittanceIntegral(sigma.z, ta, tb)};
}

void storeScattering(Image& out, int x, int y, const glm::dvec3& L, double transmittance) {
  out.at(x, y, 0) = static_cast<float>(L.x);
  out.at(x, y, 1) = static_cast<float>(L.y);
  out.at(x, y, 2) = static_cast<float>(L.z);
  out.at(x, y, 3) = static_cast<float>(transmittance);
}

// Eq. 1 with V = 1 and Eq. 3: the closed form of the unshadowed homogeneous medium.
Image unshadowedScattering(const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                           const Medium& medium, const MarchOptions& options) {
  validateCameraDepth(cameraDepth);
  validate(options);
  const int w = cameraDepth.width(), h = cameraDepth.height();
  const glm::dvec3 sigma = medium.extinction();
  const double grey = weightExtinction(medium);
  Image out(w, h, 4);
  parallelRows(h, options.threads, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const PixelRay ray = pixelRay(camera, cameraDepth, x, y, options.nearPlaneCorrection);
      storeScattering(out, x, y,
                      scatteringConstant(light, medium, ray.direction) *
                          transmittanceIntegral(sigma, ray.start, ray.surface),
                      std::exp(-grey * ray.surface));
    }
  });
  return out;
}

} // namespace crep
