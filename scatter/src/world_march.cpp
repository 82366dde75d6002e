// The world-space reference march against a standard shadow map (Klehm et al. 2014, Eq. 1 and 3;
// Yusov 2012, Eq. 15-16). Rules at the top of crep/scatter/world_march.h.
#include <crep/core/error.h>
#include <crep/core/parallel.h>
#include <crep/scatter/world_march.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace crep {

void validate(const WorldMarchOptions& o) {
  if (o.steps < 1 || o.steps > (1 << 24))
    throw InvalidArgument("WorldMarchOptions.steps", detail::formatValue(o.steps), "must be in [1, 2^24]");
  if (o.refinements < 0 || o.refinements > 60)
    throw InvalidArgument("WorldMarchOptions.refinements", detail::formatValue(o.refinements),
                          "must be in [0, 60]");
  requireFinite("WorldMarchOptions.bias", o.bias);
  if (o.threads < 0)
    throw InvalidArgument("WorldMarchOptions.threads", detail::formatValue(o.threads), "must be >= 0");
}

bool standardShadowLit(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld, const glm::dvec3& p,
                       double bias) {
  const glm::dvec4 q = lightClipFromWorld * glm::dvec4(p, 1.0);
  // Behind a perspective light's eye plane: not in its map (local lights emit nothing there).
  if (!(q.w > 0.0)) return true;
  const glm::dvec3 uvd = glm::dvec3(q) / q.w * 0.5 + 0.5;
  if (!(uvd.x >= 0.0 && uvd.x <= 1.0 && uvd.y >= 0.0 && uvd.y <= 1.0)) return true;
  const int W = shadowDepth.width(), H = shadowDepth.height();
  const int i = std::min(static_cast<int>(uvd.x * W), W - 1),
            j = std::min(static_cast<int>(uvd.y * H), H - 1);
  return std::clamp(uvd.z, 0.0, 1.0) <= static_cast<double>(shadowDepth.at(i, j)) + bias;
}

namespace {

void validateShadowMap(const Image& shadowDepth, const glm::dmat4& m) {
  if (shadowDepth.empty())
    throw InvalidArgument("shadowDepth", "empty", "must be a W x H 1-channel depth image");
  if (shadowDepth.channels() != 1)
    throw InvalidArgument("shadowDepth", std::to_string(shadowDepth.channels()) + " channels",
                          "must have 1 channel");
  for (int j = 0; j < shadowDepth.height(); ++j)
    for (int i = 0; i < shadowDepth.width(); ++i)
      if (std::isnan(shadowDepth.at(i, j)))
        throw InvalidArgument("shadowDepth",
                              "texel (" + std::to_string(i) + ", " + std::to_string(j) + ") = NaN",
                              "depth-buffer values must not be NaN");
  requireFinite("lightClipFromWorld", m);
}

/// One pixel of the world-space march; `segment(ta, tb)` integrates a lit section (per channel); returns
/// the lookups.
template <class Segment>
int worldMarchPixel(const Image& shadowDepth, const glm::dmat4& M, const glm::dvec3& origin,
                    const PixelRay& ray, const Segment& segment, const WorldMarchOptions& o, glm::dvec3& L) {
  const double s = ray.surface;
  int lookups = 0;
  const auto lit = [&](double t) {
    ++lookups;
    return standardShadowLit(shadowDepth, M, origin + t * ray.direction, o.bias);
  };
  L = glm::dvec3(0.0);
  double ta = 0.0;
  bool va = lit(0.0);
  for (int k = 1; k <= o.steps; ++k) {
    const double tb = k == o.steps ? s : s * k / o.steps;
    const bool vb = lit(tb);
    if (va == vb) {
      if (va) L += segment(ta, tb);
    } else {
      // Bisect for the change: [lo, hi] keeps va at lo and vb at hi.
      double lo = ta, hi = tb;
      for (int r = 0; r < o.refinements; ++r) {
        const double mid = 0.5 * (lo + hi);
        (lit(mid) == va ? lo : hi) = mid;
      }
      const double change = 0.5 * (lo + hi);
      if (va) L += segment(ta, change);
      if (vb) L += segment(change, tb);
    }
    ta = tb;
    va = vb;
  }
  return lookups;
}

} // namespace

