// Mitchell 2007 (GPU Gems 3 ch. 13) radial blur, CPU reference in double; the rules are at the top of
// crep/postfx/radial_blur.h.
#include <crep/core/error.h>
#include <crep/core/parallel.h>
#include <crep/postfx/radial_blur.h>
#include <crep/scatter/ray.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace crep {

namespace {

std::string field(const char* owner, const char* name) {
  return std::string(owner) + "." + name;
}

/// The cleared depth value (Camera::surfaceViewDepth's sky rule: t = 1 - d, or d reversed, not > 0).
bool isSky(const Camera& camera, double d) {
  const double t = camera.reversedZ() ? d : 1.0 - d;
  return !(t > 0.0);
}

} // namespace

void validate(const RadialBlurOptions& o, const char* owner) {
  requireNonNegative(field(owner, "exposure"), o.exposure);
  if (!(std::isfinite(o.decay) && o.decay > 0.0 && o.decay <= 1.0))
    throw InvalidArgument(field(owner, "decay"), detail::formatValue(o.decay), "must be in (0, 1]");
  requireNonNegative(field(owner, "weight"), o.weight);
  requirePositive(field(owner, "density"), o.density);
  if (o.samples < 1 || o.samples > 1024)
    throw InvalidArgument(field(owner, "samples"), detail::formatValue(o.samples), "must be in [1, 1024]");
  if (o.sourceScale < 1 || o.sourceScale > 16)
    throw InvalidArgument(field(owner, "sourceScale"), detail::formatValue(o.sourceScale),
                          "must be in [1, 16]");
  requirePositive(field(owner, "fadeMargin"), o.fadeMargin);
  if (o.threads < 0)
    throw InvalidArgument(field(owner, "threads"), detail::formatValue(o.threads), "must be >= 0");
  if (o.mode != RadialBlurMode::SourceRadiance && o.mode != RadialBlurMode::OcclusionFraction)
    throw InvalidArgument(field(owner, "mode"), detail::formatValue(static_cast<int>(o.mode)),
                          "must be SourceRadiance or OcclusionFraction");
}

// Mitchell 2007, Sec. 13.4 (the light's screen position) and Sec. 13.6 (fade toward the perpendicular).
RadialLight radialLight(const Camera& camera, const DirectionalLight& light, double fadeMargin) {
  requirePositive("RadialBlurOptions.fadeMargin", fadeMargin);
  RadialLight r;
  const glm::dvec4 q = camera.clipFromWorld() * glm::dvec4(-light.direction(), 0.0);
  if (!(q.w > 0.0)) return r; // behind the camera or in its image plane: fade 0
  const glm::dvec2 ndc = glm::dvec2(q.x, q.y) / q.w;
  r.inFront = true;
  r.uv = ndc * 0.5 + 0.5;
  const double e = std::max({std::abs(ndc.x) - 1.0, std::abs(ndc.y) - 1.0, 0.0});
  const double t = std::min(e / fadeMargin, 1.0);
  r.fade = 1.0 - t * t * (3.0 - 2.0 * t);
  return r;
}

glm::ivec2 radialSourceSize(int width, int height, int sourceScale) {
  return {(width + sourceScale - 1) / sourceScale, (height + sourceScale - 1) / sourceScale};
}

// Mitchell 2007, Sec. 13.5.1 (occlusion pre-pass: occluders black) with the sky's unshadowed
// in-scattering (Eq. 1) as the bright value, box-downsampled by sourceScale (Sec. 13.3.1).
namespace {

/// The source image from the camera depth and its unshadowed in-scattering `sky` (rule at the top).
Image sourceFrom(const Image& cameraDepth, const Image& sky, const Camera& camera,
                 const RadialBlurOptions& options) {
  const int w = cameraDepth.width(), h = cameraDepth.height(), k = options.sourceScale;
  const glm::ivec2 size = radialSourceSize(w, h, k);
  Image out(size.x, size.y, 4);
  parallelRows(size.y, options.threads, [&](int sy) {
    for (int sx = 0; sx < size.x; ++sx) {
      glm::dvec4 sum(0.0);
      int count = 0;
      for (int y = sy * k; y < std::min(h, (sy + 1) * k); ++y)
        for (int x = sx * k; x < std::min(w, (sx + 1) * k); ++x) {
          ++count;
          if (!isSky(camera, cameraDepth.at(x, y, 0))) continue;
          sum += glm::dvec4(sky.at(x, y, 0), sky.at(x, y, 1), sky.at(x, y, 2), 1.0);
        }
      const glm::dvec4 mean = sum / static_cast<double>(count);
      for (int c = 0; c < 4; ++c)
        out.at(sx, sy, c) = static_cast<float>(mean[c]);
    }
  });
  return out;
}

Image unshadowed(const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                 const Medium& medium, const RadialBlurOptions& options) {
  validate(options);
  MarchOptions march;
  march.threads = options.threads;
  return unshadowedScattering(cameraDepth, camera, light, medium, march); // validates the depth
}

} // namespace

