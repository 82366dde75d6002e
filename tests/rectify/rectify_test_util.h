// Shared helpers of the rectify/ tests: random configurations (fixed seeds) and independent reference
// computations that do not use the code under test.
#pragma once

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/rectify/rectify.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <ostream>
#include <random>
#include <vector>

#include <glm/gtc/quaternion.hpp>

namespace crep {
// doctest prints enums through operator<<.
inline std::ostream& operator<<(std::ostream& os, FallbackReason r) {
  return os << reasonToken(r);
}
inline std::ostream& operator<<(std::ostream& os, RectifyStatus s) {
  return os << statusToken(s);
}
} // namespace crep

namespace crep::test {

inline double uniform(std::mt19937_64& rng, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}
inline double logUniform(std::mt19937_64& rng, double a, double b) {
  return std::exp(uniform(rng, std::log(a), std::log(b)));
}
inline glm::dvec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  for (;;) {
    const glm::dvec3 v(n(rng), n(rng), n(rng));
    const double l = glm::length(v);
    if (l > 1e-6) return v / l;
  }
}

/// The ranges an engine's camera may take: fov 20-120 degrees, aspect 0.5-3, near in [1e-3, 1], far in [1,
/// 1e5].
inline Camera randomCamera(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  const glm::dvec3 pos(uniform(rng, -10, 10), uniform(rng, -10, 10), uniform(rng, -10, 10));
  const glm::dquat q(n(rng), n(rng), n(rng), n(rng));
  const double fov = glm::radians(uniform(rng, 20.0, 120.0));
  const double aspect = logUniform(rng, 0.5, 3.0);
  const double near = logUniform(rng, 1e-3, 1.0);
  double far = logUniform(rng, 1.0, 1e5);
  if (far < near * 1.01) far = near * 1.01;
  return Camera(pos, q, fov, aspect, near, far);
}

/// A spot light somewhere around the camera, usually aimed at a point of its frustum so the lit region
/// is not empty; cone 10-80 degrees, range reaching past that point.
inline SpotLight randomSpot(std::mt19937_64& rng, const Camera& cam) {
  const double reach = std::min(cam.far(), 50.0);
  const double ndcX = uniform(rng, -1, 1), ndcY = uniform(rng, -1, 1);
  const glm::dvec3 target =
      cam.position() + cam.rayDirection(ndcX, ndcY) * logUniform(rng, cam.near(), reach);
  const double dist = logUniform(rng, 0.1, 40.0);
  const glm::dvec3 pos = target + randomUnit(rng) * dist;
  glm::dvec3 dir = glm::normalize(target - pos);
  if (uniform(rng, 0, 1) < 0.2) dir = randomUnit(rng); // sometimes anywhere (often an empty region)
  const double cone = glm::radians(uniform(rng, 10.0, 80.0));
  const double range = dist * logUniform(rng, 1.2, 20.0);
  return SpotLight({.position = pos,
                    .direction = dir,
                    .innerConeAngle = 0.8 * cone,
                    .outerConeAngle = cone,
                    .range = range});
}

/// Independent: is the direction inside the camera's closed view cone (pyramid test in view space)?
/// Returns the signed margin in tangent units (>= 0 inside).
inline double viewConeMargin(const Camera& cam, const glm::dvec3& dirWorld) {
  const glm::dvec3 v = glm::dvec3(cam.viewFromWorld() * glm::dvec4(dirWorld, 0.0));
  if (!(v.z < 0.0)) return -1.0;
  const double ty = std::tan(0.5 * cam.fovY()), tx = ty * cam.aspect();
  const double ex = std::abs(v.x / -v.z) / tx, ey = std::abs(v.y / -v.z) / ty;
  return 1.0 - std::max(ex, ey);
}

