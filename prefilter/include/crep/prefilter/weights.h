// Prefilter weights for the n texels of one region of one row, from the region's reference-ray
// DistanceProfile t(u) (Klehm, Seidel, Eisemann 2014, Sec. 3.1, Sec. 3.2 Eq. 10-11, Sec. 4.2 Eq. 12). The
// modes' distances, the RGB rule and the sigma -> 0 limit: prefilter/README.md, "weights.h".
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

/// The boundary distances tau_0..tau_n of `mode` (world units; AverageVisibility: i, in texels). Throws
/// InvalidArgument ("texels") for n < 1 or a size mismatch.
void regionDistances(WeightMode mode, const DistanceProfile& profile, int texels, std::span<double> tau);

/// The weights w_i = exp(-s tau_i) - exp(-s tau_{i+1}), extinction s >= 0 (1/world unit); all 1 if averaged.
void regionWeights(WeightMode mode, double extinction, const DistanceProfile& profile, int texels,
                   std::span<double> weights);

/// Listing 2's mix factors m_i = w_i / sum_{j<=i} w_j in [0, 1] of the filter F_i = F_{i-1} + m_i (B(z_i) -
/// F_{i-1}); finite at s = 0.
void regionMixFactors(WeightMode mode, double extinction, const DistanceProfile& profile, int texels,
                      std::span<double> mix);

/// The same with a light-side factor (Sec. 3.2 "Angular-dependency for Sources"): `light` holds 2 n + 1
/// samples of it along the reference ray (empty: the overload above).
void regionMixFactors(WeightMode mode, double extinction, const DistanceProfile& profile, int texels,
                      std::span<const double> light, std::span<double> mix);

/// The weight total of the first u n texels divided by s, u in [0, 1] continuous: tau phi(s tau) (u n for
/// AverageVisibility). Only its ratios matter (the near-plane correction).
double regionWeightTotal(WeightMode mode, double extinction, const DistanceProfile& profile, int texels,
                         double u);

} // namespace crep
