// Perspective camera in double precision, OpenGL conventions: the view looks down -Z of view space,
// clip space z in [-w, w], depth-buffer values in [0, 1] with the default glDepthRange.
// Matrices are named target-from-source: clip = clipFromView() * viewFromWorld() * world.
#pragma once

#include <array>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace crep {

/// The eight corners of a view frustum in world space. Index = near/far * 4 + corner, corners in the
/// order (-x,-y), (+x,-y), (+x,+y), (-x,+y) of the image plane (bottom-left first, counter-clockwise).
using FrustumCorners = std::array<glm::dvec3, 8>;

class Camera {
public:
  /// Validating constructor. `orientation` rotates view space into world space (normalized here).
  /// Throws InvalidArgument naming the parameter for: non-finite values, a zero quaternion,
  /// fovY outside (0, pi), aspect <= 0, near <= 0, far <= near, far infinite.
  Camera(const glm::dvec3& position, const glm::dquat& orientation, double fovY, double aspect, double near,
         double far);

  /// Camera at `position` looking at `target` with `up` as the approximate up vector. Throws
  /// InvalidArgument when target == position or up is zero or parallel to the view direction.
  static Camera lookAt(const glm::dvec3& position, const glm::dvec3& target, const glm::dvec3& up, double fovY,
                       double aspect, double near, double far);

  const glm::dvec3& position() const noexcept { return position_; }
  const glm::dquat& orientation() const noexcept { return orientation_; }
  double fovY() const noexcept { return fovY_; }     ///< vertical field of view, radians
  double aspect() const noexcept { return aspect_; } ///< width / height
  double near() const noexcept { return near_; }     ///< distance to the near plane, world units
  double far() const noexcept { return far_; }       ///< distance to the far plane, world units

  glm::dvec3 forward() const; ///< unit view direction in world space (-Z of view space)
  glm::dvec3 right() const;   ///< unit +X of view space in world space
  glm::dvec3 up() const;      ///< unit +Y of view space in world space

  glm::dmat4 viewFromWorld() const;
  glm::dmat4 worldFromView() const;
  glm::dmat4 clipFromView() const; ///< OpenGL perspective, NDC z in [-1, 1]
  glm::dmat4 clipFromWorld() const { return clipFromView() * viewFromWorld(); }

  FrustumCorners frustumCorners() const; ///< world space, see FrustumCorners for the order

  /// World-space unit direction of the view ray through normalized device coordinates (x, y) in [-1, 1].
  glm::dvec3 rayDirection(double ndcX, double ndcY) const;

  /// Converts a depth-buffer value d in [0, 1] (glDepthRange(0, 1)) to the view-space distance along -Z.
  double linearDepth(double depthBufferValue) const;

private:
  glm::dvec3 position_;
  glm::dquat orientation_;
  double fovY_, aspect_, near_, far_;
};

} // namespace crep
