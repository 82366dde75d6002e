// Prefilter weights: Klehm, Seidel, Eisemann 2014, Sec. 3.1 (average visibility, Eq. 5), Sec. 3.2
// (transmittance weights w_i of Eq. 11 with a reference ray), Sec. 4.2 (Eq. 12, constant step ratio),
// plus exact weights from the reference ray's closed-form distances (crep/prefilter/weights.h). Definitions
// and the sigma -> 0 handling are in crep/prefilter/weights.h.
#include <crep/core/error.h>
#include <crep/prefilter/weights.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace crep {

namespace {

void requireTexels(int texels, std::size_t size, std::size_t expected) {
  if (texels < 1) throw InvalidArgument("texels", detail::formatValue(texels), "must be >= 1");
  if (size != expected)
    throw InvalidArgument("texels", detail::formatValue(texels),
                          "output size " + std::to_string(size) + " must be " + std::to_string(expected));
}

void requireExtinction(double s) {
  requireNonNegative("extinction", s);
}

/// Eq. 12 parameters of a region: first texel length D0 and log of the step ratio r (texel centres).
struct RatioParams {
  double first = 0.0, logRatio = 0.0;
};

RatioParams ratioParams(const DistanceProfile& p, int n) {
  RatioParams r;
  r.first = p.fromStart(1.0 / n);
  if (n >= 3) {
    const double t0 = p.fromStart(0.5 / n), t1 = p.fromStart(1.5 / n), t2 = p.fromStart(2.5 / n);
    const double ratio = (t2 - t1) / (t1 - t0);
    if (std::isfinite(ratio) && ratio > 0.0) r.logRatio = std::log(ratio);
  }
  return r;
}

/// tau at fractional texel position x = u n for the constant-ratio model: D0 (r^x - 1) / (r - 1).
double ratioDistance(const RatioParams& r, double x) {
  if (r.logRatio == 0.0) return x * r.first;
  return r.first * std::expm1(x * r.logRatio) / std::expm1(r.logRatio);
}

/// The mode's distance from the region start at the continuous column u (Exact/ConstantStep/ConstantRatio).
double distanceAt(WeightMode mode, const DistanceProfile& p, int n, double u, const RatioParams& ratio) {
  switch (mode) {
  case WeightMode::Exact:
    return p.fromStart(u);
  case WeightMode::ConstantStep:
    return u * p.fromStart(1.0);
  case WeightMode::ConstantRatio:
    return ratioDistance(ratio, u * n);
  case WeightMode::AverageVisibility:
    break;
  }
  return u * n;
}

} // namespace

const char* weightModeToken(WeightMode mode) {
  switch (mode) {
  case WeightMode::AverageVisibility:
    return "average-visibility";
  case WeightMode::ConstantStep:
    return "constant-step";
  case WeightMode::ConstantRatio:
    return "constant-ratio";
  case WeightMode::Exact:
    return "exact";
  }
  return "unknown";
}

void regionDistances(WeightMode mode, const DistanceProfile& profile, int texels, std::span<double> tau) {
  requireTexels(texels, tau.size(), static_cast<std::size_t>(texels) + 1);
  const RatioParams ratio = mode == WeightMode::ConstantRatio ? ratioParams(profile, texels) : RatioParams{};
  const double step = profile.fromStart(1.0) / texels;
  for (int i = 0; i <= texels; ++i) {
    double t = 0.0;
    switch (mode) {
    case WeightMode::Exact:
      t = i == texels ? profile.fromStart(1.0) : profile.fromStart(static_cast<double>(i) / texels);
      break;
    case WeightMode::ConstantStep:
      t = i * step;
      break;
    case WeightMode::ConstantRatio:
      t = ratioDistance(ratio, i);
      break;
    case WeightMode::AverageVisibility:
      t = i;
      break;
    }
    tau[static_cast<std::size_t>(i)] = i == 0 ? 0.0 : t;
  }
}

