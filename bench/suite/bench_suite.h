// The benchmark suite of crepuscular, run by `crep bench` and by the crep_bench program: prefilter and
// evaluation timings, CPU reference vs GPU pass (llvmpipe here); every method of the crep tool's
// registry on the same frame; the scaling rows of the paper's Table 2, Table 1's parallelization study
// and the achieved bandwidth of the prefilter against a memory copy. Everything is measured side by side
// in one run and printed as ratios; nothing asserts on time. The suite is a table of sections
// (benchSections()), each of which runs alone with --section NAME.
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
  int repeat = 5; ///< runs per measurement (median)
  /// A smoke test of every section at a reduced cost (benchHelp(), bench/README.md): smaller default sizes,
  /// one run per measurement, no extra sizes, no slow marches or atmosphere reference table, fewer rows.
  bool quick = false;
  std::string plot; ///< with the Table 1/2 rows: write them as an SVG bar chart beside the paper's
  /// The sections to run, in the suite's order (benchSections()); empty: the whole suite.
  std::vector<std::string> sections;
  /// "opengl", or "vulkan": the tool's crep::Scattering methods (prefilter, minmax, epipolar-sampling,
  /// epipolar-prefilter) in the sections that run the tool's methods go to a Vulkan device.
  std::string backend = "opengl";
};

/// The run's state shared by its sections (bench_suite.cpp): the options, the frame of the run's scene
/// and sizes (made on first use), figures one section measures and a later one reuses.
class BenchRun;

/// One section of the suite: `--section name` runs it alone; the whole suite runs every section in the
/// order of benchSections().
struct BenchSection {
  const char* name;
  const char* summary; ///< one line for --help
  void (*run)(BenchRun&);
};

/// The suite's sections, in the order the whole suite runs them.
const std::vector<BenchSection>& benchSections();

/// `crep bench --help`'s lines after the command's summary: the options, what --quick does and the
/// sections (one per line, from benchSections()); each line indented and ending with '\n'.
std::string benchHelp();

/// Parses [--scene NAME] [--size WxH] [--map WxH] [--bases M] [--repeat N] [--quick] [--plot FILE.svg]
/// [--section NAME[,NAME...]] (names from benchSections()) [--backend opengl|vulkan]; throws
/// crep::tool::UsageError naming the option (an unknown section: the message lists the valid names). Needs no
/// GL context.
BenchOptions parseBenchOptions(const std::vector<std::string>& argv);

/// Runs the suite (or the sections of options.sections), printing to stdout. Creates the process's GL
/// context if there is none. Throws crep::Error (GL unavailable, sizes beyond the limits, unknown scene).
void runBenchSuite(const BenchOptions& options);

} // namespace crep::bench
