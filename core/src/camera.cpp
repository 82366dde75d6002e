#include <crep/core/camera.h>
#include <crep/core/error.h>

#include "validate.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

namespace crep {

Camera::Camera(const glm::dvec3& position, const glm::dquat& orientation, double fovY, double aspect,
               double near, double far)
    : position_(position), fovY_(fovY), aspect_(aspect), near_(near), far_(far) {
  requireFinite("Camera.position", position);
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
  projectionFar_ = far;
  const double ty = std::tan(0.5 * fovY), tx = ty * aspect;
  tangents_ = glm::dvec4(-tx, tx, -ty, ty);
}

Camera Camera::fromMatrices(const glm::dmat4& v, const glm::dmat4& p, ClipDepth clipDepth,
                            double maxDistance) {
  requireFinite("Camera.viewFromWorld", v);
  requireFinite("Camera.clipFromView", p);
  if (clipDepth != ClipDepth::NegativeOneToOne && clipDepth != ClipDepth::ZeroToOne)
    throw InvalidArgument("Camera.clipDepth", std::to_string(static_cast<int>(clipDepth)),
                          "must be NegativeOneToOne or ZeroToOne");
  // viewFromWorld: rotation + translation.
  if (v[0][3] != 0.0 || v[1][3] != 0.0 || v[2][3] != 0.0 || v[3][3] != 1.0)
    throw InvalidArgument("Camera.viewFromWorld", "last row not 0 0 0 1", "must be a rigid transform");
  const glm::dmat3 rot(v);
  const glm::dmat3 rtr = glm::transpose(rot) * rot;
  double err = 0.0;
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k)
      err = std::max(err, std::abs(rtr[c][k] - (c == k ? 1.0 : 0.0)));
  if (err > 1e-4 || glm::determinant(rot) <= 0.0)
    throw InvalidArgument("Camera.viewFromWorld", "3x3 part off a rotation by " + detail::formatValue(err),
                          "must be a rigid transform (orthonormal, determinant 1; no scale or mirror)");
  const glm::dmat4 worldFromView = glm::inverse(v);
  // clipFromView: x_clip = p00 x + p20 z, y_clip = p11 y + p21 z, z_clip = A z + B, w = -z.
  const double scale = std::max(std::abs(p[0][0]), std::abs(p[1][1]));
  const double zeros[] = {p[0][1], p[0][2], p[0][3], p[1][0], p[1][2], p[1][3], p[3][0], p[3][1], p[3][3]};
  for (const double z : zeros)
    if (std::abs(z) > 1e-9 * std::max(1.0, scale))
      throw InvalidArgument(
          "Camera.clipFromView", "an element off the perspective pattern is " + detail::formatValue(z),
          "must be a perspective projection (orthographic and skewed ones are not supported)");
  if (std::abs(p[2][3] + 1.0) > 1e-9)
    throw InvalidArgument("Camera.clipFromView", "element (column 2, row 3) " + detail::formatValue(p[2][3]),
                          "must be -1 (a right-handed perspective looking down -Z)");
  if (!(p[0][0] > 0.0) || !(p[1][1] > 0.0))
    throw InvalidArgument(
        "Camera.clipFromView",
        "focal lengths " + detail::formatValue(p[0][0]) + ", " + detail::formatValue(p[1][1]), "must be > 0");
  const double A = p[2][2], B = p[3][2];
  // Depth-buffer value d = a + b / Z of view distance Z (see the header).
  const double a = clipDepth == ClipDepth::NegativeOneToOne ? 0.5 * (1.0 - A) : -A;
  const double b = clipDepth == ClipDepth::NegativeOneToOne ? 0.5 * B : B;
  if (b == 0.0)
    throw InvalidArgument("Camera.clipFromView",
                          "depth row " + detail::formatValue(A) + ", " + detail::formatValue(B),
                          "must map view distance to depth (a perspective depth row)");
  const bool reversed = b > 0.0;
  const auto distanceAt = [&](double d) {
    const double den = d - a;
    return den == 0.0 ? std::numeric_limits<double>::infinity() : b / den;
  };
  const double near = distanceAt(reversed ? 1.0 : 0.0);
  double far = distanceAt(reversed ? 0.0 : 1.0);
  if (std::abs(reversed ? a : 1.0 - a) <= 1e-12) far = std::numeric_limits<double>::infinity();
  if (!(near > 0.0) || !std::isfinite(near))
    throw InvalidArgument("Camera.clipFromView", "near plane at " + detail::formatValue(near),
                          "must have a near plane at a positive finite distance");
  if (!(far > near))
    throw InvalidArgument("Camera.clipFromView", "far plane at " + detail::formatValue(far),
                          "must have its far plane beyond the near plane " + detail::formatValue(near));
  double integrate = far;
  if (std::isinf(far)) {
    if (!(maxDistance > near) || !std::isfinite(maxDistance))
      throw InvalidArgument("Camera.maxDistance", detail::formatValue(maxDistance),
                            "must be finite and > the near plane " + detail::formatValue(near) +
                                " with an infinite far plane (how far the scattering is integrated)");
    integrate = maxDistance;
  } else if (maxDistance != 0.0) {
    if (!(maxDistance > near) || !std::isfinite(maxDistance))
      throw InvalidArgument("Camera.maxDistance", detail::formatValue(maxDistance),
                            "must be 0 (the far plane) or finite and > the near plane " +
                                detail::formatValue(near));
    integrate = std::min(maxDistance, far);
  }
  const glm::dvec4 t((p[2][0] - 1.0) / p[0][0], (p[2][0] + 1.0) / p[0][0], (p[2][1] - 1.0) / p[1][1],
                     (p[2][1] + 1.0) / p[1][1]);
  const double ty = std::max(std::abs(t.z), std::abs(t.w)), tx = std::max(std::abs(t.x), std::abs(t.y));
  Camera c(glm::dvec3(worldFromView[3]), glm::quat_cast(glm::dmat3(worldFromView)), 2.0 * std::atan(ty),
           tx / ty, near, integrate);
  c.projectionFar_ = far;
  c.tangents_ = t;
  c.reversedZ_ = reversed;
  c.clipDepth_ = clipDepth;
  return c;
}