Image radialBlurSource(const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                       const Medium& medium, const RadialBlurOptions& options) {
  return sourceFrom(cameraDepth, unshadowed(cameraDepth, camera, light, medium, options), camera, options);
}

// The bilinear filter of Mitchell 2007, Sec. 13.3.1, with GL's CLAMP_TO_EDGE.
glm::dvec4 radialBilinear(const Image& source, double sx, double sy) {
  const int w = source.width(), h = source.height(), channels = std::min(source.channels(), 4);
  const double fx = std::floor(sx), fy = std::floor(sy);
  const double ax = sx - fx, ay = sy - fy;
  // Clamp in double first: a sample far outside the image must not overflow the int conversion.
  const int x0 = static_cast<int>(std::clamp(fx, -1.0, static_cast<double>(w))),
            y0 = static_cast<int>(std::clamp(fy, -1.0, static_cast<double>(h)));
  const int xa = std::clamp(x0, 0, w - 1), xb = std::clamp(x0 + 1, 0, w - 1);
  const int ya = std::clamp(y0, 0, h - 1), yb = std::clamp(y0 + 1, 0, h - 1);
  glm::dvec4 r(0.0);
  for (int c = 0; c < channels; ++c) {
    const double bottom = (1.0 - ax) * source.at(xa, ya, c) + ax * source.at(xb, ya, c);
    const double top = (1.0 - ax) * source.at(xa, yb, c) + ax * source.at(xb, yb, c);
    r[c] = (1.0 - ay) * bottom + ay * top;
  }
  return r;
}

// Mitchell 2007, Eq. 4 (averaged over its n + 1 terms) along the screen ray toward the sun (Sec. 13.4); in
// mode OcclusionFraction Eq. 2 with 1 - D from the same sum over the sky mask.
Image radialBlur(const Image& cameraDepth, const Camera& camera, const DirectionalLight& light,
                 const Medium& medium, const RadialBlurOptions& options) {
  const Image own = unshadowed(cameraDepth, camera, light, medium, options);
  const Image source = sourceFrom(cameraDepth, own, camera, options);
  const bool fraction = options.mode == RadialBlurMode::OcclusionFraction;
  const RadialLight sun = radialLight(camera, light, options.fadeMargin);
  const int w = cameraDepth.width(), h = cameraDepth.height(), n = options.samples;
  const double k = options.sourceScale;
  const double scale = sun.fade * options.exposure * options.weight / (n + 1);
  const double grey = weightExtinction(medium);
  Image out(w, h, 4);
  parallelRows(h, options.threads, [&](int y) {
    for (int x = 0; x < w; ++x) {
      glm::dvec3 L(0.0);
      if (sun.fade > 0.0) {
        const glm::dvec2 p((x + 0.5) / w, (y + 0.5) / h);
        const glm::dvec2 delta = (p - sun.uv) * (options.density / n);
        double decay = 1.0;
        for (int i = 0; i <= n; ++i) {
          const glm::dvec2 pi = p - static_cast<double>(i) * delta;
          const glm::dvec4 v = radialBilinear(source, pi.x * w / k - 0.5, pi.y * h / k - 0.5);
          L += decay * (fraction ? glm::dvec3(v.a) : glm::dvec3(v));
          decay *= options.decay;
        }
        L *= scale;
        if (fraction) L *= glm::dvec3(own.at(x, y, 0), own.at(x, y, 1), own.at(x, y, 2));
      }
      storeScattering(out, x, y, L, std::exp(-grey * pixelRay(camera, cameraDepth, x, y).surface));
    }
  });
  return out;
}

} // namespace crep
