// S(ta, tb) of a view ray for every light type; the rules are at the top of crep/scatter/ray_scattering.h.
#include <crep/core/error.h>
#include <crep/scatter/ray.h>
#include <crep/scatter/ray_scattering.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace crep {

namespace {

// 8-point Gauss-Legendre on [-1, 1]: nodes +-x_i, weights w_i.
constexpr std::array<double, 4> kNodes = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                          0.9602898564975363};
constexpr std::array<double, 4> kWeights = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                            0.1012285362903763};

/// Appends the roots of a t^2 + b t + c = 0 that lie strictly inside (lo, hi) and satisfy keep(t).
template <class Keep>
void quadraticRoots(double a, double b, double c, double lo, double hi, std::vector<double>& out, Keep keep) {
  const auto add = [&](double t) {
    if (t > lo && t < hi && std::isfinite(t) && keep(t)) out.push_back(t);
  };
  const double scale = std::max({std::abs(a), std::abs(b), std::abs(c)});
  if (!(scale > 0.0)) return;
  if (std::abs(a) <= 1e-14 * scale) {
    if (b != 0.0) add(-c / b);
    return;
  }
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return;
  // Stable form: q = -(b + sign(b) sqrt(disc)) / 2, roots q / a and c / q.
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  add(q / a);
  if (q != 0.0) add(c / q);
}

} // namespace

LocalLight LocalLight::spot(const SpotLight& light) {
  LocalLight l;
  l.position = light.position();
  l.intensity = light.intensity();
  l.nearPlane = light.nearPlane();
  l.cone = true;
  l.axis = light.direction();
  l.cosInner = light.cosInner();
  l.cosOuter = light.cosOuter();
  return l;
}

LocalLight LocalLight::pointFace(const PointLight& light, int face) {
  LocalLight l;
  l.position = light.position();
  l.intensity = light.intensity();
  l.nearPlane = light.nearPlane();
  l.axis = PointLight::faceAxis(face); // validates face
  l.face = face;
  return l;
}

glm::dvec3 LocalLight::intensityToward(const glm::dvec3& w) const {
  if (face >= 0 && PointLight::faceOf(w) != face) return glm::dvec3(0.0);
  if (cone) return intensity * spotFalloff(glm::dot(w, axis), cosInner, cosOuter);
  return intensity;
}

const char* localLightWeightsToken(LocalLightWeights weights) {
  switch (weights) {
  case LocalLightWeights::Full:
    return "full";
  case LocalLightWeights::Angular:
    return "angular";
  case LocalLightWeights::None:
    break;
  }
  return "none";
}

double LocalLight::weightFactor(const Medium& medium, double greyExtinction, const glm::dvec3& point,
                                const glm::dvec3& v, LocalLightWeights weights) const {
  if (weights == LocalLightWeights::None) return 1.0;
  const glm::dvec3 p = point - position;
  const double d = glm::length(p);
  const glm::dvec3 w = d > 0.0 ? p / d : v;
  const double dc = std::max(d, nearPlane);
  const glm::dvec3 I = intensityToward(w);
  if (weights == LocalLightWeights::Angular) return (I.x + I.y + I.z) / 3.0;
  const glm::dvec3 phase = medium.scatteringTimesPhase(glm::dot(w, -v));
  return (phase.x + phase.y + phase.z) / 3.0 * (I.x + I.y + I.z) / 3.0 * std::exp(-greyExtinction * dc) /
         (dc * dc);
}

RayScattering::RayScattering(const DirectionalLight& light, const Medium& medium, const glm::dvec3& origin,
                             const glm::dvec3& direction)
    : medium_(&medium), origin_(origin), direction_(direction), sigma_(medium.extinction()), local_(false),
      constant_(scatteringConstant(light, medium, direction)) {}

