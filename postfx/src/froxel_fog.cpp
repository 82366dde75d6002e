// CPU references of the froxel fog (Wronski 2014, "Volumetric Fog"); the rules are numbered at the top of
// crep/postfx/froxel_fog.h.
#include <crep/postfx/froxel_fog.h>

#include <crep/core/error.h>
#include <crep/core/parallel.h>
#include <crep/scatter/ray.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

namespace crep {

namespace {

std::string field(const char* owner, const char* name) {
  return std::string(owner) + "." + name;
}

bool finite4(const glm::dvec4& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && std::isfinite(v.w);
}

void requireJitter(const glm::dvec3& j, const char* parameter) {
  for (int c = 0; c < 3; ++c)
    if (!(j[c] >= -0.5 && j[c] <= 0.5))
      throw InvalidArgument(parameter, detail::formatValue(j[c]), "cells, each component in [-0.5, 0.5]");
}

void requireVolume(const FroxelVolume& v, const FroxelGrid& grid, const char* parameter) {
  if (v.width != grid.width || v.height != grid.height || v.depth != grid.depth ||
      v.cells.size() != static_cast<std::size_t>(grid.width) * static_cast<std::size_t>(grid.height) *
                            static_cast<std::size_t>(grid.depth))
    throw InvalidArgument(
        parameter, std::to_string(v.width) + "x" + std::to_string(v.height) + "x" + std::to_string(v.depth),
        "must have the grid's size");
}

/// lowbias32 (C. Wellons): a 32-bit integer finalizer with good avalanche.
std::uint32_t lowbias32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

double latticeValue(int i, int j, int k) {
  const std::uint32_t h = (static_cast<std::uint32_t>(i) * 73856093U) ^
                          (static_cast<std::uint32_t>(j) * 19349663U) ^
                          (static_cast<std::uint32_t>(k) * 83492791U);
  return static_cast<double>(lowbias32(h)) / 4294967296.0;
}

} // namespace

void validate(const EsmOptions& o, const char* owner) {
  if (!(o.exponent > 0.0 && o.exponent <= 1e4))
    throw InvalidArgument(field(owner, "exponent"), detail::formatValue(o.exponent),
                          "per world unit along the light, must be in (0, 1e4]");
  if (o.downsample < 1 || o.downsample > 64)
    throw InvalidArgument(field(owner, "downsample"), detail::formatValue(o.downsample),
                          "must be in [1, 64]");
  if (o.blurRadius < 0 || o.blurRadius > 32)
    throw InvalidArgument(field(owner, "blurRadius"), detail::formatValue(o.blurRadius),
                          "must be in [0, 32]");
  if (!(o.bias >= -1.0 && o.bias <= 1.0))
    throw InvalidArgument(field(owner, "bias"), detail::formatValue(o.bias),
                          "depth-buffer units, must be in [-1, 1]");
}

double esmDepthExponent(const EsmOptions& options, const glm::dmat4& lightClipFromWorld) {
  // |grad NDC z| over world space (the orthographic sun map's depth is linear: d = 0.5 ndc.z + 0.5)
  const double g =
      glm::length(glm::dvec3(lightClipFromWorld[0][2], lightClipFromWorld[1][2], lightClipFromWorld[2][2]));
  const double c = options.exponent * 2.0 / g;
  if (!std::isfinite(c) || !(c > 0.0) || c > 1e7)
    throw InvalidArgument(
        "lightClipFromWorld", "depth gradient " + detail::formatValue(g),
        "must give an ESM exponent in (0, 1e7] per depth unit (a finite, non-degenerate depth row)");
  return c;
}

namespace {

/// Log-space mean (Annen et al. 2008's log-space filtering): log(sum w_i exp(c z_i)) / c, evaluated
/// around the largest z so that no term overflows.
double logSpaceMean(const double* z, const double* w, int n, double c) {
  double m = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i)
    if (w[i] > 0.0) m = std::max(m, z[i]);
  double sum = 0.0;
  for (int i = 0; i < n; ++i)
    if (w[i] > 0.0) sum += w[i] * std::exp(c * (z[i] - m));
  return m + std::log(sum) / c;
}

} // namespace

