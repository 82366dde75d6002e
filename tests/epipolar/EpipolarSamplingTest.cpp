// Epipolar sampling, CPU reference (crep/epipolar/epipolar_sampling.h; Yusov 2012, Sec. 6; Yusov 2013):
// the lines (epipole, exit arc, valid ranges, slice coordinates), the sample coordinates against the depth
// image and an independent closed form, the refinement rules on hand-made samples, exact interpolation of
// linear fields, the bilateral unwarp (constant fields, a thin bar, the corrections), the whole pipeline
// against the per-pixel closed form for F = 1, 2, 4, and the option checks.
#include "common/analytic_reference.h"
#include "common/error_checks.h"

#include <crep/core/error.h>
#include <crep/epipolar/epipolar_sampling.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

/// A light whose epipole (front) or anti-epipole (!front) is at NDC e.
DirectionalLight lightAt(const Camera& c, glm::dvec2 e, bool front) {
  const glm::dvec3 towardLight = c.rayDirection(e.x, e.y);
  return DirectionalLight(front ? -towardLight : towardLight);
}

/// How far p is outside [0, W] x [0, H] (negative inside).
double outside(glm::dvec2 p, double W, double H) {
  return std::max(std::max(-p.x, p.x - W), std::max(-p.y, p.y - H));
}

/// The test's own border parameter (counter-clockwise from the top-left corner, left side first) of a
/// border point, and the side it lies on (0 left, 1 bottom, 2 right, 3 top).
double borderParameter(glm::dvec2 X, double W, double H, int& side) {
  const double d[4] = {std::abs(X.x), std::abs(X.y), std::abs(X.x - W), std::abs(X.y - H)};
  side = static_cast<int>(std::min_element(d, d + 4) - d);
  switch (side) {
  case 0:
    return H - X.y;
  case 1:
    return H + X.x;
  case 2:
    return H + W + X.y;
  default:
    return std::fmod(2.0 * H + 2.0 * W - X.x, 2.0 * (W + H));
  }
}

/// Where the ray p + t dir (t >= 0, p inside) leaves [0, W] x [0, H].
glm::dvec2 leaveScreen(glm::dvec2 p, glm::dvec2 dir, double W, double H) {
  double t = std::numeric_limits<double>::infinity();
  if (dir.x > 0) t = std::min(t, (W - p.x) / dir.x);
  if (dir.x < 0) t = std::min(t, -p.x / dir.x);
  if (dir.y > 0) t = std::min(t, (H - p.y) / dir.y);
  if (dir.y < 0) t = std::min(t, -p.y / dir.y);
  return p + t * dir;
}

/// Distance between two slice coordinates modulo n.
double cyclicDistance(double a, double b, double n) {
  const double d = std::fmod(std::abs(a - b), n);
  return std::min(d, n - d);
}

struct LineCase {
  const char* name;
  glm::dvec2 ndc;
  bool front;
};

const LineCase kLineCases[] = {
    {"epipole on screen", {0.3, -0.2}, true}, {"anti-epipole on screen", {-0.5, 0.4}, false},
    {"epipole right", {2.5, 0.3}, true},      {"epipole top left", {-1.8, 1.6}, true},
    {"epipole below", {0.1, -3.0}, true},     {"anti-epipole bottom right", {1.4, -1.3}, false},
    {"epipole far right", {40.0, 0.5}, true}, {"anti-epipole above", {-0.2, 1.05}, false},
};

/// Fronto-parallel planes: view depth `far` everywhere except a bar of view depth `near` over columns
/// [x0, x1) (all rows).
Image barDepth(const Camera& camera, int w, int h, int x0, int x1, double nearZ, double farZ) {
  Image depth(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      depth.at(x, y) = static_cast<float>(depthBufferValue(camera, x >= x0 && x < x1 ? nearZ : farZ));
  return depth;
}

/// The ground plane with a fronto-parallel box face (view depth 9) over columns [x0, x1) and rows below y1.
Image groundWithBox(const Camera& camera, int w, int h) {
  Image depth = groundDepth(camera, w, h);
  const int x0 = w * 3 / 8, x1 = w / 2, y1 = h * 2 / 3;
  for (int y = 0; y < y1; ++y)
    for (int x = x0; x < x1; ++x)
      depth.at(x, y) = static_cast<float>(depthBufferValue(camera, 9.0));
  return depth;
}

/// Independent closed form of the unshadowed single scattering along the ray through pixel point (x, y)
/// to the surface of depth-buffer value d (Klehm et al. 2014, Eq. 1 and 3 with V = 1): RGB and the grey
/// transmittance.
glm::dvec4 closedFormRay(const Camera& camera, const DirectionalLight& light, const Medium& medium, int W,
                         int H, double x, double y, double d) {
  const glm::dvec3 v = camera.rayDirection(2.0 * x / W - 1.0, 2.0 * y / H - 1.0);
  const double z = d >= 1.0 ? camera.far() : std::clamp(camera.linearDepth(d), camera.near(), camera.far());
  const double s = z / glm::dot(v, camera.forward());
  const glm::dvec3 sigma = medium.extinction();
  const glm::dvec3 C = light.irradiance() * medium.scatteringTimesPhase(glm::dot(light.direction(), -v));
  const glm::dvec3 L = C * segmentIntegral(sigma, 0.0, s);
  return {L, std::exp(-(sigma.x + sigma.y + sigma.z) / 3.0 * s)};
}

std::size_t at(int k, int i, int Ns) {
  return static_cast<std::size_t>(k) + static_cast<std::size_t>(i) * static_cast<std::size_t>(Ns);
}

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

} // namespace

TEST_CASE("EpipolarSampling lines: the epipole and the anti-epipole project back onto the light axis") {
  const int W = 160, H = 90;
  const Camera camera = groundCamera(W, H);
  EpipolarSamplingOptions o;
  o.slices = 64;
  o.samples = 64;
  for (const LineCase& c : kLineCases) {
    if (std::abs(c.ndc.x) > 10.0) continue; // clamped to 1e5 px: no longer the exact projection
    const std::string name = c.name;
    CAPTURE(name);
    const DirectionalLight light = lightAt(camera, c.ndc, c.front);
    const EpipolarLines lines = epipolarLines(camera, light, W, H, o);
    const glm::dvec2 ndc = 2.0 * lines.epipole / glm::dvec2(W, H) - 1.0;
    const glm::dvec3 v = camera.rayDirection(ndc.x, ndc.y);
    // In front: the ray toward the light; the anti-epipole: the ray along the light's travel.
    const glm::dvec3 expected = c.front ? -light.direction() : light.direction();
    CHECK(glm::length(v - expected) < 1e-9);
    const bool onScreen = std::abs(c.ndc.x) <= 1.0 && std::abs(c.ndc.y) <= 1.0;
    CHECK(lines.epipoleOnScreen == onScreen);
    if (onScreen) {
      CHECK(lines.arcBegin == 0.0);
      CHECK(lines.arcLength == 2.0 * (W + H));
    }
  }
}