RayScattering::RayScattering(const LocalLight& light, const Medium& medium, const glm::dvec3& origin,
                             const glm::dvec3& direction)
    : medium_(&medium), origin_(origin), direction_(direction), sigma_(medium.extinction()), local_(true),
      light_(light) {
  const glm::dvec3 toLight = light.position - origin;
  t0_ = glm::dot(toLight, direction);
  h_ = glm::length(toLight - t0_ * direction);
  // The phase peak's width in gamma (theta = gamma + constant along the ray) bounds the parts.
  gammaStep_ = std::min(std::numbers::pi / 32.0, 0.5 * (1.0 - std::abs(medium.hgG())));
  gammaStep_ = std::max(gammaStep_, 1e-3);
}

glm::dvec3 RayScattering::density(double t) const {
  if (!local_) return constant_ * glm::exp(-sigma_ * t);
  const glm::dvec3 p = origin_ + t * direction_ - light_.position;
  const double d = glm::length(p);
  const glm::dvec3 w = d > 0.0 ? p / d : direction_;
  const double dc = std::max(d, light_.nearPlane);
  const glm::dvec3 E = light_.intensityToward(w) * glm::exp(-sigma_ * dc) / (dc * dc);
  return glm::exp(-sigma_ * t) * medium_->scatteringTimesPhase(glm::dot(w, -direction_)) * E;
}

double RayScattering::gammaOf(double t) const {
  return std::atan((t - t0_) / std::max(h_, light_.nearPlane));
}

glm::dvec3 RayScattering::integrandInGamma(double gamma) const {
  // t = t0 + hq tan gamma, dt / dgamma = hq / cos^2 gamma (hq = max(h, near): see the header).
  const double hq = std::max(h_, light_.nearPlane);
  const double c = std::cos(gamma);
  return density(t0_ + hq * std::tan(gamma)) * (hq / (c * c));
}

glm::dvec3 RayScattering::gaussLegendre(double a, double b, bool inGamma) const {
  const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
  glm::dvec3 sum(0.0);
  for (std::size_t i = 0; i < kNodes.size(); ++i) {
    const double dx = half * kNodes[i];
    if (inGamma)
      sum += kWeights[i] * (integrandInGamma(mid - dx) + integrandInGamma(mid + dx));
    else
      sum += kWeights[i] * (density(mid - dx) + density(mid + dx));
  }
  return sum * half;
}

std::vector<double> RayScattering::breakpoints(double ta, double tb) const {
  if (!(tb > ta)) return {};
  if (!local_) return {ta, tb};
  // Breakpoints: the near ball, the cone angles (spot), the sector planes (point face).
  std::vector<double> cuts{ta, tb};
  const glm::dvec3 p = origin_ - light_.position; // x(t) - L = p + t v
  const glm::dvec3& v = direction_;
  const double pv = glm::dot(p, v), pp = glm::dot(p, p);
  const double near = light_.nearPlane;
  quadraticRoots(1.0, 2.0 * pv, pp - near * near, ta, tb, cuts, [](double) { return true; });
  if (light_.cone) {
    const double a = glm::dot(v, light_.axis), b = glm::dot(p, light_.axis);
    for (const double cosAngle : {light_.cosInner, light_.cosOuter}) {
      const double c2 = cosAngle * cosAngle;
      quadraticRoots(a * a - c2, 2.0 * (a * b - c2 * pv), b * b - c2 * pp, ta, tb, cuts,
                     [&](double t) { return b + a * t >= 0.0; });
    }
  }
  if (light_.face >= 0) {
    const int major = light_.face / 2;
    for (int j = 0; j < 3; ++j) {
      if (j == major) continue;
      for (const double sign : {1.0, -1.0}) {
        const double slope = v[major] - sign * v[j], offset = p[major] - sign * p[j];
        if (slope != 0.0) {
          const double t = -offset / slope;
          if (t > ta && t < tb) cuts.push_back(t);
        }
      }
    }
  }
  std::sort(cuts.begin(), cuts.end());
  return cuts;
}