// Annen et al. 2008 (exponential shadow maps, log-space filtering) as downsampled and box-blurred by
// Wronski 2014: rule 1.
Image buildEsm(const Image& shadowDepth, const glm::dmat4& lightClipFromWorld, const EsmOptions& options) {
  validate(options, "EsmOptions");
  const double c = esmDepthExponent(options, lightClipFromWorld);
  if (shadowDepth.empty() || shadowDepth.channels() != 1)
    throw InvalidArgument("shadowDepth", shadowDepth.empty() ? "empty" : "several channels",
                          "must be a 1-channel depth image");
  const int W = shadowDepth.width(), H = shadowDepth.height(), f = options.downsample;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const float d = shadowDepth.at(x, y);
      if (!(d >= 0.0f && d <= 1.0f))
        throw InvalidArgument("shadowDepth",
                              "texel (" + std::to_string(x) + ", " + std::to_string(y) +
                                  ") = " + detail::formatValue(d),
                              "must be a depth-buffer value in [0, 1]");
    }
  const int w = (W + f - 1) / f, h = (H + f - 1) / f;
  std::vector<double> a(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  std::vector<double> z, wt;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      z.clear();
      for (int y = j * f; y < std::min(H, (j + 1) * f); ++y)
        for (int x = i * f; x < std::min(W, (i + 1) * f); ++x)
          z.push_back(shadowDepth.at(x, y));
      wt.assign(z.size(), 1.0 / static_cast<double>(z.size()));
      a[static_cast<std::size_t>(j * w + i)] =
          logSpaceMean(z.data(), wt.data(), static_cast<int>(z.size()), c);
    }
  // Separable box blur, horizontal then vertical, clamped to the edge, in log space.
  const int r = options.blurRadius, taps = 2 * r + 1;
  wt.assign(static_cast<std::size_t>(taps), 1.0 / taps);
  z.resize(static_cast<std::size_t>(taps));
  std::vector<double> b(a.size());
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      for (int k = -r; k <= r; ++k)
        z[static_cast<std::size_t>(k + r)] = a[static_cast<std::size_t>(j * w + std::clamp(i + k, 0, w - 1))];
      b[static_cast<std::size_t>(j * w + i)] = logSpaceMean(z.data(), wt.data(), taps, c);
    }
  Image esm(w, h, 1);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      for (int k = -r; k <= r; ++k)
        z[static_cast<std::size_t>(k + r)] = b[static_cast<std::size_t>(std::clamp(j + k, 0, h - 1) * w + i)];
      esm.at(i, j) = static_cast<float>(logSpaceMean(z.data(), wt.data(), taps, c));
    }
  return esm;
}

// Annen et al. 2008: the ESM test clamp(exp(c (z_occ - d_r)), 0, 1) with Wronski 2014's bilinear lookup
// (bilinear in exp(c z), evaluated in log space): rule 1.
double esmVisibility(const Image& esm, const glm::dmat4& lightClipFromWorld, const glm::dvec3& p,
                     const EsmOptions& options) {
  const glm::dvec4 q = lightClipFromWorld * glm::dvec4(p, 1.0);
  if (!(q.w > 0.0)) return 1.0;
  const glm::dvec3 uvd = glm::dvec3(q) / q.w * 0.5 + 0.5;
  if (!(uvd.x >= 0.0 && uvd.x <= 1.0 && uvd.y >= 0.0 && uvd.y <= 1.0)) return 1.0;
  const double c = esmDepthExponent(options, lightClipFromWorld);
  const int w = esm.width(), h = esm.height();
  const double fx = uvd.x * w - 0.5, fy = uvd.y * h - 0.5;
  const double x0 = std::floor(fx), y0 = std::floor(fy);
  const double ax = fx - x0, ay = fy - y0;
  const auto texel = [&](double x, double y) {
    return static_cast<double>(
        esm.at(std::clamp(static_cast<int>(x), 0, w - 1), std::clamp(static_cast<int>(y), 0, h - 1)));
  };
  const double z[4] = {texel(x0, y0), texel(x0 + 1.0, y0), texel(x0, y0 + 1.0), texel(x0 + 1.0, y0 + 1.0)};
  const double wt[4] = {(1.0 - ax) * (1.0 - ay), ax * (1.0 - ay), (1.0 - ax) * ay, ax * ay};
  const double occluder = logSpaceMean(z, wt, 4, c);
  const double receiver = std::clamp(uvd.z, 0.0, 1.0);
  return std::clamp(std::exp(c * (occluder + options.bias - receiver)), 0.0, 1.0);
}

