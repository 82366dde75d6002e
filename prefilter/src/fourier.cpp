// Fourier coefficients and basis of the shadow-test step function: Klehm, Seidel, Eisemann 2014,
// Sec. 3.1, Eq. 8 (coefficients a_k, basis B_k) and Eq. 9 (visibility ~ 0.5 + a . B), after Annen et
// al. 2007. Conventions and the depth-margin trap are documented in crep/prefilter/fourier.h.
#include <crep/core/error.h>
#include <crep/prefilter/fourier.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace crep {

namespace {

void requireSize(const char* what, std::size_t size) {
  if (size > static_cast<std::size_t>(kMaxBases))
    throw InvalidArgument("bases", std::to_string(size) + " (" + what + " size)",
                          "must be even and in [" + std::to_string(kMinBases) + ", " +
                              std::to_string(kMaxBases) + "]");
  validateBases(static_cast<int>(size));
}

/// Calls out(k, sin((2k - 1) pi z), cos((2k - 1) pi z)) for k = 1..M/2 from one sin/cos of pi z:
/// the odd multiples advance by the angle 2 pi z (angle addition). Eq. 8's c_k z = (2k - 1) pi z.
template <class T, class Out>
void oddHarmonics(T z, int half, Out out) {
  const T theta = std::numbers::pi_v<T> * z;
  const T s1 = std::sin(theta), c1 = std::cos(theta);
  const T s2 = T(2) * s1 * c1;        // sin(2 theta)
  const T c2 = T(1) - T(2) * s1 * s1; // cos(2 theta)
  T s = s1, c = c1;
  for (int k = 1; k <= half; ++k) {
    out(k, s, c);
    const T sn = s * c2 + c * s2;
    c = c * c2 - s * s2;
    s = sn;
  }
}

/// Eq. 8: a_{2k-1} = 2 cos(c_k z) / c_k, a_{2k} = -2 sin(c_k z) / c_k.
template <class T>
void coefficients(T z, std::span<T> a) {
  requireSize("coefficient array", a.size());
  oddHarmonics<T>(z, static_cast<int>(a.size() / 2), [&](int k, T s, T c) {
    const T twoOverCk = T(2) / (std::numbers::pi_v<T> * static_cast<T>(2 * k - 1));
    a[static_cast<std::size_t>(2 * k - 2)] = twoOverCk * c;
    a[static_cast<std::size_t>(2 * k - 1)] = -twoOverCk * s;
  });
}

/// Eq. 8: B_{2k-1} = sin(c_k z), B_{2k} = cos(c_k z).
template <class T>
void basis(T z, std::span<T> b) {
  requireSize("basis array", b.size());
  oddHarmonics<T>(z, static_cast<int>(b.size() / 2), [&](int k, T s, T c) {
    b[static_cast<std::size_t>(2 * k - 2)] = s;
    b[static_cast<std::size_t>(2 * k - 1)] = c;
  });
}

} // namespace

void validateBases(int bases, std::string_view parameter) {
  if (bases < kMinBases || bases > kMaxBases || bases % 2 != 0)
    throw InvalidArgument(std::string(parameter), detail::formatValue(bases),
                          "must be even and in [" + std::to_string(kMinBases) + ", " +
                              std::to_string(kMaxBases) + "]");
}

void fourierCoefficients(double z, std::span<double> a) {
  coefficients<double>(z, a);
}
void fourierCoefficients(float z, std::span<float> a) {
  coefficients<float>(z, a);
}
void fourierBasis(double z, std::span<double> b) {
  basis<double>(z, b);
}
void fourierBasis(float z, std::span<float> b) {
  basis<float>(z, b);
}

double fourierVisibility(double zRay, double zTexel, int bases) {
  validateBases(bases);
  double a[kMaxBases], b[kMaxBases];
  const auto n = static_cast<std::size_t>(bases);
  fourierCoefficients(zRay, std::span<double>(a, n));
  fourierBasis(zTexel, std::span<double>(b, n));
  double v = 0.5;
  for (std::size_t j = 0; j < n; ++j)
    v += a[j] * b[j];
  return v;
}

double ringingFactor(RingingFilter filter, int k, int bases) {
  validateBases(bases);
  if (filter == RingingFilter::None) return 1.0;
  const double x = std::numbers::pi * (2 * k - 1) / bases;
  return std::sin(x) / x;
}

void applyRingingFilter(RingingFilter filter, std::span<double> a) {
  requireSize("coefficient array", a.size());
  if (filter == RingingFilter::None) return;
  const int M = static_cast<int>(a.size());
  for (int k = 1; k <= M / 2; ++k) {
    const double s = ringingFactor(filter, k, M);
    a[static_cast<std::size_t>(2 * k - 2)] *= s;
    a[static_cast<std::size_t>(2 * k - 1)] *= s;
  }
}

void applyRingingFilter(RingingFilter filter, std::span<float> a) {
  requireSize("coefficient array", a.size());
  if (filter == RingingFilter::None) return;
  const int M = static_cast<int>(a.size());
  for (int k = 1; k <= M / 2; ++k) {
    const auto s = static_cast<float>(ringingFactor(filter, k, M));
    a[static_cast<std::size_t>(2 * k - 2)] *= s;
    a[static_cast<std::size_t>(2 * k - 1)] *= s;
  }
}

double texelBasisDepth(double depth, double margin) {
  if (depth >= 1.0) return 1.0;
  if (depth <= 0.0) return 0.0;
  return margin + (1.0 - 2.0 * margin) * depth;
}

double rayBasisDepth(double depth, double margin) {
  return margin + (1.0 - 2.0 * margin) * std::clamp(depth, 0.0, 1.0);
}

} // namespace crep
