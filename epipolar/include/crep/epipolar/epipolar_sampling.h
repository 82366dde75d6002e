// Epipolar sampling (Yusov 2012, Sec. 5-6; the in-scattering criterion of Yusov 2013): the scattering is
// evaluated at samples along epipolar lines (screen lines through the epipole), densely only where the
// depth or the coarse unshadowed in-scattering changes, interpolated along the lines, then warped back to
// the screen with depth-aware (bilateral) weights. CPU reference in double precision (images store
// float); the GPU passes (gpu_epipolar_sampling.h) follow the same rules stage by stage.
//
// ---------------------------------------------------------------------------------------------------
// Screen: W x H pixels, pixel coordinates with the origin at the bottom-left corner; pixel (x, y) covers
// [x, x + 1) x [y, y + 1); ndc = 2 p / (W, H) - 1 for a pixel coordinate p (a pixel centre gives
// crep::pixelRay's ray). Ns samples per line, N lines (slices).
//
// Stage 1, lines (Sec. 6.1). The epipole e: the image of m = -light.direction() as a direction, clip =
//   clipFromWorld (m, 0), w' = clip.w unless |clip.w| < 1e-9 |clip.xy| (then +-1e-9 |clip.xy|, sign of
//   clip.w, + for 0), e = (clip.xy / w' + 1) / 2 (W, H), pulled to at most 1e5 px from the screen centre.
//   In front of the camera it is the light's image, behind it the anti-epipole (same formula).
//   Border parameter sigma in [0, P), P = 2 (W + H), counter-clockwise from the top-left corner: left side
//   downward [0, H), bottom rightward [H, H + W), right upward [H + W, 2H + W), top leftward [2H + W, P).
//   Exit sides: those whose inner open half-plane holds e (left e.x > 0, bottom e.y > 0, right e.x < W,
//   top e.y < H); all four when e is on screen (closed rectangle). They form one cyclic run: the arc
//   [arcBegin, arcBegin + arcLength), every slice's exit point on it, so every slice is visible.
//   Slice i: X_i = borderPoint(arcBegin + (i + 0.5) / N arcLength mod P); entry = e + 0.5 px toward X_i on
//   screen (not e itself: that ray lies on the light axis, which no layout maps), else where e -> X_i
//   enters the screen (Liang-Barsky, t >= 0). L = |X_i - entry| < 1e-3: no valid sample. Else
//   exit = entry + (X_i - entry) max(Ns / L, 1) (short lines rescaled to one sample per pixel), sample k at
//   entry + (exit - entry) k / (Ns - 1), valid for k <= lastValid = min(Ns - 1, floor((Ns - 1) L /
//   |exit - entry| + 1e-6)).
// Stage 2, coordinates: sample (x, y), its pixel's depth-buffer value d (point sampled, pixel = floor
//   clamped to the screen), z = camera.surfaceViewDepth(d), and U = Rec. 709 luminance of the closed-form
//   unshadowed in-scattering of the ray through (x, y) to distance z / dot(v, forward). Invalid samples:
//   coordinates (-1, -1, -1, -1), U = 0.
// Stage 3, refinement (Sec. 6.2; Yusov 2013 for U): a break between valid neighbours k, k + 1 when the
//   view depths differ by more than depthThreshold * min(z) or U by more than scatteringThreshold * max(U)
//   (strict >). Samples k % S' == 0 and lastValid are marched (S' = lines.initialStepAt(k, S): S, or S / D
//   on the first quarter of each line when the epipole is near the screen); the others scan left and
//   right inside their section [a, min(a + S', lastValid)] (a = floor(k / S') S') up to a break or the
//   section end; a sample that cannot move
//   (next to a break) is marched too, the others interpolate between the two scan ends.
// Stage 4, interpolation (Sec. 6.5): linear in k between the two sources.
// Stage 5, unwarp (Sec. 6.6, 6.7) to (W / F) x (H / F): the point c = (p + 0.5) F of a target pixel gets
//   its continuous slice s = lines.sliceOf(c) (wrapping when e is on screen, clamped otherwise), on each of
//   the two nearest lines the projection of c (continuous sample index, clamped), and the bilinear weights
//   of the four samples, each kept only when the sample is valid and |z_src - z_p| <= bilateralThreshold *
//   z_p (z_p from the depth texel p F + F / 2). A total weight <= 1e-4: the pixel is corrected (evaluated
//   directly at c) instead.
// Stage 6, upscale (Sec. 6.8) for F > 1: bilinear from the target with the same bilateral test; total <=
//   1e-4: evaluated directly at the pixel centre.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/error.h> // InvalidArgument, thrown by every function here
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>

