#include "common/error_checks.h"

#include <crep/core/camera.h>
#include <crep/core/error.h>

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

using crep::Camera;
using crep::test::requireNamedInMessage;

namespace {
const double kNan = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

glm::dvec3 project(const glm::dmat4& clipFromWorld, const glm::dvec3& p) {
  const glm::dvec4 c = clipFromWorld * glm::dvec4(p, 1.0);
  return glm::dvec3(c) / c.w;
}

Camera makeCamera() {
  return Camera::lookAt({1, 2, 3}, {-4, 0.5, -7}, {0, 1, 0}, std::numbers::pi / 3, 1.7, 0.25, 90.0);
}
} // namespace

TEST_CASE("Camera: view and world matrices are inverse rotations + translation") {
  const Camera cam = makeCamera();
  const glm::dmat4 id = cam.viewFromWorld() * cam.worldFromView();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      CHECK(id[c][r] == doctest::Approx(c == r ? 1.0 : 0.0).epsilon(1e-14).scale(1.0));
  // The camera position maps to the view-space origin; the target lies on -Z.
  const glm::dvec3 origin(cam.viewFromWorld() * glm::dvec4(cam.position(), 1.0));
  CHECK(glm::length(origin) < 1e-12);
  const glm::dvec3 target(cam.viewFromWorld() * glm::dvec4(-4, 0.5, -7, 1.0));
  CHECK(std::abs(target.x) < 1e-12);
  CHECK(std::abs(target.y) < 1e-12);
  CHECK(target.z < 0.0);
  CHECK(glm::length(cam.forward() - glm::normalize(glm::dvec3(-5, -1.5, -10))) < 1e-12);
  // Up is orthogonal to forward and has a positive world-up component.
  CHECK(std::abs(glm::dot(cam.up(), cam.forward())) < 1e-12);
  CHECK(cam.up().y > 0.0);
  CHECK(glm::length(glm::cross(cam.right(), cam.up()) + cam.forward()) <
        1e-12); // right-handed, looks down -Z
}

TEST_CASE("Camera: frustum corners project onto the NDC cube corners") {
  const Camera cam = makeCamera();
  const crep::FrustumCorners corners = cam.frustumCorners();
  const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
  for (int i = 0; i < 8; ++i) {
    const glm::dvec3 ndc = project(cam.clipFromWorld(), corners[static_cast<std::size_t>(i)]);
    CHECK(ndc.x == doctest::Approx(sx[i % 4]).epsilon(1e-9));
    CHECK(ndc.y == doctest::Approx(sy[i % 4]).epsilon(1e-9));
    CHECK(ndc.z == doctest::Approx(i < 4 ? -1.0 : 1.0).epsilon(1e-9));
    // Corner distance along the view direction is near or far.
    CHECK(glm::dot(corners[static_cast<std::size_t>(i)] - cam.position(), cam.forward()) ==
          doctest::Approx(i < 4 ? cam.near() : cam.far()).epsilon(1e-12));
  }
}

TEST_CASE("Camera: rayDirection and linearDepth invert the projection") {
  const Camera cam = makeCamera();
  for (double x : {-1.0, -0.3, 0.0, 0.8})
    for (double y : {-1.0, 0.25, 1.0})
      for (double dist : {0.25, 1.0, 17.0, 89.0}) {
        const glm::dvec3 dir = cam.rayDirection(x, y);
        CHECK(glm::length(dir) == doctest::Approx(1.0).epsilon(1e-14));
        const glm::dvec3 p = cam.position() + dir * (dist / glm::dot(dir, cam.forward()));
        const glm::dvec3 ndc = project(cam.clipFromWorld(), p);
        CHECK(ndc.x == doctest::Approx(x).epsilon(1e-9).scale(1.0));
        CHECK(ndc.y == doctest::Approx(y).epsilon(1e-9).scale(1.0));
        const double depthBuffer = 0.5 * ndc.z + 0.5;
        CHECK(cam.linearDepth(depthBuffer) == doctest::Approx(dist).epsilon(1e-9));
      }
}

