// Epipolar sampling, CPU reference (rules in crep/epipolar/epipolar_sampling.h).
#include <crep/epipolar/epipolar_sampling.h>

#include <crep/core/error.h>
#include <crep/core/parallel.h>
#include <crep/scatter/ray.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace crep {

namespace {

constexpr int kMaxSlices = 16384;
constexpr double kMaxEpipoleDistance = 1e5;
constexpr double kSlabEpsilon = 1e-12;
/// Distance of the lines' first sample from an on-screen epipole, pixels (see epipolarLines).
constexpr double kEpipoleOffset = 0.5;
constexpr double kMinWeight = 1e-4;

std::string sizeString(const Image& image) {
  return std::to_string(image.width()) + " x " + std::to_string(image.height()) + " x " +
         std::to_string(image.channels());
}

void requireShape(const Image& image, int width, int height, int channels, const std::string& name) {
  if (image.width() != width || image.height() != height || image.channels() != channels)
    throw InvalidArgument(name, sizeString(image),
                          "must be " + std::to_string(width) + " x " + std::to_string(height) + " x " +
                              std::to_string(channels));
}

void requireLines(const EpipolarLines& lines, const std::string& name) {
  if (lines.width <= 0 || lines.height <= 0 || lines.samples < 2 || lines.lines.empty())
    throw InvalidArgument(name, std::to_string(lines.width) + " x " + std::to_string(lines.height),
                          "must come from epipolarLines");
}

/// The depth image of a frame: valid values and the lines' size.
void requireDepth(const Image& cameraDepth, int width, int height) {
  validateCameraDepth(cameraDepth);
  if (cameraDepth.width() != width || cameraDepth.height() != height)
    throw InvalidArgument("cameraDepth", sizeString(cameraDepth),
                          "must be the screen's " + std::to_string(width) + " x " + std::to_string(height));
}

/// Positive remainder x mod m, x - m floor(x / m).
double positiveMod(double x, double m) {
  return x - m * std::floor(x / m);
}

/// The bilateral test of Sec. 6.6: a source of view depth zSrc counts for a pixel of view depth zPix.
bool depthMatches(double zSrc, double zPix, double threshold) {
  return std::abs(zSrc - zPix) <= threshold * zPix;
}

} // namespace

void validate(const EpipolarSamplingOptions& o, const std::string& owner) {
  if (o.slices < 1 || o.slices > kMaxSlices)
    throw InvalidArgument(owner + ".slices", detail::formatValue(o.slices),
                          "must be in [1, " + std::to_string(kMaxSlices) + "]");
  if (o.samples < 32 || o.samples > 1024 || o.samples % 32 != 0)
    throw InvalidArgument(owner + ".samples", detail::formatValue(o.samples),
                          "must be a multiple of 32 in [32, 1024]");
  if (o.initialStep < 1 || o.initialStep > o.samples || (o.initialStep & (o.initialStep - 1)) != 0)
    throw InvalidArgument(owner + ".initialStep", detail::formatValue(o.initialStep),
                          "must be a power of two in [1, samples]");
  requirePositive(owner + ".depthThreshold", o.depthThreshold);
  requirePositive(owner + ".scatteringThreshold", o.scatteringThreshold);
  requireNonNegative(owner + ".bilateralThreshold", o.bilateralThreshold);
  if (o.epipoleDensity < 1 || o.epipoleDensity > 64 || (o.epipoleDensity & (o.epipoleDensity - 1)) != 0)
    throw InvalidArgument(owner + ".epipoleDensity", detail::formatValue(o.epipoleDensity),
                          "must be a power of two in [1, 64] (1 = off)");
  if (o.downscale != 1 && o.downscale != 2 && o.downscale != 4)
    throw InvalidArgument(owner + ".downscale", detail::formatValue(o.downscale), "must be 1, 2 or 4");
}

// ---- Stage 1 ----------------------------------------------------------------------------------------

// Yusov 2012, Sec. 6.1: the border order (left down, bottom right, right up, top left).
glm::dvec2 EpipolarLines::borderPoint(double sigma) const {
  const double W = width, H = height;
  const double s = positiveMod(sigma, perimeter());
  if (s < H) return {0.0, H - s};
  if (s < H + W) return {s - H, 0.0};
  if (s < 2.0 * H + W) return {W, s - H - W};
  return {W - (s - 2.0 * H - W), H};
}