namespace crep {

struct EpipolarSamplingOptions {
  int slices = 1024;                ///< N epipolar lines, [1, 16384]
  int samples = 256;                ///< Ns samples per line, a multiple of 32 in [32, 1024]
  int initialStep = 16;             ///< S: a power of two in [1, samples]; 1 = every sample marched
  bool depthCriterion = true;       ///< refine at view-depth breaks (Yusov 2012, Sec. 6.2)
  double depthThreshold = 0.05;     ///< break when |z_a - z_b| > depthThreshold * min(z_a, z_b); > 0, finite
  bool scatteringCriterion = true;  ///< refine where the unshadowed in-scattering changes (Yusov 2013)
  double scatteringThreshold = 0.1; ///< break when |U_a - U_b| > scatteringThreshold * max(U_a, U_b); > 0
  double bilateralThreshold = 0.1;  ///< a source counts when |z_src - z_pix| <= thr * z_pix; >= 0, finite
  int downscale = 1;                ///< F in {1, 2, 4}: unwarp to (W / F) x (H / F), then upscale
  /// D, a power of two in [1, 64]: when the epipole lies within the screen widened by 10% of its diagonal
  /// on each side, the first quarter of every line (rounded down to a multiple of S, at least S samples:
  /// the samples nearest the light, where the phase function's peak varies fastest along the line) gets
  /// the initial step max(S / D, 1) (Yusov 2012, Sec. 6.2: a denser initial sampling near the epipole).
  /// 1 = off. Measured with the sun in view (tests/pipeline/ScatteringEpipolarSamplingGLTest.cpp, 160x90,
  /// map 1024^2, min/max march, relative RMSE against the world-space reference, forest / colonnade / the
  /// sunset scene): D = 1 6.4% / 1.8% / 2.1% (map 512^2), D = 4 2.37% / 0.89% / 1.57%, D = 8 (default)
  /// 1.92% / 0.74% / 1.53%, D = 16 1.81% / 0.70% / 1.44%; the per-pixel march of the same map 1.58% /
  /// 0.62% / 1.05%. Cost: (D - 1) / D more initial samples on a quarter of each line.
  int epipoleDensity = 8;
};

/// Throws InvalidArgument naming owner + "." + the field.
void validate(const EpipolarSamplingOptions& options, const std::string& owner = "EpipolarSamplingOptions");

/// Stage 1: the epipolar lines of a frame (rules at the top).
struct EpipolarLines {
  int width = 0, height = 0;              ///< W, H: the camera image (full resolution)
  int samples = 0;                        ///< Ns
  glm::dvec2 epipole{0.0};                ///< e, pixel coordinates (possibly far outside the screen)
  bool epipoleOnScreen = false;           ///< 0 <= e.x <= W and 0 <= e.y <= H
  double arcBegin = 0.0, arcLength = 0.0; ///< border pixels covered by the exit points
  struct Line {
    glm::dvec2 entry{0.0}, exit{0.0};
    int lastValid = -1;
  };
  /// Samples k < denseEnd of every line use the initial step denseStep (EpipolarSamplingOptions::
  /// epipoleDensity); 0 when the epipole is too far from the screen.
  int denseEnd = 0, denseStep = 1;
  /// The initial step at sample k: denseStep below denseEnd, else S.
  int initialStepAt(int k, int S) const noexcept { return k < denseEnd ? denseStep : S; }
  std::vector<Line> lines; ///< N lines, slice i

