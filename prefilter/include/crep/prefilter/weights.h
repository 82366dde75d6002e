// Prefilter weights (Klehm, Seidel, Eisemann 2014, Sec. 3.1 average visibility, Sec. 3.2 Eq. 10-11
// transmittance weights with a reference ray, Sec. 4.2 Eq. 12 constant-ratio weights) for the n texels of
// one region of one row, described by the region's reference-ray DistanceProfile t(u), u in [0, 1].
//
// Every mode defines distances tau_0 = 0 < tau_1 < ... < tau_n from the region's start (world units)
// at the texel boundaries u_i = i / n, and weights w_i = exp(-s tau_i) - exp(-s tau_{i+1}) for texel
// i = 0..n-1 (s = the weight extinction, 1/world unit), so that sum_{i<q} w_i = 1 - exp(-s tau_q):
//   Exact        tau_i = t(u_i) - t(0)  (DistanceProfile::fromStart)                       (default)
//   ConstantStep tau_i = i D, D = (t(1) - t(0)) / n: Eq. 11 with the region's mean reference step
//   ConstantRatio tau_i = D0 (r^i - 1) / (r - 1) (i D0 if r = 1), D0 = t(u_1) - t(0) the first texel's
//                length, r = (t(2.5/n) - t(1.5/n)) / (t(1.5/n) - t(0.5/n)) from the first three texel
//                centres (Eq. 12; r = 1 if n < 3). The paper's claim that the step grows by a constant
//                factor is only approximate: a projective map preserves cross ratios, not step ratios.
//   AverageVisibility w_i = 1 for all i (Sec. 3.1, Eq. 5: the unweighted mean visibility; the
//                evaluation then factors the transmittance out as in Eq. 2-3). tau is not used.
// Measuring from the region's start instead of the camera changes every weight of a region by the same
// factor exp(-s t(0)), which the normalized storage (Appendix A) cancels; it avoids underflow far away.
//
// RGB: the weights need one scalar extinction. We use the mean of the medium's three extinction
// channels (weightExtinction) and restore each channel's own transmittance integral at evaluation
// (prefilter.h). Exact for grey media; for coloured media the visibility of every channel is averaged
// with the grey weights (error grows with |s_c - s| t). Storing three weight sets would triple the
// filtered basis, as the paper notes for coloured light textures (Sec. 3.2).
//
// sigma -> 0: regionMixFactors and regionWeightTotal are written with phi(x) = -expm1(-x) / x (phi(0) = 1),
// so they reach the length-weighted limit without any division by zero, and s = 0 is allowed.
#pragma once

#include <span>

#include <crep/core/medium.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/ray.h>

namespace crep {

enum class WeightMode {
  AverageVisibility, ///< Sec. 3.1: equal weights, transmittance factored out (Eq. 2)
  ConstantStep,      ///< Eq. 11: exponential weights with the region's mean reference step
  ConstantRatio,     ///< Eq. 12: exponential weights with a constant step ratio (the paper's rectified case)
  Exact,             ///< exponential weights from the reference ray's exact distances (default)
};

/// Stable token: "average-visibility", "constant-step", "constant-ratio", "exact".
const char* weightModeToken(WeightMode mode);

// The scalar extinction of the weights is weightExtinction(medium) and phi is oneMinusExpOverX, both in
// crep/scatter/ray.h (the same grey extinction is the alpha channel of every method's output).

/// The boundary distances tau_0..tau_n (size n + 1, n >= 1) of `mode` (see top; AverageVisibility:
/// tau_i = i, in texels). Throws InvalidArgument ("texels") for n < 1 or a size mismatch.
void regionDistances(WeightMode mode, const DistanceProfile& profile, int texels, std::span<double> tau);

/// The weights w_0..w_{n-1} (see top; sums 1 - exp(-s tau_q)) for extinction s >= 0 (all 0 if s = 0
/// for the exponential modes). AverageVisibility: all 1.
void regionWeights(WeightMode mode, double extinction, const DistanceProfile& profile, int texels,
                   std::span<double> weights);

/// The mix factors of the normalized prefix filter (Listing 2): m_i = w_i / sum_{j<=i} w_j in (0, 1],
/// m_0 = 1, computed as exp(-s tau_i) phi(s dtau_i) dtau_i / (phi(s tau_{i+1}) tau_{i+1}) with
/// dtau_i = tau_{i+1} - tau_i, so s = 0 gives the length-weighted mean; zero-length prefixes give
/// 1 / (i + 1); non-finite distances (beyond a spot light's horizon) give 0. AverageVisibility: 1/(i+1).
/// The filter is F_i = F_{i-1} + m_i (B(z_i) - F_{i-1}), F_{-1} = 0.
void regionMixFactors(WeightMode mode, double extinction, const DistanceProfile& profile, int texels,
                      std::span<double> mix);

/// The same with a light-side factor per texel (Klehm et al. 2014, Sec. 3.2 "Angular-dependency for
/// Sources": each visibility weighted by the light's contribution, as for the transmittance): `light`
/// holds 2 n + 1 samples g(k / (2 n)) of the factor along the region's reference ray (texel boundaries
/// and centres), and w_i = gbar_i (exp(-s tau_i) - exp(-s tau_{i+1})) with gbar_i = (g_2i + 4 g_2i+1 +
/// g_2i+2) / 6 (Simpson). m_i = w_i / sum_{j<=i} w_j; 1 / (i + 1) while the sum is 0 (no light yet: equal
/// weights); non-finite distances give w = 0. An empty `light` is the overload above.
void regionMixFactors(WeightMode mode, double extinction, const DistanceProfile& profile, int texels,
                      std::span<const double> light, std::span<double> mix);

/// The weight total of the first u n texels divided by s, for a continuous u in [0, 1] (tau(u) is the
/// mode's distance at fractional texel u n; exponential modes: (1 - exp(-s tau(u))) / s = tau phi(s tau),
/// = tau(u) for s = 0; AverageVisibility: u n). Only its ratios matter (the near-plane correction of
/// the evaluation combines two prefixes of one region with it).
double regionWeightTotal(WeightMode mode, double extinction, const DistanceProfile& profile, int texels,
                         double u);

} // namespace crep
