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

double rayleighPhase(double cosTheta) {
  return 3.0 / (16.0 * std::numbers::pi) * (1.0 + cosTheta * cosTheta);
}

namespace {
void requireCoefficients(const char* parameter, const glm::dvec3& c) {
  detail::requireNonNegativeVec3(parameter, c, "coefficients must be finite and >= 0 (1/world unit)");
}
} // namespace

Medium::Medium(const MediumCoefficients& c)
    : mie_(c.mieScattering), absorption_(c.absorption), g_(c.hgG), rayleigh_(c.rayleighScattering) {
  requireCoefficients("Medium.mieScattering", mie_);
  requireCoefficients("Medium.absorption", absorption_);
  requireCoefficients("Medium.rayleighScattering", rayleigh_);
  if (!std::isfinite(g_) || !(std::abs(g_) < 1.0))
    throw InvalidArgument("Medium.hgG", detail::formatValue(g_), "must be in (-1, 1)");
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
