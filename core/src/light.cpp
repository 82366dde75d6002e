#include <crep/core/error.h>
#include <crep/core/light.h>

#include "validate.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <glm/gtc/matrix_transform.hpp>

namespace crep {

namespace {
using detail::formatVec3;
/// v / |v| for any finite non-zero v: scaled by its largest component first, so neither tiny (1e-300)
/// nor huge (1e300) vectors under- or overflow in the length.
glm::dvec3 unitDirection(const char* parameter, const glm::dvec3& v) {
  const double largest = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z) || !(largest > 0.0))
    throw InvalidArgument(parameter, formatVec3(v), "must be a finite, non-zero vector");
  const glm::dvec3 scaled = v / largest;
  return scaled / glm::length(scaled);
}
void requireColor(const char* parameter, const glm::dvec3& c) {
  detail::requireNonNegativeVec3(parameter, c, "components must be finite and >= 0");
}
} // namespace

glm::dvec3 anyOrthogonal(const glm::dvec3& n) {
  // Branch-free orthonormal basis (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double b = n.x * n.y * a;
  return glm::dvec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
}

DirectionalLight::DirectionalLight(const glm::dvec3& direction, const glm::dvec3& irradiance)
    : direction_(unitDirection("DirectionalLight.direction", direction)), irradiance_(irradiance) {
  requireColor("DirectionalLight.irradiance", irradiance);
}

SpotLight::SpotLight(const glm::dvec3& position, const glm::dvec3& direction, double coneAngle, double range,
                     const glm::dvec3& intensity, double nearPlane)
    : position_(position), direction_(unitDirection("SpotLight.direction", direction)), coneAngle_(coneAngle),
      range_(range), near_(nearPlane), intensity_(intensity) {
  detail::requireFiniteVec3("SpotLight.position", position);
  if (!std::isfinite(coneAngle) || !(coneAngle > 0.0) || !(coneAngle < 0.5 * std::numbers::pi))
    throw InvalidArgument("SpotLight.coneAngle", detail::formatValue(coneAngle),
                          "half angle in radians, must be in (0, pi/2)");
  requirePositive("SpotLight.range", range);
  if (nearPlane == -1.0) near_ = range * 1e-3;
  if (!std::isfinite(near_) || !(near_ > 0.0) || !(near_ < range))
    throw InvalidArgument("SpotLight.nearPlane", detail::formatValue(nearPlane), "must be in (0, range)");
  requireColor("SpotLight.intensity", intensity);
}

glm::dmat4 SpotLight::lightViewFromWorld() const {
  // Up vector: any direction orthogonal to the axis, so no direction is degenerate.
  return glm::lookAtRH(position_, position_ + direction_, anyOrthogonal(direction_));
}

glm::dmat4 SpotLight::lightClipFromLightView() const {
  return glm::perspectiveRH_NO(2.0 * coneAngle_, 1.0, near_, range_);
}

glm::dmat4 orthographicLightClipFromWorld(const DirectionalLight& light, std::span<const glm::dvec3> points) {
  glm::dvec3 centre(0.0);
  for (const glm::dvec3& p : points)
    centre += p / static_cast<double>(points.size());
  const glm::dvec3 dir = light.direction();
  const glm::dmat4 lightViewFromWorld = glm::lookAtRH(centre - dir, centre, anyOrthogonal(dir));
  glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (const glm::dvec3& p : points) {
    const glm::dvec3 q(lightViewFromWorld * glm::dvec4(p, 1.0));
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  // View space looks down -Z: near = -hi.z, far = -lo.z; a small margin keeps boundary casters.
  const double margin = 1e-3 * glm::length(hi - lo);
  return glm::orthoRH_NO(lo.x - margin, hi.x + margin, lo.y - margin, hi.y + margin, -hi.z - margin,
                         -lo.z + margin) *
         lightViewFromWorld;
}

} // namespace crep
