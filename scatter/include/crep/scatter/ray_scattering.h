// The in-scattering of one camera view ray over sections of it, for every light type (Klehm et al. 2014,
// Eq. 1; Sec. 3.2 "Local Lights" and "Angular-dependency for Sources"): what every method multiplies by
// its visibility. For a view ray x(t) = o + t v (v unit, from the camera) and a lit section [ta, tb]:
//
//   S(ta, tb) = integral_ta^tb exp(-sigma t) sigma_s p(theta(t)) E(t) dt        (per RGB channel)
//
// with theta the scattering angle (cos theta = dot(light travel direction at x, -v)) and E the light
// reaching x without occluders:
//   directional  E = irradiance                       -> S = C (exp(-sigma ta) - exp(-sigma tb)) / sigma
//                                                        (crep/scatter/ray.h; closed form)
//   spot         E = I s(a) exp(-sigma d) / d^2        d = |x - L|, a the angle of x - L to the axis,
//                                                        s the spot falloff (crep::spotFalloff)
//   point face   E = I exp(-sigma d) / d^2             on the part of the ray whose direction from the
//                                                        light lies in the face's sector, else 0
// d is clamped below at the light's near plane (the light is a ball of that radius: a ray through the
// light's position stays finite, and nothing nearer than the near plane is in its shadow map).
//
// Local lights have no closed form (the angular falloff, the phase function and exp(-sigma d) vary along
// the ray). S is integrated in the angle gamma of x seen from the light, measured from the point of the
// ray nearest the light (t = t0 + h tan gamma, d = h / cos gamma, dt / d^2 = dgamma / h): the 1 / d^2 peak
// becomes a constant, the phase function is a function of gamma alone. Breakpoints at the near-ball, the
// cone angles (inner, outer) and the sector planes split the range into smooth pieces; each piece is cut
// into parts of at most gammaStep radians (the phase peak's width (1 - |g|) / 2, at most pi / 32) and
// integrated with 8-point Gauss-Legendre. Relative error below 1e-9 on the tests' rays (against an
// independent adaptive quadrature in t).
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include <crep/core/light.h>
#include <crep/core/medium.h>

namespace crep {

/// Which light-side factors a local light's prefilter weights carry along a region's reference ray (Klehm
/// et al. 2014, Sec. 3.2: "each visibility function is simply weighted by the light's contribution"). The
/// evaluation restores each ray's exact in-scattering per region in every mode; the mode only decides how
/// the visibility inside a region is averaged.
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
  /// prefilter's weights, Klehm et al. 2014, Sec. 3.2): mean_c(sigma_s p(theta))_c * mean_c(I_c falloff) *
  /// exp(-s d) / d^2 with s the grey extinction and d clamped below at the near plane.
  double weightFactor(const Medium& medium, double greyExtinction, const glm::dvec3& point,
                      const glm::dvec3& v, LocalLightWeights weights = LocalLightWeights::Full) const;
};

/// S(ta, tb) of one view ray (see top).
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
  /// The sorted cuts of [ta, tb] into the pieces segment() integrates, ends included: the near ball's,
  /// the cone angles' (inner, outer) and the sector planes' crossings inside it ({ta, tb} for a
  /// directional light, empty when tb <= ta).
  std::vector<double> breakpoints(double ta, double tb) const;
  /// The share of S(ta, tEnd) that [ta, tb] holds (ta <= tb <= tEnd), per channel, by Simpson's rule in
  /// gamma on each side of tb over the part of [ta, tEnd] the light reaches (its outer cone or sector; all
  /// of it for a ray through the near ball): 5 integrand values. Exact where the integrand in gamma is a
  /// cubic; 1 when the light reaches the part only before tb. Local lights only (1 for a directional light).
  /// The rule of the GPU evaluation's last region with a section table (crep_localPartialShare).
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
