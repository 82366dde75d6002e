// Property tests of the projective rectification: over 10,000 random cameras and lights (fixed seeds, double
// precision), view rays keep one row and depth, light rays one (column, row), the lit region maps into the
// unit cube of exactly one split with tight bounds and no gaps, nothing is NaN or Inf, and the
// usable/unusable decision matches independent brute-force checks.
#include <crep/core/error.h>
#include <crep/rectify/rectify.h>

#include "rectify/rectify_checks.h"

#include <doctest/doctest.h>

#include <chrono>
#include <cstdio>
#include <functional>

using namespace crep;
using namespace crep::test;

namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace

TEST_CASE("rectify: directional properties over 10,000 random cameras and lights") {
  const auto t0 = std::chrono::steady_clock::now();
  std::mt19937_64 rng(0x3c7e1f1ed);
  Worst both[2]; // [0] default thresholds, [1] up to the degenerate cone
  for (int i = 0; i < 10000; ++i) {
    Worst& w = both[i % 2];
    const Camera cam = randomCamera(rng);
    const DirectionalLight light(randomUnit(rng));
    // Half the sweep with the default thresholds, half up to the degenerate cone (span 179.9 degrees,
    // no epipole-angle criterion).
    const RectifyOptions o = i % 2 ? randomOptions(rng, 179.9, 0.0) : randomOptions(rng, 150.0, 5.0);
    const Rectification r = rectify(cam, light, o);
    CHECK(std::isfinite(r.measure));
    if (!r.projective()) {
      ++w.fallback;
      CHECK(r.splits.empty());
      CHECK(r.reason != FallbackReason::None);
      continue;
    }
    ++w.projective;
    CHECK(r.splitCount() == o.splits);
    CHECK(r.measure < o.maxSpanDegrees);
    const glm::dvec3 l = light.direction(), c = cam.position();
    // Light-ray points up to 4x the point's own distance away (farther, p's own rounding dominates).
    checkProjective(
        r, cam, rng, [&](const glm::dvec3& p, double t) { return p + t * glm::length(p - c) * l; },
        [](const glm::dvec3&) { return true; }, w);
  }
  report("directional, default thresholds", both[0], secondsSince(t0));
  report("directional, span up to 179.9 deg", both[1], secondsSince(t0), true, 1e-8);
  CHECK(both[0].projective + both[1].projective > 5000);
}

TEST_CASE("rectify: spot light properties over 10,000 random configurations") {
  const auto t0 = std::chrono::steady_clock::now();
  std::mt19937_64 rng(0x5b07);
  Worst both[2]; // [0] default thresholds, [1] up to the degenerate cone
  for (int i = 0; i < 10000; ++i) {
    Worst& w = both[i % 2];
    const Camera cam = randomCamera(rng);
    const SpotLight spot = randomSpot(rng, cam);
    const RectifyOptions o = i % 2 ? randomOptions(rng, 179.9, 0.1) : randomOptions(rng, 150.0, 5.0);
    const Rectification r = rectify(cam, spot, o);
    CHECK(std::isfinite(r.measure));
    // Region vertices lie in both frusta (independent GL clip tests).
    for (const auto& v : r.regionVertices) {
      CHECK(insideClip(cam.clipFromWorld(), v, 1e-6));
      CHECK(insideClip(spot.lightClipFromWorld(), v, 1e-6));
    }
    if (r.status == RectifyStatus::Empty) {
      ++w.empty;
      continue;
    }
    if (!r.projective()) {
      ++w.fallback;
      continue;
    }
    ++w.projective;
    const glm::dvec3 L = spot.position();
    const glm::dmat4 lightClip = spot.lightClipFromWorld(), camClip = cam.clipFromWorld();
    checkProjective(
        r, cam, rng, [&](const glm::dvec3& p, double t) { return L + (1.0 + 0.9 * t) * (p - L); },
        [&](const glm::dvec3& p) { return insideClip(lightClip, p, -1e-9) && insideClip(camClip, p, -1e-9); },
        w);
  }
  report("spot, default thresholds", both[0], secondsSince(t0));
  report("spot, span up to 179.9 deg, epipole angle down to 0.1 deg", both[1], secondsSince(t0), true, 1e-8);
  CHECK(both[0].projective + both[1].projective > 3000);
}