TEST_CASE("EpipolarSampling lines: valid samples fill the visible segment, exits cover the exit arc only") {
  const int W = 160, H = 90;
  const double P = 2.0 * (W + H);
  const Camera camera = groundCamera(W, H);
  for (const int Ns : {64, 128}) {
    EpipolarSamplingOptions o;
    o.slices = 128;
    o.samples = Ns;
    for (const LineCase& c : kLineCases) {
      const std::string name = c.name;
      CAPTURE(name);
      CAPTURE(Ns);
      const EpipolarLines lines = epipolarLines(camera, lightAt(camera, c.ndc, c.front), W, H, o);
      REQUIRE(static_cast<int>(lines.lines.size()) == o.slices);
      const glm::dvec2 e = lines.epipole;
      // The exit sides: e strictly on the inner side (all four on screen); their total length.
      const bool exitSide[4] = {lines.epipoleOnScreen || e.x > 0, lines.epipoleOnScreen || e.y > 0,
                                lines.epipoleOnScreen || e.x < W, lines.epipoleOnScreen || e.y < H};
      const double sideLength[4] = {double(H), double(W), double(H), double(W)};
      double arc = 0.0;
      for (int s = 0; s < 4; ++s)
        arc += exitSide[s] ? sideLength[s] : 0.0;
      CHECK(std::abs(lines.arcLength - arc) < 1e-9);
      int degenerate = 0, shortLines = 0, longLines = 0;
      double worstInside = 0.0, worstNext = -1.0, worstSpacing = 0.0, worstSigma = 0.0;
      for (int i = 0; i < o.slices; ++i) {
        const EpipolarLines::Line& line = lines.lines[static_cast<std::size_t>(i)];
        if (line.lastValid < 0) {
          ++degenerate;
          continue;
        }
        for (int k = 0; k <= line.lastValid; ++k)
          worstInside = std::max(worstInside, outside(lines.samplePoint(i, k), W, H));
        if (line.lastValid + 1 < Ns) // the next sample is beyond the border (not inside by more than 1e-9)
          worstNext = std::min(worstNext == -1.0 ? 1e300 : worstNext,
                               outside(lines.samplePoint(i, line.lastValid + 1), W, H));
        // The border point the line leaves the screen through: on an exit side, at the slice's sigma.
        const glm::dvec2 X = leaveScreen(line.entry, line.exit - line.entry, W, H);
        int side = 0;
        const double sigma = borderParameter(X, W, H, side);
        CHECK(exitSide[side]);
        const double expectedSigma = std::fmod(lines.arcBegin + (i + 0.5) / o.slices * lines.arcLength, P);
        worstSigma = std::max(worstSigma, cyclicDistance(sigma, expectedSigma, P));
        // Spacing: |X - entry| / (Ns - 1) on long lines, Ns / (Ns - 1) (one sample per pixel) on short ones.
        const double L = glm::length(X - line.entry);
        const double spacing = glm::length(line.exit - line.entry) / (Ns - 1);
        const double expected = L >= Ns ? L / (Ns - 1) : double(Ns) / (Ns - 1);
        (L >= Ns ? longLines : shortLines)++;
        worstSpacing = std::max(worstSpacing, std::abs(spacing - expected));
        // On screen: half a pixel from the epipole toward the exit (the ray at e itself is the light axis).
        if (lines.epipoleOnScreen) {
          CHECK(glm::length(line.entry - e) == doctest::Approx(0.5).epsilon(1e-12));
          CHECK(glm::dot(glm::normalize(line.entry - e), glm::normalize(X - e)) ==
                doctest::Approx(1.0).epsilon(1e-12));
        }
      }
      CHECK(worstInside <= 1e-3);
      CHECK(worstNext > -1e-9);
      CHECK(worstSigma < 1e-6);
      CHECK(worstSpacing < 1e-9);
      // Every slice is visible: no line of the arc is empty in these configurations (the epipole is not
      // within 1e-3 px of a border line through a slice's exit point).
      CHECK(degenerate == 0);
      MESSAGE(std::string(std::string(c.name) + ", Ns " + std::to_string(Ns) + ": epipole (" + fmt(e.x) +
                          ", " + fmt(e.y) + "), arc [" + fmt(lines.arcBegin) + ", +" + fmt(lines.arcLength) +
                          "], short lines " + std::to_string(shortLines) + ", long " +
                          std::to_string(longLines) + ", degenerate " + std::to_string(degenerate)));
    }
  }
}

TEST_CASE("EpipolarSampling lines: sliceOf of a line's samples returns the line, with any line offset") {
  const int W = 160, H = 90;
  const Camera camera = groundCamera(W, H);
  EpipolarSamplingOptions o;
  o.slices = 256;
  o.samples = 64;
  for (const double offset : {0.0, 0.25, 0.5})
    for (const LineCase& c : kLineCases) {
      const std::string name = c.name;
      CAPTURE(name);
      CAPTURE(offset);
      const EpipolarLines lines = epipolarLines(camera, lightAt(camera, c.ndc, c.front), W, H, o, offset);
      const EpipolarLines unshifted = epipolarLines(camera, lightAt(camera, c.ndc, c.front), W, H, o);
      const double N = o.slices;
      double worst = 0.0, worstExit = 0.0;
      int checked = 0;
      for (int i = 0; i < o.slices; ++i) {
        // Line i runs toward the border point (i + 0.5 + offset) spacings into the unshifted exit arc.
        const EpipolarLines::Line& l = lines.lines[static_cast<std::size_t>(i)];
        const glm::dvec2 X =
            lines.borderPoint(unshifted.arcBegin + (i + 0.5 + offset) / N * unshifted.arcLength);
        const glm::dvec2 along = l.exit - l.entry, toX = X - l.entry;
        if (glm::length(along) > 1e-6 && glm::length(toX) > 1e-6)
          worstExit = std::max(worstExit, std::abs(along.x * toX.y - along.y * toX.x) /
                                              (glm::length(along) * glm::length(toX)));
        for (int k = 0; k <= lines.lines[static_cast<std::size_t>(i)].lastValid; ++k) {
          const glm::dvec2 p = lines.samplePoint(i, k);
          if (glm::length(p - lines.epipole) < 1e-3) {
            CHECK_FALSE(lines.sliceOf(p).has_value());
            continue;
          }
          const std::optional<double> s = lines.sliceOf(p);
          REQUIRE(s.has_value());
          worst = std::max(worst, std::abs(*s - i));
          ++checked;
        }
      }
      CHECK(worst < 1e-6);
      CHECK(worstExit < 1e-6);
      CHECK(checked > o.slices * 10);
      if (lines.epipoleOnScreen) {
        // The wrap-around: the ray from e through the top-left corner (sigma = 0 = P) is half a slice (plus
        // the offset) before slice 0 and half a slice (less it) after slice N - 1.
        const glm::dvec2 corner(0.0, H);
        const std::optional<double> s = lines.sliceOf(lines.epipole + 0.5 * (corner - lines.epipole));
        REQUIRE(s.has_value());
        CHECK(cyclicDistance(*s, -0.5 - offset, N) < 1e-6);
        CHECK(*s >= -0.5 - offset - 1e-9);
        CHECK(*s < N - 0.5 - offset + 1e-9);
        CHECK_FALSE(lines.sliceOf(lines.epipole + glm::dvec2(4e-4, -5e-4)).has_value());
      }
    }
  CHECK_THROWS_WITH_AS(epipolarLines(camera, lightAt(camera, kLineCases[0].ndc, true), W, H, o, 0.6),
                       doctest::Contains("lineOffset"), InvalidArgument);
}