  double perimeter() const noexcept { return 2.0 * (width + height); } ///< P
  /// The sigma of a border point: the side it is nearest to (ties: left, bottom, right, top), in [0, P).
  double borderSigma(glm::dvec2 p) const;
  /// The border point of sigma (taken mod P).
  glm::dvec2 borderPoint(double sigma) const;
  /// The continuous slice coordinate of a pixel point p (slice i at i); nullopt within 1e-3 px of e.
  /// Off screen, a sigma that falls outside the arc by rounding goes to the nearer end of the arc.
  std::optional<double> sliceOf(glm::dvec2 p) const;
  /// Sample k of line i: entry + (exit - entry) k / (Ns - 1).
  glm::dvec2 samplePoint(int line, int k) const;
};

/// Yusov 2012, Sec. 6.1: epipole, exit arc, entry/exit points and valid range of every line. Throws
/// InvalidArgument for bad options, "width" / "height" (<= 0, > Image::kMaxDimension, not a multiple of
/// options.downscale).
EpipolarLines epipolarLines(const Camera& camera, const DirectionalLight& light, int width, int height,
                            const EpipolarSamplingOptions& options);

/// Stage 2 output.
struct EpipolarSamples {
  Image coordinates; ///< Ns x N, 4 channels: x, y (pixel coordinates), d (depth-buffer value), z (view depth)
  Image unshadowed;  ///< Ns x N, 1 channel: U, luminance of the unshadowed in-scattering of the sample's ray
};

/// Yusov 2012, Sec. 6.1 (sample coordinates) and Yusov 2013 (U for the in-scattering criterion).
/// cameraDepth: W x H (validateCameraDepth; "cameraDepth" when its size is not the lines').
EpipolarSamples epipolarSamples(const EpipolarLines& lines, const Image& cameraDepth, const Camera& camera,
                                const DirectionalLight& light, const Medium& medium);

/// Yusov 2012, Sec. 6.2 (depth breaks) and Yusov 2013 (in-scattering breaks): sources (left, right) of
/// sample k of line i at index k + i Ns; (k, k) = marched, (-1, -1) = invalid.
std::vector<glm::ivec2> refineSamples(const EpipolarSamples& samples, const EpipolarLines& lines,
                                      const EpipolarSamplingOptions& options);

/// Yusov 2012, Sec. 6.5: marched samples copied from `marched` (Ns x N RGBA), the others linear between
/// their sources, invalid samples 0.
Image interpolateSamples(const std::vector<glm::ivec2>& sources, const Image& marched);

/// Stage 5 / 6 output.
struct UnwarpResult {
  Image image;                  ///< RGBA; corrected pixels 0 (to be evaluated)
  Image coordinates;            ///< 4 channels per pixel: point x, y (full-resolution pixels), d, z
  std::vector<int> corrections; ///< pixel indices y * width + x, increasing
};

/// Yusov 2012, Sec. 6.6 (bilateral unwarp) and 6.7 (the pixels it cannot fill, to correct), to the
/// (W / F) x (H / F) target. interpolated: Ns x N RGBA; cameraDepth: W x H.
UnwarpResult unwarpSamples(const EpipolarLines& lines, const EpipolarSamples& samples,
                           const Image& interpolated, const Image& cameraDepth, const Camera& camera,
                           const EpipolarSamplingOptions& options);

/// Yusov 2012, Sec. 6.8: bilateral upscale of a complete target (corrections evaluated) to W x H.
UnwarpResult upscaleSamples(const UnwarpResult& target, const Image& cameraDepth, const Camera& camera,
                            const EpipolarSamplingOptions& options);

/// RGBA (RGB in-scattering, A transmittance) of the view ray through pixel point (x, y) to the surface of
/// depth-buffer value d.
using SampleEvaluator = std::function<glm::dvec4(double x, double y, double depthValue)>;

struct EpipolarSamplingResult {
  Image image; ///< W x H RGBA
  int validSamples = 0, marchedSamples = 0;
  int correctedPixels = 0;     ///< at the target resolution (unwarp)
  int correctedFullPixels = 0; ///< at full resolution (upscale, F > 1)
};

/// Yusov 2012, Sec. 6 (all stages) on the CPU: `evaluate` is called (from one thread, in increasing sample /
/// pixel order) for the marched samples, the corrected target pixels (at c) and the corrected full pixels
/// (at the pixel centre).
EpipolarSamplingResult epipolarSampling(const Camera& camera, const DirectionalLight& light,
                                        const Medium& medium, const Image& cameraDepth,
                                        const EpipolarSamplingOptions& options,
                                        const SampleEvaluator& evaluate);

} // namespace crep
