// Marches of camera view rays along the rows of a rectified map (Klehm et al. 2014, Sec. 2.2): the
// brute-force march, the reference of every rectified method on the same map, and its scaffolding, shared
// with epipolar/'s tree march. The rule (rows, T(i), light textures): scatter/README.md,
// "crep/scatter/rectified_march.h".
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/error.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/core/parallel.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/light_texture.h>
#include <crep/scatter/ray.h>
#include <crep/scatter/ray_scattering.h>

namespace crep {

/// One pixel's ray mapped onto its row.
struct RowRay {
  double row = 0.0;   ///< normalized row of the ray
  double depth = 0.0; ///< z_r, clamped to [0, 1]
  int texelRow = 0;   ///< j
  int last = 0;       ///< e: the last texel crossed
};

/// Maps `ray` (from `origin`) into a W x H map of `layout`; false when the layout cannot map its end.
bool mapRowRay(const RectifiedLayout& layout, const glm::dvec3& origin, const PixelRay& ray, int width,
               int height, RowRay& out);

/// T(i): the ray's own world distance at texel boundary i.
class RowDistances {
public:
  RowDistances(const RectifiedLayout& layout, const RowRay& ray, int width, double surface);
  double at(int i) const;

private:
  int n_, last_;
  double surface_;
  std::vector<double> bounds_;
  std::vector<DistanceProfile> profiles_;
};

/// The scaffolding over any ray source (no validation): ray i = rayOf(i) at texel (i % width, i / width),
/// walk(RowRay, RowDistances, litSection, steps) per ray, chunks of `chunk` rays in parallel (README).
template <class Light, class RayOf, class Walk>
MarchResult marchRectifiedRays(const RectifiedMap& map, int width, int height, int chunk,
                               const Camera& camera, const Light& light, const Medium& medium,
                               const MarchOptions& options, const Image* lightColors, const RayOf& rayOf,
                               const Walk& walk) {
  constexpr bool kLocal = std::is_same_v<Light, LocalLight>;
  const RectifiedLayout& layout = *map.layout;
  const int w = width, h = height, W = map.width(), H = map.height();
  const long long count = static_cast<long long>(w) * h;
  const glm::dvec3 sigma = medium.extinction();
  const double grey = weightExtinction(medium);
  const glm::dvec3 origin = camera.position();
  MarchResult out{Image(w, h, 4), Image(w, h, 1)};
  const int chunks = static_cast<int>((count + chunk - 1) / chunk);
  parallelRows(chunks, options.threads, [&](int c) {
    const long long first = static_cast<long long>(c) * chunk, last = std::min(first + chunk, count);
    for (long long index = first; index < last; ++index) {
      const int y = static_cast<int>(index / w), x = static_cast<int>(index - static_cast<long long>(y) * w);
      const PixelRay ray = rayOf(index);
      std::optional<RayScattering> local;
      if constexpr (kLocal) local.emplace(light, medium, origin, ray.direction);
      const auto section = [&](double ta, double tb) {
        if constexpr (kLocal)
          return local->segment(ta, tb);
        else
          return transmittanceIntegral(sigma, ta, tb);
      };
      glm::dvec3 L(0.0);
      int steps = 0;
      RowRay r;
      if (!mapRowRay(layout, origin, ray, W, H, r)) {
        L = section(ray.start, ray.surface);
      } else {
        const RowDistances T(layout, r, W, ray.surface);
        if (lightColors) {
          // Light textures: the section's parts per texel, each times its texel's colour.
          walk(
              r, T,
              [&](double ta, double tb) {
                ta = std::max(ta, ray.start);
                if (!(tb > ta)) return;
                int lo = 0, hi = r.last; // the first texel i with T(i + 1) > ta
                while (lo < hi) {
                  const int mid = (lo + hi) / 2;
                  if (T.at(mid + 1) > ta)
                    hi = mid;
                  else
                    lo = mid + 1;
                }
                for (int i = lo; i <= r.last; ++i) {
                  const double a = std::max(ta, T.at(i)), b = std::min(tb, T.at(i + 1));
                  if (a >= tb) break;
                  if (!(b > a)) continue;
                  const glm::dvec3 col(lightColors->at(i, r.texelRow, 0), lightColors->at(i, r.texelRow, 1),
                                       lightColors->at(i, r.texelRow, 2));
                  L += col * section(a, b);
                }
              },
              steps);
        } else {
          walk(
              r, T, [&](double ta, double tb) { L += section(std::max(ta, ray.start), tb); }, steps);
        }
      }
      if constexpr (!kLocal) L = scatteringConstant(light, medium, ray.direction) * L;
      storeScattering(out.scattering, x, y, L, std::exp(-grey * ray.surface));
      out.steps.at(x, y) = static_cast<float>(steps);
    }
  });
  return out;
}

/// Validates the map, "cameraDepth", the options and "lightColors", then marchRectifiedRays on every
/// pixel's ray (pixelRay), one image row per chunk.
template <class Light, class Walk>
MarchResult marchRectifiedRows(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                               const Light& light, const Medium& medium, const MarchOptions& options,
                               const Image* lightColors, const Walk& walk) {
  validate(map);
  validateCameraDepth(cameraDepth);
  validate(options);
  if (lightColors) validateLightColors(*lightColors, map.width(), map.height(), "lightColors");
  const int w = cameraDepth.width();
  return marchRectifiedRays(
      map, w, cameraDepth.height(), w, camera, light, medium, options, lightColors,
      [&](long long i) {
        const int y = static_cast<int>(i / w), x = static_cast<int>(i - static_cast<long long>(y) * w);
        return pixelRay(camera, cameraDepth, x, y, options.nearPlaneCorrection);
      },
      walk);
}

/// The same at screen samples (Yusov 2012, Sec. 6.4): ray i = screenRay at samples[i] into texel (i, 0);
/// at most Image::kMaxDimension samples (InvalidArgument "samples"); bit for bit at pixel centres.
template <class Light, class Walk>
MarchResult marchRectifiedSamples(const RectifiedMap& map, std::span<const ScreenSample> samples, int width,
                                  int height, const Camera& camera, const Light& light, const Medium& medium,
                                  const MarchOptions& options, const Image* lightColors, const Walk& walk) {
  validate(map);
  validateScreenSamples(samples, width, height);
  validate(options);
  if (lightColors) validateLightColors(*lightColors, map.width(), map.height(), "lightColors");
  if (samples.size() > static_cast<std::size_t>(Image::kMaxDimension))
    throw InvalidArgument("samples", std::to_string(samples.size()) + " samples",
                          "at most Image::kMaxDimension = " + std::to_string(Image::kMaxDimension) +
                              " per call (the result is samples.size() x 1): split the list");
  if (samples.empty()) return {};
  return marchRectifiedRays(
      map, static_cast<int>(samples.size()), 1, 256, camera, light, medium, options, lightColors,
      [&](long long i) {
        const ScreenSample& s = samples[static_cast<std::size_t>(i)];
        return screenRay(camera, width, height, s.x, s.y, s.depth, options.nearPlaneCorrection);
      },
      walk);
}

/// marchRectifiedRows without a light texture.
template <class Light, class Walk>
MarchResult marchRectifiedRows(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                               const Light& light, const Medium& medium, const MarchOptions& options,
                               const Walk& walk) {
  return marchRectifiedRows(map, cameraDepth, camera, light, medium, options, nullptr, walk);
}

/// The brute-force march, texel by texel: the reference of every method on the same map. Throws
/// InvalidArgument for the map, "cameraDepth" or the options. O(pixels x texels crossed).
MarchResult bruteForceMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                            const DirectionalLight& light, const Medium& medium,
                            const MarchOptions& options = {});
/// The same for a local light (a spot, or one point-light face, on a map of its rectification).
MarchResult bruteForceMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                            const LocalLight& light, const Medium& medium, const MarchOptions& options = {});
/// With a light texture's colour map (lightColorMap() of the map's layout and size), directional ...
MarchResult bruteForceMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                            const DirectionalLight& light, const Medium& medium, const Image& lightColors,
                            const MarchOptions& options = {});
/// ... and a local light.
MarchResult bruteForceMarch(const RectifiedMap& map, const Image& cameraDepth, const Camera& camera,
                            const LocalLight& light, const Medium& medium, const Image& lightColors,
                            const MarchOptions& options = {});
/// At screen samples (Yusov 2012, Sec. 6.4; results samples.size() x 1). Throws InvalidArgument for the
/// map, "samples[i]", "width" / "height" or the options.
MarchResult bruteForceMarch(const RectifiedMap& map, std::span<const ScreenSample> samples, int width,
                            int height, const Camera& camera, const DirectionalLight& light,
                            const Medium& medium, const MarchOptions& options = {});

} // namespace crep