TEST_CASE("EpipolarSampling lines: the offset that puts lines on the centres of a map's rows") {
  // Line i at (i + 0.5 + offset) / N of the arc, row r's centre at (r + 0.5) / R: with R = m N the line is
  // at m (i + 0.5 + offset) - 0.5 rows from row 0's centre, an integer for every i exactly when it is one
  // for i = 0.
  for (const auto& [rows, lines] : {std::pair{1024, 1024}, std::pair{512, 256}, std::pair{1024, 256},
                                    std::pair{768, 256}, std::pair{1000, 256}, std::pair{256, 512}}) {
    CAPTURE(rows);
    CAPTURE(lines);
    const double offset = epipolarLineOffset(rows, lines);
    CHECK(offset >= 0.0);
    CHECK(offset <= 0.5);
    if (rows % lines != 0) {
      CHECK(offset == 0.0);
      continue;
    }
    const double m = static_cast<double>(rows) / lines;
    for (int i : {0, 1, lines / 2, lines - 1}) {
      const double fromCentre = m * (i + 0.5 + offset) - 0.5;
      CHECK(std::abs(fromCentre - std::round(fromCentre)) < 1e-12); // on a row's centre
    }
  }
  CHECK(epipolarLineOffset(512, 256) == 0.25);
  CHECK(epipolarLineOffset(1024, 1024) == 0.0);
  CHECK(epipolarLineOffset(0, 256) == 0.0);
}

TEST_CASE("EpipolarSampling lines: a light parallel to the image plane gives finite, nearly parallel lines") {
  const int W = 160, H = 90;
  const Camera camera = groundCamera(W, H);
  EpipolarSamplingOptions o;
  o.slices = 128;
  o.samples = 64;
  for (const glm::dvec3 direction :
       {camera.right(), -camera.up(), glm::normalize(camera.right() + camera.up())}) {
    const EpipolarLines lines = epipolarLines(camera, DirectionalLight(direction), W, H, o);
    // The epipole at infinity is pulled to 1e5 px from the centre.
    CHECK(std::abs(glm::length(lines.epipole - glm::dvec2(W / 2.0, H / 2.0)) - 1e5) < 1e-6);
    CHECK_FALSE(lines.epipoleOnScreen);
    int valid = 0;
    double worstDirection = 0.0;
    const glm::dvec2 axis = glm::normalize(glm::dvec2(W / 2.0, H / 2.0) - lines.epipole);
    for (const EpipolarLines::Line& line : lines.lines) {
      CHECK(std::isfinite(line.entry.x + line.entry.y + line.exit.x + line.exit.y));
      if (line.lastValid < 0) continue;
      ++valid;
      // Lines point away from the epipole, within the screen's angle seen from 1e5 px (< 1e-3 rad).
      const glm::dvec2 dir = glm::normalize(line.exit - line.entry);
      worstDirection = std::max(worstDirection, glm::length(dir - axis));
    }
    CHECK(valid == o.slices);
    CHECK(worstDirection < 2e-3);
  }
}

TEST_CASE("EpipolarSampling samples: depth of the containing pixel, view depth, closed-form luminance") {
  const int W = 96, H = 64;
  const Camera camera = groundCamera(W, H);
  const Medium medium = colouredMedium();
  const Image depth = groundWithBox(camera, W, H);
  EpipolarSamplingOptions o;
  o.slices = 128;
  o.samples = 64;
  for (const LineCase& c : kLineCases) {
    const std::string name = c.name;
    CAPTURE(name);
    const DirectionalLight light = lightAt(camera, c.ndc, c.front);
    const EpipolarLines lines = epipolarLines(camera, light, W, H, o);
    const EpipolarSamples samples = epipolarSamples(lines, depth, camera, light, medium);
    REQUIRE(samples.coordinates.width() == o.samples);
    REQUIRE(samples.coordinates.height() == o.slices);
    REQUIRE(samples.coordinates.channels() == 4);
    REQUIRE(samples.unshadowed.channels() == 1);
    double worstXY = 0.0, worstZ = 0.0, worstU = 0.0;
    int dMismatch = 0, invalidWrong = 0;
    for (int i = 0; i < o.slices; ++i) {
      const int last = lines.lines[static_cast<std::size_t>(i)].lastValid;
      for (int k = 0; k < o.samples; ++k) {
        if (k > last) {
          for (int ch = 0; ch < 4; ++ch)
            invalidWrong += samples.coordinates.at(k, i, ch) != -1.0f;
          invalidWrong += samples.unshadowed.at(k, i) != 0.0f;
          continue;
        }
        const glm::dvec2 p = lines.samplePoint(i, k);
        worstXY = std::max(worstXY, std::abs(samples.coordinates.at(k, i, 0) - p.x) +
                                        std::abs(samples.coordinates.at(k, i, 1) - p.y));
        const int qx = std::clamp(static_cast<int>(std::floor(p.x)), 0, W - 1);
        const int qy = std::clamp(static_cast<int>(std::floor(p.y)), 0, H - 1);
        const double d = samples.coordinates.at(k, i, 2);
        dMismatch += d != depth.at(qx, qy);
        const double z = d >= 1.0 ? camera.far() : camera.linearDepth(d);
        worstZ = std::max(worstZ, std::abs(samples.coordinates.at(k, i, 3) - z) / z);
        const glm::dvec4 L = closedFormRay(camera, light, medium, W, H, p.x, p.y, d);
        const double U = 0.2126 * L.x + 0.7152 * L.y + 0.0722 * L.z;
        worstU = std::max(worstU, std::abs(samples.unshadowed.at(k, i) - U) / U);
      }
    }
    CHECK(dMismatch == 0);
    CHECK(invalidWrong == 0);
    CHECK(worstXY < 1e-4);
    CHECK(worstZ < 1e-6);
    CHECK(worstU < 1e-6);
  }
}