// Yusov 2012, Sec. 6.1: the inverse of borderPoint for the nearest side (ties: the earlier side).
double EpipolarLines::borderSigma(glm::dvec2 p) const {
  const double W = width, H = height;
  const double distance[4] = {std::abs(p.x), std::abs(p.y), std::abs(p.x - W), std::abs(p.y - H)};
  int side = 0;
  for (int s = 1; s < 4; ++s)
    if (distance[s] < distance[side]) side = s;
  const double x = std::clamp(p.x, 0.0, W), y = std::clamp(p.y, 0.0, H);
  switch (side) {
  case 0:
    return H - y;
  case 1:
    return H + x;
  case 2:
    return H + W + y;
  default:
    return positiveMod(2.0 * H + W + (W - x), perimeter());
  }
}

// Yusov 2012, Sec. 6.6: the slice of a pixel point from the border point its epipolar line exits through.
std::optional<double> EpipolarLines::sliceOf(glm::dvec2 p) const {
  const glm::dvec2 v = p - epipole;
  if (glm::length(v) < 1e-3) return std::nullopt;
  const double size[2] = {static_cast<double>(width), static_cast<double>(height)};
  double tExit = std::numeric_limits<double>::infinity();
  for (int c = 0; c < 2; ++c) {
    if (std::abs(v[c]) < kSlabEpsilon) continue;
    const double t0 = (0.0 - epipole[c]) / v[c], t1 = (size[c] - epipole[c]) / v[c];
    tExit = std::min(tExit, std::max(t0, t1));
  }
  const glm::dvec2 X = epipole + tExit * v;
  const double P = perimeter();
  double m = positiveMod(borderSigma(X) - arcBegin, P);
  // Off screen, a point on the line through the arc's first corner may land a rounding error before
  // arcBegin (m close to P): it belongs to the arc's start, not its end.
  if (!epipoleOnScreen && m > arcLength && m - arcLength > P - m) m -= P;
  return m / arcLength * static_cast<double>(lines.size()) - 0.5;
}

glm::dvec2 EpipolarLines::samplePoint(int line, int k) const {
  const Line& l = lines[static_cast<std::size_t>(line)];
  return l.entry + (l.exit - l.entry) * (static_cast<double>(k) / static_cast<double>(samples - 1));
}

// Line i at (i + 0.5 + offset) / N of the arc, row r's centre at (r + 0.5) / R: for R = m N a centre when
// m (0.5 + offset) - 0.5 is an integer, already for offset 0 when m is odd.
double epipolarLineOffset(int rows, int lines) {
  if (rows <= 0 || lines <= 0 || rows % lines != 0 || (rows / lines) % 2 != 0) return 0.0;
  return 0.5 / (rows / lines);
}

// Yusov 2012, Sec. 6.1: epipole, exit arc, line end points (rescaled short lines), valid sample range.

