// Fourier expansion of the shadow-test step (Klehm, Seidel, Eisemann 2014, Sec. 3.1, Eq. 8-9; after Annen et
// al. 2007): ray coefficients a(z), texel basis B(z), M bases. Indexing, storage and the depth-margin trap:
// prefilter/README.md, "fourier.h".
#pragma once

#include <span>
#include <string_view>

namespace crep {

/// Default number of bases M (the paper's: 8 RGBA layers).
inline constexpr int kDefaultBases = 32;
inline constexpr int kMinBases = 4;
inline constexpr int kMaxBases = 128;

/// Throws InvalidArgument (parameter "bases") unless M is even and in [kMinBases, kMaxBases].
void validateBases(int bases, std::string_view parameter = "bases");

/// Eq. 8 ray coefficients a_1..a_M at depth z into a.size() = M values (validated), one sin/cos per call.
void fourierCoefficients(double z, std::span<double> a);
void fourierCoefficients(float z, std::span<float> a);

/// Eq. 8 basis B_1..B_M at depth z, into b.size() = M values, same recurrence. Values in [-1, 1].
void fourierBasis(double z, std::span<double> b);
void fourierBasis(float z, std::span<float> b);

/// Eq. 9: 0.5 + a(zRay) . B(zTexel) with M bases (unclamped; overshoots by the Gibbs phenomenon).
double fourierVisibility(double zRay, double zTexel, int bases);

/// Optional damping of the ray coefficients against ringing (not in the paper; the basis is unchanged).
enum class RingingFilter {
  None,    ///< Eq. 8 as published (default of the evaluation)
  Lanczos, ///< Lanczos 1956 sigma factors sin(x_k) / x_k, x_k = pi (2k - 1) / M
};

/// Multiplies a_1..a_M (a.size() = M, validated) in place by the filter's factors (None: unchanged).
void applyRingingFilter(RingingFilter filter, std::span<double> a);
void applyRingingFilter(RingingFilter filter, std::span<float> a);
/// sigma_k of harmonic k = 1..M/2 (1 for None).
double ringingFactor(RingingFilter filter, int k, int bases);

/// The depth fed to B for a stored map depth, margin m in [0, 0.25]: >= 1 -> 1, <= 0 -> 0, else m + (1 - 2m)
/// depth (NaN is the caller's error).
double texelBasisDepth(double depth, double margin);
/// The depth fed to a for a view ray's depth: m + (1 - 2m) clamp(depth, 0, 1).
double rayBasisDepth(double depth, double margin);

} // namespace crep
