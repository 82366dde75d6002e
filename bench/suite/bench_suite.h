// The benchmark suite of crepuscular, run by `crep bench` and by the crep_bench program: prefilter and
// evaluation timings, CPU reference vs GPU pass (llvmpipe here); every method of the crep tool's
// registry on the same frame; the scaling rows of the paper's Table 2, Table 1's parallelization study
// and the achieved bandwidth of the prefilter against a memory copy. Everything is measured side by side
// in one run and printed as ratios; nothing asserts on time.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

namespace crep::bench {

struct BenchOptions {
  std::string scene = "forest";
  int screenWidth = 1920, screenHeight = 1080;
  int mapWidth = 1024, mapHeight = 1024;
  int bases = 32;
  int repeat = 5;     ///< runs per measurement (median)
  bool quick = false; ///< one size only: no Table 1/2 rows, one CPU run
  std::string plot;   ///< with the Table 1/2 rows: write them as an SVG bar chart beside the paper's
  /// Empty: the whole suite; "epipolar-sampling", "sun-in-view", "atmosphere" or "local-lights" (the
  /// local-light sections and the spot scaling): that section alone.
  std::string section;
};

/// Parses [--scene NAME] [--size WxH] [--map WxH] [--bases M] [--repeat N] [--quick] [--plot FILE.svg]
/// [--section epipolar-sampling|sun-in-view|atmosphere|local-lights];
/// throws crep::tool::UsageError naming the option.
BenchOptions parseBenchOptions(const std::vector<std::string>& argv);

/// Runs the suite, printing to stdout. Creates the process's GL context if there is none. Throws
/// crep::Error (GL unavailable, sizes beyond the limits, unknown scene).
void runBenchSuite(const BenchOptions& options);

} // namespace crep::bench
