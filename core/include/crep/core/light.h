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

/// The parameters of a SpotLight by name (designated initializers):
///   crep::SpotLight lamp({.position = p, .direction = axis, .innerConeAngle = 0.35, .outerConeAngle = 0.5,
///                         .color = glm::dvec3(1.0, 0.8, 0.6), .intensity = 40.0, .range = 30.0});
struct SpotLightParams {
  glm::dvec3 position{0.0};
  glm::dvec3 direction{0.0, 0.0, -1.0}; ///< the cone's axis, the direction light travels along it
  double innerConeAngle = 0.35;         ///< half angle (radians) of full intensity, in (0, outerConeAngle)
  double outerConeAngle = 0.5;          ///< half angle (radians) beyond which nothing is emitted, < pi / 2
  glm::dvec3 color{1.0};                ///< linear RGB, >= 0
  double intensity = 1.0;  ///< radiant intensity on the axis per unit colour (per steradian), > 0
  double range = 100.0;    ///< far plane of its shadow frustum (world units), > 0
  double nearPlane = -1.0; ///< near plane of its shadow frustum, in (0, range); -1: range * 1e-3
};

/// A cone light (Klehm et al. 2014, Sec. 3.2 "Local Lights"): intensity() * falloff(cos a) toward angle a
/// from the axis, / d^2 at distance d; shadow frustum lightClipFromWorld() (core/README.md, "light.h").
class SpotLight {
public:
  /// Throws InvalidArgument naming the field ("SpotLight.innerConeAngle", "SpotLight.outerConeAngle" also
  /// for angles out of order, ".intensity", ".color", ".range", ".nearPlane", ".direction", ".position").
  explicit SpotLight(const SpotLightParams& params);

  const glm::dvec3& position() const noexcept { return position_; }
  const glm::dvec3& direction() const noexcept { return direction_; }
  double innerConeAngle() const noexcept { return inner_; }
  double outerConeAngle() const noexcept { return outer_; }
  /// The shadow frustum's half angle (= outerConeAngle()).
  double coneAngle() const noexcept { return outer_; }
  double range() const noexcept { return range_; }
  double nearPlane() const noexcept { return near_; }
  /// Radiant intensity on the axis per channel: color * intensity (W / sr, arbitrary units).
  const glm::dvec3& intensity() const noexcept { return intensity_; }
  double cosInner() const noexcept { return cosInner_; }
  double cosOuter() const noexcept { return cosOuter_; }
  /// The angular falloff s in [0, 1] for the cosine of the angle to the axis (see the class comment).
  double falloff(double cosAngle) const;

  /// The light's own view (looking down -Z along `direction`) and perspective projection covering the cone.
  glm::dmat4 lightViewFromWorld() const;
  glm::dmat4 lightClipFromLightView() const;
  glm::dmat4 lightClipFromWorld() const { return lightClipFromLightView() * lightViewFromWorld(); }

private:
  glm::dvec3 position_;
  glm::dvec3 direction_;
  double inner_, outer_, range_, near_;
  glm::dvec3 intensity_;
  double cosInner_, cosOuter_;
};

/// The parameters of a PointLight by name.
struct PointLightParams {
  glm::dvec3 position{0.0};
  glm::dvec3 color{1.0};   ///< linear RGB, >= 0
  double intensity = 1.0;  ///< radiant intensity per unit colour (per steradian, every direction), > 0
  double range = 100.0;    ///< far plane of its six shadow frusta (world units), > 0
  double nearPlane = -1.0; ///< near plane of the frusta, in (0, range); -1: range * 1e-3
};

/// An omnidirectional light as six spot faces in GL cube-map order (Klehm et al. 2014, Sec. 3.2 "Local
/// Lights"), each direction in exactly one face; face i's shadow frustum is faceClipFromWorld(i).
class PointLight {
public:
  /// Throws InvalidArgument naming the field ("PointLight.position", ".color", ".intensity", ".range",
  /// ".nearPlane").
  explicit PointLight(const PointLightParams& params);

  const glm::dvec3& position() const noexcept { return position_; }
  double range() const noexcept { return range_; }
  double nearPlane() const noexcept { return near_; }
  /// Radiant intensity per channel: color * intensity.
  const glm::dvec3& intensity() const noexcept { return intensity_; }

  /// Unit axis of face i (+X, -X, +Y, -Y, +Z, -Z for i = 0..5).
  static glm::dvec3 faceAxis(int face);
  /// The face whose sector holds direction w (any non-zero vector; see the class comment).
  static int faceOf(const glm::dvec3& w);
  /// Face i's view (looking down -Z along faceAxis(i)) and its 90 degree perspective projection.
  glm::dmat4 faceViewFromWorld(int face) const;
  glm::dmat4 faceClipFromWorld(int face) const;

private:
  glm::dvec3 position_;
  double range_, near_;
  glm::dvec3 intensity_;
};

/// s(t) = t^2 (3 - 2 t) with t = clamp((cosAngle - cosOuter) / (cosInner - cosOuter), 0, 1) (cosInner >
/// cosOuter): the spot falloff, shared by SpotLight::falloff and the marches.
double spotFalloff(double cosAngle, double cosInner, double cosOuter);

/// Any unit vector orthogonal to `n` (n must be unit length); stable for every direction.
glm::dvec3 anyOrthogonal(const glm::dvec3& n);

/// A standard shadow map's matrix for `light`: an orthographic projection looking along the light whose
/// box tightly covers `points` (plus a margin of 1e-3 of its diagonal), GL conventions (NDC z in [-1, 1]).
/// Casters between the light and the box need GL_DEPTH_CLAMP to be kept. `points` must not be empty.
glm::dmat4 orthographicLightClipFromWorld(const DirectionalLight& light, std::span<const glm::dvec3> points);

} // namespace crep
