// Command-line options shared by the commands that run methods (render, compare, scatter).
#pragma once

#include "args.h"
#include "frame.h"
#include "methods.h"

#include <crep/postfx/tone_mapping.h>

#include <set>
#include <string>
#include <vector>

namespace crep::tool {

/// --method --map-size --bases --format --splits --steps
extern const std::set<std::string> kMethodOptions;

/// The MethodSettings of those options (UsageError naming the option for bad values).
MethodSettings methodSettings(const Args& args);

/// The image-size rules of the methods that reduce their resolution, checked before any GL work (UsageError
/// naming the option): --scale S (the prefiltered per-pixel evaluation, method `prefilter`) needs an image
/// size that is a multiple of 1 / S per axis, --downscale F (epipolar-sampling, epipolar-prefilter) a
/// multiple of F. `sizeText` says where the size comes from ("--size 160x90", "the depth image 'd.exr'
/// (160x90)"). With `explicitMethod` (render and scatter: the one --method given) a --scale other than 1 with
/// an epipolar method is refused too (they evaluate at their samples; --downscale reduces their resolution).
void requireMethodImageSize(const MethodSettings& settings, const std::vector<std::string>& methods,
                            glm::ivec2 size, const std::string& sizeText, bool explicitMethod);

/// "rgba8" | "rgba16f" | "rgba32f" (UsageError naming --format otherwise).
StorageFormat parseFormat(const std::string& text);

/// Largest --map-size: the rectified map is a square image that scatter resamples on the CPU and
/// bench reads back, so its pixels are bounded by Image::kMaxPixels (16384^2). GL_MAX_TEXTURE_SIZE is
/// checked when the textures are made (GlError naming --map-size), before any output is written.
constexpr int kMaxMapSize = 16384;

/// Bounds of --exposure: the PNG tone mapping multiplies by it as a float (ToneMap::exposure), so it
/// must stay a normal float (about 1.2e-38 to 3.4e38); round bounds well inside that range.
constexpr double kMinExposure = 1e-30, kMaxExposure = 1e30;

/// --exposure X (default 1): a finite number in [kMinExposure, kMaxExposure] (UsageError otherwise).
double exposureOption(const Args& args);

/// Help text of those options (indented for `crep help`).
extern const char* const kMethodOptionsHelp;

/// crep render's tone mapping of its PNG: --tonemap NAME|all (crep/postfx/tone_mapping.h operator names),
/// --middle-grey, --white-point, --saturation (ToneMapOptions' ranges), --auto-exposure (flag).
extern const std::set<std::string> kToneMapValuedOptions;
constexpr const char* kAutoExposureFlag = "auto-exposure";
struct ToneMapSettings {
  bool enabled = false; ///< --tonemap given (else the PNG is clamp(v * exposure), as without it)
  bool all = false;     ///< --tonemap all: a sheet with one tile per operator
  ToneMapOptions options;
};
/// The settings of those options; `exposure` is --exposure, the manual scale without --auto-exposure.
/// UsageError naming the option for an unknown name (listing the names), values out of range, or a
/// tone-mapping option without --tonemap.
ToneMapSettings toneMapSettings(const Args& args, double exposure);
/// Help text of those options.
extern const char* const kToneMapOptionsHelp;

} // namespace crep::tool