glm::dvec3 RayScattering::partialShare(double ta, double tb, double tEnd) const {
  if (!local_) return glm::dvec3(1.0);
  // The part the light reaches: the pieces inside the outer cone / the sector (one interval: both are
  // convex), or everything when the ray passes through the near ball.
  double lo = ta, hi = tEnd;
  if (h_ > light_.nearPlane && (light_.cone || light_.face >= 0)) {
    lo = std::numeric_limits<double>::infinity();
    hi = -lo;
    const std::vector<double> cuts = breakpoints(ta, tEnd);
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
      if (!(cuts[i + 1] > cuts[i])) continue;
      const glm::dvec3 p = origin_ + 0.5 * (cuts[i] + cuts[i + 1]) * direction_ - light_.position;
      const glm::dvec3 w = glm::normalize(p);
      if (light_.face >= 0 && PointLight::faceOf(w) != light_.face) continue;
      if (light_.cone && !(glm::dot(w, light_.axis) > light_.cosOuter)) continue;
      lo = std::min(lo, cuts[i]);
      hi = std::max(hi, cuts[i + 1]);
    }
  }
  if (!(lo < hi)) return glm::dvec3(0.0);
  // Inside that part a point face's sector holds by construction: its ends lie on the sector's planes,
  // where faceOf could fall on either side (crep_localPartialShare does the same).
  RayScattering inside = *this;
  if (h_ > light_.nearPlane) inside.light_.face = -1;
  const auto integrandInGamma = [&](double g) { return inside.integrandInGamma(g); };
  const double b = std::clamp(tb, lo, hi);
  // gamma kept 1e-6 inside +-pi / 2, as the GPU must (crep_localPartialShare).
  constexpr double kMax = 0.5 * 3.14159265358979323846 - 1e-6;
  const double ga = std::clamp(gammaOf(lo), -kMax, kMax), gb = std::clamp(gammaOf(b), -kMax, kMax),
               ge = std::clamp(gammaOf(hi), -kMax, kMax);
  const glm::dvec3 fa = integrandInGamma(ga), fb = integrandInGamma(gb), fe = integrandInGamma(ge);
  const glm::dvec3 part = (gb - ga) * (fa + 4.0 * integrandInGamma(0.5 * (ga + gb)) + fb);
  const glm::dvec3 whole = part + (ge - gb) * (fb + 4.0 * integrandInGamma(0.5 * (gb + ge)) + fe);
  glm::dvec3 share;
  for (int c = 0; c < 3; ++c)
    share[c] = whole[c] > 0.0 ? part[c] / whole[c] : (gb - ga) / std::max(ge - ga, 1e-300);
  return share;
}

glm::dvec3 RayScattering::segment(double ta, double tb) const {
  if (!(tb > ta)) return glm::dvec3(0.0);
  if (!local_) return constant_ * transmittanceIntegral(sigma_, ta, tb);
  const std::vector<double> cuts = breakpoints(ta, tb);
  const glm::dvec3 p = origin_ - light_.position;
  const glm::dvec3& v = direction_;
  const double near = light_.nearPlane;

  glm::dvec3 total(0.0);
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double t1 = cuts[i], t2 = cuts[i + 1];
    if (!(t2 > t1)) continue;
    const double tm = 0.5 * (t1 + t2);
    const bool insideBall = glm::length(p + tm * v) < near;
    if (insideBall) {
      constexpr int kParts = 8;
      for (int k = 0; k < kParts; ++k)
        total += gaussLegendre(t1 + (t2 - t1) * k / kParts, t1 + (t2 - t1) * (k + 1) / kParts, false);
      continue;
    }
    const double ga = gammaOf(t1), gb = gammaOf(t2);
    const int parts = std::max(1, static_cast<int>(std::ceil((gb - ga) / gammaStep_)));
    for (int k = 0; k < parts; ++k)
      total += gaussLegendre(ga + (gb - ga) * k / parts, ga + (gb - ga) * (k + 1) / parts, true);
  }
  return total;
}

} // namespace crep