namespace {

/// One pixel ray's march with the light's rule for a lit section, its radiance and its lookups: C times
/// the transmittance integrals for the directional light, RayScattering's section integrals for a local one.
/// A lit part's integral times the light texture's colour at its midpoint's light ray (world_march.h,
/// "Light textures"), or the integral alone without a texture.
template <class Section>
auto coloured(const LightTexture* texture, const Camera& camera, const PixelRay& ray,
              const Section& section) {
  return [=, &camera, &ray, &section](double ta, double tb) {
    const glm::dvec3 v = section(ta, tb);
    if (!texture) return v;
    return v * lightTextureColor(*texture, camera.position() + (0.5 * (ta + tb)) * ray.direction);
  };
}

int marchRadiance(const Image& shadowDepth, const glm::dmat4& M, const Camera& camera, const PixelRay& ray,
                  const DirectionalLight& light, const Medium& medium, const WorldMarchOptions& options,
                  const LightTexture* texture, glm::dvec3& radiance) {
  const glm::dvec3 sigma = medium.extinction();
  glm::dvec3 L;
  const auto section = [&](double ta, double tb) { return transmittanceIntegral(sigma, ta, tb); };
  const int lookups = worldMarchPixel(shadowDepth, M, camera.position(), ray,
                                      coloured(texture, camera, ray, section), options, L);
  radiance = scatteringConstant(light, medium, ray.direction) * L;
  return lookups;
}

int marchRadiance(const Image& shadowDepth, const glm::dmat4& M, const Camera& camera, const PixelRay& ray,
                  const LocalLight& light, const Medium& medium, const WorldMarchOptions& options,
                  const LightTexture* texture, glm::dvec3& radiance) {
  const RayScattering rs(light, medium, camera.position(), ray.direction);
  const auto section = [&](double ta, double tb) { return rs.segment(ta, tb); };
  return worldMarchPixel(shadowDepth, M, camera.position(), ray, coloured(texture, camera, ray, section),
                         options, radiance);
}

template <class Light>
MarchResult marchImage(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                       const Image& cameraDepth, const Camera& camera, const Light& light,
                       const Medium& medium, const WorldMarchOptions& options,
                       const LightTexture* texture = nullptr) {
  validateShadowMap(shadowDepth, lightClipFromWorld);
  validateCameraDepth(cameraDepth);
  validate(options);
  if (texture) validateLightTexture(*texture, light, "lightTexture");
  const int w = cameraDepth.width(), h = cameraDepth.height();
  MarchResult out{Image(w, h, 4), Image(w, h, 1)};
  const double grey = weightExtinction(medium);
  parallelRows(h, options.threads, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const PixelRay ray = pixelRay(camera, cameraDepth, x, y);
      glm::dvec3 L;
      const int lookups =
          marchRadiance(shadowDepth, lightClipFromWorld, camera, ray, light, medium, options, texture, L);
      storeScattering(out.scattering, x, y, L, std::exp(-grey * ray.surface));
      out.steps.at(x, y) = static_cast<float>(lookups);
    }
  });
  return out;
}

} // namespace

// Klehm et al. 2014, Eq. 1 and 3 (Yusov 2012, Eq. 15-16) against a standard shadow map: the
// rectification-free reference.
MarchResult worldSpaceMarch(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                            const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                            const Medium& medium, const WorldMarchOptions& options) {
  return marchImage(shadowDepth, lightClipFromWorld, cameraDepth, camera, light, medium, options);
}

// The same for a local light (crep/scatter/ray_scattering.h): each lit section integrated by RayScattering.
MarchResult worldSpaceMarch(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                            const Image& cameraDepth, const Camera& camera, const LocalLight& light,
                            const Medium& medium, const WorldMarchOptions& options) {
  return marchImage(shadowDepth, lightClipFromWorld, cameraDepth, camera, light, medium, options);
}

// Light textures (Klehm et al. 2014, Sec. 3.2): each lit part times the texture at its light ray.
MarchResult worldSpaceMarch(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                            const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                            const Medium& medium, const LightTexture& lightTexture,
                            const WorldMarchOptions& options) {
  return marchImage(shadowDepth, lightClipFromWorld, cameraDepth, camera, light, medium, options,
                    &lightTexture);
}

MarchResult worldSpaceMarch(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                            const Image& cameraDepth, const Camera& camera, const LocalLight& light,
                            const Medium& medium, const LightTexture& lightTexture,
                            const WorldMarchOptions& options) {
  return marchImage(shadowDepth, lightClipFromWorld, cameraDepth, camera, light, medium, options,
                    &lightTexture);
}

void worldSpaceMarchPixels(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                           const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                           const Medium& medium, std::span<const int> pixels, Image& scattering, Image* steps,
                           const WorldMarchOptions& options) {
  validateShadowMap(shadowDepth, lightClipFromWorld);
  validateCameraDepth(cameraDepth);
  validate(options);
  const int w = cameraDepth.width(), h = cameraDepth.height();
  if (scattering.width() != w || scattering.height() != h || scattering.channels() != 4)
    throw InvalidArgument("scattering",
                          std::to_string(scattering.width()) + " x " + std::to_string(scattering.height()),
                          "must be an RGBA image of cameraDepth's size");
  if (steps && (steps->width() != w || steps->height() != h || steps->channels() != 1))
    throw InvalidArgument("steps", std::to_string(steps->width()) + " x " + std::to_string(steps->height()),
                          "must be a 1-channel image of cameraDepth's size");
  for (int p : pixels)
    if (p < 0 || p >= w * h)
      throw InvalidArgument("pixels", detail::formatValue(p),
                            "must be in [0, " + std::to_string(w * h) + ")");
  const double grey = weightExtinction(medium);
  const int count = static_cast<int>(pixels.size());
  parallelRows(count, options.threads, [&](int k) {
    const int p = pixels[static_cast<std::size_t>(k)], x = p % w, y = p / w;
    const PixelRay ray = pixelRay(camera, cameraDepth, x, y);
    glm::dvec3 L;
    const int lookups =
        marchRadiance(shadowDepth, lightClipFromWorld, camera, ray, light, medium, options, nullptr, L);
    storeScattering(scattering, x, y, L, std::exp(-grey * ray.surface));
    if (steps) steps->at(x, y) = static_cast<float>(lookups);
  });
}

} // namespace crep
