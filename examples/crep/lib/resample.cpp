#include "resample.h"

#include <crep/core/error.h>
#include <crep/core/parallel.h>

#include <algorithm>
#include <cmath>

namespace crep::tool {

void checkLightMatrix(const glm::dmat4& m, const glm::dvec3& lightDirection, const std::string& field) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r]))
        throw FormatError(field + ": element " + std::to_string(4 * c + r) + " is not finite");
  if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0)
    throw FormatError(field +
                      ": not an orthographic (affine) matrix: its last row must be 0 0 0 1 (a directional "
                      "light's standard shadow map)");
  if (std::abs(glm::determinant(m)) < 1e-300) throw FormatError(field + ": not invertible");
  // The light direction must map to a pure depth change: every light ray is one texel.
  const glm::dvec3 d = glm::dvec3(m * glm::dvec4(lightDirection, 0.0));
  const double scale =
      std::max({glm::length(glm::dvec3(m[0])), glm::length(glm::dvec3(m[1])), glm::length(glm::dvec3(m[2]))});
  if (std::hypot(d.x, d.y) > 1e-3 * scale || !(d.z > 0.0))
    throw FormatError(field + ": does not look along light.direction (the light direction maps to clip (" +
                      std::to_string(d.x) + ", " + std::to_string(d.y) + ", " + std::to_string(d.z) +
                      "), expected (0, 0, > 0))");
}

Image pointResampleShadowMap(const RectifiedLayout& layout, int width, int height, const Image& shadow,
                             const glm::dmat4& lightClipFromWorld) {
  Image out(width, height, 1, 1.0f);
  const glm::dmat4 worldFromLightClip = glm::inverse(lightClipFromWorld);
  const int sw = shadow.width(), sh = shadow.height();
  parallelRows(height, 0, [&](int j) {
    const double row = (j + 0.5) / height;
    for (int i = 0; i < width; ++i) {
      const LightRay ray = layout.lightRay((i + 0.5) / width, row);
      const glm::dvec4 clip = lightClipFromWorld * glm::dvec4(ray.origin, 1.0);
      const double x = clip.x / clip.w, y = clip.y / clip.w;
      if (!(x >= -1.0 && x <= 1.0 && y >= -1.0 && y <= 1.0)) continue;
      const int tx = std::clamp(static_cast<int>(std::floor((x + 1.0) * 0.5 * sw)), 0, sw - 1);
      const int ty = std::clamp(static_cast<int>(std::floor((y + 1.0) * 0.5 * sh)), 0, sh - 1);
      const double d = shadow.at(tx, ty, 0);
      if (!(d < 1.0)) continue;
      const glm::dvec4 h = worldFromLightClip * glm::dvec4(x, y, 2.0 * d - 1.0, 1.0);
      try {
        const RectPoint p = layout.toRectified(glm::dvec3(h) / h.w);
        out.at(i, j) = static_cast<float>(std::clamp(p.depth, 0.0, 1.0));
      } catch (const InvalidArgument&) {
        // Not mappable (behind the camera plane): cannot shadow the frustum; stays lit.
      }
    }
  });
  return out;
}

} // namespace crep::tool