namespace {

/// Hand-made lines for the refinement tests: Ns = 64, line 0 full, line 1 valid up to 40, line 2 empty.
EpipolarLines handLines() {
  EpipolarLines lines;
  lines.width = 64;
  lines.height = 64;
  lines.samples = 64;
  lines.lines.resize(3);
  lines.lines[0].lastValid = 63;
  lines.lines[1].lastValid = 40;
  lines.lines[2].lastValid = -1;
  return lines;
}

EpipolarSamples handSamples(const EpipolarLines& lines, double z, double U) {
  const int Ns = lines.samples, N = static_cast<int>(lines.lines.size());
  EpipolarSamples s{Image(Ns, N, 4, -1.0f), Image(Ns, N, 1, 0.0f)};
  for (int i = 0; i < N; ++i)
    for (int k = 0; k <= lines.lines[static_cast<std::size_t>(i)].lastValid; ++k) {
      s.coordinates.at(k, i, 0) = static_cast<float>(k);
      s.coordinates.at(k, i, 1) = static_cast<float>(i);
      s.coordinates.at(k, i, 2) = 0.5f;
      s.coordinates.at(k, i, 3) = static_cast<float>(z);
      s.unshadowed.at(k, i) = static_cast<float>(U);
    }
  return s;
}

/// The sources of a line without breaks: initial samples marched, the others between their section's ends.
glm::ivec2 sectionSources(int k, int S, int last) {
  if (k % S == 0 || k == last) return glm::ivec2(k);
  const int a = k / S * S;
  return {a, std::min(a + S, last)};
}

} // namespace

TEST_CASE(
    "EpipolarSampling refinement: initial samples, breaks in depth and in-scattering, strict thresholds") {
  const EpipolarLines lines = handLines();
  const int Ns = 64;
  EpipolarSamplingOptions o;
  o.samples = Ns;
  o.slices = 3;

  SUBCASE("S = 1 marches every valid sample") {
    o.initialStep = 1;
    const std::vector<glm::ivec2> src = refineSamples(handSamples(lines, 10.0, 1.0), lines, o);
    REQUIRE(src.size() == std::size_t(3 * Ns));
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < Ns; ++k)
        CHECK(src[at(k, i, Ns)] ==
              (k <= lines.lines[static_cast<std::size_t>(i)].lastValid ? glm::ivec2(k) : glm::ivec2(-1)));
  }

  SUBCASE("constant depth and no scattering criterion: exactly the initial samples are marched") {
    o.initialStep = 16;
    o.scatteringCriterion = false;
    EpipolarSamples s = handSamples(lines, 10.0, 1.0);
    for (int k = 0; k < Ns; ++k) // U changes wildly, ignored without the criterion
      s.unshadowed.at(k, 0) = static_cast<float>(1 + k % 3 * 10);
    const std::vector<glm::ivec2> src = refineSamples(s, lines, o);
    for (int i = 0; i < 3; ++i) {
      const int last = lines.lines[static_cast<std::size_t>(i)].lastValid;
      for (int k = 0; k < Ns; ++k)
        CHECK(src[at(k, i, Ns)] == (k <= last ? sectionSources(k, 16, last) : glm::ivec2(-1)));
    }
  }

  SUBCASE("a depth step between k0 and k0 + 1") {
    o.initialStep = 16;
    EpipolarSamples s = handSamples(lines, 10.0, 1.0);
    const int k0 = 20;
    for (int k = k0 + 1; k < Ns; ++k)
      s.coordinates.at(k, 0, 3) = 20.0f;
    const std::vector<glm::ivec2> src = refineSamples(s, lines, o);
    for (int k = 0; k < Ns; ++k) {
      CAPTURE(k);
      glm::ivec2 expected = sectionSources(k, 16, 63);
      if (k == k0 || k == k0 + 1)
        expected = glm::ivec2(k); // next to the break
      else if (k > 16 && k < k0)
        expected = {16, k0}; // the section's start and the break's near side
      else if (k > k0 + 1 && k < 32)
        expected = {k0 + 1, 32};
      CHECK(src[at(k, 0, Ns)] == expected);
    }
    // Line 1 is untouched.
    for (int k = 0; k <= 40; ++k)
      CHECK(src[at(k, 1, Ns)] == sectionSources(k, 16, 40));
  }

  SUBCASE("thresholds are strict: equal to the threshold is no break, above it is") {
    o.initialStep = 32;
    o.depthThreshold = 0.5;      // |z_a - z_b| > 0.5 min(z): 10 -> 15 is not a break, 10 -> 15.5 is
    o.scatteringThreshold = 0.5; // |U_a - U_b| > 0.5 max(U): 4 -> 2 is not a break, 4 -> 1.5 is
    EpipolarSamples s = handSamples(lines, 10.0, 4.0);
    s.coordinates.at(5, 0, 3) = 15.0f; // 4|5 and 5|6: differences 5 = 0.5 * 10
    s.unshadowed.at(40, 0) = 2.0f;     // 39|40 and 40|41: differences 2 = 0.5 * 4
    std::vector<glm::ivec2> src = refineSamples(s, lines, o);
    for (int k = 0; k < Ns; ++k)
      CHECK(src[at(k, 0, Ns)] == sectionSources(k, 32, 63));
    s.coordinates.at(5, 0, 3) = 15.5f;
    s.unshadowed.at(40, 0) = 1.5f;
    src = refineSamples(s, lines, o);
    for (const int k : {4, 5, 6, 39, 40, 41})
      CHECK(src[at(k, 0, Ns)] == glm::ivec2(k));
    CHECK(src[at(3, 0, Ns)] == glm::ivec2(0, 4));
    CHECK(src[at(7, 0, Ns)] == glm::ivec2(6, 32));
    CHECK(src[at(38, 0, Ns)] == glm::ivec2(32, 39));
    CHECK(src[at(42, 0, Ns)] == glm::ivec2(41, 63));
    // Each criterion alone.
    o.scatteringCriterion = false;
    src = refineSamples(s, lines, o);
    CHECK(src[at(40, 0, Ns)] == glm::ivec2(32, 63));
    CHECK(src[at(5, 0, Ns)] == glm::ivec2(5));
    o.scatteringCriterion = true;
    o.depthCriterion = false;
    src = refineSamples(s, lines, o);
    CHECK(src[at(5, 0, Ns)] == glm::ivec2(0, 32));
    CHECK(src[at(40, 0, Ns)] == glm::ivec2(40));
  }

  SUBCASE("invalid samples have no sources") {
    const std::vector<glm::ivec2> src = refineSamples(handSamples(lines, 10.0, 1.0), lines, o);
    for (int k = 41; k < Ns; ++k)
      CHECK(src[at(k, 1, Ns)] == glm::ivec2(-1));
    for (int k = 0; k < Ns; ++k)
      CHECK(src[at(k, 2, Ns)] == glm::ivec2(-1));
  }
}