TEST_CASE("Camera: invalid parameters throw InvalidArgument naming the parameter") {
  const glm::dquat q(1, 0, 0, 0);
  requireNamedInMessage([&] { Camera({kNan, 0, 0}, q, 1.0, 1.0, 0.1, 10.0); }, "Camera.position");
  requireNamedInMessage(
      [&] {
        Camera({0, 0, 0}, glm::dquat(0, 0, 0, 0), 1.0, 1.0, 0.1, 10.0);
      },
      "Camera.orientation");
  requireNamedInMessage([&] { Camera({0, 0, 0}, q, 0.0, 1.0, 0.1, 10.0); }, "Camera.fovY");
  requireNamedInMessage([&] { Camera({0, 0, 0}, q, std::numbers::pi, 1.0, 0.1, 10.0); }, "Camera.fovY");
  requireNamedInMessage([&] { Camera({0, 0, 0}, q, kNan, 1.0, 0.1, 10.0); }, "Camera.fovY");
  requireNamedInMessage([&] { Camera({0, 0, 0}, q, 1.0, 0.0, 0.1, 10.0); }, "Camera.aspect");
  requireNamedInMessage([&] { Camera({0, 0, 0}, q, 1.0, -2.0, 0.1, 10.0); }, "Camera.aspect");
  requireNamedInMessage([&] { Camera({0, 0, 0}, q, 1.0, 1.0, 0.0, 10.0); }, "Camera.near");
  requireNamedInMessage([&] { Camera({0, 0, 0}, q, 1.0, 1.0, -1.0, 10.0); }, "Camera.near");
  requireNamedInMessage([&] { Camera({0, 0, 0}, q, 1.0, 1.0, 1.0, 1.0); }, "Camera.far");
  requireNamedInMessage([&] { Camera({0, 0, 0}, q, 1.0, 1.0, 1.0, 0.5); }, "Camera.far");
  requireNamedInMessage([&] { Camera({0, 0, 0}, q, 1.0, 1.0, 1.0, kInf); }, "Camera.far");
  requireNamedInMessage(
      [&] {
        Camera::lookAt({1, 1, 1}, {1, 1, 1}, {0, 1, 0}, 1.0, 1.0, 0.1, 10.0);
      },
      "Camera.target");
  requireNamedInMessage(
      [&] {
        Camera::lookAt({0, 0, 0}, {0, 5, 0}, {0, 1, 0}, 1.0, 1.0, 0.1, 10.0);
      },
      "Camera.up");
  requireNamedInMessage(
      [&] {
        Camera::lookAt({0, 0, 0}, {0, 0, -1}, {0, 0, 0}, 1.0, 1.0, 0.1, 10.0);
      },
      "Camera.up");
  // The message carries the offending value.
  try {
    Camera({0, 0, 0}, q, 1.0, 1.0, -0.5, 10.0);
  } catch (const crep::InvalidArgument& e) {
    CHECK(std::string(e.what()).find("-0.5") != std::string::npos);
  }
}

// ---------------------------------------------------------------------------------------------------
// Engine conventions (Camera::fromMatrices). The expected depths come from the matrices themselves: a
// world point is projected with the engine's clipFromView * viewFromWorld, its window depth is taken by the
// clip convention's rule (NDC z -> (z + 1) / 2 or z), and linearDepth must give back its view distance.

namespace {

/// The engine's window depth of world point p under `clipFromWorld` in a clip-depth convention.
double windowDepth(const glm::dmat4& clipFromWorld, const glm::dvec3& p, crep::ClipDepth convention) {
  const double z = project(clipFromWorld, p).z;
  return convention == crep::ClipDepth::NegativeOneToOne ? 0.5 * (z + 1.0) : z;
}

/// A reversed-Z, [0, 1] clip depth, infinite far projection (the common modern engine matrix):
/// clip z = near, w = -z_view, so depth = near / Z.
glm::dmat4 reversedInfinite(double fovY, double aspect, double near) {
  const double ty = std::tan(0.5 * fovY);
  glm::dmat4 m(0.0);
  m[0][0] = 1.0 / (ty * aspect);
  m[1][1] = 1.0 / ty;
  m[2][3] = -1.0;
  m[3][2] = near;
  return m;
}

} // namespace

TEST_CASE("Camera::fromMatrices: GL's own matrices give the same camera") {
  const Camera c = makeCamera();
  const Camera m = Camera::fromMatrices(c.viewFromWorld(), c.clipFromView());
  CHECK(glm::length(m.position() - c.position()) < 1e-12);
  CHECK(glm::length(m.forward() - c.forward()) < 1e-12);
  CHECK(glm::length(m.up() - c.up()) < 1e-12);
  CHECK(m.near() == doctest::Approx(c.near()).epsilon(1e-12));
  CHECK(m.far() == doctest::Approx(c.far()).epsilon(1e-12));
  CHECK(m.fovY() == doctest::Approx(c.fovY()).epsilon(1e-12));
  CHECK(m.aspect() == doctest::Approx(c.aspect()).epsilon(1e-12));
  CHECK_FALSE(m.reversedZ());
  CHECK(m.symmetric());
  for (const double d : {0.0, 0.3, 0.9, 0.999, 1.0})
    CHECK(m.linearDepth(d) == doctest::Approx(c.linearDepth(d)).epsilon(1e-10));
}

