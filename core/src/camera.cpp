#include <crep/core/camera.h>
#include <crep/core/error.h>

#include "validate.h"

#include <cmath>
#include <numbers>

#include <glm/gtc/matrix_transform.hpp>

namespace crep {

Camera::Camera(const glm::dvec3& position, const glm::dquat& orientation, double fovY, double aspect, double near,
               double far)
    : position_(position), fovY_(fovY), aspect_(aspect), near_(near), far_(far) {
  detail::requireFiniteVec3("Camera.position", position);
  const double qlen = std::sqrt(orientation.w * orientation.w + orientation.x * orientation.x +
                                orientation.y * orientation.y + orientation.z * orientation.z);
  if (!std::isfinite(qlen) || qlen < 1e-12)
    throw InvalidArgument("Camera.orientation", detail::formatValue(qlen) + " (quaternion length)",
                          "must be a finite, non-zero quaternion");
  orientation_ = orientation / qlen;
  if (!std::isfinite(fovY) || !(fovY > 0.0) || !(fovY < std::numbers::pi))
    throw InvalidArgument("Camera.fovY", detail::formatValue(fovY), "radians, must be in (0, pi)");
  requirePositive("Camera.aspect", aspect);
  requirePositive("Camera.near", near);
  requirePositive("Camera.far", far);
  if (!(far > near))
    throw InvalidArgument("Camera.far", detail::formatValue(far),
                          "must be > Camera.near = " + detail::formatValue(near));
}

Camera Camera::lookAt(const glm::dvec3& position, const glm::dvec3& target, const glm::dvec3& up, double fovY,
                      double aspect, double near, double far) {
  detail::requireFiniteVec3("Camera.position", position);
  detail::requireFiniteVec3("Camera.target", target);
  detail::requireFiniteVec3("Camera.up", up);
  const glm::dvec3 toTarget = target - position;
  const double dist = glm::length(toTarget);
  if (!(dist > 0.0) || !std::isfinite(dist))
    throw InvalidArgument("Camera.target", "position + " + detail::formatValue(dist), "must differ from Camera.position");
  const glm::dvec3 f = toTarget / dist;
  const double upLen = glm::length(up);
  if (!(upLen > 0.0))
    throw InvalidArgument("Camera.up", detail::formatValue(upLen) + " (length)", "must be non-zero");
  glm::dvec3 r = glm::cross(f, up / upLen);
  const double rLen = glm::length(r);
  if (!(rLen > 1e-9))
    throw InvalidArgument("Camera.up", detail::formatValue(rLen) + " (sine of the angle to the view direction)",
                          "must not be parallel to the view direction");
  r /= rLen;
  const glm::dvec3 u = glm::cross(r, f);
  // Columns of worldFromView's rotation: view +X = r, +Y = u, +Z = -f.
  const glm::dmat3 worldFromViewRot(r, u, -f);
  return Camera(position, glm::quat_cast(worldFromViewRot), fovY, aspect, near, far);
}

glm::dvec3 Camera::forward() const { return orientation_ * glm::dvec3(0, 0, -1); }
glm::dvec3 Camera::right() const { return orientation_ * glm::dvec3(1, 0, 0); }
glm::dvec3 Camera::up() const { return orientation_ * glm::dvec3(0, 1, 0); }

glm::dmat4 Camera::worldFromView() const {
  glm::dmat4 m(glm::mat3_cast(orientation_));
  m[3] = glm::dvec4(position_, 1.0);
  return m;
}

glm::dmat4 Camera::viewFromWorld() const {
  const glm::dmat3 viewFromWorldRot = glm::transpose(glm::mat3_cast(orientation_));
  glm::dmat4 m(viewFromWorldRot);
  m[3] = glm::dvec4(-(viewFromWorldRot * position_), 1.0);
  return m;
}

glm::dmat4 Camera::clipFromView() const { return glm::perspectiveRH_NO(fovY_, aspect_, near_, far_); }

FrustumCorners Camera::frustumCorners() const {
  FrustumCorners corners;
  const double ty = std::tan(0.5 * fovY_), tx = ty * aspect_;
  const glm::dvec3 f = forward(), r = right(), u = up();
  const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
  for (int plane = 0; plane < 2; ++plane) {
    const double d = plane == 0 ? near_ : far_;
    for (int c = 0; c < 4; ++c) corners[plane * 4 + c] = position_ + d * (f + sx[c] * tx * r + sy[c] * ty * u);
  }
  return corners;
}

glm::dvec3 Camera::rayDirection(double ndcX, double ndcY) const {
  const double ty = std::tan(0.5 * fovY_), tx = ty * aspect_;
  return glm::normalize(forward() + ndcX * tx * right() + ndcY * ty * up());
}

double Camera::linearDepth(double d) const {
  // Inverse of the GL perspective depth mapping: z_ndc = 2d - 1 = (f+n)/(f-n) - 2fn/((f-n) z).
  const double zNdc = 2.0 * d - 1.0;
  return 2.0 * near_ * far_ / (far_ + near_ - zNdc * (far_ - near_));
}

} // namespace crep