TEST_CASE("rectify: point light faces cover the frustum and keep the properties") {
  std::mt19937_64 rng(0xfacade);
  Worst both[2]; // [0] default thresholds, [1] up to the degenerate cone
  int covered = 0, samples = 0;
  for (int i = 0; i < 1000; ++i) {
    Worst& w = both[i % 2];
    const Camera cam = randomCamera(rng);
    const double reach = std::min(cam.far(), 50.0);
    const glm::dvec3 L = cam.position() + cam.rayDirection(uniform(rng, -1.5, 1.5), uniform(rng, -1.5, 1.5)) *
                                              logUniform(rng, 0.01, reach);
    const double range = logUniform(rng, 1.0, 200.0);
    const RectifyOptions o = i % 2 ? randomOptions(rng, 179.9, 0.1) : randomOptions(rng, 150.0, 5.0);
    const auto faces = rectifyPointLight(cam, L, range, o);
    for (const auto& r : faces) {
      if (r.status == RectifyStatus::Empty) {
        ++w.empty;
        continue;
      }
      if (!r.projective()) {
        ++w.fallback;
        continue;
      }
      ++w.projective;
      checkProjective(
          r, cam, rng, [&](const glm::dvec3& p, double t) { return L + (1.0 + 0.9 * t) * (p - L); },
          [](const glm::dvec3&) { return false; }, w);
    }
    // Every lit frustum point (within range of the light, per face axis) is in some non-empty face.
    for (int s = 0; s < 8; ++s) {
      const glm::dvec3 p =
          cam.position() + cam.rayDirection(uniform(rng, -1, 1), uniform(rng, -1, 1)) *
                               logUniform(rng, cam.near() * 2, std::min(cam.far(), 2 * range));
      const glm::dvec3 d = p - L;
      const double axisDist = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
      if (axisDist <= range * 1e-3 * 1.01 || axisDist >= range * 0.99) continue;
      // Only points clearly inside the camera frustum.
      const glm::dvec4 n = toNdc(cam.clipFromWorld(), p);
      if (std::max({std::abs(n.x), std::abs(n.y), std::abs(n.z)}) > 0.999) continue;
      ++samples;
      int dominant = 0;
      for (int a = 1; a < 3; ++a)
        if (std::abs(d[a]) > std::abs(d[dominant])) dominant = a;
      const auto& face = faces[static_cast<std::size_t>(2 * dominant + (d[dominant] < 0 ? 1 : 0))];
      if (face.status != RectifyStatus::Empty) ++covered;
      if (face.projective()) {
        const RectPoint q = face.toRectified(p);
        CHECK(q.row >= -1e-9);
        CHECK(q.row <= 1 + 1e-9);
        CHECK(q.column >= -1e-9);
        CHECK(q.column <= 1 + 1e-9);
        CHECK(q.depth >= -1e-9);
        CHECK(q.depth <= 1 + 1e-9);
      }
    }
  }
  report("point faces, default thresholds", both[0], 0.0);
  report("point faces, span up to 179.9 deg, epipole angle down to 0.1 deg", both[1], 0.0, true, 1e-8);
  CHECK(covered == samples);
  CHECK(samples > 1000);
}