EpipolarLines epipolarLines(const Camera& camera, const DirectionalLight& light, int width, int height,
                            const EpipolarSamplingOptions& options, double lineOffset) {
  validate(options);
  if (!(lineOffset >= 0.0 && lineOffset <= 0.5))
    throw InvalidArgument("lineOffset", detail::formatValue(lineOffset), "must be in [0, 0.5]");
  if (width <= 0 || width > Image::kMaxDimension || width % options.downscale != 0)
    throw InvalidArgument("width", detail::formatValue(width),
                          "must be in [1, " + std::to_string(Image::kMaxDimension) +
                              "] and a multiple of downscale " + std::to_string(options.downscale));
  if (height <= 0 || height > Image::kMaxDimension || height % options.downscale != 0)
    throw InvalidArgument("height", detail::formatValue(height),
                          "must be in [1, " + std::to_string(Image::kMaxDimension) +
                              "] and a multiple of downscale " + std::to_string(options.downscale));
  EpipolarLines out;
  out.width = width;
  out.height = height;
  out.samples = options.samples;
  const double W = width, H = height, P = out.perimeter();
  const glm::dvec2 size(W, H);

  // The epipole (or anti-epipole): the image of the direction toward the light.
  const glm::dvec4 clip = camera.clipFromWorld() * glm::dvec4(-light.direction(), 0.0);
  const double xy = glm::length(glm::dvec2(clip));
  double w = clip.w;
  if (!(std::abs(w) >= 1e-9 * xy)) w = (clip.w >= 0.0 ? 1.0 : -1.0) * 1e-9 * xy;
  glm::dvec2 e = (glm::dvec2(clip) / w + 1.0) * 0.5 * size;
  const glm::dvec2 centre = 0.5 * size;
  const double fromCentre = glm::length(e - centre);
  if (fromCentre > kMaxEpipoleDistance) e = centre + (e - centre) * (kMaxEpipoleDistance / fromCentre);
  out.epipole = e;
  out.epipoleOnScreen = e.x >= 0.0 && e.x <= W && e.y >= 0.0 && e.y <= H;

  // Denser initial samples near the epipole (EpipolarSamplingOptions::epipoleDensity).
  const double margin = 0.1 * std::hypot(double(W), double(H));
  if (options.epipoleDensity > 1 && e.x >= -margin && e.x <= W + margin && e.y >= -margin &&
      e.y <= H + margin) {
    const int S = options.initialStep;
    out.denseEnd = std::max(S, options.samples / 4 / S * S);
    out.denseStep = std::max(S / options.epipoleDensity, 1);
  }

  // The exit arc: the cyclic run of exit sides (left, bottom, right, top).
  if (out.epipoleOnScreen) {
    out.arcBegin = 0.0;
    out.arcLength = P;
  } else {
    const bool exitSide[4] = {e.x > 0.0, e.y > 0.0, e.x < W, e.y < H};
    const double sideBegin[4] = {0.0, H, H + W, 2.0 * H + W};
    const double sideLength[4] = {H, W, H, W};
    for (int s = 0; s < 4; ++s) {
      if (!exitSide[s]) continue;
      out.arcLength += sideLength[s];
      if (!exitSide[(s + 3) % 4]) out.arcBegin = sideBegin[s];
    }
  }

  const int N = options.slices, Ns = options.samples;
  // The lines' slots start lineOffset of a spacing later (sliceOf and the GPU unwarp measure from arcBegin).
  out.arcBegin = positiveMod(out.arcBegin + lineOffset * out.arcLength / N, P);
  out.lines.resize(static_cast<std::size_t>(N));
  for (int i = 0; i < N; ++i) {
    EpipolarLines::Line& line = out.lines[static_cast<std::size_t>(i)];
    const double sigma = positiveMod(out.arcBegin + (i + 0.5) / N * out.arcLength, P);
    const glm::dvec2 X = out.borderPoint(sigma);
    glm::dvec2 entry = e;
    if (out.epipoleOnScreen && glm::length(X - e) > kEpipoleOffset) {
      // Not exactly at the epipole: that ray lies on the light axis, where no layout maps it (every
      // line's sample 0 would be an unshadowed ray into or away from the light, interpolated over the
      // first initialStep samples of every line). Half a pixel out, sample 0 is an ordinary ray.
      entry = e + kEpipoleOffset * glm::normalize(X - e);
    } else if (!out.epipoleOnScreen) {
      const glm::dvec2 d = X - e;
      double tEntry = 0.0;
      for (int c = 0; c < 2; ++c) {
        if (std::abs(d[c]) < kSlabEpsilon) continue;
        const double t0 = (0.0 - e[c]) / d[c], t1 = (size[c] - e[c]) / d[c];
        tEntry = std::max(tEntry, std::min(t0, t1));
      }
      entry = e + tEntry * d;
    }
    const double L = glm::length(X - entry);
    if (L < 1e-3) {
      line.entry = line.exit = X;
      line.lastValid = -1;
      continue;
    }
    line.entry = entry;
    line.exit = entry + (X - entry) * std::max(Ns / L, 1.0);
    const double length = glm::length(line.exit - line.entry);
    line.lastValid = std::min(Ns - 1, static_cast<int>(std::floor((Ns - 1) * L / length + 1e-6)));
  }
  return out;
}

// ---- Stage 2 ----------------------------------------------------------------------------------------