TEST_CASE("Camera::fromMatrices: reversed-Z, [0, 1] clip depth and an infinite far plane") {
  const Camera c = makeCamera();
  const glm::dmat4 proj = reversedInfinite(c.fovY(), c.aspect(), c.near());
  const Camera r = Camera::fromMatrices(c.viewFromWorld(), proj, crep::ClipDepth::ZeroToOne, 120.0);
  CHECK(r.reversedZ());
  CHECK(std::isinf(r.projectionFar()));
  CHECK(r.far() == 120.0);
  CHECK(r.near() == doctest::Approx(c.near()).epsilon(1e-12));
  CHECK(r.clipDepth() == crep::ClipDepth::ZeroToOne);
  // The camera's own projection is the engine's.
  const glm::dmat4 back = r.clipFromView();
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 4; ++k)
      CHECK(back[i][k] == doctest::Approx(proj[i][k]).epsilon(1e-12));
  // Depths as the engine writes them, read back as view distances.
  const glm::dmat4 clipFromWorld = proj * c.viewFromWorld();
  for (const double t : {0.3, 1.0, 7.5, 60.0, 500.0}) {
    const glm::dvec3 p = c.position() + t * c.rayDirection(0.2, -0.4);
    const double Z = glm::dot(p - c.position(), c.forward());
    const double d = windowDepth(clipFromWorld, p, crep::ClipDepth::ZeroToOne);
    CHECK(d == doctest::Approx(c.near() / Z).epsilon(1e-12));
    CHECK(r.linearDepth(d) == doctest::Approx(Z).epsilon(1e-10));
    CHECK(r.depthBufferValue(Z) == doctest::Approx(d).epsilon(1e-12));
    CHECK(r.surfaceViewDepth(d) == doctest::Approx(std::min(Z, 120.0)).epsilon(1e-10));
  }
  CHECK(r.surfaceViewDepth(0.0) == 120.0); // cleared to 0: the sky, integrated to maxDistance
  CHECK(r.surfaceViewDepth(1.0) == doctest::Approx(c.near()).epsilon(1e-12));
  CHECK(r.surfaceViewDepth(kNan) == 120.0);
  // The frustum the library covers ends at maxDistance.
  const crep::FrustumCorners corners = r.frustumCorners(), expected = makeCamera().frustumCorners();
  for (int i = 0; i < 4; ++i)
    CHECK(glm::length(corners[std::size_t(i)] - expected[std::size_t(i)]) < 1e-9);
  CHECK(glm::dot(corners[4] - r.position(), r.forward()) == doctest::Approx(120.0).epsilon(1e-12));
}

TEST_CASE("Camera::fromMatrices: every clip convention, reversal and far plane reads its own depths") {
  const Camera c = makeCamera();
  for (const auto convention : {crep::ClipDepth::NegativeOneToOne, crep::ClipDepth::ZeroToOne})
    for (const bool reversed : {false, true})
      for (const bool infinite : {false, true}) {
        CAPTURE(static_cast<int>(convention));
        CAPTURE(reversed);
        CAPTURE(infinite);
        // Build the engine matrix from its definition: d(Z) = a + b / Z with d(near) = 0 or 1 and d(far) the
        // other, then the clip depth row of the convention.
        const double n = c.near(), f = infinite ? kInf : 90.0;
        const double dn = reversed ? 1.0 : 0.0, df = reversed ? 0.0 : 1.0;
        const double b = infinite ? (dn - df) * n : (dn - df) / (1.0 / n - 1.0 / f);
        const double a = dn - b / n;
        glm::dmat4 p = c.clipFromView();
        p[2][2] = convention == crep::ClipDepth::NegativeOneToOne ? 1.0 - 2.0 * a : -a;
        p[3][2] = convention == crep::ClipDepth::NegativeOneToOne ? 2.0 * b : b;
        const Camera e = Camera::fromMatrices(c.viewFromWorld(), p, convention, infinite ? 80.0 : 0.0);
        CHECK(e.reversedZ() == reversed);
        CHECK(std::isinf(e.projectionFar()) == infinite);
        CHECK(e.near() == doctest::Approx(n).epsilon(1e-12));
        for (const double t : {0.5, 3.0, 40.0}) {
          const glm::dvec3 q = c.position() + t * c.rayDirection(-0.6, 0.1);
          const double Z = glm::dot(q - c.position(), c.forward());
          const double d = windowDepth(p * c.viewFromWorld(), q, convention);
          CHECK(e.linearDepth(d) == doctest::Approx(Z).epsilon(1e-9));
        }
        const glm::dmat4 back = e.clipFromView();
        for (int i = 0; i < 4; ++i)
          for (int k = 0; k < 4; ++k)
            CHECK(back[i][k] == doctest::Approx(p[i][k]).epsilon(1e-12));
      }
}

