// Command-line options shared by the commands that run methods (render, compare, scatter).
#pragma once

#include "args.h"
#include "frame.h"
#include "methods.h"

#include <set>
#include <string>

namespace crep::tool {

/// --method --map-size --bases --format --splits --steps
extern const std::set<std::string> kMethodOptions;

/// The MethodSettings of those options (UsageError naming the option for bad values).
MethodSettings methodSettings(const Args& args);

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

} // namespace crep::tool
