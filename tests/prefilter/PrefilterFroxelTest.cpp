// crep::evaluateFroxels (crep/prefilter/prefilter.h "Froxel volumes"), CPU only: the fill at the cell
// centres is the per-pixel evaluation of a camera image of the grid's size whose depth buffer holds each
// slice's depth; samples beyond the camera's integration far take the sky's value; jitter bounds and grid
// errors are named. Analytic scene: the ground camera (reversed-Z, infinite projection: depth-buffer values
// near / Z keep view depths to float precision), the side light and the half-space occluder map.
#include <crep/core/error.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/froxel_grid.h>

#include "common/analytic_scene.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

using namespace crep;

namespace {

/// The camera of `c` with a reversed-Z infinite projection ([0, 1] clip depth, integration far c.far()).
Camera reversedInfinite(const Camera& c) {
  const double f = 1.0 / std::tan(0.5 * c.fovY());
  glm::dmat4 P(0.0);
  P[0][0] = f / c.aspect();
  P[1][1] = f;
  P[2][3] = -1.0;
  P[3][2] = c.near();
  return Camera::fromMatrices(c.viewFromWorld(), P, ClipDepth::ZeroToOne, c.far());
}

struct Frame {
  Camera camera = reversedInfinite(test::groundCamera(24, 16));
  DirectionalLight light = test::sideLight();
  Medium medium = test::colouredMedium();
  FilteredBasis basis;
  Frame() {
    const auto layout = test::projectiveLayout(camera, light, 2);
    const test::HalfSpace plane;
    const RectifiedMap map =
        castRectifiedMap(layout, 128, 32, [&](const LightRay& ray) { return test::planeHit(plane, ray); });
    PrefilterOptions o;
    o.regionsPerSplit = 2;
    o.format = StorageFormat::RGBA32F;
    basis = prefilter(map, medium, o);
  }
};

const Frame& frame() {
  static const Frame f;
  return f;
}

/// The per-pixel evaluation of every slice of `grid` at its centre depth (the sky beyond the camera far).
Image perSlice(const FroxelGrid& grid, const EvaluateOptions& options) {
  const Frame& f = frame();
  const FroxelDepthRange range = froxelDepthRange(grid, f.camera, "test");
  Image out(grid.width, grid.height * grid.depth, 4);
  for (int z = 0; z < grid.depth; ++z) {
    // froxel_grid.h: Z = near (far / near)^w at the slice centre w = (z + 0.5) / D; beyond the camera's
    // integration far the pixel is the sky (depth 0 with reversed Z), which integrates to far.
    const double Z = range.near * std::pow(range.far / range.near, (z + 0.5) / grid.depth);
    const float d = Z >= f.camera.far() ? 0.0f : static_cast<float>(f.camera.depthBufferValue(Z));
    const Image p =
        evaluate(f.basis, Image(grid.width, grid.height, 1, d), f.camera, f.light, f.medium, options);
    for (int y = 0; y < grid.height; ++y)
      for (int x = 0; x < grid.width; ++x)
        for (int c = 0; c < 4; ++c)
          out.at(x, z * grid.height + y, c) = p.at(x, y, c);
  }
  return out;
}

double maxDifference(const Image& a, const Image& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.data().size(); ++i)
    worst = std::max(worst, std::abs(static_cast<double>(a.data()[i]) - b.data()[i]));
  return worst;
}

double peak(const Image& a) {
  double p = 0.0;
  for (const float v : a.data())
    p = std::max(p, static_cast<double>(std::abs(v)));
  return p;
}

} // namespace

TEST_CASE("prefilter froxels (CPU): the fill at cell centres is the per-pixel evaluation of each slice") {
  const Frame& f = frame();
  FroxelGrid grid;
  grid.width = 24;
  grid.height = 16;
  grid.depth = 12;
  for (const int option : {0, 1, 2}) {
    // 0: defaults (scattering prefix table), 1: near-plane correction, 2: no table.
    CAPTURE(option);
    EvaluateOptions o;
    o.nearPlaneCorrection = option == 1;
    if (option == 2) o.visibilityTableSamples = 0;
    const Image filled = evaluateFroxels(f.basis, grid, glm::dvec3(0.0), f.camera, f.light, f.medium, o);
    const Image pixels = perSlice(grid, o);
    // The same per-ray code; the ray ends differ by the float rounding of d = near / Z (6e-8 relative) and
    // both outputs are floats: |d| <= 1e-6 of the peak (shadow edges included: the occluder's step is
    // filtered, so a 6e-8 relative shift of the end moves the result by about that fraction).
    CHECK(maxDifference(filled, pixels) <= 1e-6 * peak(pixels));
    CHECK(peak(pixels) > 0.0);
  }
}

