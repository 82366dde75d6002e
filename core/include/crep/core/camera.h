// Perspective camera in double precision: view down -Z, depth-buffer values in [0, 1], matrices named
// target-from-source. Engine conventions accepted by Camera::fromMatrices (clip depth, reversed-Z, infinite
// far, off-centre) and the depth formula: core/README.md, "camera.h".
#pragma once

#include <array>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace crep {

/// The eight corners of a view frustum in world space. Index = near/far * 4 + corner, corners in the
/// order (-x,-y), (+x,-y), (+x,+y), (-x,+y) of the image plane (bottom-left first, counter-clockwise).
using FrustumCorners = std::array<glm::dvec3, 8>;

/// Clip-space depth range of the engine's projection matrix (glClipControl's depth mode).
enum class ClipDepth {
  NegativeOneToOne, ///< OpenGL's default: clip z in [-w, w]
  ZeroToOne,        ///< GL_ZERO_TO_ONE, Vulkan, Metal and the other APIs: clip z in [0, w]
};

class Camera {
public:
  /// Validating constructor. `orientation` rotates view space into world space (normalized here).
  /// Throws InvalidArgument naming the parameter for: non-finite values, a zero quaternion,
  /// fovY outside (0, pi), aspect <= 0, near <= 0, far <= near, far infinite.
  Camera(const glm::dvec3& position, const glm::dquat& orientation, double fovY, double aspect, double near,
         double far);

  /// Camera at `position` looking at `target` with `up` as the approximate up vector. Throws
  /// InvalidArgument when target == position or up is zero or parallel to the view direction.
  static Camera lookAt(const glm::dvec3& position, const glm::dvec3& target, const glm::dvec3& up,
                       double fovY, double aspect, double near, double far);

  /// The camera of an engine's matrices: rigid `viewFromWorld`, perspective `clipFromView` in `clipDepth`;
  /// `maxDistance` > near is the integration distance (needed with an infinite far plane; 0 = the far
  /// plane). InvalidArgument naming "Camera.viewFromWorld", "Camera.clipFromView" or "Camera.maxDistance".
  static Camera fromMatrices(const glm::dmat4& viewFromWorld, const glm::dmat4& clipFromView,
                             ClipDepth clipDepth = ClipDepth::NegativeOneToOne, double maxDistance = 0.0);

  const glm::dvec3& position() const noexcept { return position_; }
  const glm::dquat& orientation() const noexcept { return orientation_; }
  /// Vertical field of view, radians, and width / height: of the symmetric frustum that covers this one
  /// (the frustum itself when it is symmetric).
  double fovY() const noexcept { return fovY_; }
  double aspect() const noexcept { return aspect_; }
  double near() const noexcept { return near_; } ///< distance to the near plane, world units
  /// How far the scattering is integrated, world units: the far plane, or maxDistance (fromMatrices).
  double far() const noexcept { return far_; }
  /// The projection's far plane: far(), or +infinity for an infinite far plane.
  double projectionFar() const noexcept { return projectionFar_; }
  bool reversedZ() const noexcept { return reversedZ_; } ///< near -> depth 1, far -> depth 0
  ClipDepth clipDepth() const noexcept { return clipDepth_; }
  /// The image plane at unit distance: x from tangents.x (left) to .y (right), y from .z (bottom) to .w
  /// (top), in units of the view distance. Symmetric: (-tan(fovY/2) aspect, +.., -tan(fovY/2), +..).
  const glm::dvec4& tangents() const noexcept { return tangents_; }
  bool symmetric() const noexcept { return tangents_.x == -tangents_.y && tangents_.z == -tangents_.w; }

  glm::dvec3 forward() const; ///< unit view direction in world space (-Z of view space)
  glm::dvec3 right() const;   ///< unit +X of view space in world space
  glm::dvec3 up() const;      ///< unit +Y of view space in world space

  glm::dmat4 viewFromWorld() const;
  glm::dmat4 worldFromView() const;
  /// The projection in the camera's conventions (clip depth, reversal, far plane, off-centre): a depth
  /// buffer rendered with it holds the values linearDepth() reads.
  glm::dmat4 clipFromView() const;
  glm::dmat4 clipFromWorld() const { return clipFromView() * viewFromWorld(); }

  FrustumCorners frustumCorners() const; ///< world space, see FrustumCorners for the order

  /// World-space unit direction of the view ray through normalized device coordinates (x, y) in [-1, 1].
  glm::dvec3 rayDirection(double ndcX, double ndcY) const;

  /// Converts a depth-buffer value d in [0, 1] (glDepthRange(0, 1)) to the view-space distance along -Z
  /// (the camera's conventions; +infinity at the far plane of an infinite projection).
  double linearDepth(double depthBufferValue) const;
  /// The depth-buffer value of view distance Z > 0 (inverse of linearDepth).
  double depthBufferValue(double viewDistance) const;
  /// The distance a pixel's scattering is integrated to (crep::pixelRay's rule): linearDepth(d) within
  /// [near(), far()]; the sky (the cleared value: d >= 1 standard, d <= 0 reversed, also NaN) is far().
  double surfaceViewDepth(double depthBufferValue) const;

private:
  glm::dvec3 position_;
  glm::dquat orientation_;
  double fovY_, aspect_, near_, far_;
  double projectionFar_;
  glm::dvec4 tangents_;
  bool reversedZ_ = false;
  ClipDepth clipDepth_ = ClipDepth::NegativeOneToOne;
};

} // namespace crep