// Yusov 2012, Sec. 6.1 (sample positions, point-sampled depth) and Yusov 2013 (unshadowed in-scattering U).
EpipolarSamples epipolarSamples(const EpipolarLines& lines, const Image& cameraDepth, const Camera& camera,
                                const DirectionalLight& light, const Medium& medium) {
  requireLines(lines, "epipolarSamples.lines");
  requireDepth(cameraDepth, lines.width, lines.height);
  const int Ns = lines.samples, N = static_cast<int>(lines.lines.size());
  const int W = lines.width, H = lines.height;
  EpipolarSamples out{Image(Ns, N, 4, -1.0f), Image(Ns, N, 1, 0.0f)};
  const glm::dvec3 sigma = medium.extinction();
  const glm::dvec3 luminance(0.2126, 0.7152, 0.0722);
  const glm::dvec3 forward = camera.forward();
  parallelRows(N, 0, [&](int i) {
    const int last = lines.lines[static_cast<std::size_t>(i)].lastValid;
    for (int k = 0; k <= last; ++k) {
      const glm::dvec2 p = lines.samplePoint(i, k);
      const int qx = std::max(0, std::min(static_cast<int>(std::floor(p.x)), W - 1));
      const int qy = std::max(0, std::min(static_cast<int>(std::floor(p.y)), H - 1));
      const double d = cameraDepth.at(qx, qy);
      const double z = camera.surfaceViewDepth(d);
      const glm::dvec3 v = camera.rayDirection(2.0 * p.x / W - 1.0, 2.0 * p.y / H - 1.0);
      const double s = z / glm::dot(v, forward);
      const glm::dvec3 L = scatteringConstant(light, medium, v) * transmittanceIntegral(sigma, 0.0, s);
      out.coordinates.at(k, i, 0) = static_cast<float>(p.x);
      out.coordinates.at(k, i, 1) = static_cast<float>(p.y);
      out.coordinates.at(k, i, 2) = static_cast<float>(d);
      out.coordinates.at(k, i, 3) = static_cast<float>(z);
      out.unshadowed.at(k, i) = static_cast<float>(glm::dot(luminance, L));
    }
  });
  return out;
}

// ---- Stage 3 ----------------------------------------------------------------------------------------

// Yusov 2012, Sec. 6.2 (depth breaks, sections of S samples, marching next to breaks) and Yusov 2013
// (breaks in the unshadowed in-scattering).
std::vector<glm::ivec2> refineSamples(const EpipolarSamples& samples, const EpipolarLines& lines,
                                      const EpipolarSamplingOptions& options) {
  validate(options);
  requireLines(lines, "refineSamples.lines");
  const int Ns = lines.samples, N = static_cast<int>(lines.lines.size());
  requireShape(samples.coordinates, Ns, N, 4, "refineSamples.samples.coordinates");
  requireShape(samples.unshadowed, Ns, N, 1, "refineSamples.samples.unshadowed");
  const int S = options.initialStep;
  std::vector<glm::ivec2> sources(static_cast<std::size_t>(Ns) * static_cast<std::size_t>(N), glm::ivec2(-1));
  parallelRows(N, 0, [&](int i) {
    const int last = lines.lines[static_cast<std::size_t>(i)].lastValid;
    // breaks[k]: a break between k and k + 1 (both valid).
    std::vector<char> breaks(static_cast<std::size_t>(Ns), 0);
    for (int k = 0; k < last; ++k) {
      const double za = samples.coordinates.at(k, i, 3), zb = samples.coordinates.at(k + 1, i, 3);
      const double ua = samples.unshadowed.at(k, i), ub = samples.unshadowed.at(k + 1, i);
      breaks[static_cast<std::size_t>(k)] =
          (options.depthCriterion && std::abs(za - zb) > options.depthThreshold * std::min(za, zb)) ||
          (options.scatteringCriterion && std::abs(ua - ub) > options.scatteringThreshold * std::max(ua, ub));
    }
    for (int k = 0; k <= last; ++k) {
      const int step = lines.initialStepAt(k, S);
      const int a = k / step * step, b = std::min(a + step, last);
      int left = k, right = k;
      while (left > a && !breaks[static_cast<std::size_t>(left - 1)])
        --left;
      while (right < b && !breaks[static_cast<std::size_t>(right)])
        ++right;
      const bool marched = k % step == 0 || k == last || left == k || right == k;
      sources[static_cast<std::size_t>(k) + static_cast<std::size_t>(i) * static_cast<std::size_t>(Ns)] =
          marched ? glm::ivec2(k) : glm::ivec2(left, right);
    }
  });
  return sources;
}

