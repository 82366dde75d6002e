// The epipolar fallback layout (crep/epipolar/epipolar.h; Klehm et al. 2014 Sec. 4.1, Yusov 2012 slices):
// properties over random camera / light configurations (view rays keep row and depth, light rays keep row
// and column, everything visible maps into the map, distances are the closed form), the slice count rule
// (no pixel farther than half a pixel from its slice), the epipole cases, bad input.
#include "common/analytic_reference.h"
#include "common/error_checks.h"

#include <crep/core/error.h>
#include <crep/epipolar/epipolar.h>

#include <doctest/doctest.h>

#include <glm/gtc/quaternion.hpp>

#include <cmath>
#include <random>
#include <string>

using namespace crep;
using namespace crep::test;

namespace {

double uniform(std::mt19937_64& rng, double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}

glm::dvec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  for (;;) {
    const glm::dvec3 v(n(rng), n(rng), n(rng));
    if (glm::length(v) > 1e-6) return glm::normalize(v);
  }
}

/// A light direction with its epipole at NDC e (in front when front, else the anti-epipole there).
DirectionalLight lightAt(const Camera& c, glm::dvec2 e, bool front) {
  const glm::dvec3 towardLight = c.rayDirection(e.x, e.y);
  return DirectionalLight(front ? -towardLight : towardLight);
}

/// Distance in pixels from pixel centre (px, py) to the image line of slice `slice` of the layout.
double pixelToSliceLine(const EpipolarLayout& L, const Camera& c, int w, int h, double px, double py,
                        int slice) {
  const glm::dvec3 m = -L.lightDirection();
  const glm::dvec3 N = glm::cross(m, L.slices()[static_cast<std::size_t>(slice)].direction);
  const double tY = std::tan(0.5 * c.fovY()), tX = tY * c.aspect();
  // N . (F + (2 px / w - 1) tX R + (2 py / h - 1) tY U) = alpha px + beta py + gamma
  const double alpha = 2.0 * tX / w * glm::dot(N, c.right()), beta = 2.0 * tY / h * glm::dot(N, c.up());
  const double gamma = glm::dot(N, c.forward()) - tX * glm::dot(N, c.right()) - tY * glm::dot(N, c.up());
  return std::abs(alpha * px + beta * py + gamma) / std::sqrt(alpha * alpha + beta * beta);
}

} // namespace

TEST_CASE(
    "epipolar layout: view rays keep row and depth, light rays keep row and column, distances are exact") {
  std::mt19937_64 rng(5);
  int configurations = 0, onScreen = 0, anti = 0;
  double worstRow = 0.0, worstDepth = 0.0, worstColumn = 0.0, worstDistance = 0.0, worstOutside = 0.0;
  for (int trial = 0; trial < 300; ++trial) {
    const Camera camera = randomEpipolarCamera(rng);
    const DirectionalLight light(randomUnit(rng));
    const int w = 64, h = 36;
    EpipolarOptions o;
    o.regions = 1 + trial % 3;
    const EpipolarLayout L(camera, light, w, h, o);
    ++configurations;
    onScreen += L.epipoleOnScreen();
    anti += L.epipoleKind() == EpipoleKind::AntiEpipole;
    REQUIRE(L.sliceCount() == static_cast<int>(std::ceil(L.arcLength() - 1e-9)));
    for (int k = 0; k < 40; ++k) {
      const double ndcX = uniform(rng, -1, 1), ndcY = uniform(rng, -1, 1);
      const glm::dvec3 v = camera.rayDirection(ndcX, ndcY);
      if (glm::length(glm::cross(v, light.direction())) < 1e-3) continue; // on the light axis
      const double sFar = camera.far() / glm::dot(v, camera.forward());
      const double t0 = uniform(rng, 0.01, 1.0) * sFar, t1 = uniform(rng, 0.01, 1.0) * sFar;
      const RectPoint p0 = L.toRectified(camera.position() + t0 * v);
      const RectPoint p1 = L.toRectified(camera.position() + t1 * v);
      // Same row (up to the seam of a full border arc) and depth along the view ray.
      const double dRow = std::abs(p0.row - p1.row);
      worstRow = std::max(worstRow, std::min(dRow, 1.0 - dRow));
      worstDepth = std::max(worstDepth, std::abs(p0.depth - p1.depth));
      // Everything visible maps into the map (column by construction of bMax; depth to rounding of the
      // per-slice psi bounds).
      worstOutside =
          std::max({worstOutside, p0.column - 1.0, -p0.depth, p0.depth - 1.0, -p0.row, p0.row - 1.0});
      // The closed-form distance along the ray.
      const double t = L.rayDistance(p0.row, p0.depth, p0.column);
      worstDistance = std::max(worstDistance, std::abs(t - t0) / t0);
      // The texel's light ray maps back to the same row and column.
      const int H = L.sliceCount();
      const double row = (L.sliceIndex(p0.row) + 0.5) / H, column = p0.column;
      const LightRay ray = L.lightRay(column, row);
      for (const double s : {-50.0, 3.0, 200.0}) {
        const RectPoint q = L.toRectified(ray.origin + s * ray.direction);
        worstColumn = std::max({worstColumn, std::abs(q.row - row), std::abs(q.column - column)});
      }
    }
  }
  MESSAGE(configurations << " configurations (" << onScreen << " with the epipole on screen, " << anti
                         << " with the anti-epipole in front): worst |row change| along a view ray "
                         << worstRow << ", |depth change| " << worstDepth
                         << "; light rays: worst |row or column change| " << worstColumn
                         << "; worst relative distance error " << worstDistance
                         << "; worst excursion outside [0, 1] " << worstOutside);
  CHECK(worstRow < 1e-9);
  CHECK(worstDepth < 1e-9);
  CHECK(worstColumn < 1e-9);
  CHECK(worstDistance < 1e-9);
  CHECK(worstOutside < 1e-6);
  CHECK(onScreen > 3);
  CHECK(anti > 50);
}

