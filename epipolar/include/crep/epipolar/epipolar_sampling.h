// Epipolar sampling (Yusov 2012, Sec. 5-6; the in-scattering criterion of Yusov 2013): CPU reference in
// double of every stage; the GPU passes (gpu_epipolar_sampling.h) follow it stage by stage. Screen
// conventions and the rules of the six stages: epipolar/README.md, "crep/epipolar/epipolar_sampling.h".
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
  /// D, a power of two in [1, 64] (1 = off): initial step S / D on the first quarter of each line when the
  /// epipole is near the screen (Yusov 2012, Sec. 6.2). Cost: (D - 1) / D more initial samples there.
  int epipoleDensity = 8;
};

/// Throws InvalidArgument naming owner + "." + the field.
void validate(const EpipolarSamplingOptions& options, const std::string& owner = "EpipolarSamplingOptions");

/// Stage 1: the epipolar lines of a frame (README).
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
  /// Samples k < denseEnd use the initial step denseStep (epipoleDensity); 0 when the epipole is far.
  int denseEnd = 0, denseStep = 1;
  /// The initial step at sample k: denseStep below denseEnd, else S.
  int initialStepAt(int k, int S) const noexcept { return k < denseEnd ? denseStep : S; }
  std::vector<Line> lines; ///< N lines, slice i

  double perimeter() const noexcept { return 2.0 * (width + height); } ///< P
  /// The sigma of a border point: the side it is nearest to (ties: left, bottom, right, top), in [0, P).
  double borderSigma(glm::dvec2 p) const;
  /// The border point of sigma (taken mod P).
  glm::dvec2 borderPoint(double sigma) const;
  /// The continuous slice coordinate of pixel point p (slice i at i); nullopt within 1e-3 px of e.
  std::optional<double> sliceOf(glm::dvec2 p) const;
  /// Sample k of line i: entry + (exit - entry) k / (Ns - 1).
  glm::dvec2 samplePoint(int line, int k) const;
};

/// Yusov 2012, Sec. 6.1: epipole, exit arc and every line. Throws InvalidArgument for bad options or
/// "width" / "height" (<= 0, > Image::kMaxDimension, not a multiple of options.downscale) or "lineOffset"
/// (outside [0, 0.5]). Per frame, O(N). lineOffset moves every line along the border by that fraction of
/// the line spacing (arcBegin with it): crep::Scattering puts the lines on its epipolar map's row centres.
EpipolarLines epipolarLines(const Camera& camera, const DirectionalLight& light, int width, int height,
                            const EpipolarSamplingOptions& options, double lineOffset = 0.0);

/// The lineOffset that puts `lines` lines on the centres of `rows` rows spanning the same border arc: with
/// rows = m lines and m even each line would lie on a boundary between two rows (half a row moves it to a
/// centre); 0 otherwise (no line on a boundary, or a ratio that does not repeat).
double epipolarLineOffset(int rows, int lines);

/// Stage 2 output.
struct EpipolarSamples {
  Image coordinates; ///< Ns x N, 4 channels: x, y (pixel coordinates), d (depth-buffer value), z (view depth)
  Image unshadowed;  ///< Ns x N, 1 channel: U, luminance of the unshadowed in-scattering of the sample's ray
};

/// Yusov 2012, Sec. 6.1 (sample coordinates) and Yusov 2013 (U for the in-scattering criterion).
/// cameraDepth: W x H (validateCameraDepth; "cameraDepth" when its size is not the lines').
EpipolarSamples epipolarSamples(const EpipolarLines& lines, const Image& cameraDepth, const Camera& camera,
                                const DirectionalLight& light, const Medium& medium);

/// Yusov 2012, Sec. 6.2 and Yusov 2013: sources (left, right) of sample k of line i at k + i Ns;
/// (k, k) = marched, (-1, -1) = invalid.
std::vector<glm::ivec2> refineSamples(const EpipolarSamples& samples, const EpipolarLines& lines,
                                      const EpipolarSamplingOptions& options);

/// Yusov 2012, Sec. 6.5: marched samples from `marched` (Ns x N RGBA), the others linear, invalid 0.
Image interpolateSamples(const std::vector<glm::ivec2>& sources, const Image& marched);

/// Stage 5 / 6 output.
struct UnwarpResult {
  Image image;                  ///< RGBA; corrected pixels 0 (to be evaluated)
  Image coordinates;            ///< 4 channels per pixel: point x, y (full-resolution pixels), d, z
  std::vector<int> corrections; ///< pixel indices y * width + x, increasing
};

/// Yusov 2012, Sec. 6.6-6.7: bilateral unwarp to (W / F) x (H / F), the unfilled pixels to correct.
/// interpolated: Ns x N RGBA; cameraDepth: W x H.
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

/// Yusov 2012, Sec. 6, all stages on the CPU; `evaluate` is called from one thread, in increasing order.
EpipolarSamplingResult epipolarSampling(const Camera& camera, const DirectionalLight& light,
                                        const Medium& medium, const Image& cameraDepth,
                                        const EpipolarSamplingOptions& options,
                                        const SampleEvaluator& evaluate);

} // namespace crep