inline double angleBetween(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

/// Independent brute force: the smallest angle between the line of dir (both directions) and the view
/// rays on the screen border (densely sampled per side, refined around the best sample by golden
/// section), or 0 when the epipole itself is on screen (the view ray through it).
/// The camera's view ray through NDC (x, y), with the basis computed once (Camera::rayDirection
/// recomputes it per call).
struct ViewRays {
  glm::dvec3 f, r, u;
  double tx, ty;
  explicit ViewRays(const Camera& cam)
      : f(cam.forward()), r(cam.right()), u(cam.up()), ty(std::tan(0.5 * cam.fovY())) {
    tx = ty * cam.aspect();
  }
  glm::dvec3 operator()(double x, double y) const { return glm::normalize(f + x * tx * r + y * ty * u); }
};

inline double minAngleToViewRays(const Camera& cam, const glm::dvec3& dir, int n = 64) {
  const ViewRays rays(cam);
  const auto angle = [&](double x, double y) {
    const glm::dvec3 r = rays(x, y);
    return std::min(angleBetween(r, dir), angleBetween(r, -dir));
  };
  double best = std::numbers::pi;
  for (int side = 0; side < 4; ++side) {
    const auto at = [&](double t) {
      return side == 0 ? angle(t, -1) : side == 1 ? angle(t, 1) : side == 2 ? angle(-1, t) : angle(1, t);
    };
    int bi = 0;
    double bv = at(-1.0);
    for (int i = 1; i <= n; ++i)
      if (const double v = at(-1.0 + 2.0 * i / n); v < bv) bv = v, bi = i;
    double lo = -1.0 + 2.0 * std::max(0, bi - 1) / n, hi = -1.0 + 2.0 * std::min(n, bi + 1) / n;
    for (int it = 0; it < 60; ++it) { // ternary search; the sample bracket holds one minimum
      const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
      if (at(m1) < at(m2))
        hi = m2;
      else
        lo = m1;
    }
    best = std::min({best, bv, at(0.5 * (lo + hi))});
  }
  for (double s : {1.0, -1.0}) {
    const glm::dvec3 v = glm::dvec3(cam.viewFromWorld() * glm::dvec4(s * dir, 0.0));
    if (v.z < 0.0) {
      const double ty = std::tan(0.5 * cam.fovY()), tx = ty * cam.aspect();
      const double ex = v.x / -v.z / tx, ey = v.y / -v.z / ty;
      if (std::abs(ex) <= 1.0 && std::abs(ey) <= 1.0) best = std::min(best, angle(ex, ey));
    }
  }
  return best;
}

/// Independent brute force of the angular span: the largest angle between two view rays sampled on
/// the screen border (corners included), both projected onto the plane orthogonal to dir. Exact when
/// the projected frustum fits in a half-plane (the extremes are corners).
inline double bruteForceSpanDegrees(const Camera& cam, const glm::dvec3& dir, int n = 8) {
  const ViewRays rays(cam);
  std::vector<glm::dvec3> p;
  for (int i = 0; i <= n; ++i) {
    const double t = -1.0 + 2.0 * i / n;
    for (const glm::dvec2 s : {glm::dvec2(t, -1), glm::dvec2(t, 1), glm::dvec2(-1, t), glm::dvec2(1, t)}) {
      const glm::dvec3 r = rays(s.x, s.y);
      const glm::dvec3 q = r - glm::dot(r, dir) * dir;
      if (glm::length(q) > 0.0) p.push_back(glm::normalize(q));
    }
  }
  double best = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j)
      best = std::max(best, angleBetween(p[i], p[j]));
  return glm::degrees(best);
}

/// Independent: NDC of a world point under a GL clip matrix (w returned in .w).
inline glm::dvec4 toNdc(const glm::dmat4& clipFromWorld, const glm::dvec3& p) {
  const glm::dvec4 c = clipFromWorld * glm::dvec4(p, 1.0);
  return glm::dvec4(glm::dvec3(c) / c.w, c.w);
}

/// Independent: is p inside the GL frustum of clipFromWorld (with a relative tolerance)?
inline bool insideClip(const glm::dmat4& clipFromWorld, const glm::dvec3& p, double tol = 1e-9) {
  const glm::dvec4 c = clipFromWorld * glm::dvec4(p, 1.0);
  if (!(c.w > 0.0)) return false;
  return std::abs(c.x) <= c.w * (1 + tol) && std::abs(c.y) <= c.w * (1 + tol) &&
         std::abs(c.z) <= c.w * (1 + tol);
}

/// Independent: does the line through a and b meet the intersection of two GL frusta? Returns the
/// signed length of the parameter interval (t in units of |b - a|; > 0 meets, < 0 misses).
inline double lineMeetsFrusta(const glm::dvec3& a, const glm::dvec3& b, const glm::dmat4& m1,
                              const glm::dmat4& m2) {
  double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
  for (const glm::dmat4* m : {&m1, &m2}) {
    const glm::dvec4 c0 = *m * glm::dvec4(a, 1.0), c1 = *m * glm::dvec4(b - a, 0.0);
    for (int i = 0; i < 3; ++i)
      for (double s : {1.0, -1.0}) {
        // w - s * coord >= 0, affine in t: f0 + t f1
        const double f0 = c0.w - s * c0[i], f1 = c1.w - s * c1[i];
        if (f1 == 0.0) {
          if (f0 < 0.0) return -std::numeric_limits<double>::infinity();
        } else if (f1 > 0.0) {
          lo = std::max(lo, -f0 / f1);
        } else {
          hi = std::min(hi, -f0 / f1);
        }
      }
  }
  return hi - lo;
}

} // namespace crep::test
