#include <crep/core/error.h>
#include <crep/core/light.h>

#include "validate.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

namespace crep {

namespace {
/// v / |v| for any finite non-zero v: scaled by its largest component first, so neither tiny (1e-300)
/// nor huge (1e300) vectors under- or overflow in the length.
glm::dvec3 unitDirection(const char* parameter, const glm::dvec3& v) {
  const double largest = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z) || !(largest > 0.0))
    throw InvalidArgument(parameter, detail::formatValue(v), "must be a finite, non-zero vector");
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

SpotLight::SpotLight(const SpotLightParams& p)
    : position_(p.position), direction_(unitDirection("SpotLight.direction", p.direction)),
      inner_(p.innerConeAngle), outer_(p.outerConeAngle), range_(p.range), near_(p.nearPlane),
      intensity_(p.color * p.intensity) {
  requireFinite("SpotLight.position", p.position);
  const double quarter = 0.5 * std::numbers::pi;
  if (!std::isfinite(outer_) || !(outer_ > 0.0) || !(outer_ < quarter))
    throw InvalidArgument("SpotLight.outerConeAngle", detail::formatValue(outer_),
                          "half angle in radians, must be in (0, pi/2)");
  if (!std::isfinite(inner_) || !(inner_ > 0.0) || !(inner_ < outer_))
    throw InvalidArgument(
        "SpotLight.innerConeAngle", detail::formatValue(inner_),
        "half angle in radians, must be in (0, outerConeAngle = " + detail::formatValue(outer_) + ")");
  requirePositive("SpotLight.range", range_);
  if (near_ == -1.0) near_ = range_ * 1e-3;
  if (!std::isfinite(near_) || !(near_ > 0.0) || !(near_ < range_))
    throw InvalidArgument("SpotLight.nearPlane", detail::formatValue(p.nearPlane), "must be in (0, range)");
  requireColor("SpotLight.color", p.color);
  requirePositive("SpotLight.intensity", p.intensity);
  if (!(std::max({p.color.x, p.color.y, p.color.z}) > 0.0))
    throw InvalidArgument("SpotLight.color", "(0, 0, 0)", "at least one channel must be > 0");
  cosInner_ = std::cos(inner_);
  cosOuter_ = std::cos(outer_);
}

double spotFalloff(double cosAngle, double cosInner, double cosOuter) {
  const double t = std::clamp((cosAngle - cosOuter) / (cosInner - cosOuter), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

double SpotLight::falloff(double cosAngle) const {
  return spotFalloff(cosAngle, cosInner_, cosOuter_);
}

glm::dmat4 SpotLight::lightViewFromWorld() const {
  // Up vector: any direction orthogonal to the axis, so no direction is degenerate.
  return glm::lookAtRH(position_, position_ + direction_, anyOrthogonal(direction_));
}

glm::dmat4 SpotLight::lightClipFromLightView() const {
  return glm::perspectiveRH_NO(2.0 * outer_, 1.0, near_, range_);
}

PointLight::PointLight(const PointLightParams& p)
    : position_(p.position), range_(p.range), near_(p.nearPlane), intensity_(p.color * p.intensity) {
  requireFinite("PointLight.position", p.position);
  requirePositive("PointLight.range", range_);
  if (near_ == -1.0) near_ = range_ * 1e-3;
  if (!std::isfinite(near_) || !(near_ > 0.0) || !(near_ < range_))
    throw InvalidArgument("PointLight.nearPlane", detail::formatValue(p.nearPlane), "must be in (0, range)");
  requireColor("PointLight.color", p.color);
  if (!(std::max({p.color.x, p.color.y, p.color.z}) > 0.0))
    throw InvalidArgument("PointLight.color", "(0, 0, 0)", "at least one channel must be > 0");
  requirePositive("PointLight.intensity", p.intensity);
}

glm::dvec3 PointLight::faceAxis(int face) {
  if (face < 0 || face > 5)
    throw InvalidArgument("PointLight face", std::to_string(face), "must be in [0, 5]");
  glm::dvec3 axis(0.0);
  axis[face / 2] = face % 2 == 0 ? 1.0 : -1.0;
  return axis;
}

int PointLight::faceOf(const glm::dvec3& w) {
  const glm::dvec3 a = glm::abs(w);
  const int major = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
  return 2 * major + (w[major] >= 0.0 ? 0 : 1);
}

glm::dmat4 PointLight::faceViewFromWorld(int face) const {
  const glm::dvec3 axis = faceAxis(face);
  glm::dvec3 up(0.0);
  up[(face / 2 + 2) % 3] = 1.0; // orthogonal to the axis
  return glm::lookAtRH(position_, position_ + axis, up);
}

glm::dmat4 PointLight::faceClipFromWorld(int face) const {
  return glm::perspectiveRH_NO(0.5 * std::numbers::pi, 1.0, near_, range_) * faceViewFromWorld(face);
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
