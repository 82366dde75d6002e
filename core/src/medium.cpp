#include <crep/core/error.h>
#include <crep/core/medium.h>

#include "validate.h"

#include <cmath>
#include <numbers>

namespace crep {

double henyeyGreenstein(double g, double cosTheta) {
  const double denom = 1.0 + g * g - 2.0 * g * cosTheta;
  return (1.0 - g * g) / (4.0 * std::numbers::pi * denom * std::sqrt(denom));
}

double rayleighPhase(double cosTheta) { return 3.0 / (16.0 * std::numbers::pi) * (1.0 + cosTheta * cosTheta); }

namespace {
void requireCoefficients(const char* parameter, const glm::dvec3& c) {
  detail::requireNonNegativeVec3(parameter, c, "coefficients must be finite and >= 0 (1/world unit)");
}
} // namespace

Medium::Medium(const glm::dvec3& mieScattering, const glm::dvec3& absorption, double hgG,
               const glm::dvec3& rayleighScattering)
    : mie_(mieScattering), absorption_(absorption), g_(hgG), rayleigh_(rayleighScattering) {
  requireCoefficients("Medium.mieScattering", mieScattering);
  requireCoefficients("Medium.absorption", absorption);
  requireCoefficients("Medium.rayleighScattering", rayleighScattering);
  if (!std::isfinite(hgG) || !(std::abs(hgG) < 1.0))
    throw InvalidArgument("Medium.hgG", detail::formatValue(hgG), "must be in (-1, 1)");
  const glm::dvec3 t = extinction();
  const char* channel[3] = {"Medium.extinction.r", "Medium.extinction.g", "Medium.extinction.b"};
  for (int i = 0; i < 3; ++i)
    if (!(t[i] > 0.0))
      throw InvalidArgument(channel[i], detail::formatValue(t[i]),
                            "extinction (scattering + absorption) must be > 0 in every channel");
}

glm::dvec3 Medium::scatteringTimesPhase(double cosTheta) const {
  return mie_ * henyeyGreenstein(g_, cosTheta) + rayleigh_ * rayleighPhase(cosTheta);
}

} // namespace crep
