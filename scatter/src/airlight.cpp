// The closed-form airlight of a local light (Sun et al. 2005 extended); the rules are at the top of
// crep/scatter/airlight.h.
#include <crep/core/error.h>
#include <crep/core/light.h>
#include <crep/scatter/airlight.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace crep {

namespace {

constexpr double kHalfPi = 0.5 * std::numbers::pi;
/// a of the corner function G(r) ~ (1 + a r) / (1 + (1 + 2 a) r + a r^2) (see airlightScale).
constexpr double kAirlightCornerA = 0.9135;

// 8-point Gauss-Legendre on [-1, 1]: nodes +-x_i, weights w_i.
constexpr std::array<double, 4> kNodes = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                          0.9602898564975363};
constexpr std::array<double, 4> kWeights = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                            0.1012285362903763};

template <class F>
double gaussLegendre8(double a, double b, const F& f) {
  const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
  double sum = 0.0;
  for (std::size_t i = 0; i < kNodes.size(); ++i)
    sum += kWeights[i] * (f(mid - half * kNodes[i]) + f(mid + half * kNodes[i]));
  return sum * half;
}

double phaseOf(double g, bool rayleigh, double cosTheta) {
  return rayleigh ? rayleighPhase(cosTheta) : henyeyGreenstein(g, cosTheta);
}

/// integral_a^b exp(-u (tan xi' - tan a)) p(cos 2 xi') dxi' for 0 <= a < b <= pi / 2, to ~1e-13 relative.
/// u > 0 substitutes s = u (tan xi' - tan a) (dxi' = cos^2 xi' ds / u), so a sharp decay is resolved in s:
/// parts of at most 2 in s, cut at s = 40 (exp(-40) = 4e-18).
double intervalIntegral(double g, bool rayleigh, double u, double a, double b) {
  const auto p = [&](double xi) { return phaseOf(g, rayleigh, std::cos(2.0 * xi)); };
  if (!(u > 0.0)) {
    double sum = 0.0;
    constexpr int kParts = 4;
    for (int k = 0; k < kParts; ++k)
      sum += gaussLegendre8(a + (b - a) * k / kParts, a + (b - a) * (k + 1) / kParts, p);
    return sum;
  }
  const double ta = std::tan(a);
  const double S = b >= kHalfPi ? std::numeric_limits<double>::infinity() : u * (std::tan(b) - ta);
  const double end = std::min(S, 40.0);
  const int parts = std::max(1, static_cast<int>(std::ceil(end / 2.0)));
  double sum = 0.0;
  for (int k = 0; k < parts; ++k)
    sum += gaussLegendre8(end * k / parts, end * (k + 1) / parts, [&](double s) {
      const double xi = std::atan(ta + s / u), c = std::cos(xi);
      return std::exp(-s) * p(xi) * c * c / u;
    });
  return sum;
}

/// T at the grid points xi[0] < ... < xi[n - 1] = pi / 2 (T = 0 there), by the backward recursion
/// T_j = I_j + exp(-u (tan xi_j+1 - tan xi_j)) T_j+1: every factor <= 1.
std::vector<double> tailsOnGrid(double g, bool rayleigh, double u, const std::vector<double>& xi) {
  std::vector<double> T(xi.size(), 0.0);
  for (std::size_t j = xi.size() - 1; j-- > 0;) {
    const double carry = xi[j + 1] >= kHalfPi || !(u > 0.0)
                             ? (u > 0.0 ? 0.0 : 1.0)
                             : std::exp(-u * (std::tan(xi[j + 1]) - std::tan(xi[j])));
    T[j] = intervalIntegral(g, rayleigh, u, xi[j], xi[j + 1]) + carry * T[j + 1];
  }
  return T;
}

} // namespace

double airlightRowU(double y) {
  return y >= 1.0 ? std::numeric_limits<double>::infinity() : kAirlightUScale * y * y / (1.0 - y);
}
double airlightURow(double u) {
  if (std::isinf(u)) return 1.0;
  if (!(u > 0.0)) return 0.0;
  const double c = kAirlightUScale;
  return std::clamp(2.0 * u / (u + std::sqrt(u * u + 4.0 * c * u)), 0.0,
                    1.0); // the root of c y^2 = u (1 - y)
}
double airlightColumnXi(double x) {
  if (!(x < 1.0)) return kHalfPi;
  const double q = std::max(x, 0.0) / (1.0 - x); // q^2 = tan(xi)
  return std::atan(q * q);
}
double airlightXiColumn(double eta) {
  // x = sqrt(sin xi) / (sqrt(sin xi) + sqrt(cos xi)), xi = pi / 2 - eta.
  const double a = std::sqrt(std::cos(std::clamp(eta, 0.0, kHalfPi))),
               b = std::sqrt(std::sin(std::clamp(eta, 0.0, kHalfPi)));
  return a / (a + b);
}

double airlightScale(double u, double eta) {
  if (!(eta > 0.0) || std::isinf(u)) return 0.0;
  const double sn = std::sin(std::min(eta, kHalfPi)), r = u / sn, a = kAirlightCornerA;
  return sn * (1.0 + a * r) / (1.0 + (1.0 + 2.0 * a) * r + a * r * r);
}

double airlightTail(double g, bool rayleigh, double u, double xi) {
  if (!(xi < kHalfPi)) return 0.0;
  constexpr int kIntervals = 512;
  std::vector<double> grid(kIntervals + 1);
  for (int k = 0; k <= kIntervals; ++k)
    grid[std::size_t(k)] = k == kIntervals ? kHalfPi : xi + (kHalfPi - xi) * k / kIntervals;
  return tailsOnGrid(g, rayleigh, u, grid)[0];
}

