// The in-scattering S(ta, tb) of one camera view ray for every light type (Klehm et al. 2014, Eq. 1;
// Sec. 3.2 "Local Lights" and "Angular-dependency for Sources"). The integrand per light type and the
// quadrature of local lights: scatter/README.md, "crep/scatter/ray_scattering.h".
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include <crep/core/light.h>
#include <crep/core/medium.h>

namespace crep {

/// Which light-side factors a local light's prefilter weights carry along a region's reference ray
/// (Klehm et al. 2014, Sec. 3.2): changes only how the visibility inside a region is averaged.
enum class LocalLightWeights {
  Full,    ///< phase x angular falloff x exp(-s d) / d^2 of the reference ray
  Angular, ///< the angular falloff (and the point face's sector) only
  None,    ///< none: the transmittance weights of a directional light
};
/// "full", "angular", "none".
const char* localLightWeightsToken(LocalLightWeights weights);

/// A local light as the integrand sees it: a spot light, or face `face` of a point light.
struct LocalLight {
  glm::dvec3 position{0.0};
  glm::dvec3 intensity{0.0}; ///< radiant intensity per channel (on the axis for a spot)
  double nearPlane = 0.0;    ///< d is clamped below at it
  bool cone = false;         ///< spot: the angular falloff applies
  glm::dvec3 axis{0.0, 0.0, -1.0};
  double cosInner = 1.0, cosOuter = 0.0;
  int face = -1; ///< point light face (PointLight::faceOf sector), -1: every direction

  static LocalLight spot(const SpotLight& light);
  static LocalLight pointFace(const PointLight& light, int face);
  /// Radiant intensity toward unit direction w (falloff and sector applied).
  glm::dvec3 intensityToward(const glm::dvec3& w) const;
  /// The grey light-side factor of the integrand at `point` on a view ray of unit direction `v` (the
  /// prefilter's weights, Klehm et al. 2014, Sec. 3.2; README).
  double weightFactor(const Medium& medium, double greyExtinction, const glm::dvec3& point,
                      const glm::dvec3& v, LocalLightWeights weights = LocalLightWeights::Full) const;
};

/// S(ta, tb) of one view ray: closed form (directional), 8-point Gauss-Legendre per part (local lights).
class RayScattering {
public:
  RayScattering(const DirectionalLight& light, const Medium& medium, const glm::dvec3& origin,
                const glm::dvec3& direction);
  RayScattering(const LocalLight& light, const Medium& medium, const glm::dvec3& origin,
                const glm::dvec3& direction);

  /// S(ta, tb) per channel; 0 when tb <= ta.
  glm::dvec3 segment(double ta, double tb) const;
  /// The integrand exp(-sigma t) sigma_s p(theta(t)) E(t) at t (per channel).
  glm::dvec3 density(double t) const;
  /// The sorted cuts of [ta, tb] into the pieces segment() integrates, ends included (empty if tb <= ta).
  std::vector<double> breakpoints(double ta, double tb) const;
  /// The share of S(ta, tEnd) that [ta, tb] holds, per channel, by Simpson's rule in gamma (5 integrand
  /// values; README); 1 for a directional light. The rule of crep_localPartialShare.
  glm::dvec3 partialShare(double ta, double tb, double tEnd) const;

private:
  glm::dvec3 integrandInGamma(double gamma) const; ///< density(t(gamma)) * dt / dgamma
  glm::dvec3 gaussLegendre(double ta, double tb, bool inGamma) const;
  double gammaOf(double t) const;

  const Medium* medium_;
  glm::dvec3 origin_, direction_, sigma_;
  bool local_;
  glm::dvec3 constant_{0.0}; ///< directional: C of Eq. 1
  LocalLight light_;
  double t0_ = 0.0, h_ = 0.0; ///< nearest point of the ray's line to the light, and its distance
  double gammaStep_ = 0.0;
};

} // namespace crep
