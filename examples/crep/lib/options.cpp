#include "options.h"

#include <algorithm>
#include <cmath>

namespace crep::tool {

static_assert(static_cast<long long>(kMaxMapSize) * kMaxMapSize <= Image::kMaxPixels);

const std::set<std::string> kMethodOptions = {"method",
                                              "map-size",
                                              "bases",
                                              "format",
                                              "reconstruction",
                                              "splits",
                                              "steps",
                                              "scale",
                                              "slices",
                                              "samples",
                                              "initial-step",
                                              "downscale",
                                              "epipole-block",
                                              "epipole-block-radius",
                                              "epipole-block-pixels"};

const char* const kMethodOptionsHelp =
    R"(            --map-size N        shadow map and rectified map size (default 1024, at most 16384)
            --reconstruction R  prefiltered methods' visibility: exact (default: the depth test per texel)
                                | fourier (Klehm et al. 2014: the truncated series of --bases M)
            --bases M           Fourier bases, even, in [4, 128] (default 32; with --reconstruction fourier)
            --format F          filtered-basis storage rgba8 (default) | rgba16f | rgba32f (fourier)
            --splits K          rectification splits (default 8, 2 prefilter regions each; --map-size must
                                be a multiple of 2 K and of 16, the epipolar fallback's 8 x 2 regions)
            --steps N           reference march: sections per view ray, changes bisected (default 256)
            --scale S           prefiltered method: evaluate at 1 (default), 0.5 or 0.25 of the image
                                size per axis, depth-aware upsampling (the size a multiple of 1 / S)
            --slices N          epipolar-sampling, epipolar-prefilter: epipolar lines (default 1024)
            --samples N         samples per line, a multiple of 32 in [32, 1024] (default 256)
            --initial-step N    every N-th sample evaluated before refinement, a power of two (default 16)
            --downscale F       unwarp at 1 / F of the image per axis, F = 1 (default), 2 or 4, then a
                                depth-aware upscale (the size a multiple of F)
            --epipole-block B   prefilter, epipolar-prefilter with the sun in view: the pixels next to
                                the epipole by the min/max tree march over the frame's epipolar map
                                (tree, default) or the world-space march of the reference (world)
            --epipole-block-radius R  that block's radius, a fraction of the screen diagonal in
                                [0, 0.5] (default 0.06; 0: no block)
            --epipole-block-pixels N  most pixels of that block on screen, the radius shrinks to
                                hold at most N (default 2048; 0: no bound)
)";

StorageFormat parseFormat(const std::string& text) {
  if (text == "rgba8") return StorageFormat::RGBA8;
  if (text == "rgba16f") return StorageFormat::RGBA16F;
  if (text == "rgba32f") return StorageFormat::RGBA32F;
  throw UsageError("option --format: '" + text + "' is not rgba8, rgba16f or rgba32f");
}

double exposureOption(const Args& args) {
  return args.number("exposure", 1.0, kMinExposure, kMaxExposure);
}

MethodSettings methodSettings(const Args& args) {
  MethodSettings s;
  s.mapSize = args.integer("map-size", s.mapSize, 1, kMaxMapSize);
  s.steps = args.integer("steps", s.steps, 1, 65536);
  s.prefilter.bases = args.integer("bases", s.prefilter.bases, kMinBases, kMaxBases);
  if (s.prefilter.bases % 2 != 0) throw UsageError("option --bases: must be even");
  s.prefilter.format = parseFormat(args.string("format", "rgba8"));
  const std::string reconstruction = args.string("reconstruction", "exact");
  if (reconstruction == "exact")
    s.prefilter.reconstruction = VisibilityReconstruction::Exact;
  else if (reconstruction == "fourier")
    s.prefilter.reconstruction = VisibilityReconstruction::Fourier;
  else
    throw UsageError("option --reconstruction: '" + reconstruction + "' is not exact or fourier");
  s.rectify.splits = args.integer("splits", s.rectify.splits, 1, RectifyOptions::kMaxSplits);
  s.scale = args.number("scale", 1.0, 0.25, 1.0);
  if (s.scale != 1.0 && s.scale != 0.5 && s.scale != 0.25)
    throw UsageError("option --scale: must be 1, 0.5 or 0.25");
  s.sampling.slices = args.integer("slices", s.sampling.slices, 1, 16384);
  s.sampling.samples = args.integer("samples", s.sampling.samples, 32, 1024);
  s.sampling.initialStep = args.integer("initial-step", s.sampling.initialStep, 1, 1024);
  s.sampling.downscale = args.integer("downscale", s.sampling.downscale, 1, 4);
  const std::string block = args.string("epipole-block", "tree");
  if (block == "tree")
    s.epipoleBlock = Scattering::EpipoleBlockMethod::TreeMarch;
  else if (block == "world")
    s.epipoleBlock = Scattering::EpipoleBlockMethod::WorldMarch;
  else
    throw UsageError("option --epipole-block: '" + block + "' is not tree or world");
  s.epipoleBlockRadius = args.number("epipole-block-radius", s.epipoleBlockRadius, 0.0, 0.5);
  s.epipoleBlockMaxPixels = args.integer("epipole-block-pixels", s.epipoleBlockMaxPixels, 0, 1 << 28);
  try {
    validate(s.sampling, "EpipolarSamplingOptions");
  } catch (const InvalidArgument& e) {
    // The option of the field the library names (EpipolarSamplingOptions.initialStep -> --initial-step).
    const std::string& p = e.parameter();
    const std::string option = p.ends_with(".slices")        ? "option --slices"
                               : p.ends_with(".samples")     ? "option --samples"
                               : p.ends_with(".initialStep") ? "option --initial-step"
                               : p.ends_with(".downscale")
                                   ? "option --downscale"
                                   : "options --slices/--samples/--initial-step/--downscale";
    throw UsageError(option + ": " + e.what());
  }
  // Scattering's rule (crep/pipeline/scattering.h): a multiple of the prefilter regions of both layouts.
  Scattering::CreateInfo info;
  info.rectify = s.rectify;
  info.prefilter = s.prefilter;
  const int perSplit = s.prefilter.regionsPerSplit, multiple = info.mapSizeMultiple();
  if (s.mapSize % multiple != 0)
    throw UsageError("option --map-size: " + std::to_string(s.mapSize) + " must be a multiple of " +
                     std::to_string(multiple) + " (--splits " + std::to_string(s.rectify.splits) + " x " +
                     std::to_string(perSplit) + " prefilter regions, and the epipolar fallback's " +
                     std::to_string(info.epipolarRegions * perSplit) + ")");
  return s;
}

void requireMethodImageSize(const MethodSettings& settings, const std::vector<std::string>& methods,
                            glm::ivec2 size, const std::string& sizeText, bool explicitMethod) {
  const auto has = [&](const char* name) {
    return std::find(methods.begin(), methods.end(), name) != methods.end();
  };
  const bool epipolar = has("epipolar-sampling") || has("epipolar-prefilter");
  const std::string scaleText = settings.scale == 0.5 ? "0.5" : settings.scale == 0.25 ? "0.25" : "1";
  if (explicitMethod && epipolar && settings.scale != 1.0)
    throw UsageError("option --scale: " + scaleText +
                     " applies to the per-pixel prefiltered evaluation; --method " + methods.front() +
                     " evaluates at its epipolar samples (--downscale reduces its resolution)");
  const auto multiple = [&](int factor, const std::string& option, const std::string& value,
                            const char* who) {
    if (size.x % factor == 0 && size.y % factor == 0) return;
    throw UsageError("option " + option + ": " + value + " needs an image size that is a multiple of " +
                     std::to_string(factor) + " per axis (" + who + "); " + sizeText + " is not");
  };
  if (has("prefilter") && settings.scale != 1.0)
    multiple(static_cast<int>(std::lround(1.0 / settings.scale)), "--scale", scaleText,
             "the prefiltered evaluation at reduced resolution");
  if (epipolar && settings.sampling.downscale != 1)
    multiple(settings.sampling.downscale, "--downscale", std::to_string(settings.sampling.downscale),
             "the epipolar unwarp at reduced resolution");
}

const std::set<std::string> kToneMapValuedOptions = {"tonemap", "middle-grey", "white-point", "saturation"};

const char* const kToneMapOptionsHelp =
    R"(            --tonemap NAME      tone-map the PNG with an operator: exp | reinhard | reinhard-mod |
                                uncharted2 | filmic-alu | log | adaptive-log, or `all` (a sheet with
                                one tile per operator); default: clamp(v * exposure)
            --auto-exposure     exposure middle-grey / log-average luminance (else --exposure)
            --middle-grey K     key, in (0, 1000] (default 0.18)
            --white-point W     in [0.001, 1e6] (default 3)
            --saturation S      colour saturation of the luminance operators, in [0, 8] (default 1)
)";