// ---- Stage 4 ----------------------------------------------------------------------------------------

// Yusov 2012, Sec. 6.5: linear interpolation along the line between the two marched sources.
Image interpolateSamples(const std::vector<glm::ivec2>& sources, const Image& marched) {
  if (marched.empty() || marched.channels() != 4 ||
      sources.size() !=
          static_cast<std::size_t>(marched.width()) * static_cast<std::size_t>(marched.height()))
    throw InvalidArgument("interpolateSamples.marched", sizeString(marched),
                          "must be Ns x N x 4 with Ns N = sources.size() = " +
                              std::to_string(sources.size()));
  const int Ns = marched.width(), N = marched.height();
  Image out(Ns, N, 4, 0.0f);
  for (int i = 0; i < N; ++i)
    for (int k = 0; k < Ns; ++k) {
      const glm::ivec2 src =
          sources[static_cast<std::size_t>(k) + static_cast<std::size_t>(i) * static_cast<std::size_t>(Ns)];
      if (src.x < 0) continue;
      if (src.y >= Ns || src.x > k || src.y < k)
        throw InvalidArgument("interpolateSamples.sources",
                              "(" + std::to_string(src.x) + ", " + std::to_string(src.y) + ")",
                              "must bracket sample " + std::to_string(k) + " within the line");
      if (src.x == src.y) {
        for (int c = 0; c < 4; ++c)
          out.at(k, i, c) = marched.at(k, i, c);
        continue;
      }
      const double w = static_cast<double>(k - src.x) / static_cast<double>(src.y - src.x);
      for (int c = 0; c < 4; ++c)
        out.at(k, i, c) =
            static_cast<float>((1.0 - w) * marched.at(src.x, i, c) + w * marched.at(src.y, i, c));
    }
  return out;
}

// ---- Stage 5 ----------------------------------------------------------------------------------------

// Yusov 2012, Sec. 6.6 (bilateral unwarp from the two nearest lines) and 6.7 (pixels left to correct).
UnwarpResult unwarpSamples(const EpipolarLines& lines, const EpipolarSamples& samples,
                           const Image& interpolated, const Image& cameraDepth, const Camera& camera,
                           const EpipolarSamplingOptions& options) {
  validate(options);
  requireLines(lines, "unwarpSamples.lines");
  const int Ns = lines.samples, N = static_cast<int>(lines.lines.size());
  requireShape(samples.coordinates, Ns, N, 4, "unwarpSamples.samples.coordinates");
  requireShape(interpolated, Ns, N, 4, "unwarpSamples.interpolated");
  requireDepth(cameraDepth, lines.width, lines.height);
  const int F = options.downscale;
  if (lines.width % F != 0 || lines.height % F != 0)
    throw InvalidArgument("unwarpSamples.options.downscale", detail::formatValue(F),
                          "must divide the screen size " + std::to_string(lines.width) + " x " +
                              std::to_string(lines.height));
  const int w = lines.width / F, h = lines.height / F;
  const double thr = options.bilateralThreshold;
  UnwarpResult out{Image(w, h, 4, 0.0f), Image(w, h, 4, 0.0f), {}};
  std::vector<std::vector<int>> rowCorrections(static_cast<std::size_t>(h));
  parallelRows(h, 0, [&](int py) {
    for (int px = 0; px < w; ++px) {
      const glm::dvec2 c = (glm::dvec2(px, py) + 0.5) * static_cast<double>(F);
      const double d = cameraDepth.at(px * F + F / 2, py * F + F / 2);
      const double z = camera.surfaceViewDepth(d);
      out.coordinates.at(px, py, 0) = static_cast<float>(c.x);
      out.coordinates.at(px, py, 1) = static_cast<float>(c.y);
      out.coordinates.at(px, py, 2) = static_cast<float>(d);
      out.coordinates.at(px, py, 3) = static_cast<float>(z);

      double total = 0.0;
      glm::dvec4 sum(0.0);
      if (const std::optional<double> s = lines.sliceOf(c)) {
        int i0 = static_cast<int>(std::floor(*s)), i1 = i0 + 1;
        double f = *s - i0;
        if (lines.epipoleOnScreen) {
          i0 = ((i0 % N) + N) % N;
          i1 = ((i1 % N) + N) % N;
        } else if (*s < 0.0) {
          i0 = i1 = 0;
          f = 0.0;
        } else if (*s > N - 1) {
          i0 = i1 = N - 1;
          f = 0.0;
        } else {
          i1 = std::min(i1, N - 1); // s == N - 1 exactly: f = 0
        }
        const int lineIndex[2] = {i0, i1};
        const double lineWeight[2] = {1.0 - f, f};
        for (int j = 0; j < 2; ++j) {
          const EpipolarLines::Line& line = lines.lines[static_cast<std::size_t>(lineIndex[j])];
          if (line.lastValid < 0) continue;
          const glm::dvec2 axis = line.exit - line.entry;
          const double u =
              std::clamp(glm::dot(c - line.entry, axis) / glm::dot(axis, axis) * (Ns - 1), 0.0, Ns - 1.0);
          const int k0 = std::min(static_cast<int>(std::floor(u)), Ns - 2);
          const double g = u - k0;
          const int k[2] = {k0, k0 + 1};
          const double sampleWeight[2] = {1.0 - g, g};
          for (int m = 0; m < 2; ++m) {
            if (k[m] > line.lastValid) continue;
            const double zSrc = samples.coordinates.at(k[m], lineIndex[j], 3);
            if (!depthMatches(zSrc, z, thr)) continue;
            const double weight = lineWeight[j] * sampleWeight[m];
            total += weight;
            for (int ch = 0; ch < 4; ++ch)
              sum[ch] += weight * interpolated.at(k[m], lineIndex[j], ch);
          }
        }
      }
      if (total <= kMinWeight) {
        rowCorrections[static_cast<std::size_t>(py)].push_back(py * w + px);
        continue;
      }
      for (int ch = 0; ch < 4; ++ch)
        out.image.at(px, py, ch) = static_cast<float>(sum[ch] / total);
    }
  });
  for (const std::vector<int>& row : rowCorrections)
    out.corrections.insert(out.corrections.end(), row.begin(), row.end());
  return out;
}