TEST_CASE("EpipolarSampling refinement: a denser initial step on the first quarter of each line near the "
          "epipole") {
  const int W = 160, H = 90, Ns = 128;
  const Camera camera = groundCamera(W, H);
  EpipolarSamplingOptions o;
  o.slices = 32;
  o.samples = Ns;
  o.initialStep = 16;
  o.depthCriterion = o.scatteringCriterion = false; // no breaks: only the initial samples are marched
  struct Case {
    glm::dvec2 ndc;
    int density, denseEnd, denseStep;
  };
  // On screen, and within 10% of the diagonal outside it (0.2 NDC = 16 px of 160, the margin 18.4 px):
  // the first 32 samples (a quarter of 128) at step 16 / D; far off screen, or D = 1: none.
  for (const Case& c : {Case{{0.3, 0.2}, 8, 32, 2}, Case{{1.2, 0.0}, 4, 32, 4}, Case{{0.0, 0.0}, 64, 32, 1},
                        Case{{3.0, 0.0}, 8, 0, 1}, Case{{0.3, 0.2}, 1, 0, 1}}) {
    CAPTURE(c.ndc.x);
    CAPTURE(c.density);
    o.epipoleDensity = c.density;
    const EpipolarLines lines = epipolarLines(camera, lightAt(camera, c.ndc, true), W, H, o);
    CHECK(lines.denseEnd == c.denseEnd);
    CHECK(lines.denseStep == c.denseStep);
    const EpipolarSamples samples = handSamples(lines, 10.0, 1.0);
    const std::vector<glm::ivec2> src = refineSamples(samples, lines, o);
    int marched = 0, expected = 0;
    for (int i = 0; i < o.slices; ++i) {
      const int last = lines.lines[static_cast<std::size_t>(i)].lastValid;
      for (int k = 0; k <= last; ++k) {
        const int step = k < c.denseEnd ? c.denseStep : o.initialStep;
        const bool initial = k % step == 0 || k == last;
        expected += initial;
        const glm::ivec2 s = src[at(k, i, Ns)];
        marched += s == glm::ivec2(k);
        if (!initial) { // interpolated between the ends of its own section
          const int a = k / step * step;
          CHECK(s == glm::ivec2(a, std::min(a + step, last)));
        }
      }
    }
    CHECK(marched == expected);
  }
  o.epipoleDensity = 3;
  CHECK_THROWS_WITH_AS(validate(o), doctest::Contains("EpipolarSamplingOptions.epipoleDensity"),
                       InvalidArgument);
}

TEST_CASE("EpipolarSampling interpolation: a field linear along each line is reproduced exactly") {
  const int W = 96, H = 64;
  const Camera camera = groundCamera(W, H);
  const Medium medium = colouredMedium();
  const Image depth = groundWithBox(camera, W, H);
  EpipolarSamplingOptions o;
  o.slices = 64;
  o.samples = 64;
  o.initialStep = 16;
  const DirectionalLight light = lightAt(camera, {0.2, 0.1}, true);
  const EpipolarLines lines = epipolarLines(camera, light, W, H, o);
  const EpipolarSamples samples = epipolarSamples(lines, depth, camera, light, medium);
  const std::vector<glm::ivec2> src = refineSamples(samples, lines, o);
  const int Ns = o.samples, N = o.slices;
  // Integer-valued linear fields per line and channel (exact in float); garbage at the unmarched samples.
  auto field = [](int k, int i, int c) { return (c + 1) * k + 100 * i - 37 * c; };
  Image marched(Ns, N, 4, std::numeric_limits<float>::quiet_NaN());
  int marchedCount = 0, interpolatedCount = 0;
  for (int i = 0; i < N; ++i)
    for (int k = 0; k < Ns; ++k)
      if (src[at(k, i, Ns)] == glm::ivec2(k)) {
        ++marchedCount;
        for (int c = 0; c < 4; ++c)
          marched.at(k, i, c) = static_cast<float>(field(k, i, c));
      }
  const Image result = interpolateSamples(src, marched);
  double worst = 0.0;
  int invalidNonZero = 0;
  for (int i = 0; i < N; ++i)
    for (int k = 0; k < Ns; ++k) {
      const bool valid = src[at(k, i, Ns)].x >= 0;
      interpolatedCount += valid && src[at(k, i, Ns)] != glm::ivec2(k);
      for (int c = 0; c < 4; ++c) {
        if (!valid) {
          invalidNonZero += result.at(k, i, c) != 0.0f;
          continue;
        }
        worst = std::max(worst, std::abs(double(result.at(k, i, c)) - field(k, i, c)));
      }
    }
  CHECK(worst <= 1e-12);
  CHECK(invalidNonZero == 0);
  CHECK(interpolatedCount > marchedCount); // the test exercises interpolation
  MESSAGE(std::string("interpolation: marched " + std::to_string(marchedCount) + ", interpolated " +
                      std::to_string(interpolatedCount) + ", max error " + fmt(worst)));
}

