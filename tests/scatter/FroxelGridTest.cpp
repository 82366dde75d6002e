// crep::FroxelGrid (crep/scatter/froxel_grid.h): the froxel volume's coordinates round-trip, the slice
// rule is exponential (each slice the same ratio deeper), cell centres project to the pixel rays of their
// cell, the Halton jitter stays in its cell and averages to its centre, bad sizes are named.
#include <crep/core/error.h>
#include <crep/scatter/froxel_grid.h>

#include <doctest/doctest.h>

#include <cmath>
#include <string>

using namespace crep;

namespace {

Camera testCamera() {
  return Camera::fromMatrices(
      glm::lookAt(glm::dvec3(1.0, 2.0, 3.0), glm::dvec3(-4.0, 1.5, -20.0), glm::dvec3(0.0, 1.0, 0.0)),
      // an off-centre frustum (jittered projection) so the tangents are asymmetric
      glm::frustum(-0.12, 0.1, -0.06, 0.07, 0.2, 150.0));
}

} // namespace

TEST_CASE("FroxelGrid: world point and volume coordinate are inverse, slices are exponential") {
  const Camera cam = testCamera();
  const FroxelGrid grid;
  const FroxelDepthRange r = froxelDepthRange(grid, cam, "grid");
  CHECK(r.near == doctest::Approx(cam.near()));
  CHECK(r.far == doctest::Approx(cam.far()));
  for (double u : {0.0, 0.3, 0.97})
    for (double v : {0.05, 0.5, 1.0})
      for (double w : {-0.2, 0.0, 0.41, 1.0}) {
        const glm::dvec3 uvw(u, v, w);
        const glm::dvec3 back = froxelCoord(cam, r, froxelWorldPoint(cam, r, uvw));
        CHECK(back.x == doctest::Approx(u).epsilon(1e-12));
        CHECK(back.y == doctest::Approx(v).epsilon(1e-12));
        CHECK(back.z == doctest::Approx(w).epsilon(1e-10));
        // the point lies at view depth Z(w) along the camera's ray through (u, v)
        const glm::dvec3 p = froxelWorldPoint(cam, r, uvw);
        CHECK(glm::dot(p - cam.position(), cam.forward()) == doctest::Approx(froxelViewDepth(r, w)));
        const glm::dvec3 ray = cam.rayDirection(2.0 * u - 1.0, 2.0 * v - 1.0);
        CHECK(glm::length(glm::cross(glm::normalize(p - cam.position()), ray)) < 1e-12);
        CHECK(glm::length(p - cam.position()) ==
              doctest::Approx(froxelRayDistance(cam, uvw, froxelViewDepth(r, w))));
      }
  // exponential: equal steps in w are equal ratios in Z, the ends are near and far
  CHECK(froxelViewDepth(r, 0.0) == doctest::Approx(r.near));
  CHECK(froxelViewDepth(r, 1.0) == doctest::Approx(r.far));
  const double ratio = froxelViewDepth(r, 1.0 / grid.depth) / froxelViewDepth(r, 0.0);
  for (int k = 1; k < grid.depth; ++k)
    CHECK(froxelViewDepth(r, (k + 1.0) / grid.depth) / froxelViewDepth(r, double(k) / grid.depth) ==
          doctest::Approx(ratio));
  CHECK(std::pow(ratio, grid.depth) == doctest::Approx(r.far / r.near));
  CHECK(froxelSliceCoord(r, 0.0) == -INFINITY);
  CHECK(std::isinf(froxelCoord(cam, r, cam.position() - cam.forward()).z));
}

TEST_CASE("FroxelGrid: explicit depth range and the Halton jitter") {
  const Camera cam = testCamera();
  FroxelGrid grid;
  grid.nearDepth = 1.0;
  grid.farDepth = 64.0;
  const FroxelDepthRange r = froxelDepthRange(grid, cam, "grid");
  CHECK(froxelViewDepth(r, 0.5) == doctest::Approx(8.0));
  glm::dvec3 sum(0.0);
  const int n = 120; // a multiple of 2^3, 3, 5: every component's mean is exactly the centre
  for (int i = 0; i < n; ++i) {
    const glm::dvec3 j = froxelJitter(i);
    for (int c = 0; c < 3; ++c) {
      CHECK(j[c] >= -0.5);
      CHECK(j[c] < 0.5);
    }
    sum += j;
  }
  for (int c = 0; c < 3; ++c)
    CHECK(std::abs(sum[c] / n) < 0.02);
  CHECK(froxelJitter(3) != froxelJitter(4));
  CHECK(froxelJitter(5) == froxelJitter(5 + 1024));
}

TEST_CASE("FroxelGrid: bad sizes and depths name the field") {
  const Camera cam = testCamera();
  auto fails = [](const FroxelGrid& g, const std::string& field) {
    try {
      validate(g, "FroxelFog::CreateInfo");
      FAIL("no error for " << field);
    } catch (const InvalidArgument& e) {
      CHECK(e.parameter() == "FroxelFog::CreateInfo.grid." + field);
    }
  };
  FroxelGrid g;
  g.width = 0;
  fails(g, "width");
  g = {};
  g.height = -3;
  fails(g, "height");
  g = {};
  g.depth = 5000;
  fails(g, "depth");
  g = {};
  g.nearDepth = NAN;
  fails(g, "nearDepth");
  g = {};
  g.farDepth = INFINITY;
  fails(g, "farDepth");
  g = {};
  g.nearDepth = 10.0;
  g.farDepth = 5.0;
  fails(g, "farDepth");
  g = {};
  g.nearDepth = 500.0; // beyond the camera's far (150)
  CHECK_THROWS_AS(froxelDepthRange(g, cam, "FroxelFog::CreateInfo"), InvalidArgument);
}