void validate(const FroxelDensity& d, const char* owner) {
  requireFinite(field(owner, "heightBase"), d.heightBase);
  if (!(d.heightFalloff >= 0.0) || !std::isfinite(d.heightFalloff))
    throw InvalidArgument(field(owner, "heightFalloff"), detail::formatValue(d.heightFalloff),
                          "world units, must be finite and >= 0 (0 = no height fog)");
  if (!(d.noiseAmplitude >= 0.0 && d.noiseAmplitude <= 1.0))
    throw InvalidArgument(field(owner, "noiseAmplitude"), detail::formatValue(d.noiseAmplitude),
                          "must be in [0, 1] (0 = no noise)");
  if (!(d.noiseFrequency > 0.0) || !std::isfinite(d.noiseFrequency))
    throw InvalidArgument(field(owner, "noiseFrequency"), detail::formatValue(d.noiseFrequency),
                          "lattice cells per world unit, must be finite and > 0");
}

// The noise of Wronski 2014's density ("Perlin noise animated by wind"), here value noise: see the header.
double froxelValueNoise(const glm::dvec3& p) {
  const glm::dvec3 f = glm::floor(p);
  const glm::dvec3 t = p - f;
  const glm::dvec3 s = t * t * (3.0 - 2.0 * t);
  const int i = static_cast<int>(f.x), j = static_cast<int>(f.y), k = static_cast<int>(f.z);
  double v[2][2][2];
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx)
        v[dz][dy][dx] = latticeValue(i + dx, j + dy, k + dz);
  const auto lerp = [](double a, double b, double u) { return a + u * (b - a); };
  const double y0 = lerp(lerp(v[0][0][0], v[0][0][1], s.x), lerp(v[0][1][0], v[0][1][1], s.x), s.y);
  const double y1 = lerp(lerp(v[1][0][0], v[1][0][1], s.x), lerp(v[1][1][0], v[1][1][1], s.x), s.y);
  return lerp(y0, y1, s.z);
}

// Wronski 2014, "Density estimation": vertical (exponential height) attenuation times animated noise.
double froxelDensity(const FroxelDensity& d, const glm::dvec3& p, const glm::dvec3& noiseOffset) {
  double rho = 1.0;
  if (d.heightFalloff > 0.0)
    rho *= std::exp(std::clamp(-(p.y - d.heightBase) / d.heightFalloff, -60.0, 20.0));
  if (d.noiseAmplitude > 0.0)
    rho *= 1.0 + d.noiseAmplitude * (2.0 * froxelValueNoise(d.noiseFrequency * (p + noiseOffset)) - 1.0);
  return rho;
}

FroxelVolume::FroxelVolume(int w, int h, int d, const glm::dvec4& fill)
    : width(w), height(h), depth(d),
      cells(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * static_cast<std::size_t>(d), fill) {}

glm::dvec4 FroxelVolume::sample(const glm::dvec3& uvw) const {
  if (!std::isfinite(uvw.x) || !std::isfinite(uvw.y) || !std::isfinite(uvw.z))
    return glm::dvec4(std::numeric_limits<double>::quiet_NaN());
  const glm::dvec3 size(width, height, depth);
  const glm::dvec3 f = uvw * size - 0.5;
  const glm::dvec3 f0 = glm::floor(f);
  const glm::dvec3 a = f - f0;
  const auto clampi = [](double v, int n) { return static_cast<int>(std::clamp(v, 0.0, n - 1.0)); };
  glm::dvec4 sum(0.0);
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        const double wgt = (dx ? a.x : 1.0 - a.x) * (dy ? a.y : 1.0 - a.y) * (dz ? a.z : 1.0 - a.z);
        sum += wgt * at(clampi(f0.x + dx, width), clampi(f0.y + dy, height), clampi(f0.z + dz, depth));
      }
  return sum;
}