// ---- Stage 6 ----------------------------------------------------------------------------------------

// Yusov 2012, Sec. 6.8: bilateral bilinear upscale of the target to full resolution.
UnwarpResult upscaleSamples(const UnwarpResult& target, const Image& cameraDepth, const Camera& camera,
                            const EpipolarSamplingOptions& options) {
  validate(options);
  validateCameraDepth(cameraDepth);
  const int F = options.downscale;
  const int W = cameraDepth.width(), H = cameraDepth.height();
  if (W % F != 0 || H % F != 0)
    throw InvalidArgument("cameraDepth", sizeString(cameraDepth),
                          "must be a multiple of downscale " + std::to_string(F));
  const int w = W / F, h = H / F;
  requireShape(target.image, w, h, 4, "upscaleSamples.target.image");
  requireShape(target.coordinates, w, h, 4, "upscaleSamples.target.coordinates");
  const double thr = options.bilateralThreshold;
  UnwarpResult out{Image(W, H, 4, 0.0f), Image(W, H, 4, 0.0f), {}};
  // One axis: the two texels and the weight of the second (one texel when the grid is 1 wide).
  auto axis = [F](int q, int n, int& i0, int& i1, double& g) {
    if (n == 1) {
      i0 = i1 = 0;
      g = 0.0;
      return;
    }
    const double u = std::clamp((q + 0.5) / F - 0.5, 0.0, n - 1.0);
    i0 = std::min(static_cast<int>(std::floor(u)), n - 2);
    i1 = i0 + 1;
    g = u - i0;
  };
  std::vector<std::vector<int>> rowCorrections(static_cast<std::size_t>(H));
  parallelRows(H, 0, [&](int qy) {
    int y0, y1;
    double gy;
    axis(qy, h, y0, y1, gy);
    for (int qx = 0; qx < W; ++qx) {
      const double d = cameraDepth.at(qx, qy);
      const double z = camera.surfaceViewDepth(d);
      out.coordinates.at(qx, qy, 0) = static_cast<float>(qx + 0.5);
      out.coordinates.at(qx, qy, 1) = static_cast<float>(qy + 0.5);
      out.coordinates.at(qx, qy, 2) = static_cast<float>(d);
      out.coordinates.at(qx, qy, 3) = static_cast<float>(z);
      int x0, x1;
      double gx;
      axis(qx, w, x0, x1, gx);
      const int tx[4] = {x0, x1, x0, x1}, ty[4] = {y0, y0, y1, y1};
      const double tw[4] = {(1.0 - gx) * (1.0 - gy), gx * (1.0 - gy), (1.0 - gx) * gy, gx * gy};
      double total = 0.0;
      glm::dvec4 sum(0.0);
      for (int j = 0; j < 4; ++j) {
        if (!depthMatches(target.coordinates.at(tx[j], ty[j], 3), z, thr)) continue;
        total += tw[j];
        for (int ch = 0; ch < 4; ++ch)
          sum[ch] += tw[j] * target.image.at(tx[j], ty[j], ch);
      }
      if (total <= kMinWeight) {
        rowCorrections[static_cast<std::size_t>(qy)].push_back(qy * W + qx);
        continue;
      }
      for (int ch = 0; ch < 4; ++ch)
        out.image.at(qx, qy, ch) = static_cast<float>(sum[ch] / total);
    }
  });
  for (const std::vector<int>& row : rowCorrections)
    out.corrections.insert(out.corrections.end(), row.begin(), row.end());
  return out;
}