namespace {

/// The stages up to the unwarp with an evaluator on the marched samples (x, y, d, z of the sample).
struct Staged {
  EpipolarLines lines;
  EpipolarSamples samples;
  std::vector<glm::ivec2> sources;
  Image interpolated;
  UnwarpResult unwarp;
};

template <class Eval>
Staged runStages(const Camera& camera, const DirectionalLight& light, const Image& depth,
                 const EpipolarSamplingOptions& o, const Eval& eval) {
  Staged s;
  s.lines = epipolarLines(camera, light, depth.width(), depth.height(), o);
  s.samples = epipolarSamples(s.lines, depth, camera, light, colouredMedium());
  s.sources = refineSamples(s.samples, s.lines, o);
  Image marched(o.samples, o.slices, 4, std::numeric_limits<float>::quiet_NaN());
  for (int i = 0; i < o.slices; ++i)
    for (int k = 0; k < o.samples; ++k)
      if (s.sources[at(k, i, o.samples)] == glm::ivec2(k)) {
        const glm::dvec4 v = eval(s.samples.coordinates.at(k, i, 3));
        for (int c = 0; c < 4; ++c)
          marched.at(k, i, c) = static_cast<float>(v[c]);
      }
  s.interpolated = interpolateSamples(s.sources, marched);
  s.unwarp = unwarpSamples(s.lines, s.samples, s.interpolated, depth, camera, o);
  return s;
}

/// The test's own total bilateral weight of target pixel (px, py) (F = 1), from the spec's rule.
double unwarpWeight(const Staged& s, const Camera& camera, const Image& depth,
                    const EpipolarSamplingOptions& o, int px, int py) {
  const glm::dvec2 c(px + 0.5, py + 0.5);
  const double z = camera.surfaceViewDepth(depth.at(px, py));
  const std::optional<double> slice = s.lines.sliceOf(c);
  if (!slice) return 0.0;
  const int N = o.slices, Ns = o.samples;
  double f = *slice - std::floor(*slice);
  int lo = static_cast<int>(std::floor(*slice)), hi = lo + 1;
  if (s.lines.epipoleOnScreen) {
    lo = (lo + N) % N;
    hi = (hi + N) % N;
  } else if (*slice <= 0.0 || *slice >= N - 1) {
    lo = hi = *slice <= 0.0 ? 0 : N - 1;
    f = 0.0;
  }
  double total = 0.0;
  const int line[2] = {lo, hi};
  const double lw[2] = {1.0 - f, f};
  for (int j = 0; j < 2; ++j) {
    const EpipolarLines::Line& L = s.lines.lines[static_cast<std::size_t>(line[j])];
    if (L.lastValid < 0) continue;
    const glm::dvec2 a = L.exit - L.entry;
    const double u = std::clamp(glm::dot(c - L.entry, a) / glm::dot(a, a) * (Ns - 1), 0.0, Ns - 1.0);
    const int k0 = std::min(static_cast<int>(u), Ns - 2);
    for (int m = 0; m < 2; ++m) {
      const int k = k0 + m;
      const double w = lw[j] * (m == 0 ? 1.0 - (u - k0) : u - k0);
      if (k > L.lastValid) continue;
      if (std::abs(s.samples.coordinates.at(k, line[j], 3) - z) <= o.bilateralThreshold * z) total += w;
    }
  }
  return total;
}

} // namespace

TEST_CASE("EpipolarSampling unwarp: a constant field stays constant, only the epipole pixel is corrected") {
  const int W = 96, H = 64;
  const Camera camera = groundCamera(W, H);
  const Image depth = groundWithBox(camera, W, H);
  EpipolarSamplingOptions o;
  o.slices = 256;
  o.samples = 128;
  o.initialStep = 8;
  const double constant = 0.75;
  const auto eval = [&](double) { return glm::dvec4(constant, 2 * constant, 3 * constant, 0.5); };
  // The epipole exactly at the centre of pixel (40, 30) (corrected: no slice), on screen elsewhere, and off
  // screen.
  const glm::dvec2 cases[] = {
      {2.0 * 40.5 / W - 1.0, 2.0 * 30.5 / H - 1.0}, {0.23, -0.31}, {1.7, 0.4}, {-0.4, -2.2}};
  for (const glm::dvec2 ndc : cases) {
    CAPTURE(ndc.x);
    for (const double threshold : {0.1, 1e30}) {
      o.bilateralThreshold = threshold;
      const Staged s = runStages(camera, lightAt(camera, ndc, true), depth, o, eval);
      const Image& img = s.unwarp.image;
      REQUIRE(img.width() == W);
      REQUIRE(img.height() == H);
      const std::set<int> corrected(s.unwarp.corrections.begin(), s.unwarp.corrections.end());
      CHECK(std::is_sorted(s.unwarp.corrections.begin(), s.unwarp.corrections.end()));
      CHECK(corrected.size() == s.unwarp.corrections.size());
      double worst = 0.0;
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
          if (corrected.count(y * W + x)) continue;
          for (int c = 0; c < 3; ++c)
            worst = std::max(worst, std::abs(img.at(x, y, c) - (c + 1) * constant));
          worst = std::max(worst, std::abs(img.at(x, y, 3) - 0.5));
        }
      CHECK(worst <= 1e-12);
      if (threshold > 1.0) {
        // Every pixel has a valid sample nearby: only a pixel centre on the epipole is corrected.
        const glm::dvec2 e = s.lines.epipole;
        std::vector<int> expected;
        if (std::abs(e.x - 40.5) < 1e-3 && std::abs(e.y - 30.5) < 1e-3) expected.push_back(30 * W + 40);
        CHECK(s.unwarp.corrections == expected);
      }
      MESSAGE(std::string("constant field, epipole (" + fmt(s.lines.epipole.x) + ", " +
                          fmt(s.lines.epipole.y) + "), bilateral " + fmt(threshold) + ": corrected " +
                          std::to_string(s.unwarp.corrections.size())));
    }
  }
}

