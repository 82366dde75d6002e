// Light sources. Colours are linear RGB. Directions are unit vectors in world space.
#pragma once

#include <span>

#include <glm/glm.hpp>

namespace crep {

/// A light at infinity (the sun). `direction` is the direction the light travels (from the sun
/// toward the scene), normalized by the constructor.
class DirectionalLight {
public:
  /// Throws InvalidArgument for a zero-length or non-finite direction, or a negative/non-finite radiance.
  explicit DirectionalLight(const glm::dvec3& direction, const glm::dvec3& irradiance = glm::dvec3(1.0));

  const glm::dvec3& direction() const noexcept { return direction_; }
  /// Irradiance on a surface facing the light (linear RGB, arbitrary units; scales the image).
  const glm::dvec3& irradiance() const noexcept { return irradiance_; }

private:
  glm::dvec3 direction_;
  glm::dvec3 irradiance_;
};

/// A cone light: light leaves `position` in the directions within `coneAngle` of `direction`.
class SpotLight {
public:
  /// `coneAngle` is the half angle in radians, in (0, pi/2); `range` > 0 is the far plane of its
  /// shadow frustum; `nearPlane` in (0, range) its near plane. Intensity is radiant intensity (W/sr
  /// per channel): irradiance at distance r on a facing surface is intensity / r^2.
  SpotLight(const glm::dvec3& position, const glm::dvec3& direction, double coneAngle, double range,
            const glm::dvec3& intensity = glm::dvec3(1.0), double nearPlane = -1.0 /* range * 1e-3 */);

  const glm::dvec3& position() const noexcept { return position_; }
  const glm::dvec3& direction() const noexcept { return direction_; }
  double coneAngle() const noexcept { return coneAngle_; }
  double range() const noexcept { return range_; }
  double nearPlane() const noexcept { return near_; }
  const glm::dvec3& intensity() const noexcept { return intensity_; }

  /// The light's own view (looking down -Z along `direction`) and perspective projection covering the cone.
  glm::dmat4 lightViewFromWorld() const;
  glm::dmat4 lightClipFromLightView() const;
  glm::dmat4 lightClipFromWorld() const { return lightClipFromLightView() * lightViewFromWorld(); }

private:
  glm::dvec3 position_;
  glm::dvec3 direction_;
  double coneAngle_, range_, near_;
  glm::dvec3 intensity_;
};

/// Any unit vector orthogonal to `n` (n must be unit length); stable for every direction.
glm::dvec3 anyOrthogonal(const glm::dvec3& n);

/// A standard shadow map's matrix for `light`: an orthographic projection looking along the light whose
/// box tightly covers `points` (plus a margin of 1e-3 of its diagonal), GL conventions (NDC z in [-1, 1]).
/// Casters between the light and the box need GL_DEPTH_CLAMP to be kept. `points` must not be empty.
glm::dmat4 orthographicLightClipFromWorld(const DirectionalLight& light, std::span<const glm::dvec3> points);

} // namespace crep