// ---- The whole pipeline -----------------------------------------------------------------------------

namespace {

void store(Image& image, int x, int y, const glm::dvec4& value) {
  for (int c = 0; c < 4; ++c)
    image.at(x, y, c) = static_cast<float>(value[c]);
}

/// Evaluates the corrections of an unwarp / upscale result at their coordinates, into its image.
void correct(UnwarpResult& result, const SampleEvaluator& evaluate) {
  const int w = result.image.width();
  for (const int index : result.corrections) {
    const int x = index % w, y = index / w;
    store(result.image, x, y,
          evaluate(result.coordinates.at(x, y, 0), result.coordinates.at(x, y, 1),
                   result.coordinates.at(x, y, 2)));
  }
}

} // namespace

// Yusov 2012, Sec. 6.1-6.8 with Yusov 2013's criterion: all stages, the evaluator for the marched samples
// and the corrections.
EpipolarSamplingResult epipolarSampling(const Camera& camera, const DirectionalLight& light,
                                        const Medium& medium, const Image& cameraDepth,
                                        const EpipolarSamplingOptions& options,
                                        const SampleEvaluator& evaluate) {
  validate(options);
  validateCameraDepth(cameraDepth);
  if (!evaluate) throw InvalidArgument("epipolarSampling.evaluate", "empty", "must be a callable");
  const EpipolarLines lines =
      epipolarLines(camera, light, cameraDepth.width(), cameraDepth.height(), options);
  const EpipolarSamples samples = epipolarSamples(lines, cameraDepth, camera, light, medium);
  const std::vector<glm::ivec2> sources = refineSamples(samples, lines, options);
  const int Ns = lines.samples, N = static_cast<int>(lines.lines.size());

  EpipolarSamplingResult result;
  Image marched(Ns, N, 4, 0.0f);
  for (int i = 0; i < N; ++i)
    for (int k = 0; k < Ns; ++k) {
      const glm::ivec2 src =
          sources[static_cast<std::size_t>(k) + static_cast<std::size_t>(i) * static_cast<std::size_t>(Ns)];
      if (src.x < 0) continue;
      ++result.validSamples;
      if (src.x != k || src.y != k) continue;
      ++result.marchedSamples;
      const glm::dvec2 p = lines.samplePoint(i, k); // double, not the float coordinates
      store(marched, k, i, evaluate(p.x, p.y, samples.coordinates.at(k, i, 2)));
    }
  const Image interpolated = interpolateSamples(sources, marched);
  UnwarpResult target = unwarpSamples(lines, samples, interpolated, cameraDepth, camera, options);
  result.correctedPixels = static_cast<int>(target.corrections.size());
  correct(target, evaluate);
  if (options.downscale == 1) {
    result.image = std::move(target.image);
    return result;
  }
  UnwarpResult full = upscaleSamples(target, cameraDepth, camera, options);
  result.correctedFullPixels = static_cast<int>(full.corrections.size());
  correct(full, evaluate);
  result.image = std::move(full.image);
  return result;
}

} // namespace crep
