// `crep bench`: the benchmark suite (suite/bench_suite.h), the same as crep_bench. Registered with the
// crep tool's command registry (examples/crep/lib/command_registry.h) during static initialization;
// bench/CMakeLists.txt links this object library into the crep executable, so examples/ does not
// know about bench/.
#include "bench_suite.h"
#include "command_registry.h"

#include <string>
#include <vector>

namespace {

const crep::tool::CommandRegistrar kBenchCommand({
    "bench",
    "the benchmark suite of bench/ (as crep_bench): CPU reference vs GPU passes, methods side\n"
    "            by side, bandwidth vs a copy, Table 1/2 rows; ratios measured in one run\n" +
        crep::bench::benchHelp(),
    [](const std::vector<std::string>& args) {
      crep::bench::runBenchSuite(crep::bench::parseBenchOptions(args));
      return 0;
    },
});

} // namespace
