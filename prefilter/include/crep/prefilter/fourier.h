// Fourier expansion of the shadow-test step function (Klehm, Seidel, Eisemann 2014, Sec. 3.1, Eq. 8-9,
// after Annen et al. 2007's convolution shadow maps).
//
// With c_k = pi (2k - 1), k = 1..M/2 (M even, the number of "bases": sine and cosine counted
// separately, as in the paper's journal version):
//   a_{2k-1}(z) = 2 cos(c_k z) / c_k      a_{2k}(z) = -2 sin(c_k z) / c_k      (ray coefficients)
//   B_{2k-1}(z) = sin(c_k z)              B_{2k}(z) = cos(c_k z)               (texel basis)
// and  0.5 + a(z_r) . B(z_i) = 0.5 + sum_k (2 / c_k) sin(c_k (z_i - z_r)),  the M/2-term Fourier
// series of the period-2 square wave that is 1 for z_i - z_r in (0, 1) (ray in front of the occluder:
// lit) and 0 for z_i - z_r in (-1, 0) (shadowed); 0.5 exactly at the jumps d = 0 and d = +-1.
//
// Arrays are 0-based: element j holds the paper's index j + 1, so a[2k-2] = a_{2k-1}, a[2k-1] = a_{2k}
// (k = 1..M/2), i.e. even elements are the cosine coefficients / sine bases. The filtered-basis storage
// packs element j into layer j / 4, channel j % 4 (RGBA).
//
// Trap (found here, not in the paper): the period is 2 in depth, so with texel and ray depths both in
// [0, 1] the differences reach +-1, where the series jumps again: a ray at depth ~0 against an empty
// texel (depth 1) would see visibility 0.5, not 1, and a ray at depth 1 an empty texel at 0.5 too.
// texelBasisDepth / rayBasisDepth below move the ray depths into [m, 1 - m] and send the map's exact
// end values 0 (caster clamped in front) and 1 (nothing) to 0 and 1, so every difference keeps a
// margin >= m from the jumps that do not belong to it.
#pragma once

#include <span>
#include <string_view>

namespace crep {

/// Default number of bases M (the paper's default: 8 RGBA layers).
inline constexpr int kDefaultBases = 32;
inline constexpr int kMinBases = 4;
inline constexpr int kMaxBases = 128;

/// Throws InvalidArgument (parameter "bases") unless M is even and in [kMinBases, kMaxBases].
void validateBases(int bases, std::string_view parameter = "bases");

/// Eq. 8 ray coefficients a_1..a_M at depth z, into a.size() = M values (M validated as above).
/// All values from one sin/cos of pi z by the angle-addition recurrence (relative error ~M eps).
void fourierCoefficients(double z, std::span<double> a);
void fourierCoefficients(float z, std::span<float> a);

/// Eq. 8 basis B_1..B_M at depth z, into b.size() = M values, same recurrence. Values in [-1, 1].
void fourierBasis(double z, std::span<double> b);
void fourierBasis(float z, std::span<float> b);

/// Eq. 9: 0.5 + a(zRay) . B(zTexel) with M bases (unclamped; overshoots by the Gibbs phenomenon).
double fourierVisibility(double zRay, double zTexel, int bases);

/// Optional damping of the ray coefficients against ringing (not in the paper). Lanczos sigma factors:
/// a_{2k-1} and a_{2k} are multiplied by sigma_k = sin(x_k) / x_k, x_k = pi (2k - 1) / M (the harmonic
/// over M = twice the number of harmonics, Lanczos 1956). The visibility 0.5 + sigma a . B is then the
/// step convolved with a box of width 2 / M in depth difference: the Gibbs overshoot drops from 8.9% to
/// ~1.2% of the jump and the ringing far from the jump by an order of magnitude, at the price of a
/// wider transition. Measured (prefilter/README.md, M = 32): the no-occluder error drops 25x and the
/// half-space shadow error 1.2x, but on the built-in scenes (receivers are in the map, so the texels just
/// before every hit have nearly the ray's depth) the wider step costs 1.5-1.8x. Only the ray side
/// changes: the filtered basis is the same.
enum class RingingFilter {
  None,    ///< Eq. 8 as published (default of the evaluation)
  Lanczos, ///< sigma factors as above
};

/// Multiplies a_1..a_M (a.size() = M, validated) in place by the filter's factors (None: unchanged).
void applyRingingFilter(RingingFilter filter, std::span<double> a);
void applyRingingFilter(RingingFilter filter, std::span<float> a);
/// sigma_k of harmonic k = 1..M/2 (1 for None).
double ringingFactor(RingingFilter filter, int k, int bases);

/// The depth fed to B for a stored map depth (see the trap above), margin m in [0, 0.25]:
///   depth >= 1 -> 1, depth <= 0 -> 0, else m + (1 - 2m) depth.   (NaN is the caller's error)
double texelBasisDepth(double depth, double margin);
/// The depth fed to a for a view ray's depth: m + (1 - 2m) clamp(depth, 0, 1).
double rayBasisDepth(double depth, double margin);

} // namespace crep
