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
    "            by side, bandwidth vs a copy, Table 1/2 rows; ratios measured in one run\n"
    "            --scene NAME (forest) --size WxH (1920x1080) --map WxH (1024x1024)\n"
    "            --bases M (32; any even M in [4, 128]) --repeat N (5) --quick (one size, no tables);\n"
    "            the --map width is a multiple of 32 (16 with --quick); --plot FILE.svg writes the\n"
    "            Table 1/2 rows as a chart beside the paper's (not with --quick); --section\n"
    "            epipolar-sampling | sun-in-view | atmosphere runs that section alone;\n"
    "            --section local-lights: the local-light sections and the spot scaling (1-8 spots)\n",
    [](const std::vector<std::string>& args) {
      crep::bench::runBenchSuite(crep::bench::parseBenchOptions(args));
      return 0;
    },
});

} // namespace
