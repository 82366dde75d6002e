// The measurement behind the default split scheme (rectify.h SplitScheme, rectify/README.md "Split
// schemes"): along the reference ray of every row, the world length each texel covers inside the camera
// frustum. Printed as a table; the assertions lock the conclusion (logarithmic is best) so a change of
// the construction that invalidates the documented numbers fails here.
#include <crep/rectify/rectify.h>

#include "rectify/rectify_test_util.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

struct Spread {
  double absolute = 0; ///< max / min world length per texel over the covered texels of a row (worst row)
  double relative = 0; ///< max / min of (length per texel / distance from the camera) (worst row)
  double worstRel = 0; ///< max of (length per texel / distance) x W: the coarsest relative resolution
  double covered = 0;  ///< mean fraction of a row's texels inside the frustum
};

/// W texels per row in total (W / K per split), `rowCount` rows.
Spread measure(const Camera& cam, const Rectification& r, int W, int rowCount) {
  Spread s;
  int rows = 0;
  for (int j = 0; j < rowCount; ++j) {
    const double row = (j + 0.5) / rowCount;
    const RowReference ref = r.rowReference(row);
    const double cosine = glm::dot(ref.direction, cam.forward());
    const double tNear = cam.near() / cosine, tFar = cam.far() / cosine;
    double lmin = 1e300, lmax = 0, rmin = 1e300, rmax = 0;
    int covered = 0;
    double t1 = r.rayDistance(row, ref.depth, 0.0); // == referenceDistance, without recomputing ref
    for (int i = 0; i < W; ++i) {
      const double t0 = t1;
      t1 = r.rayDistance(row, ref.depth, static_cast<double>(i + 1) / W);
      if (t0 < tNear || t1 > tFar) continue; // only texels entirely inside the frustum
      const double len = t1 - t0, rel = len / (0.5 * (t0 + t1));
      ++covered;
      lmin = std::min(lmin, len);
      lmax = std::max(lmax, len);
      rmin = std::min(rmin, rel);
      rmax = std::max(rmax, rel);
    }
    if (covered < 2) continue;
    ++rows;
    s.absolute = std::max(s.absolute, lmax / lmin);
    s.relative = std::max(s.relative, rmax / rmin);
    s.worstRel = std::max(s.worstRel, rmax * W);
    s.covered += static_cast<double>(covered) / W;
  }
  s.covered /= std::max(rows, 1);
  return s;
}

struct Scheme {
  const char* name;
  SplitScheme scheme;
  double blend;
};
const Scheme kSchemes[] = {{"uniform", SplitScheme::Uniform, 0.0},
                           {"blend 0.25", SplitScheme::Blend, 0.25},
                           {"blend 0.5", SplitScheme::Blend, 0.5},
                           {"blend 0.75", SplitScheme::Blend, 0.75},
                           {"logarithmic", SplitScheme::Logarithmic, 1.0}};

} // namespace

TEST_CASE("rectify: split scheme study (spread of world length per texel along the rows)") {
  // The calibration setup of rectify/README.md: 60 degree camera, near 0.1, far 80, 1024 columns, light from
  // the side.
  const Camera cam = Camera::lookAt({0, 2, 0}, {0, 2, -1}, {0, 1, 0}, glm::radians(60.0), 1.0, 0.1, 80.0);
  const DirectionalLight light(glm::dvec3(1, -0.3, 0.2));
  const int W = 1024;
  std::string table = "\n  K  scheme        abs. spread  rel. spread  worst len/dist x W  covered\n";
  for (const int K : {1, 2, 4, 8}) {
    Spread results[5];
    for (int s = 0; s < 5; ++s) {
      RectifyOptions o;
      o.splits = K;
      o.scheme = kSchemes[s].scheme;
      o.blend = kSchemes[s].blend;
      const Rectification r = rectify(cam, light, o);
      REQUIRE(r.projective());
      results[s] = measure(cam, r, W, 64);
      char line[160];
      std::snprintf(line, sizeof line, "  %d  %-12s %12.4g %12.4g %19.4g %8.2f\n", K, kSchemes[s].name,
                    results[s].absolute, results[s].relative, results[s].worstRel, results[s].covered);
      table += line;
      if (K == 1) break; // one split: every scheme is the same map
    }
    if (K == 1) continue;
    // Logarithmic: the smallest relative spread and worst relative texel length for every K, and an
    // absolute spread no larger than uniform's and the 50/50 blend's.
    for (int s = 0; s < 4; ++s) {
      CHECK(results[4].relative < results[s].relative);
      CHECK(results[4].worstRel < results[s].worstRel);
    }
    CHECK(results[4].absolute < results[0].absolute);
    CHECK(results[4].absolute < results[2].absolute);
  }
  MESSAGE("split scheme study, side light:" << table);

  // The same over 200 random light directions that are projective with the defaults: median of each
  // metric for K = 4.
  std::mt19937_64 rng(0x5717);
  std::vector<double> rel[5], worst[5], abs[5];
  int configs = 0;
  while (configs < 200) {
    const DirectionalLight l(randomUnit(rng));
    if (!rectify(cam, l).projective()) continue;
    ++configs;
    for (int s = 0; s < 5; ++s) {
      RectifyOptions o;
      o.scheme = kSchemes[s].scheme;
      o.blend = kSchemes[s].blend;
      const Spread m = measure(cam, rectify(cam, l, o), 256, 16);
      rel[s].push_back(m.relative);
      worst[s].push_back(m.worstRel);
      abs[s].push_back(m.absolute);
    }
  }
  const auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  std::string table2 = "\n  scheme        abs. spread  rel. spread  worst len/dist x W\n";
  for (int s = 0; s < 5; ++s) {
    char line[160];
    std::snprintf(line, sizeof line, "  %-12s %12.4g %12.4g %19.4g\n", kSchemes[s].name, median(abs[s]),
                  median(rel[s]), median(worst[s]));
    table2 += line;
  }
  MESSAGE("split scheme study, K = 4, 256 columns, median over 200 random projective light directions:"
          << table2);
  for (int s = 0; s < 4; ++s) {
    CHECK(median(rel[4]) < median(rel[s]));
    CHECK(median(worst[4]) < median(worst[s]));
  }
}