TEST_CASE(
    "epipolar layout: with one slice per border pixel no pixel is more than half a pixel from its slice") {
  std::mt19937_64 rng(9);
  const int w = 48, h = 27;
  for (int trial = 0; trial < 40; ++trial) {
    const Camera camera = randomEpipolarCamera(rng);
    // Epipoles on screen, just off it, far off it, behind the camera.
    const glm::dvec2 e(uniform(rng, -3, 3), uniform(rng, -3, 3));
    const DirectionalLight light = lightAt(camera, e, trial % 2 == 0);
    const EpipolarLayout L(camera, light, w, h);
    CAPTURE(trial);
    CAPTURE(e.x);
    CAPTURE(e.y);
    double worst = 0.0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const glm::dvec3 v = camera.rayDirection(2.0 * (x + 0.5) / w - 1.0, 2.0 * (y + 0.5) / h - 1.0);
        if (glm::length(glm::cross(v, light.direction())) < 1e-9) continue;
        const RectPoint p = L.toRectified(camera.position() + v);
        worst = std::max(worst, pixelToSliceLine(L, camera, w, h, x + 0.5, y + 0.5, L.sliceIndex(p.row)));
      }
    CHECK(worst <= 0.5 + 1e-6);
    const bool inside = std::abs(e.x) <= 1.0 && std::abs(e.y) <= 1.0;
    CHECK(L.epipoleOnScreen() == inside);
    if (inside) CHECK(L.arcLength() == doctest::Approx(2.0 * (w + h)));
    CHECK(L.sliceCount() <= 2 * (w + h));
  }
}

