#include <crep/core/camera.h>
#include <crep/core/error.h>

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

using crep::Camera;

namespace {
const double kNan = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

glm::dvec3 project(const glm::dmat4& clipFromWorld, const glm::dvec3& p) {
  const glm::dvec4 c = clipFromWorld * glm::dvec4(p, 1.0);
  return glm::dvec3(c) / c.w;
}

// Expects InvalidArgument whose parameter is `parameter` and whose message names it.
template <class F>
void expectInvalid(const std::string& parameter, F&& f) {
  try {
    f();
    FAIL("expected InvalidArgument for " << parameter);
  } catch (const crep::InvalidArgument& e) {
    CHECK(e.parameter() == parameter);
    CHECK(std::string(e.what()).find(parameter) != std::string::npos);
  }
}

Camera makeCamera() {
  return Camera::lookAt({1, 2, 3}, {-4, 0.5, -7}, {0, 1, 0}, std::numbers::pi / 3, 1.7, 0.25, 90.0);
}
} // namespace

TEST_CASE("Camera: view and world matrices are inverse rotations + translation") {
  const Camera cam = makeCamera();
  const glm::dmat4 id = cam.viewFromWorld() * cam.worldFromView();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) CHECK(id[c][r] == doctest::Approx(c == r ? 1.0 : 0.0).epsilon(1e-14).scale(1.0));
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
  CHECK(glm::length(glm::cross(cam.right(), cam.up()) + cam.forward()) < 1e-12); // right-handed, looks down -Z
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
  expectInvalid("Camera.position", [&] { Camera({kNan, 0, 0}, q, 1.0, 1.0, 0.1, 10.0); });
  expectInvalid("Camera.orientation", [&] { Camera({0, 0, 0}, glm::dquat(0, 0, 0, 0), 1.0, 1.0, 0.1, 10.0); });
  expectInvalid("Camera.fovY", [&] { Camera({0, 0, 0}, q, 0.0, 1.0, 0.1, 10.0); });
  expectInvalid("Camera.fovY", [&] { Camera({0, 0, 0}, q, std::numbers::pi, 1.0, 0.1, 10.0); });
  expectInvalid("Camera.fovY", [&] { Camera({0, 0, 0}, q, kNan, 1.0, 0.1, 10.0); });
  expectInvalid("Camera.aspect", [&] { Camera({0, 0, 0}, q, 1.0, 0.0, 0.1, 10.0); });
  expectInvalid("Camera.aspect", [&] { Camera({0, 0, 0}, q, 1.0, -2.0, 0.1, 10.0); });
  expectInvalid("Camera.near", [&] { Camera({0, 0, 0}, q, 1.0, 1.0, 0.0, 10.0); });
  expectInvalid("Camera.near", [&] { Camera({0, 0, 0}, q, 1.0, 1.0, -1.0, 10.0); });
  expectInvalid("Camera.far", [&] { Camera({0, 0, 0}, q, 1.0, 1.0, 1.0, 1.0); });
  expectInvalid("Camera.far", [&] { Camera({0, 0, 0}, q, 1.0, 1.0, 1.0, 0.5); });
  expectInvalid("Camera.far", [&] { Camera({0, 0, 0}, q, 1.0, 1.0, 1.0, kInf); });
  expectInvalid("Camera.target", [&] { Camera::lookAt({1, 1, 1}, {1, 1, 1}, {0, 1, 0}, 1.0, 1.0, 0.1, 10.0); });
  expectInvalid("Camera.up", [&] { Camera::lookAt({0, 0, 0}, {0, 5, 0}, {0, 1, 0}, 1.0, 1.0, 0.1, 10.0); });
  expectInvalid("Camera.up", [&] { Camera::lookAt({0, 0, 0}, {0, 0, -1}, {0, 0, 0}, 1.0, 1.0, 0.1, 10.0); });
  // The message carries the offending value.
  try {
    Camera({0, 0, 0}, q, 1.0, 1.0, -0.5, 10.0);
  } catch (const crep::InvalidArgument& e) {
    CHECK(std::string(e.what()).find("-0.5") != std::string::npos);
  }
}
