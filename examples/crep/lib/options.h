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

/// Help text of those options (indented for `crep help`).
extern const char* const kMethodOptionsHelp;

} // namespace crep::tool
