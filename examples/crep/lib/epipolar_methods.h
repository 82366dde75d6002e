// Registry entries and fallbacks that need the epipolar module (epipolar_methods.cpp): present when the
// build has crep/epipolar/*.h, no-ops otherwise.
#pragma once

#include "frame.h"

#include <optional>
#include <vector>

namespace crep::tool {

/// Appends "minmax" and "brute" (marches over the rectified rows) when the epipolar module is built.
void appendEpipolarMethods(std::vector<Method>& registry);
/// The prefiltered method on a frame whose rectification is not projective: the epipolar resampling
/// fallback (min/max march over the resampled epipolar map plus the epipole block), or nullopt when the
/// epipolar module is not built (the caller then runs the reference march).
std::optional<MethodOutput> prefilterFallback(Frame& frame, const MethodSettings& settings,
                                              const Rectification& rect);
/// Whether the epipolar module is part of this build.
bool epipolarAvailable();

} // namespace crep::tool
