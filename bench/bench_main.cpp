// crep_bench: the benchmark suite (suite/bench_suite.h) as a program of its own; `crep bench` runs the
// same suite. Prints ratios measured side by side in one run; never asserts on time.
//
// usage: crep_bench [--scene NAME] [--size WxH] [--map WxH] [--bases M] [--repeat N] [--quick]
//                   [--plot FILE.svg] [--section NAME[,NAME...]] (`crep bench --help` lists the sections)
#include "args.h"
#include "bench_suite.h"

#include <crep/core/error.h>

#include <cstdio>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  try {
    crep::bench::runBenchSuite(
        crep::bench::parseBenchOptions(std::vector<std::string>(argv + 1, argv + argc)));
  } catch (const crep::tool::UsageError& e) {
    std::fprintf(stderr, "crep_bench: %s\n", e.what());
    return 2;
  } catch (const crep::Error& e) {
    std::fprintf(stderr, "crep_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