TEST_CASE(
    "prefilter froxels (CPU): samples beyond the camera's far take the sky's value, jitter moves them") {
  const Frame& f = frame();
  FroxelGrid grid;
  grid.width = 8;
  grid.height = 6;
  grid.depth = 8;
  grid.farDepth = 30.0 * f.camera.far(); // the last 3 slices lie beyond the integration far
  const Image filled = evaluateFroxels(f.basis, grid, glm::dvec3(0.0), f.camera, f.light, f.medium);
  const Image pixels = perSlice(grid, {});
  const FroxelDepthRange range = froxelDepthRange(grid, f.camera, "test");
  int beyond = 0;
  for (int z = 0; z < grid.depth; ++z)
    if (range.near * std::pow(range.far / range.near, (z + 0.5) / grid.depth) >= f.camera.far()) ++beyond;
  REQUIRE(beyond == 3);
  // Beyond the far plane both sides integrate the same ray to far / cos: bit for bit; in front of it as in
  // the test above.
  CHECK(maxDifference(filled, pixels) <= 1e-6 * peak(pixels));
  for (int z = grid.depth - beyond; z < grid.depth; ++z)
    for (int y = 0; y < grid.height; ++y)
      for (int x = 0; x < grid.width; ++x)
        for (int c = 0; c < 4; ++c)
          CHECK(filled.at(x, z * grid.height + y, c) == pixels.at(x, z * grid.height + y, c));

  // A jitter of -1/2 cell in depth samples the front face of each slice: slice z's front face is slice
  // z - 1's back face; with (0, 0, +1/2) the back face. So the two fills agree with a shift of one slice.
  FroxelGrid g = grid;
  g.farDepth = 0.0;
  const Image front = evaluateFroxels(f.basis, g, glm::dvec3(0.0, 0.0, -0.5), f.camera, f.light, f.medium);
  const Image back = evaluateFroxels(f.basis, g, glm::dvec3(0.0, 0.0, 0.5), f.camera, f.light, f.medium);
  double worst = 0.0;
  for (int z = 1; z < g.depth; ++z)
    for (int y = 0; y < g.height; ++y)
      for (int x = 0; x < g.width; ++x)
        for (int c = 0; c < 4; ++c)
          worst = std::max(worst, std::abs(static_cast<double>(front.at(x, z * g.height + y, c)) -
                                           back.at(x, (z - 1) * g.height + y, c)));
  // (z + 0.5 - 0.5) / D and (z - 1 + 0.5 + 0.5) / D are the same double: identical rays.
  CHECK(worst == 0.0);
  CHECK(maxDifference(front, back) > 0.0);
}

TEST_CASE("prefilter froxels (CPU): bad grids, jitter and a local light's basis are named") {
  const Frame& f = frame();
  FroxelGrid grid;
  grid.width = 4;
  grid.height = 4;
  grid.depth = 4;
  CHECK_NOTHROW(evaluateFroxels(f.basis, grid, glm::dvec3(0.5, -0.5, 0.5), f.camera, f.light, f.medium));
  CHECK_THROWS_WITH_AS(
      evaluateFroxels(f.basis, grid, glm::dvec3(0.0, 0.5000001, 0.0), f.camera, f.light, f.medium),
      doctest::Contains("evaluateFroxels.jitter"), InvalidArgument);
  CHECK_THROWS_WITH_AS(
      evaluateFroxels(f.basis, grid, glm::dvec3(0.0, 0.0, std::nan("")), f.camera, f.light, f.medium),
      doctest::Contains("evaluateFroxels.jitter"), InvalidArgument);
  FroxelGrid bad = grid;
  bad.height = 5000;
  CHECK_THROWS_WITH_AS(evaluateFroxels(f.basis, bad, glm::dvec3(0.0), f.camera, f.light, f.medium),
                       doctest::Contains("evaluateFroxels.grid.height"), InvalidArgument);
  bad = grid;
  bad.nearDepth = 2.0 * f.camera.far(); // far 0 = the camera's, in front of the volume's near
  CHECK_THROWS_WITH_AS(evaluateFroxels(f.basis, bad, glm::dvec3(0.0), f.camera, f.light, f.medium),
                       doctest::Contains("evaluateFroxels.grid.farDepth"), InvalidArgument);
  FilteredBasis local = f.basis;
  local.localLight = true;
  CHECK_THROWS_WITH_AS(evaluateFroxels(local, grid, glm::dvec3(0.0), f.camera, f.light, f.medium),
                       doctest::Contains("FilteredBasis.localLight"), InvalidArgument);
}