TEST_CASE("EpipolarSampling unwarp: no pixel mixes values across a depth edge, corrections are the unfilled "
          "pixels") {
  const int W = 96, H = 64;
  const Camera camera = groundCamera(W, H);
  const double nearZ = 6.0, farZ = 50.0;
  const Image depth = barDepth(camera, W, H, 50, 53, nearZ, farZ);
  EpipolarSamplingOptions o;
  o.slices = 64; // 5 px apart at the border: some pixels see no sample of their own depth
  o.samples = 128;
  o.initialStep = 16;
  o.bilateralThreshold = 0.1;
  const auto eval = [](double z) { return glm::dvec4(z, z, z, 1.0); }; // the value is the sample's view depth
  // Epipoles beside the bar (lines across it), above and below it (lines along it), off screen.
  const glm::dvec2 cases[] = {{-0.3, 0.2}, {0.6, -0.5}, {2.2, 0.3}, {-0.1, -1.9}, {0.07, 0.6}, {0.08, -1.6}};
  int totalCorrected = 0;
  for (const glm::dvec2 ndc : cases) {
    CAPTURE(ndc.x);
    const Staged s = runStages(camera, lightAt(camera, ndc, true), depth, o, eval);
    const std::set<int> corrected(s.unwarp.corrections.begin(), s.unwarp.corrections.end());
    double worst = 0.0;
    int mismatched = 0, nearEdge = 0;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const double z = camera.surfaceViewDepth(depth.at(x, y));
        CHECK(s.unwarp.coordinates.at(x, y, 3) == doctest::Approx(z).epsilon(1e-6));
        const double total = unwarpWeight(s, camera, depth, o, x, y);
        mismatched += (total <= 1e-4) != (corrected.count(y * W + x) == 1);
        if (corrected.count(y * W + x)) {
          // Next to the bar's edges, or a screen corner (its centre can lie beyond the last valid sample of
          // both its lines when they leave the screen through different sides).
          const bool corner = std::min(x, W - 1 - x) <= 1 && std::min(y, H - 1 - y) <= 1;
          nearEdge += std::min(std::abs(x - 50), std::abs(x - 52)) <= 2 || corner;
          continue;
        }
        worst = std::max(worst, std::abs(s.unwarp.image.at(x, y, 0) - z) / z);
      }
    CHECK(worst <= o.bilateralThreshold);
    CHECK(worst < 1e-6); // constant depth per region: every source matches exactly
    CHECK(mismatched == 0);
    CHECK(nearEdge == static_cast<int>(corrected.size()));
    totalCorrected += static_cast<int>(corrected.size());
    MESSAGE(std::string("thin bar, epipole (" + fmt(s.lines.epipole.x) + ", " + fmt(s.lines.epipole.y) +
                        "): corrected " + std::to_string(corrected.size()) + ", worst relative " +
                        fmt(worst)));
  }
  CHECK(totalCorrected > 0); // the comparison with the recomputed weights is not vacuous
}

TEST_CASE(
    "EpipolarSampling upscale: values stay on their side of depth edges, unreachable pixels are corrected") {
  const int W = 96, H = 64;
  const Camera camera = groundCamera(W, H);
  Image depth = barDepth(camera, W, H, 49, 55, 6.0, 50.0);
  // A 1-px bar at column 44: no target texel (columns F i + F / 2) sees it for F = 2, 4.
  for (int y = 0; y < H; ++y)
    depth.at(44, y) = static_cast<float>(depthBufferValue(camera, 6.0));
  for (const int F : {2, 4}) {
    EpipolarSamplingOptions o;
    o.downscale = F;
    const int w = W / F, h = H / F;
    UnwarpResult target{Image(w, h, 4), Image(w, h, 4), {}};
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double d = depth.at(x * F + F / 2, y * F + F / 2), z = camera.surfaceViewDepth(d);
        target.coordinates.at(x, y, 3) = static_cast<float>(z);
        for (int c = 0; c < 4; ++c)
          target.image.at(x, y, c) = static_cast<float>(z);
      }
    const UnwarpResult full = upscaleSamples(target, depth, camera, o);
    const std::set<int> corrected(full.corrections.begin(), full.corrections.end());
    double worst = 0.0;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        CHECK(full.coordinates.at(x, y, 0) == x + 0.5f);
        if (corrected.count(y * W + x)) continue;
        const double z = camera.surfaceViewDepth(depth.at(x, y));
        worst = std::max(worst, std::abs(full.image.at(x, y, 0) - z) / z);
      }
    CHECK(worst < 1e-6);
    // The wide bar (6 px) has a target texel in reach of each of its pixels and so has the background next
    // to it: the corrected pixels are exactly the thin bar's.
    std::vector<int> expected;
    for (int y = 0; y < H; ++y)
      expected.push_back(y * W + 44);
    CHECK(full.corrections == expected);
    MESSAGE(
        std::string("upscale F = " + std::to_string(F) + ": corrected " + std::to_string(corrected.size())));
  }
}

TEST_CASE("EpipolarSampling pipeline: the unshadowed closed form within 1 percent for F = 1, 2, 4") {
  const int W = 320, H = 192;
  const Camera camera = groundCamera(W, H);
  const Medium medium = colouredMedium();
  const Image depth = groundWithBox(camera, W, H);
  struct Case {
    const char* name;
    DirectionalLight light;
  };
  const Case cases[] = {{"side light (anti-epipole off screen)", sideLight()},
                        {"low sun in view", lightAt(camera, {0.25, 0.35}, true)},
                        {"sun behind (anti-epipole on screen)", lightAt(camera, {-0.3, -0.2}, false)}};
  for (const Case& c : cases) {
    const Image ref = closedForm(depth, camera, c.light, medium, std::nullopt);
    for (const int F : {1, 2, 4}) {
      const std::string name = c.name;
      CAPTURE(name);
      CAPTURE(F);
      EpipolarSamplingOptions o;
      o.slices = 256;
      o.samples = 128;
      o.initialStep = 8;
      o.downscale = F;
      int evaluations = 0;
      const EpipolarSamplingResult r =
          epipolarSampling(camera, c.light, medium, depth, o, [&](double x, double y, double d) {
            ++evaluations;
            return closedFormRay(camera, c.light, medium, W, H, x, y, d);
          });
      REQUIRE(r.image.width() == W);
      REQUIRE(r.image.height() == H);
      int nonFinite = 0;
      for (const float v : r.image.data())
        nonFinite += !std::isfinite(v);
      CHECK(nonFinite == 0);
      CHECK(evaluations == r.marchedSamples + r.correctedPixels + r.correctedFullPixels);
      CHECK(r.marchedSamples <= r.validSamples);
      if (F == 1) CHECK(r.correctedFullPixels == 0);
      const ImageMetrics m = rgbMetrics(r.image, ref);
      CHECK(m.relativeRmse < 0.01);
      MESSAGE(std::string(std::string(c.name) + ", F = " + std::to_string(F) + ": relative RMSE " +
                          fmt(m.relativeRmse) + ", max abs " + fmt(m.maxAbsError) + " (peak " + fmt(m.peak) +
                          "); samples valid " + std::to_string(r.validSamples) + ", marched " +
                          std::to_string(r.marchedSamples) + ", corrected " +
                          std::to_string(r.correctedPixels) + " target + " +
                          std::to_string(r.correctedFullPixels) + " full"));
    }
  }
}