TEST_CASE("epipolar layout: exit sides and arcs for epipoles around the screen (Yusov's border order)") {
  const Camera camera = groundCamera(160, 90);
  struct Case {
    glm::dvec2 e;
    int sides;
    double begin, length;
  };
  // Border order: left (0..90), bottom (90..250), right (250..340), top (340..500).
  const Case cases[] = {
      {{0.2, -0.3}, 15, 0.0, 500.0},  // on screen: the whole border
      {{0.0, 2.0}, 7, 0.0, 340.0},    // above: exits through left, bottom, right
      {{-3.0, 0.0}, 14, 90.0, 410.0}, // left: bottom, right, top
      {{3.0, -3.0}, 9, 340.0, 250.0}, // below right: top, left (wrapping past the corner)
  };
  for (const Case& c : cases) {
    for (const bool front : {true, false}) {
      CAPTURE(c.e.x);
      CAPTURE(c.e.y);
      CAPTURE(front);
      const EpipolarLayout L(camera, lightAt(camera, c.e, front), 160, 90);
      CHECK(L.epipoleKind() == (front ? EpipoleKind::Epipole : EpipoleKind::AntiEpipole));
      CHECK(L.epipoleNdc().x == doctest::Approx(c.e.x));
      CHECK(L.epipoleNdc().y == doctest::Approx(c.e.y));
      CHECK(L.exitSides() == c.sides);
      CHECK(L.arcBegin() == doctest::Approx(c.begin));
      CHECK(L.arcLength() == doctest::Approx(c.length));
      CHECK(L.sliceCount() == static_cast<int>(c.length));
      // Depth grows along the light's travel: the first occluder is the smallest depth (GL_LESS).
      const LightRay ray = L.lightRay(0.5, 0.5);
      CHECK(L.toRectified(ray.origin - ray.direction).depth <
            L.toRectified(ray.origin + ray.direction).depth);
      // Epipole in front and on screen: every slice starts at psi = 0; behind: ends at pi.
      if (c.sides == 15) {
        for (const auto& s : L.slices())
          CHECK((front ? s.psiMin : std::numbers::pi - s.psiMax) < 1e-9);
      }
    }
  }
  // The light axis parallel to the image plane: the epipole at infinity.
  const DirectionalLight sideways(camera.right());
  const EpipolarLayout L(camera, sideways, 160, 90);
  CHECK(L.epipoleKind() == EpipoleKind::AtInfinity);
  CHECK(!L.epipoleOnScreen());
  CHECK(L.epipoleBlockPixels().empty());
}

TEST_CASE("epipolar layout: epipole block pixels lie within the radius of the epipole") {
  const Camera camera = groundCamera(160, 90);
  EpipolarOptions o;
  o.epipoleBlockRadius = 0.05;
  const EpipolarLayout L(camera, lightAt(camera, {0.5, 0.25}, true), 160, 90, o);
  REQUIRE(L.epipoleOnScreen());
  const glm::dvec2 e = *L.epipolePixel();
  CHECK(e.x == doctest::Approx(120.0));
  CHECK(e.y == doctest::Approx(56.25));
  const double r = L.epipoleBlockRadiusPixels();
  CHECK(r == doctest::Approx(0.05 * std::sqrt(160.0 * 160.0 + 90.0 * 90.0)));
  const std::vector<int> block = L.epipoleBlockPixels();
  CHECK(static_cast<double>(block.size()) == doctest::Approx(std::numbers::pi * r * r).epsilon(0.1));
  for (int p : block)
    CHECK(glm::length(glm::dvec2(p % 160 + 0.5, p / 160 + 0.5) - e) <= r);
  o.epipoleBlockRadius = 0.0;
  CHECK(EpipolarLayout(camera, lightAt(camera, {0.5, 0.25}, true), 160, 90, o).epipoleBlockPixels().empty());
}

TEST_CASE("epipolar layout: maxBlockPixels bounds the block's pixels on screen at any screen size") {
  for (const glm::ivec2 size : {glm::ivec2(160, 90), glm::ivec2(640, 360), glm::ivec2(1920, 1080)}) {
    CAPTURE(size.x);
    const Camera camera = groundCamera(size.x, size.y);
    EpipolarOptions o;
    o.epipoleBlockRadius = 0.06;
    const DirectionalLight inView = lightAt(camera, {0.5, 0.25}, true);
    const EpipolarLayout full(camera, inView, size.x, size.y, o);
    const double r0 = full.epipoleBlockRadiusPixels();
    // The count is exactly the pixels epipoleBlockPixels() lists (pixel centres within the radius).
    CHECK(full.blockPixelCount(r0) == static_cast<long long>(full.epipoleBlockPixels().size()));
    o.maxBlockPixels = 2048;
    const EpipolarLayout capped(camera, inView, size.x, size.y, o);
    const double r = capped.epipoleBlockRadiusPixels();
    const long long n = static_cast<long long>(capped.epipoleBlockPixels().size());
    MESSAGE(size.x << "x" << size.y << ": 6% radius " << r0 << " px (" << full.blockPixelCount(r0)
                   << " pixels), capped at 2048 pixels: " << r << " px (" << n << " pixels)");
    CHECK(n == capped.blockPixelCount(r));
    CHECK(n <= 2048);
    if (full.blockPixelCount(r0) <= 2048) {
      CHECK(r == r0); // small screens keep the whole 6%
    } else {
      CHECK(r < r0);
      CHECK(capped.blockPixelCount(r + 0.01) > 2048); // the largest radius under the bound
      CHECK(n > 2048 - 8.0 * r);                      // one ring of pixels at most below it
    }
    // The light just beyond the right edge: the disc is mostly off screen and keeps its radius.
    const DirectionalLight outside = lightAt(camera, {1.03, 0.5}, true);
    const EpipolarLayout edge(camera, outside, size.x, size.y, o);
    REQUIRE_FALSE(edge.epipoleOnScreen());
    o.maxBlockPixels = 0;
    const EpipolarLayout edgeFull(camera, outside, size.x, size.y, o);
    if (edgeFull.blockPixelCount(edgeFull.epipoleBlockRadiusPixels()) <= 2048)
      CHECK(edge.epipoleBlockRadiusPixels() == edgeFull.epipoleBlockRadiusPixels());
    CHECK(edge.blockPixelCount(edge.epipoleBlockRadiusPixels()) <= 2048);
  }
}