// Wronski 2014, "Density estimation and volume lighting": rule 2 (sun with ESM shadow and phase, ambient).
FroxelVolume froxelLighting(const FroxelGrid& grid, const Camera& camera, const DirectionalLight& light,
                            const Medium& medium, const FroxelLightingInputs& in) {
  validate(grid, "froxelLighting");
  validate(in.density, "FroxelLightingInputs.density");
  requireJitter(in.jitter, "FroxelLightingInputs.jitter");
  for (int c = 0; c < 3; ++c) {
    if (!(in.ambient[c] >= 0.0) || !std::isfinite(in.ambient[c]))
      throw InvalidArgument("FroxelLightingInputs.ambient", detail::formatValue(in.ambient[c]),
                            "must be finite and >= 0");
    if (!std::isfinite(in.noiseOffset[c]))
      throw InvalidArgument("FroxelLightingInputs.noiseOffset", detail::formatValue(in.noiseOffset[c]),
                            "must be finite");
  }
  if (in.esm) {
    validate(in.esmOptions, "FroxelLightingInputs.esmOptions");
    if (in.esm->empty() || in.esm->channels() != 1)
      throw InvalidArgument("FroxelLightingInputs.esm", "empty or several channels",
                            "must be buildEsm's image");
  }
  const FroxelDepthRange range = froxelDepthRange(grid, camera, "froxelLighting");
  const double sbar = weightExtinction(medium);
  const glm::dvec3 sigmaS = medium.scattering();
  FroxelVolume out(grid.width, grid.height, grid.depth);
  parallelRows(grid.depth, 0, [&](int z) {
    for (int y = 0; y < grid.height; ++y)
      for (int x = 0; x < grid.width; ++x) {
        const glm::dvec3 uvw((x + 0.5 + in.jitter.x) / grid.width, (y + 0.5 + in.jitter.y) / grid.height,
                             (z + 0.5 + in.jitter.z) / grid.depth);
        const glm::dvec3 p = froxelWorldPoint(camera, range, uvw);
        const glm::dvec3 v = camera.rayDirection(2.0 * uvw.x - 1.0, 2.0 * uvw.y - 1.0);
        const double vis = in.esm ? esmVisibility(*in.esm, in.lightClipFromWorld, p, in.esmOptions) : 1.0;
        const double rho = froxelDensity(in.density, p, in.noiseOffset);
        const glm::dvec3 S =
            rho * (light.irradiance() * medium.scatteringTimesPhase(glm::dot(light.direction(), -v)) * vis +
                   in.ambient * sigmaS);
        glm::dvec4 cell(S, rho * sbar);
        if (!finite4(cell)) cell = glm::dvec4(0.0);
        out.at(x, y, z) = cell;
      }
  });
  return out;
}

// Wronski 2014, "Solving scattering equation": the front-to-back scan, here with the exact exponential
// integral of every piece (rule 3).
FroxelVolume froxelAccumulate(const FroxelVolume& lighting, const FroxelGrid& grid, const Camera& camera,
                              const Medium& medium, const glm::dvec3& jitter) {
  validate(grid, "froxelAccumulate");
  requireVolume(lighting, grid, "froxelAccumulate.lighting");
  requireJitter(jitter, "froxelAccumulate.jitter");
  const FroxelDepthRange range = froxelDepthRange(grid, camera, "froxelAccumulate");
  const glm::dvec3 k = medium.extinction() / weightExtinction(medium);
  FroxelVolume out(grid.width, grid.height, grid.depth);
  parallelRows(grid.height, 0, [&](int y) {
    for (int x = 0; x < grid.width; ++x) {
      glm::dvec3 L(0.0);
      double tau = 0.0;
      const auto piece = [&](const glm::dvec4& cell, double ta, double tb) {
        const double len = tb - ta;
        if (!(len > 0.0)) return;
        const glm::dvec3 T = glm::exp(-k * tau);
        L += T * glm::dvec3(cell) * transmittanceIntegral(k * cell.w, 0.0, len);
        tau += cell.w * len;
      };
      double tPrev = 0.0;
      for (int z = 0; z < grid.depth; ++z) {
        const glm::dvec3 uvw((x + 0.5 + jitter.x) / grid.width, (y + 0.5 + jitter.y) / grid.height,
                             (z + 0.5 + jitter.z) / grid.depth);
        const double t = froxelRayDistance(camera, uvw, froxelViewDepth(range, uvw.z));
        if (z == 0) {
          piece(lighting.at(x, y, 0), 0.0, t);
        } else {
          const double mid = 0.5 * (tPrev + t);
          piece(lighting.at(x, y, z - 1), tPrev, mid);
          piece(lighting.at(x, y, z), mid, t);
        }
        out.at(x, y, z) = glm::dvec4(L, std::exp(-tau));
        tPrev = t;
      }
    }
  });
  return out;
}

