// Homogeneous participating medium: coefficients per RGB channel in 1/world-unit.
#pragma once

#include <glm/glm.hpp>

namespace crep {

/// Henyey-Greenstein phase function, normalized over the sphere (1/sr). cosTheta is the cosine of
/// the scattering angle (between the light's travel direction and the scattered direction).
double henyeyGreenstein(double g, double cosTheta);
/// Rayleigh phase function 3/(16 pi) (1 + cos^2), normalized over the sphere (1/sr).
double rayleighPhase(double cosTheta);

/// The coefficients of a Medium by name (1 / world unit, per RGB channel), for designated initializers:
///   crep::Medium fog({.mieScattering = glm::dvec3(0.02), .hgG = 0.76, .absorption = glm::dvec3(0.002)});
struct MediumCoefficients {
  glm::dvec3 mieScattering{0.0};      ///< scatters with the Henyey-Greenstein phase of hgG
  double hgG = 0.0;                   ///< Henyey-Greenstein asymmetry g, |g| < 1
  glm::dvec3 rayleighScattering{0.0}; ///< scatters with the Rayleigh phase
  glm::dvec3 absorption{0.0};         ///< only extinguishes
};

class Medium {
public:
  /// `mieScattering` scatters with Henyey-Greenstein(hgG), `rayleighScattering` with the Rayleigh
  /// phase, `absorption` only extinguishes. Throws InvalidArgument naming the coefficient ("Medium.hgG",
  /// "Medium.extinction.g", ...) for negative or non-finite coefficients, |g| >= 1, or a channel whose
  /// extinction is not > 0.
  explicit Medium(const MediumCoefficients& c);
  /// The positional form of 0.1: deprecated, absorption and g were easy to swap.
  [[deprecated("name the coefficients: crep::Medium({.mieScattering = ..., .hgG = ..., .absorption = "
               "...})")]] Medium(const glm::dvec3& mieScattering,
                                 const glm::dvec3& absorption = glm::dvec3(0.0), double hgG = 0.0,
                                 const glm::dvec3& rayleighScattering = glm::dvec3(0.0))
      : Medium(MediumCoefficients{mieScattering, hgG, rayleighScattering, absorption}) {}
  /// The coefficients back by name.
  MediumCoefficients coefficients() const { return {mie_, g_, rayleigh_, absorption_}; }

  const glm::dvec3& mieScattering() const noexcept { return mie_; }
  const glm::dvec3& rayleighScattering() const noexcept { return rayleigh_; }
  const glm::dvec3& absorption() const noexcept { return absorption_; }
  double hgG() const noexcept { return g_; }

  glm::dvec3 scattering() const { return mie_ + rayleigh_; }               ///< sigma_s
  glm::dvec3 extinction() const { return mie_ + rayleigh_ + absorption_; } ///< sigma_t = sigma_s + sigma_a

  /// sigma_s * phase for the scattering angle with cosine cosTheta (1/(world unit * sr)).
  glm::dvec3 scatteringTimesPhase(double cosTheta) const;

private:
  glm::dvec3 mie_, absorption_;
  double g_;
  glm::dvec3 rayleigh_;
};

} // namespace crep