Camera Camera::lookAt(const glm::dvec3& position, const glm::dvec3& target, const glm::dvec3& up, double fovY,
                      double aspect, double near, double far) {
  requireFinite("Camera.position", position);
  requireFinite("Camera.target", target);
  requireFinite("Camera.up", up);
  const glm::dvec3 toTarget = target - position;
  const double dist = glm::length(toTarget);
  if (!(dist > 0.0) || !std::isfinite(dist))
    throw InvalidArgument("Camera.target", "position + " + detail::formatValue(dist),
                          "must differ from Camera.position");
  const glm::dvec3 f = toTarget / dist;
  const double upLen = glm::length(up);
  if (!(upLen > 0.0))
    throw InvalidArgument("Camera.up", detail::formatValue(upLen) + " (length)", "must be non-zero");
  glm::dvec3 r = glm::cross(f, up / upLen);
  const double rLen = glm::length(r);
  if (!(rLen > 1e-9))
    throw InvalidArgument("Camera.up",
                          detail::formatValue(rLen) + " (sine of the angle to the view direction)",
                          "must not be parallel to the view direction");
  r /= rLen;
  const glm::dvec3 u = glm::cross(r, f);
  // Columns of worldFromView's rotation: view +X = r, +Y = u, +Z = -f.
  const glm::dmat3 worldFromViewRot(r, u, -f);
  return Camera(position, glm::quat_cast(worldFromViewRot), fovY, aspect, near, far);
}