AirlightTable makeAirlightTable(double g, int uSamples, int xiSamples) {
  if (!std::isfinite(g) || !(std::abs(g) < 1.0))
    throw InvalidArgument("g", std::to_string(g), "must be in (-1, 1)");
  if (uSamples < 2) throw InvalidArgument("uSamples", std::to_string(uSamples), "must be >= 2");
  if (xiSamples < 2) throw InvalidArgument("xiSamples", std::to_string(xiSamples), "must be >= 2");
  AirlightTable table;
  table.uSamples = uSamples;
  table.xiSamples = xiSamples;
  table.g = g;
  table.values.assign(std::size_t(uSamples) * std::size_t(xiSamples) * 2, 0.0f);
  std::vector<double> xi(static_cast<std::size_t>(xiSamples));
  for (int j = 0; j < xiSamples; ++j)
    xi[std::size_t(j)] = j == xiSamples - 1 ? kHalfPi : airlightColumnXi(double(j) / (xiSamples - 1));
  for (int i = 0; i < uSamples; ++i) {
    const double u = airlightRowU(double(i) / (uSamples - 1));
    for (int c = 0; c < 2; ++c) {
      const bool rayleigh = c == 1;
      std::vector<double> T;
      if (std::isfinite(u)) T = tailsOnGrid(g, rayleigh, u, xi);
      for (int j = 0; j < xiSamples; ++j) {
        const double x = xi[std::size_t(j)], eta = kHalfPi - x;
        // The limits of N = T / K: p(cos 2 xi) for u -> infinity, p(-1) at the horizon xi = pi / 2.
        double N = phaseOf(g, rayleigh, std::cos(2.0 * x));
        if (std::isfinite(u) && j < xiSamples - 1) N = T[std::size_t(j)] / airlightScale(u, eta);
        if (j == xiSamples - 1) N = phaseOf(g, rayleigh, -1.0);
        table.values[(std::size_t(i) * std::size_t(xiSamples) + std::size_t(j)) * 2 + std::size_t(c)] =
            static_cast<float>(N);
      }
    }
  }
  return table;
}

glm::dvec2 AirlightTable::lookup(double u, double xi) const {
  const double y = airlightURow(u);
  const double fx = airlightXiColumn(kHalfPi - xi) * (xiSamples - 1);
  const double fy = std::clamp(y, 0.0, 1.0) * (uSamples - 1);
  const int x0 = std::min(static_cast<int>(fx), xiSamples - 2),
            y0 = std::min(static_cast<int>(fy), uSamples - 2);
  const double ax = fx - x0, ay = fy - y0;
  const auto at = [&](int i, int j) {
    const std::size_t k = (std::size_t(i) * std::size_t(xiSamples) + std::size_t(j)) * 2;
    return glm::dvec2(values[k], values[k + 1]);
  };
  return (1.0 - ay) * ((1.0 - ax) * at(y0, x0) + ax * at(y0, x0 + 1)) +
         ay * ((1.0 - ax) * at(y0 + 1, x0) + ax * at(y0 + 1, x0 + 1));
}

AirlightScattering::AirlightScattering(const LocalLight& light, const Medium& medium,
                                       const AirlightTable& table, const glm::dvec3& origin,
                                       const glm::dvec3& direction)
    : exact_(light, medium, origin, direction), table_(&table), light_(light), origin_(origin),
      direction_(direction), sigma_(medium.extinction()), mie_(medium.mieScattering()),
      rayleigh_(medium.rayleighScattering()), g_(medium.hgG()) {
  const glm::dvec3 p = origin - light.position;
  t0_ = -glm::dot(p, direction);
  perp_ = p + t0_ * direction;
  h_ = glm::length(perp_);
}

glm::dvec3 AirlightScattering::endTerm(double t) const {
  const double v = t - t0_, d = std::sqrt(h_ * h_ + v * v);
  const double s = v >= 0.0 ? v + d : h_ * h_ / (d - v); // v + d without cancellation
  const double xi = std::atan2(s, h_), eta = std::atan2(h_, s);
  glm::dvec3 E(0.0);
  for (int c = 0; c < 3; ++c) {
    const double u = sigma_[c] * h_;
    const glm::dvec2 N = table_->lookup(u, xi);
    E[c] = std::exp(-sigma_[c] * (t + d)) * (mie_[c] * N.x + rayleigh_[c] * N.y) * airlightScale(u, eta);
  }
  return E;
}

glm::dvec3 AirlightScattering::segment(double ta, double tb) const {
  if (!(tb > ta)) return glm::dvec3(0.0);
  // A ray through the light's near ball: the exact quadrature throughout.
  if (!(h_ > light_.nearPlane)) return exact_.segment(ta, tb);
  const std::vector<double> cuts = exact_.breakpoints(ta, tb);
  glm::dvec3 total(0.0);
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double t1 = cuts[i], t2 = cuts[i + 1];
    if (!(t2 > t1)) continue;
    const glm::dvec3 wm = glm::normalize(perp_ + (0.5 * (t1 + t2) - t0_) * direction_);
    if (light_.face >= 0 && PointLight::faceOf(wm) != light_.face) continue;
    if (light_.cone) {
      const double c = glm::dot(wm, light_.axis);
      if (c <= light_.cosOuter) continue;
      if (c < light_.cosInner) { // the falloff band: the exact quadrature
        total += exact_.segment(t1, t2);
        continue;
      }
    }
    total += light_.intensity * (2.0 / h_) * (endTerm(t1) - endTerm(t2));
  }
  return total;
}

} // namespace crep
