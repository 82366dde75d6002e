// `crep bench`: the benchmark suite of bench/ (bench/suite/bench_suite.h), the same as crep_bench.
#include "bench_suite.h"
#include "commands.h"

namespace crep::tool {

int benchCommand(const std::vector<std::string>& args) {
  bench::runBenchSuite(bench::parseBenchOptions(args));
  return 0;
}

} // namespace crep::tool