TEST_CASE("EpipolarSampling pipeline: every output pixel is written (constant evaluator)") {
  const int W = 160, H = 96;
  const Camera camera = groundCamera(W, H);
  const Image depth = groundWithBox(camera, W, H);
  const glm::dvec4 value(0.25, 0.5, 1.5, 0.75);
  for (const int F : {1, 2, 4})
    for (const glm::dvec2 ndc : {glm::dvec2(0.1, 0.2), glm::dvec2(1.6, -0.4)}) {
      CAPTURE(F);
      EpipolarSamplingOptions o;
      o.slices = 128;
      o.samples = 64;
      o.downscale = F;
      o.bilateralThreshold = 0.0; // only exact depth matches: many corrections
      const EpipolarSamplingResult r =
          epipolarSampling(camera, lightAt(camera, ndc, true), colouredMedium(), depth, o,
                           [&](double, double, double) { return value; });
      int wrong = 0;
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
          for (int c = 0; c < 4; ++c)
            wrong += r.image.at(x, y, c) != static_cast<float>(value[c]);
      CHECK(wrong == 0);
      CHECK(r.correctedPixels > 0);
      MESSAGE(std::string("constant, bilateral 0, F = " + std::to_string(F) + ": valid " +
                          std::to_string(r.validSamples) + ", marched " + std::to_string(r.marchedSamples) +
                          ", corrected " + std::to_string(r.correctedPixels) + " + " +
                          std::to_string(r.correctedFullPixels)));
    }
}

TEST_CASE("EpipolarSampling validate: each option and size out of range names its field") {
  const auto bad = [&](auto change) {
    EpipolarSamplingOptions o;
    change(o);
    return invalidParameter([&] { validate(o); });
  };
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(invalidParameter([] { validate(EpipolarSamplingOptions{}); }) == "no exception");
  CHECK(bad([](auto& o) { o.slices = 0; }) == "EpipolarSamplingOptions.slices");
  CHECK(bad([](auto& o) { o.slices = 16385; }) == "EpipolarSamplingOptions.slices");
  CHECK(bad([](auto& o) { o.samples = 48; }) == "EpipolarSamplingOptions.samples");
  CHECK(bad([](auto& o) { o.samples = 0; }) == "EpipolarSamplingOptions.samples");
  CHECK(bad([](auto& o) { o.samples = 1056; }) == "EpipolarSamplingOptions.samples");
  CHECK(bad([](auto& o) { o.initialStep = 0; }) == "EpipolarSamplingOptions.initialStep");
  CHECK(bad([](auto& o) { o.initialStep = 12; }) == "EpipolarSamplingOptions.initialStep");
  CHECK(bad([](auto& o) {
          o.samples = 64;
          o.initialStep = 128;
        }) == "EpipolarSamplingOptions.initialStep");
  CHECK(bad([](auto& o) { o.depthThreshold = 0.0; }) == "EpipolarSamplingOptions.depthThreshold");
  CHECK(bad([&](auto& o) { o.depthThreshold = inf; }) == "EpipolarSamplingOptions.depthThreshold");
  CHECK(bad([&](auto& o) { o.scatteringThreshold = nan; }) == "EpipolarSamplingOptions.scatteringThreshold");
  CHECK(bad([](auto& o) { o.scatteringThreshold = -1.0; }) == "EpipolarSamplingOptions.scatteringThreshold");
  CHECK(bad([](auto& o) { o.bilateralThreshold = -0.1; }) == "EpipolarSamplingOptions.bilateralThreshold");
  CHECK(bad([&](auto& o) { o.bilateralThreshold = inf; }) == "EpipolarSamplingOptions.bilateralThreshold");
  CHECK(bad([](auto& o) { o.downscale = 3; }) == "EpipolarSamplingOptions.downscale");
  EpipolarSamplingOptions o;
  o.downscale = 0;
  CHECK(invalidParameter([&] { validate(o, "EpipolarSamplingPass::CreateInfo.options"); }) ==
        "EpipolarSamplingPass::CreateInfo.options.downscale");

  // Sizes.
  const Camera camera = groundCamera(96, 64);
  const DirectionalLight light = sideLight();
  o = EpipolarSamplingOptions{};
  o.slices = 16;
  o.samples = 32;
  o.downscale = 4;
  CHECK(invalidParameter([&] { epipolarLines(camera, light, 0, 64, o); }) == "width");
  CHECK(invalidParameter([&] { epipolarLines(camera, light, 98, 64, o); }) == "width");
  CHECK(invalidParameter([&] { epipolarLines(camera, light, 96, 66, o); }) == "height");
  const EpipolarLines lines = epipolarLines(camera, light, 96, 64, o);
  const Image depth = groundDepth(camera, 96, 64);
  CHECK(invalidParameter([&] {
          epipolarSamples(lines, groundDepth(camera, 64, 64), camera, light, colouredMedium());
        }) == "cameraDepth");
  Image badDepth = depth;
  badDepth.at(3, 3) = 2.0f;
  CHECK(invalidParameter([&] { epipolarSamples(lines, badDepth, camera, light, colouredMedium()); }) ==
        "cameraDepth");
  const EpipolarSamples samples = epipolarSamples(lines, depth, camera, light, colouredMedium());
  const std::vector<glm::ivec2> sources = refineSamples(samples, lines, o);
  EpipolarSamples wrong = samples;
  wrong.unshadowed = Image(32, 15, 1);
  CHECK(invalidParameter([&] { refineSamples(wrong, lines, o); }) == "refineSamples.samples.unshadowed");
  CHECK(invalidParameter([&] { interpolateSamples(sources, Image(32, 15, 4)); }) ==
        "interpolateSamples.marched");
  const Image interpolated = interpolateSamples(sources, Image(32, 16, 4));
  CHECK(invalidParameter([&] { unwarpSamples(lines, samples, Image(32, 16, 3), depth, camera, o); }) ==
        "unwarpSamples.interpolated");
  const UnwarpResult target = unwarpSamples(lines, samples, interpolated, depth, camera, o);
  CHECK(target.image.width() == 24);
  CHECK(target.image.height() == 16);
  EpipolarSamplingOptions o2 = o;
  o2.downscale = 2;
  CHECK(invalidParameter([&] { upscaleSamples(target, depth, camera, o2); }) ==
        "upscaleSamples.target.image");
  CHECK(invalidParameter([&] {
          epipolarSampling(camera, light, colouredMedium(), groundDepth(camera, 90, 64), o,
                           [](double, double, double) { return glm::dvec4(0.0); });
        }) == "width");
}