ToneMapSettings toneMapSettings(const Args& args, double exposure) {
  ToneMapSettings s;
  s.enabled = args.has("tonemap");
  if (!s.enabled) {
    for (const char* name : {"middle-grey", "white-point", "saturation", kAutoExposureFlag})
      if (args.has(name)) throw UsageError(std::string("option --") + name + " needs --tonemap");
    return s;
  }
  const std::string name = args.string("tonemap", "");
  s.all = name == "all";
  if (!s.all) {
    const auto op = findToneMapOperator(name);
    if (!op)
      throw UsageError("option --tonemap: '" + name + "' is not one of " + toneMapOperatorNames() + ", all");
    s.options.op = *op;
  }
  s.options.middleGrey = args.number("middle-grey", s.options.middleGrey);
  if (!(s.options.middleGrey > 0.0 && s.options.middleGrey <= 1e3))
    throw UsageError("option --middle-grey: must be in (0, 1000]");
  s.options.whitePoint = args.number("white-point", s.options.whitePoint, 1e-3, 1e6);
  s.options.saturation = args.number("saturation", s.options.saturation, 0.0, 8.0);
  s.options.autoExposure = args.has(kAutoExposureFlag);
  s.options.exposure = exposure;
  validate(s.options, "crep render tone mapping"); // the ranges above are ToneMapOptions' own
  return s;
}

} // namespace crep::tool
