// No jump across the horizon (Yusov 2013, "Performing Look-ups into the Table", Fig. 5): the aerial
// perspective of a segment of fixed length does not care whether its ray would later hit the ground, so
// Eq. 8's two look-ups (at the camera and at the segment's end, on one side of the horizon: Listing 2) must
// change smoothly while the view direction sweeps through the horizon. The sky itself does jump there (below
// the horizon the table's rays end on a black ground), which AtmospherePhysicsTest reports.
#include "atmosphere/atmosphere_test_util.h"

#include <crep/atmosphere/atmosphere.h>
#include <crep/core/light.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

namespace {

using namespace crep;

double luminance(const glm::dvec3& c) {
  return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
}

} // namespace

TEST_CASE("Atmosphere horizon: aerial perspective of a fixed segment has no jump through the horizon") {
  const AtmosphereTables& t = test::smallAtmosphereTables(2);
  const double deg = std::numbers::pi / 180.0;
  for (const double altitude : {50.0, 1000.0}) {
    for (const double sunElevation : {30.0, 5.0}) {
      for (const double length : {2000.0, 10000.0}) {
        AtmospherePlacement placement{1.0, altitude};
        // The sun towards -z at sunElevation; the view sweeps in the vertical plane towards the sun.
        const DirectionalLight sun(
            -glm::dvec3(0.0, std::sin(sunElevation * deg), -std::cos(sunElevation * deg)), glm::dvec3(1.0));
        // The horizon's dip at this altitude, then +-6 degrees around it in 1201 steps.
        const double R = t.parameters.earthRadius;
        const double dip = std::acos(R / (R + altitude)) / deg;
        // Only directions whose segment stays above the ground (a surface beyond the ground is no view).
        std::vector<double> values, elevations;
        const int n = 1201;
        const glm::dvec3 C(0.0, R + altitude, 0.0);
        for (int i = 0; i < n; ++i) {
          const double e = (-dip - 6.0 + 12.0 * i / (n - 1)) * deg;
          const glm::dvec3 v(0.0, std::sin(e), -std::cos(e));
          const double b = glm::dot(C, v), disc = b * b - (glm::dot(C, C) - R * R);
          if (disc >= 0.0 && -b - std::sqrt(disc) > 0.0 && -b - std::sqrt(disc) < 1.1 * length) continue;
          const AtmosphereRay r =
              atmosphereRay(t, placement, sun, glm::dvec3(0.0), v, length, false, {}, AtmosphereRayOptions{});
          values.push_back(luminance(r.inscattering));
          elevations.push_back(e);
        }
        REQUIRE(values.size() > 100);
        // Steps between neighbours; those whose two directions lie within the horizon band (the blend's
        // width around the horizon) are the horizon's.
        const double eps = horizonBlendWidth(t.parameters, t.options.size, altitude);
        const double ch = cosHorizon(t.parameters, altitude);
        std::vector<double> steps, band;
        for (std::size_t i = 1; i < values.size(); ++i) {
          const double step = std::abs(values[i] - values[i - 1]);
          steps.push_back(step);
          const double e = 0.5 * (elevations[i] + elevations[i - 1]);
          if (std::abs(std::sin(e) - ch) < eps) band.push_back(step);
        }
        std::vector<double> sorted = steps;
        std::sort(sorted.begin(), sorted.end());
        const double median = sorted[sorted.size() / 2], largest = sorted.back();
        const double bandLargest = band.empty() ? 0.0 : *std::max_element(band.begin(), band.end());
        const double range =
            *std::max_element(values.begin(), values.end()) - *std::min_element(values.begin(), values.end());
        MESSAGE("altitude " << altitude << " m, sun " << sunElevation << " deg, segment " << length
                            << " m: across the horizon band the largest step is "
                            << bandLargest / std::max(median, 1e-300) << " x the median step ("
                            << bandLargest / std::max(range, 1e-300) << " of the range); anywhere "
                            << largest / std::max(median, 1e-300) << " x ("
                            << largest / std::max(range, 1e-300) << " of the range)");
        for (double v : values)
          REQUIRE(std::isfinite(v));
        if (std::getenv("CREP_HORIZON_DUMP"))
          for (std::size_t i = 0; i < values.size(); i += 10)
            MESSAGE(i << " e=" << elevations[i] / deg << " " << values[i]);
        // Within the sweep's typical step across the horizon: Fig. 5's seam (before the blend: one step of
        // 99.8% of the range) would be a large multiple of the median step; so would the optical depth
        // table's steps (before the segment transmittance was integrated: up to 294 median steps near it).
        REQUIRE(!band.empty());
        CHECK(bandLargest <= 10.0 * median);
        // Away from the horizon the short segments' Eq. 8 keeps the tables' interpolation kinks: up to 19
        // median steps on this sweep, but no step beyond 5% of the range (the seam was 99.8%).
        CHECK(largest <= 0.05 * range);
      }
    }
  }
}