TEST_CASE("epipolar layout: profiles and reference rays follow the contract of rectified_map.h") {
  const Camera camera = groundCamera(160, 90);
  EpipolarOptions o;
  o.regions = 3;
  for (const glm::dvec2 e : {glm::dvec2(0.1, 0.2), glm::dvec2(2.5, 0.4)}) {
    const EpipolarLayout L(camera, lightAt(camera, e, true), 160, 90, o);
    for (int j = 0; j < L.sliceCount(); j += 37) {
      const double row = (j + 0.5) / L.sliceCount();
      for (const double depth : {0.0, 0.3, 1.0}) {
        for (int k = 0; k < 3; ++k) {
          const DistanceProfile p = L.rayProfile(row, depth, k);
          CHECK(p.valid());
          for (const double u : {0.0, 0.4, 1.0})
            CHECK(p(u) == doctest::Approx(L.rayDistance(row, depth, (k + u) / 3.0)));
        }
      }
      const double ref = L.referenceDepth(row);
      CHECK(ref >= 0.0);
      CHECK(ref <= 1.0);
      CHECK(L.referenceProfile(row, 1)(0.5) == doctest::Approx(L.referenceDistance(row, 0.5)));
      // The view ray of (row, depth) is the direction whose angle to the light is psi.
      const glm::dvec3 v = L.viewRayDirection(row, 0.25);
      CHECK(std::acos(glm::dot(v, -L.lightDirection())) == doctest::Approx(L.psi(j, 0.25)));
    }
  }
}

TEST_CASE("epipolar layout: bad input gets a named InvalidArgument") {
  const Camera camera = groundCamera(16, 9);
  const DirectionalLight light = sideLight();
  CHECK(invalidParameter([&] { EpipolarLayout(camera, light, 0, 9); }) == "EpipolarLayout.screenSize");
  CHECK(invalidParameter([&] { EpipolarLayout(camera, light, 16, Image::kMaxDimension + 1); }) ==
        "EpipolarLayout.screenSize");
  EpipolarOptions o;
  o.regions = 0;
  CHECK(invalidParameter([&] { EpipolarLayout(camera, light, 16, 9, o); }) == "EpipolarOptions.regions");
  o = {};
  o.slicesPerBorderPixel = std::nan("");
  CHECK(invalidParameter([&] { EpipolarLayout(camera, light, 16, 9, o); }) ==
        "EpipolarOptions.slicesPerBorderPixel");
  o = {};
  o.slices = -1;
  CHECK(invalidParameter([&] { EpipolarLayout(camera, light, 16, 9, o); }) == "EpipolarOptions.slices");
  o = {};
  o.epipoleBlockRadius = -1.0;
  CHECK(invalidParameter([&] { EpipolarLayout(camera, light, 16, 9, o); }) ==
        "EpipolarOptions.epipoleBlockRadius");
  o = {};
  o.maxBlockPixels = -1;
  CHECK(invalidParameter([&] { EpipolarLayout(camera, light, 16, 9, o); }) ==
        "EpipolarOptions.maxBlockPixels");
  const EpipolarLayout L(camera, light, 16, 9);
  CHECK(invalidParameter([&] { L.toRectified(camera.position()); }) == "EpipolarLayout.toRectified.world");
  CHECK(invalidParameter([&] { L.toRectified(glm::dvec3(std::nan(""))); }) ==
        "EpipolarLayout.toRectified.world");
  CHECK(invalidParameter([&] { L.rayProfile(0.5, 0.5, 4); }) == "EpipolarLayout.region");
}
