// The bench section "backends": the passes written against the backend seam (crep/gpu/backend.h) on
// the GL backend (llvmpipe here) and the Vulkan backend (lavapipe), the same inputs, side by side.
#pragma once

#include "bench_suite.h"

namespace crep::bench {

/// Prints per-frame ms of the seam's passes on each backend and their ratio; a line saying so when the
/// build has no Vulkan backend (CREP_VULKAN off) or no Vulkan device answers.
void backendsBench(const BenchOptions& o);

} // namespace crep::bench