glm::dvec3 Camera::forward() const {
  return orientation_ * glm::dvec3(0, 0, -1);
}
glm::dvec3 Camera::right() const {
  return orientation_ * glm::dvec3(1, 0, 0);
}
glm::dvec3 Camera::up() const {
  return orientation_ * glm::dvec3(0, 1, 0);
}

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

glm::dmat4 Camera::clipFromView() const {
  const bool infinite = std::isinf(projectionFar_);
  if (symmetric() && !reversedZ_ && !infinite && clipDepth_ == ClipDepth::NegativeOneToOne)
    return glm::perspectiveRH_NO(fovY_, aspect_, near_, projectionFar_);
  const double n = near_, f = projectionFar_;
  const glm::dvec4& t = tangents_;
  // d = a + b / Z (see the header), then the clip depth row of the convention.
  double a, b;
  if (!reversedZ_) {
    a = infinite ? 1.0 : f / (f - n);
    b = infinite ? -n : -f * n / (f - n);
  } else {
    a = infinite ? 0.0 : -n / (f - n);
    b = infinite ? n : f * n / (f - n);
  }
  glm::dmat4 m(0.0);
  m[0][0] = 2.0 / (t.y - t.x);
  m[2][0] = (t.y + t.x) / (t.y - t.x);
  m[1][1] = 2.0 / (t.w - t.z);
  m[2][1] = (t.w + t.z) / (t.w - t.z);
  m[2][3] = -1.0;
  m[2][2] = clipDepth_ == ClipDepth::NegativeOneToOne ? 1.0 - 2.0 * a : -a;
  m[3][2] = clipDepth_ == ClipDepth::NegativeOneToOne ? 2.0 * b : b;
  return m;
}

FrustumCorners Camera::frustumCorners() const {
  FrustumCorners corners;
  const glm::dvec3 f = forward(), r = right(), u = up();
  const double sx[4] = {tangents_.x, tangents_.y, tangents_.y, tangents_.x};
  const double sy[4] = {tangents_.z, tangents_.z, tangents_.w, tangents_.w};
  for (int plane = 0; plane < 2; ++plane) {
    const double d = plane == 0 ? near_ : far_;
    for (int c = 0; c < 4; ++c)
      corners[plane * 4 + c] = position_ + d * (f + sx[c] * r + sy[c] * u);
  }
  return corners;
}

glm::dvec3 Camera::rayDirection(double ndcX, double ndcY) const {
  const double cx = 0.5 * (tangents_.x + tangents_.y), hx = 0.5 * (tangents_.y - tangents_.x);
  const double cy = 0.5 * (tangents_.z + tangents_.w), hy = 0.5 * (tangents_.w - tangents_.z);
  return glm::normalize(forward() + (cx + ndcX * hx) * right() + (cy + ndcY * hy) * up());
}

double Camera::linearDepth(double d) const {
  // t = (1/Z - 1/f) / (1/n - 1/f): 1 - d (standard) or d (reversed), exact where it matters (near the far
  // plane); Z = n f / (n + t (f - n)), or n / t for an infinite far plane.
  const double t = reversedZ_ ? d : 1.0 - d;
  if (std::isinf(projectionFar_)) return t > 0.0 ? near_ / t : std::numeric_limits<double>::infinity();
  return near_ * projectionFar_ / (near_ + t * (projectionFar_ - near_));
}

double Camera::depthBufferValue(double Z) const {
  const double invFar = std::isinf(projectionFar_) ? 0.0 : 1.0 / projectionFar_;
  const double t = (1.0 / Z - invFar) / (1.0 / near_ - invFar);
  return reversedZ_ ? t : 1.0 - t;
}

double Camera::surfaceViewDepth(double d) const {
  const double t = reversedZ_ ? d : 1.0 - d;
  if (!(t > 0.0)) return far_; // the cleared value (sky), beyond it, or NaN
  if (t >= 1.0) return near_;
  return std::clamp(linearDepth(d), near_, far_);
}

} // namespace crep
