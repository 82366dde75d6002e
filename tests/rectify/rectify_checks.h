// The properties of a projective rectification (crep/rectify/rectify.h), checked by the rectify/ test files
// (doctest assertions): rows and depths kept along view rays, (column, row) along light rays, the lit region
// inside exactly one split's unit cube, finite values.
#pragma once

#include <crep/core/error.h>
#include <crep/rectify/rectify.h>

#include "rectify/rectify_test_util.h"

#include <doctest/doctest.h>

#include <functional>
#include <limits>
#include <string>

namespace crep::test {

/// Worst deviations over a sweep (checked once at the end so the sweep stays fast).
struct Worst {
  double viewRowDepth = 0;   ///< row / depth spread along one view ray (normalized units)
  double lightColumnRow = 0; ///< column / row spread along one light ray
  double helperVsMatrix = 0; ///< toRectified vs the split matrix
  double outsideCube = 0;    ///< how far a region point lands outside the unit cube of its split
  double tightness = 0;      ///< distance of the extreme region vertices from the cube faces
  double gap = 0;            ///< mismatch at shared split boundaries
  double roundTrip = 0;      ///< |toWorld(toRectified(p)) - p| / |p - camera| / column conditioning
  double distance = 0;       ///< rayDistance vs |p - camera|, relative, / column conditioning
  int notOneSplit = 0;       ///< region points in no split, or in two that do not share a boundary
  int nonFinite = 0;         ///< NaN / Inf anywhere
  int leftToRight = 0;       ///< view rays whose column does not increase with distance
  int projective = 0, fallback = 0, empty = 0;
  int points = 0;