TEST_CASE("Camera::fromMatrices: off-centre projections (jitter, asymmetric frusta)") {
  const Camera c = makeCamera();
  // Sub-pixel jitter as a TAA engine applies it: the ray of NDC x is the unjittered ray of x + jx.
  const double jx = 2.0 * 0.37 / 1280.0, jy = -2.0 * 0.21 / 720.0;
  glm::dmat4 p = c.clipFromView();
  p[2][0] += jx;
  p[2][1] += jy;
  const Camera j = Camera::fromMatrices(c.viewFromWorld(), p);
  CHECK_FALSE(j.symmetric());
  for (const glm::dvec2 ndc : {glm::dvec2(-1, -1), glm::dvec2(0.3, 0.8), glm::dvec2(1, 1)})
    CHECK(glm::length(j.rayDirection(ndc.x, ndc.y) - c.rayDirection(ndc.x + jx, ndc.y + jy)) < 1e-12);
  // A world point projects where the ray through its NDC says (the matrix and the rays agree).
  const glm::dvec3 q = c.position() + 5.0 * c.rayDirection(0.1, 0.2);
  const glm::dvec3 ndc = project(p * c.viewFromWorld(), q);
  CHECK(glm::length(j.rayDirection(ndc.x, ndc.y) - glm::normalize(q - c.position())) < 1e-12);
  // The left half of the frustum (a VR eye's outer half): its frustum corners are the symmetric camera's
  // left corners and the centre line.
  const double tx = std::tan(0.5 * c.fovY()) * c.aspect();
  glm::dmat4 half = c.clipFromView();
  half[0][0] = 2.0 / tx; // x from -tx to 0
  half[2][0] = -1.0;
  const Camera h = Camera::fromMatrices(c.viewFromWorld(), half);
  CHECK(h.tangents().x == doctest::Approx(-tx).epsilon(1e-12));
  CHECK(std::abs(h.tangents().y) < 1e-12);
  CHECK(h.aspect() == doctest::Approx(c.aspect()).epsilon(1e-12)); // the symmetric cover
  const crep::FrustumCorners hc = h.frustumCorners(), cc = c.frustumCorners();
  CHECK(glm::length(hc[0] - cc[0]) < 1e-9);
  CHECK(glm::length(hc[1] - 0.5 * (cc[0] + cc[1])) < 1e-9);
}

TEST_CASE("Camera::fromMatrices: bad matrices are named") {
  const Camera c = makeCamera();
  glm::dmat4 p = c.clipFromView();
  glm::dmat4 nan = p;
  nan[1][1] = kNan;
  requireNamedInMessage([&] { Camera::fromMatrices(c.viewFromWorld(), nan); }, "Camera.clipFromView");
  glm::dmat4 ortho(1.0);
  ortho[2][2] = -0.1;
  requireNamedInMessage([&] { Camera::fromMatrices(c.viewFromWorld(), ortho); }, "Camera.clipFromView");
  glm::dmat4 scaled = c.viewFromWorld();
  scaled[0] *= 2.0;
  requireNamedInMessage([&] { Camera::fromMatrices(scaled, p); }, "Camera.viewFromWorld");
  const glm::dmat4 inf = reversedInfinite(1.0, 1.5, 0.1);
  requireNamedInMessage([&] { Camera::fromMatrices(c.viewFromWorld(), inf, crep::ClipDepth::ZeroToOne); },
                        "Camera.maxDistance");
  requireNamedInMessage(
      [&] { Camera::fromMatrices(c.viewFromWorld(), inf, crep::ClipDepth::ZeroToOne, 0.05); },
      "Camera.maxDistance");
  glm::dmat4 flipped = p; // near behind the camera
  flipped[3][2] = -flipped[3][2];
  requireNamedInMessage([&] { Camera::fromMatrices(c.viewFromWorld(), flipped); }, "Camera.clipFromView");
}