void regionWeights(WeightMode mode, double extinction, const DistanceProfile& profile, int texels,
                   std::span<double> weights) {
  requireExtinction(extinction);
  requireTexels(texels, weights.size(), static_cast<std::size_t>(texels));
  if (mode == WeightMode::AverageVisibility) {
    for (double& w : weights)
      w = 1.0;
    return;
  }
  std::vector<double> tau(static_cast<std::size_t>(texels) + 1);
  regionDistances(mode, profile, texels, tau);
  for (std::size_t i = 0; i < weights.size(); ++i) {
    // exp(-s tau_i) - exp(-s tau_{i+1}) without the cancellation of the difference.
    const double w = std::exp(-extinction * tau[i]) * -std::expm1(-extinction * (tau[i + 1] - tau[i]));
    weights[i] = std::isfinite(w) ? w : 0.0;
  }
}

void regionMixFactors(WeightMode mode, double extinction, const DistanceProfile& profile, int texels,
                      std::span<double> mix) {
  requireExtinction(extinction);
  requireTexels(texels, mix.size(), static_cast<std::size_t>(texels));
  if (mode == WeightMode::AverageVisibility) {
    for (std::size_t i = 0; i < mix.size(); ++i)
      mix[i] = 1.0 / static_cast<double>(i + 1);
    return;
  }
  std::vector<double> tau(static_cast<std::size_t>(texels) + 1);
  regionDistances(mode, profile, texels, tau);
  for (std::size_t i = 0; i < mix.size(); ++i) {
    const double t0 = tau[i], t1 = tau[i + 1];
    if (!std::isfinite(t1) || !std::isfinite(t0)) {
      mix[i] = i == 0 ? 1.0 : 0.0; // beyond a spot light's horizon: no weight
      continue;
    }
    const double dt = t1 - t0;
    // w_i / s and (sum_{j<=i} w_j) / s, both finite for s = 0.
    const double num = std::exp(-extinction * t0) * oneMinusExpOverX(extinction * dt) * dt;
    const double den = oneMinusExpOverX(extinction * t1) * t1;
    double m;
    if (i == 0)
      m = 1.0;
    else if (!(den > 0.0))
      m = 1.0 / static_cast<double>(i + 1); // zero-length prefix: equal weights
    else
      m = std::clamp(num / den, 0.0, 1.0);
    mix[i] = m;
  }
}

void regionMixFactors(WeightMode mode, double extinction, const DistanceProfile& profile, int texels,
                      std::span<const double> light, std::span<double> mix) {
  if (light.empty()) {
    regionMixFactors(mode, extinction, profile, texels, mix);
    return;
  }
  requireExtinction(extinction);
  requireTexels(texels, mix.size(), static_cast<std::size_t>(texels));
  requireTexels(texels, light.size(), 2 * static_cast<std::size_t>(texels) + 1);
  std::vector<double> tau(static_cast<std::size_t>(texels) + 1);
  regionDistances(mode, profile, texels, tau);
  double sum = 0.0;
  for (std::size_t i = 0; i < mix.size(); ++i) {
    const double t0 = tau[i], t1 = tau[i + 1];
    double w = 0.0;
    if (std::isfinite(t0) && std::isfinite(t1)) {
      const double dt = t1 - t0;
      const double transmittance = mode == WeightMode::AverageVisibility
                                       ? 1.0
                                       : std::exp(-extinction * t0) * oneMinusExpOverX(extinction * dt) * dt;
      const double g = (light[2 * i] + 4.0 * light[2 * i + 1] + light[2 * i + 2]) / 6.0;
      w = std::isfinite(g) && g > 0.0 ? g * transmittance : 0.0;
    }
    sum += w;
    mix[i] = sum > 0.0 ? std::clamp(w / sum, 0.0, 1.0) : 1.0 / static_cast<double>(i + 1);
  }
}

double regionWeightTotal(WeightMode mode, double extinction, const DistanceProfile& profile, int texels,
                         double u) {
  requireExtinction(extinction);
  if (texels < 1) throw InvalidArgument("texels", detail::formatValue(texels), "must be >= 1");
  if (mode == WeightMode::AverageVisibility) return u * texels;
  const RatioParams ratio = mode == WeightMode::ConstantRatio ? ratioParams(profile, texels) : RatioParams{};
  const double tau = distanceAt(mode, profile, texels, u, ratio);
  if (!std::isfinite(tau)) return extinction > 0.0 ? 1.0 / extinction : tau;
  return tau * oneMinusExpOverX(extinction * tau);
}

} // namespace crep
