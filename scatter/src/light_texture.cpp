// Light textures projected from the light (Klehm et al. 2014, Sec. 3.2 "Angular-dependency for Sources":
// coloured light textures; Yusov 2012, coloured light shafts). Rules at the top of
// crep/scatter/light_texture.h.
#include <crep/core/error.h>
#include <crep/core/parallel.h>
#include <crep/scatter/light_texture.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace crep {

namespace {

std::string texelString(int i, int j) {
  return "texel (" + std::to_string(i) + ", " + std::to_string(j) + ")";
}

/// Row k of a column-major matrix.
glm::dvec4 row(const glm::dmat4& m, int k) {
  return {m[0][k], m[1][k], m[2][k], m[3][k]};
}

} // namespace

void validateLightColors(const Image& colors, int width, int height, std::string_view field) {
  const std::string name(field);
  if (colors.empty()) throw InvalidArgument(name, "empty", "must be an RGB image");
  if (colors.channels() < 3 || colors.channels() > 4)
    throw InvalidArgument(name, std::to_string(colors.channels()) + " channels", "must have 3 or 4 channels");
  if (width > 0 && (colors.width() != width || colors.height() != height))
    throw InvalidArgument(name, std::to_string(colors.width()) + " x " + std::to_string(colors.height()),
                          "must be " + std::to_string(width) + " x " + std::to_string(height));
  for (int j = 0; j < colors.height(); ++j)
    for (int i = 0; i < colors.width(); ++i)
      for (int c = 0; c < 3; ++c) {
        const float v = colors.at(i, j, c);
        if (!std::isfinite(v) || v < 0.0f)
          throw InvalidArgument(
              name, texelString(i, j) + " channel " + std::to_string(c) + " = " + detail::formatValue(v),
              "colours must be finite and >= 0");
      }
}

void validate(const LightTexture& t, std::string_view owner) {
  const std::string o(owner);
  if (t.rgb == nullptr) throw InvalidArgument(o + ".rgb", "null", "must point to an RGB image");
  validateLightColors(*t.rgb, 0, 0, o + ".rgb");
  requireFinite(o + ".textureClipFromWorld", t.textureClipFromWorld);
}

namespace {

/// Rows x, y, w of the matrix applied to (v, h) vanish (relative 1e-6): every point of the ray maps to
/// one texture point.
void requireAlongRays(const glm::dmat4& m, const glm::dvec3& v, double h, std::string_view field,
                      const char* what) {
  requireFinite(field, m);
  for (const int k : {0, 1, 3}) {
    const glm::dvec4 r = row(m, k);
    const double value = glm::dot(glm::dvec3(r), v) + r.w * h;
    const double scale = glm::length(glm::dvec3(r)) * glm::length(v) + std::abs(r.w * h);
    if (!(std::abs(value) <= 1e-6 * scale))
      throw InvalidArgument(std::string(field),
                            "row " + std::to_string(k) + " applied to the " + what + " = " +
                                detail::formatValue(value),
                            "must project along the light's rays (x, y and w of the clip point constant "
                            "along every light ray)");
  }
}

} // namespace

void validateLightProjection(const glm::dmat4& m, const DirectionalLight& light, std::string_view field) {
  requireAlongRays(m, light.direction(), 0.0, field, "light direction (d, 0)");
}

void validateLightProjection(const glm::dmat4& m, const LocalLight& light, std::string_view field) {
  requireAlongRays(m, light.position, 1.0, field, "light position (L, 1)");
}

void validateLightTexture(const LightTexture& texture, const DirectionalLight& light,
                          std::string_view owner) {
  validate(texture, owner);
  validateLightProjection(texture.textureClipFromWorld, light, std::string(owner) + ".textureClipFromWorld");
}

void validateLightTexture(const LightTexture& texture, const LocalLight& light, std::string_view owner) {
  validate(texture, owner);
  validateLightProjection(texture.textureClipFromWorld, light, std::string(owner) + ".textureClipFromWorld");
}

// GL_LINEAR + GL_CLAMP_TO_EDGE of the projected texture (light_texture.h, "Rule").
glm::dvec3 lightTextureColor(const LightTexture& t, const glm::dvec3& p) {
  const glm::dvec4 q = t.textureClipFromWorld * glm::dvec4(p, 1.0);
  if (!(q.w > 0.0)) return glm::dvec3(0.0);
  const Image& img = *t.rgb;
  const int W = img.width(), H = img.height();
  const double x = (0.5 * q.x / q.w + 0.5) * W - 0.5, y = (0.5 * q.y / q.w + 0.5) * H - 0.5;
  if (!std::isfinite(x) || !std::isfinite(y)) return glm::dvec3(0.0);
  // Far outside the texture every texel index clamps to the edge; keep the floor in int range.
  const double xc = std::clamp(x, -1.0, static_cast<double>(W)),
               yc = std::clamp(y, -1.0, static_cast<double>(H));
  const double fx0 = std::floor(xc), fy0 = std::floor(yc);
  const double fx = xc - fx0, fy = yc - fy0;
  const int x0 = static_cast<int>(fx0), y0 = static_cast<int>(fy0);
  const int i0 = std::clamp(x0, 0, W - 1), i1 = std::clamp(x0 + 1, 0, W - 1);
  const int j0 = std::clamp(y0, 0, H - 1), j1 = std::clamp(y0 + 1, 0, H - 1);
  // a + f (b - a): the GL_LINEAR weights, written so that equal texels give their value exactly.
  glm::dvec3 out;
  for (int c = 0; c < 3; ++c) {
    const double c00 = img.at(i0, j0, c), c10 = img.at(i1, j0, c), c01 = img.at(i0, j1, c),
                 c11 = img.at(i1, j1, c);
    const double bottom = c00 + fx * (c10 - c00), top = c01 + fx * (c11 - c01);
    out[c] = bottom + fy * (top - bottom);
  }
  return out;
}

glm::dvec3 lightTextureColor(const LightTexture& texture, const LightRay& ray) {
  return lightTextureColor(texture, ray.origin + ray.direction);
}

// The colour map of a rectified map: each texel's light ray (Klehm et al. 2014, Sec. 3.2: the light-side
// factor per colour component).
Image lightColorMap(const LightTexture& texture, const RectifiedLayout& layout, int width, int height,
                    int threads) {
  validate(texture);
  if (width <= 0) throw InvalidArgument("lightColorMap.width", detail::formatValue(width), "must be > 0");
  if (height <= 0) throw InvalidArgument("lightColorMap.height", detail::formatValue(height), "must be > 0");
  Image out(width, height, 3);
  parallelRows(height, threads, [&](int j) {
    const double rowCoord = (j + 0.5) / height;
    for (int i = 0; i < width; ++i) {
      glm::dvec3 c(0.0);
      try {
        c = lightTextureColor(texture, layout.lightRay((i + 0.5) / width, rowCoord));
      } catch (const InvalidArgument&) {
        // A texel without a light ray (beyond the far end of the map): no light.
      }
      for (int k = 0; k < 3; ++k)
        out.at(i, j, k) = static_cast<float>(c[k]);
    }
  });
  return out;
}

} // namespace crep
