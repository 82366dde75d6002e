// How often a frame falls back, by reason: 10^4 uniformly random sun directions for a 60 degree 16:9 camera
// (near 0.1, far 100). The impossible case (a view ray parallel to the light: the light's line through the
// camera meets the frustum) has a closed form: the two directions of that line fall in the frustum's solid
// angle Omega = 4 asin(sin a sin b) (a, b the half angles), so its probability is 2 Omega / (4 pi); the test
// checks the sampled fraction against it within 4 binomial standard deviations. The other fractions are
// printed for the README ("Fallback").
#include <crep/rectify/rectify.h>

#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <random>
#include <string>

using namespace crep;

TEST_CASE("rectify: fallback fractions over 10^4 random sun directions (60 degree 16:9 camera)") {
  const double fovY = glm::radians(60.0), aspect = 16.0 / 9.0;
  const Camera camera = Camera::lookAt({0, 2, 0}, {0, 2, -1}, {0, 1, 0}, fovY, aspect, 0.1, 100.0);
  std::mt19937_64 rng(20261201);
  std::normal_distribution<double> normal;
  const int N = 10000;
  std::map<std::string, int> byReason;
  for (int i = 0; i < N; ++i) {
    glm::dvec3 d(normal(rng), normal(rng), normal(rng));
    if (glm::length(d) < 1e-9) d = {0, -1, 0};
    const Rectification r = rectify(camera, DirectionalLight(d));
    ++byReason[reasonToken(r.reason)];
  }
  std::string table;
  for (const auto& [reason, count] : byReason) {
    char line[96];
    std::snprintf(line, sizeof line, "  %-28s %6d  %6.2f%%\n", reason.c_str(), count, 100.0 * count / N);
    table += line;
  }
  MESSAGE("rectify() over " << N << " random directions:\n" << table);
  int total = 0;
  for (const auto& [reason, count] : byReason)
    total += count;
  CHECK(total == N);

  const double a = 0.5 * fovY, b = std::atan(std::tan(a) * aspect);
  const double omega = 4.0 * std::asin(std::sin(a) * std::sin(b));
  const double expected = 2.0 * omega / (4.0 * std::numbers::pi);
  const double sampled = byReason["view-ray-parallel-to-light"] / static_cast<double>(N);
  const double sigma = std::sqrt(expected * (1.0 - expected) / N);
  MESSAGE("impossible: sampled " << sampled << ", closed form " << expected << " (sd " << sigma << ")");
  CHECK(std::abs(sampled - expected) < 4.0 * sigma);
}