  void note(double& slot, double v) {
    if (!std::isfinite(v))
      ++nonFinite;
    else
      slot = std::max(slot, v);
  }
};

inline bool finite(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}
inline bool finite(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// Normalized (splitColumn, row, depth) of p under split k's matrix.
inline glm::dvec3 viaMatrix(const Rectification& r, int k, const glm::dvec3& p) {
  const glm::dvec4 n = toNdc(r.splits[static_cast<std::size_t>(k)].rectClipFromWorld, p);
  return 0.5 * (glm::dvec3(n) + 1.0);
}

/// A random point of the convex region (a random convex combination of up to 4 of its vertices).
inline glm::dvec3 regionPoint(const Rectification& r, std::mt19937_64& rng) {
  const auto& v = r.regionVertices;
  glm::dvec3 p(0.0);
  double sum = 0.0;
  for (int i = 0; i < 4; ++i) {
    const double w = -std::log(uniform(rng, 1e-12, 1.0));
    p += w * v[std::uniform_int_distribution<std::size_t>(0, v.size() - 1)(rng)];
    sum += w;
  }
  return p / sum;
}

/// Checks every property above on one projective rectification. `lightPoint(p, t)` returns the
/// point of p's light ray at parameter t (t = 0: p itself); `inRegion` is an independent test of
/// region membership used for rejection-sampled frustum points.
inline void checkProjective(const Rectification& r, const Camera& cam, std::mt19937_64& rng,
                            const std::function<glm::dvec3(const glm::dvec3&, double)>& lightPoint,
                            const std::function<bool(const glm::dvec3&)>& inRegion, Worst& w) {
  const glm::dvec3 c = cam.position();
  const int K = r.splitCount();
  bool ok = K >= 1 && finite(r.frame.axisX) && finite(r.frame.axisY) && finite(r.frame.axisZ) &&
            std::isfinite(r.frame.rowSlopeMin + r.frame.rowSlopeMax + r.frame.depthSlopeMin +
                          r.frame.depthSlopeMax + r.frame.axisMin + r.frame.axisMax);
  for (const auto& s : r.splits)
    ok = ok && finite(s.rectClipFromWorld) && std::isfinite(s.rangeBegin + s.rangeEnd);
  if (!ok) ++w.nonFinite;

  // No gaps: ranges are contiguous and cover [axisMin, axisMax]; the matrices agree on the boundary.
  if (!(r.splits.front().rangeBegin == r.frame.axisMin && r.splits.back().rangeEnd == r.frame.axisMax))
    w.gap = 1;
  for (int k = 0; k + 1 < K; ++k) {
    if (!(r.splits[static_cast<std::size_t>(k)].rangeEnd ==
          r.splits[static_cast<std::size_t>(k) + 1].rangeBegin) ||
        !(r.splits[static_cast<std::size_t>(k)].rangeEnd > r.splits[static_cast<std::size_t>(k)].rangeBegin))
      w.gap = 1;
    const double row = uniform(rng, 0, 1), depth = uniform(rng, 0, 1);
    const double column = static_cast<double>(k + 1) / K;
    glm::dvec3 p;
    try {
      p = r.toWorld(column, row, depth);
    } catch (const InvalidArgument&) {
      continue; // spot light: that (column, depth) pair lies beyond the view ray's horizon
    }
    const glm::dvec3 lo = viaMatrix(r, k, p), hi = viaMatrix(r, k + 1, p);
    w.note(w.gap,
           std::max({std::abs(lo.x - 1.0), std::abs(hi.x), std::abs(lo.y - hi.y), std::abs(lo.z - hi.z)}));
  }

  // Tight bounds: some region vertex touches each face of the map.
  double rowLo = 1e300, rowHi = -1e300, depLo = 1e300, depHi = -1e300, colLo = 1e300, colHi = -1e300;
  for (const auto& v : r.regionVertices) {
    const RectPoint q = r.toRectified(v);
    rowLo = std::min(rowLo, q.row);
    rowHi = std::max(rowHi, q.row);
    depLo = std::min(depLo, q.depth);
    depHi = std::max(depHi, q.depth);
    colLo = std::min(colLo, q.column);
    colHi = std::max(colHi, q.column);
  }
  w.note(w.tightness, std::max({std::abs(rowLo), std::abs(rowHi - 1), std::abs(depLo), std::abs(depHi - 1),
                                std::abs(colLo), std::abs(colHi - 1)}));

  const auto checkPoint = [&](const glm::dvec3& p) {
    ++w.points;
    const RectPoint q = r.toRectified(p);
    if (!std::isfinite(q.column + q.row + q.depth + q.splitColumn)) ++w.nonFinite;
    // Inside the unit cube of its split, and of no other split except across a shared boundary.
    int inside = 0, first = -1, last = -1;
    for (int k = 0; k < K; ++k) {
      const glm::dvec3 m = viaMatrix(r, k, p);
      const double out = std::max({-m.x, m.x - 1, -m.y, m.y - 1, -m.z, m.z - 1, 0.0});
      if (k == q.split) {
        w.note(w.outsideCube, out);
        w.note(w.helperVsMatrix,
               std::max({std::abs(m.x - q.splitColumn), std::abs(m.y - q.row), std::abs(m.z - q.depth)}));
      }
      if (out <= 1e-9) {
        ++inside;
        if (first < 0) first = k;
        last = k;
      }
    }
    if (inside < 1 || inside > 2 || (inside == 2 && last != first + 1) || q.split < first || q.split > last)
      ++w.notOneSplit;
    // Round trip and closed-form distance, relative to the conditioning of the column: a column u
    // in [0, 1] pins zeta only to ~eps (|zeta_begin| + |zeta_end|), i.e. X to that times X (like a
    // depth buffer, a split spanning 1e-3..1e5 cannot resolve X near its far end better than 1e-8).
    const glm::dvec3 back = r.toWorld(q.column, q.row, q.depth);
    const double dist = glm::length(p - c);
    const Split& s = r.splits[static_cast<std::size_t>(q.split)];
    const double X = glm::dot(r.frame.axisX, p - c);
    const double kappa = 1.0 + (std::abs(s.zetaBegin) + std::abs(s.zetaEnd)) * X;
    w.note(w.roundTrip, glm::length(back - p) / dist / kappa);
    w.note(w.distance, std::abs(r.rayDistance(q.row, q.depth, q.column) - dist) / dist / kappa);
    return q;
  };

  // Region points: vertices, random convex combinations, rejection-sampled frustum points.
  std::vector<glm::dvec3> pts(r.regionVertices.begin(), r.regionVertices.end());
  for (int i = 0; i < 24; ++i)
    pts.push_back(regionPoint(r, rng));
  for (int i = 0, found = 0; i < 64 && found < 8; ++i) {
    const double t = logUniform(rng, cam.near(), cam.far());
    const glm::dvec3 p =
        c +
        t * (cam.forward() + uniform(rng, -1, 1) * std::tan(0.5 * cam.fovY()) * cam.aspect() * cam.right() +
             uniform(rng, -1, 1) * std::tan(0.5 * cam.fovY()) * cam.up());
    if (inRegion(p)) {
      pts.push_back(p);
      ++found;
    }
  }
  for (const auto& p : pts) {
    const RectPoint q = checkPoint(p);
    // The view ray through p: same row and depth; the column grows with the distance.
    double lastColumn = -std::numeric_limits<double>::infinity();
    for (double lambda : {0.25, 0.5, 1.0, 2.0, 8.0}) {
      const RectPoint v = r.toRectified(c + lambda * (p - c));
      w.note(w.viewRowDepth, std::max(std::abs(v.row - q.row), std::abs(v.depth - q.depth)));
      const int k = v.split;
      const glm::dvec3 m = viaMatrix(r, k, c + lambda * (p - c));
      w.note(w.viewRowDepth, std::max(std::abs(m.y - q.row), std::abs(m.z - q.depth)));
      if (!(v.column > lastColumn)) ++w.leftToRight;
      lastColumn = v.column;
    }
    // The light ray through p: same (column, row), via the helper and via the split matrix.
    for (double t : {-0.9, -0.5, 0.5, 1.0, 4.0}) {
      const glm::dvec3 lp = lightPoint(p, t);
      const RectPoint v = r.toRectified(lp);
      w.note(w.lightColumnRow, std::max(std::abs(v.column - q.column), std::abs(v.row - q.row)));
      const glm::dvec3 m = viaMatrix(r, q.split, lp);
      w.note(w.lightColumnRow, std::max(std::abs(m.x - q.splitColumn), std::abs(m.y - q.row)));
    }
  }
}

/// Asserts the worst deviations. `tol` is 1e-9 (the rectification's accuracy goal) for configurations that
/// pass the default thresholds; near the degenerate cone the rounding of the input points themselves is
/// amplified by the conditioning (1 / cos(span / 2) up to 1146 at 179.9 degrees, 1 / sin(epipole angle)), and
/// the sweeps that go there state 1e-8.
inline void report(const char* name, const Worst& w, double seconds, bool verbose = true, double tol = 1e-9) {
  if (verbose)
    MESSAGE(std::string(name) << ": " << w.projective << " projective, " << w.fallback << " fallback, "
                              << w.empty << " empty; " << w.points << " region points; worst: view row/depth "
                              << w.viewRowDepth << ", light column/row " << w.lightColumnRow
                              << ", helper vs matrix " << w.helperVsMatrix << ", outside cube "
                              << w.outsideCube << ", tightness " << w.tightness << ", gap " << w.gap
                              << ", round trip " << w.roundTrip << ", distance " << w.distance << "; "
                              << seconds << " s");
  CHECK(w.nonFinite == 0);
  CHECK(w.notOneSplit == 0);
  CHECK(w.leftToRight == 0);
  CHECK(w.viewRowDepth < tol);
  CHECK(w.lightColumnRow < tol);
  CHECK(w.helperVsMatrix < tol);
  CHECK(w.outsideCube < tol);
  CHECK(w.tightness < tol);
  CHECK(w.gap < tol);
  CHECK(w.roundTrip < 1e-12);
  CHECK(w.distance < 1e-12);
}

/// Random split count, scheme, blend and layout; the given thresholds.
inline RectifyOptions randomOptions(std::mt19937_64& rng, double maxSpan, double minEpipole) {
  RectifyOptions o;
  o.splits = std::uniform_int_distribution<int>(1, 8)(rng);
  o.scheme = static_cast<SplitScheme>(std::uniform_int_distribution<int>(0, 2)(rng));
  o.blend = uniform(rng, 0, 1);
  o.layout = uniform(rng, 0, 1) < 0.5 ? SplitLayout::Regions : SplitLayout::Layers;
  o.maxSpanDegrees = maxSpan;
  o.minEpipoleAngleDegrees = minEpipole;
  return o;
}

} // namespace crep::test