TEST_CASE("rectify: the decision matches independent brute-force checks (directional)") {
  std::mt19937_64 rng(0xdec1de);
  int parallelCount = 0, nonLinear = 0, tooClose = 0, projective = 0, ambiguous = 0, mismatches = 0;
  for (int i = 0; i < 10000; ++i) {
    const Camera cam = randomCamera(rng);
    const glm::dvec3 l = randomUnit(rng);
    const DirectionalLight light(l);
    // Is any view ray within epsilon of +-l? (screen border + epipole, sampled densely; independent)
    const double minAngle = minAngleToViewRays(cam, l);
    const double margin = std::max(viewConeMargin(cam, l), viewConeMargin(cam, -l));
    const bool inside = margin >= 0.0;
    const double eps = 1e-9;
    if (std::abs(margin) < 1e-7) {
      ++ambiguous; // within rounding of the cone boundary: either answer is right
      continue;
    }
    CHECK((minAngle <= eps) == inside); // the two independent checks agree

    RectifyOptions only;
    only.maxSpanDegrees = 180.0; // fall back only when impossible
    only.minEpipoleAngleDegrees = 0.0;
    const Rectification r180 = rectify(cam, light, only);
    if (r180.projective() == inside) ++mismatches;
    if (inside) CHECK(r180.reason == FallbackReason::ViewRayParallelToLight);

    // Default thresholds: span and epipole-angle criteria against the brute-force span of sampled
    // border rays and the brute-force angle above.
    const Rectification r = rectify(cam, light);
    const RectifyOptions defaults;
    const double span = inside ? 180.0 : bruteForceSpanDegrees(cam, l);
    const double angleDeg = glm::degrees(minAngle);
    if (!inside) {
      CHECK(r.span == doctest::Approx(span).epsilon(1e-9));
      CHECK(r.epipoleAngle == doctest::Approx(angleDeg).epsilon(1e-7));
    }
    if (std::abs(span - defaults.maxSpanDegrees) < 1e-6 ||
        std::abs(angleDeg - defaults.minEpipoleAngleDegrees) < 1e-6) {
      ++ambiguous;
      continue;
    }
    const FallbackReason expected = inside                            ? FallbackReason::ViewRayParallelToLight
                                    : span >= defaults.maxSpanDegrees ? FallbackReason::NonLinearity
                                    : angleDeg < defaults.minEpipoleAngleDegrees
                                        ? FallbackReason::EpipoleTooClose
                                        : FallbackReason::None;
    if (r.reason != expected || r.projective() != (expected == FallbackReason::None)) ++mismatches;
    (r.projective()                             ? projective
     : inside                                   ? parallelCount
     : r.reason == FallbackReason::NonLinearity ? nonLinear
                                                : tooClose)++;
  }
  MESSAGE("decision (directional): " << projective << " projective, " << parallelCount << " parallel, "
                                     << nonLinear << " non-linear, " << tooClose << " epipole too close, "
                                     << ambiguous << " within rounding of a threshold");
  CHECK(mismatches == 0);
  CHECK(ambiguous < 5);
  CHECK(parallelCount > 500);
  CHECK(nonLinear > 100);
}

TEST_CASE("rectify: the decision matches independent brute-force checks (spot)") {
  std::mt19937_64 rng(0x5b0751);
  int impossible = 0, projective = 0, empty = 0, ambiguous = 0, mismatches = 0;
  for (int i = 0; i < 10000; ++i) {
    const Camera cam = randomCamera(rng);
    const SpotLight spot = randomSpot(rng, cam);
    RectifyOptions only;
    only.maxSpanDegrees = 180.0; // fall back only when impossible
    only.minEpipoleAngleDegrees = 0.0;
    const Rectification r = rectify(cam, spot, only);
    if (r.status == RectifyStatus::Empty) {
      ++empty;
      continue;
    }
    // Impossible iff the camera-light line meets the lit region (a 1D LP against both GL frusta).
    const glm::dvec3 L = spot.position(), c = cam.position();
    const double len = lineMeetsFrusta(c, L, cam.clipFromWorld(), spot.lightClipFromWorld());
    if (std::abs(len) < 1e-9) {
      ++ambiguous;
      continue;
    }
    const bool meets = len > 0.0;
    if (r.projective() == meets) ++mismatches;
    (meets ? impossible : projective)++;
  }
  MESSAGE("decision (spot): " << projective << " projective, " << impossible << " impossible, " << empty
                              << " empty, " << ambiguous << " ambiguous");
  CHECK(mismatches == 0);
  CHECK(ambiguous < 5);
  CHECK(impossible > 100);
}