// Wronski 2014, "Applying effect": one trilinear lookup per pixel at its own depth (rule 4).
Image froxelApply(const FroxelVolume& integrated, const FroxelGrid& grid, const Camera& camera,
                  const Image& cameraDepth, const glm::dvec3& offset) {
  validate(grid, "froxelApply");
  requireVolume(integrated, grid, "froxelApply.integrated");
  requireJitter(offset, "froxelApply.offset");
  validateCameraDepth(cameraDepth);
  const FroxelDepthRange range = froxelDepthRange(grid, camera, "froxelApply");
  const int w = cameraDepth.width(), h = cameraDepth.height();
  const glm::dvec3 size(grid.width, grid.height, grid.depth);
  const double firstTex = 0.5 / grid.depth;
  const double Z0 = froxelViewDepth(range, (0.5 + offset.z) / grid.depth);
  Image out(w, h, 4);
  parallelRows(h, 0, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const glm::dvec2 uv((x + 0.5) / w, (y + 0.5) / h);
      double Z = camera.surfaceViewDepth(cameraDepth.at(x, y));
      // The column the fetch reads at the image border (clamped to the outermost sample rays): the depth
      // on its ray at the pixel's own distance.
      const glm::dvec2 texUv = uv - glm::dvec2(offset) / glm::dvec2(size);
      const glm::dvec2 column = glm::clamp(texUv, 0.5 / glm::dvec2(size), 1.0 - 0.5 / glm::dvec2(size)) +
                                glm::dvec2(offset) / glm::dvec2(size);
      if (column != uv)
        Z *= glm::dot(camera.rayDirection(2.0 * column.x - 1.0, 2.0 * column.y - 1.0), camera.forward()) /
             glm::dot(camera.rayDirection(2.0 * uv.x - 1.0, 2.0 * uv.y - 1.0), camera.forward());
      const glm::dvec3 tex = glm::dvec3(uv, froxelSliceCoord(range, Z)) - offset / size;
      glm::dvec4 v;
      if (tex.z < firstTex) {
        const double f = Z / Z0;
        v = f * integrated.sample(glm::dvec3(tex.x, tex.y, firstTex)) + (1.0 - f) * glm::dvec4(0, 0, 0, 1);
      } else {
        v = integrated.sample(tex);
      }
      storeScattering(out, x, y, glm::dvec3(v), v.w);
    }
  });
  return out;
}

// Wronski 2014, "Temporal reprojection": history reprojected in 3D, clamped to the current neighbourhood,
// blended (rule 5).
FroxelVolume froxelTemporal(const FroxelVolume& current, const FroxelVolume* history, const FroxelGrid& grid,
                            const Camera& camera, const Camera& previousCamera, double historyWeight) {
  validate(grid, "froxelTemporal");
  requireVolume(current, grid, "froxelTemporal.current");
  if (history) requireVolume(*history, grid, "froxelTemporal.history");
  if (!(historyWeight >= 0.0 && historyWeight < 1.0))
    throw InvalidArgument("froxelTemporal.historyWeight", detail::formatValue(historyWeight),
                          "must be in [0, 1)");
  const FroxelDepthRange range = froxelDepthRange(grid, camera, "froxelTemporal");
  const FroxelDepthRange previousRange = froxelDepthRange(grid, previousCamera, "froxelTemporal");
  FroxelVolume out(grid.width, grid.height, grid.depth);
  parallelRows(grid.depth, 0, [&](int z) {
    for (int y = 0; y < grid.height; ++y)
      for (int x = 0; x < grid.width; ++x) {
        glm::dvec4 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
        glm::dvec4 sum(0.0);
        int n = 0;
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int xx = x + dx, yy = y + dy, zz = z + dz;
              if (xx < 0 || yy < 0 || zz < 0 || xx >= grid.width || yy >= grid.height || zz >= grid.depth)
                continue;
              const glm::dvec4& c = current.at(xx, yy, zz);
              if (!finite4(c)) continue;
              lo = glm::min(lo, c);
              hi = glm::max(hi, c);
              sum += c;
              ++n;
            }
        glm::dvec4 c = current.at(x, y, z);
        if (!finite4(c)) c = n > 0 ? sum / static_cast<double>(n) : glm::dvec4(0.0);
        glm::dvec4 result = c;
        if (history && historyWeight > 0.0 && n > 0) {
          const glm::dvec3 centre((x + 0.5) / grid.width, (y + 0.5) / grid.height, (z + 0.5) / grid.depth);
          const glm::dvec3 prev =
              froxelCoord(previousCamera, previousRange, froxelWorldPoint(camera, range, centre));
          const bool inside = prev.x >= 0.0 && prev.x <= 1.0 && prev.y >= 0.0 && prev.y <= 1.0 &&
                              prev.z >= 0.0 && prev.z <= 1.0;
          if (inside) {
            const glm::dvec4 hist = history->sample(prev);
            if (finite4(hist)) result = c + historyWeight * (glm::clamp(hist, lo, hi) - c);
          }
        }
        out.at(x, y, z) = result;
      }
  });
  return out;
}

} // namespace crep
