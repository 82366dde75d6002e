// The bench suite's table of sections at the parse level (bench/suite/bench_suite.h): every section's
// name is accepted by --section and listed by --help; an unknown name is a usage error listing them all.
// No GL: parseBenchOptions runs before any GL work.
#include "args.h"
#include "bench_suite.h"

#include <doctest/doctest.h>

#include <set>
#include <string>
#include <vector>

using crep::bench::benchSections;
using crep::bench::parseBenchOptions;

TEST_CASE("bench sections: each name is unique, has a summary and is listed by --help") {
  const std::string help = crep::bench::benchHelp();
  std::set<std::string> names;
  for (const crep::bench::BenchSection& s : benchSections()) {
    INFO(s.name);
    CHECK(names.insert(s.name).second);
    CHECK(std::string(s.summary).size() > 10);
    CHECK((s.run != nullptr));
    CHECK(help.find("  " + std::string(s.name) + " ") != std::string::npos);
  }
  CHECK(names.size() >= 13);
  for (const char* name : {"passes", "local-lights", "atmosphere", "scaling", "parallelization"})
    CHECK(names.count(name) == 1);
}

TEST_CASE("bench --section: every listed name parses alone, a comma list runs in the suite's order") {
  std::vector<std::string> all;
  for (const crep::bench::BenchSection& s : benchSections()) {
    INFO(s.name);
    const crep::bench::BenchOptions o = parseBenchOptions({"--section", s.name});
    CHECK(o.sections == std::vector<std::string>{s.name});
    all.push_back(s.name);
  }
  CHECK(parseBenchOptions({}).sections.empty()); // the whole suite
  // Given backwards and twice: run once each, in the order of benchSections().
  std::string reversed;
  for (auto it = all.rbegin(); it != all.rend(); ++it)
    reversed += *it + ",";
  reversed += all.front();
  CHECK(parseBenchOptions({"--section", reversed}).sections == all);
}

TEST_CASE("bench --section: an unknown or empty name is a usage error listing the valid names") {
  for (const char* bad : {"bogus", "passes,bogus", "", "passes,", "Passes"}) {
    INFO(bad);
    std::string message;
    try {
      (void)parseBenchOptions({"--section", bad});
    } catch (const crep::tool::UsageError& e) {
      message = e.what();
    }
    REQUIRE(!message.empty());
    CHECK(message.find("--section") != std::string::npos);
    for (const crep::bench::BenchSection& s : benchSections())
      CHECK(message.find(s.name) != std::string::npos);
  }
}

TEST_CASE("bench --quick: smaller default sizes and one run, explicit options kept") {
  const crep::bench::BenchOptions quick = parseBenchOptions({"--quick"});
  CHECK(quick.screenWidth == 640);
  CHECK(quick.screenHeight == 360);
  CHECK(quick.mapWidth == 512);
  CHECK(quick.repeat == 1);
  const crep::bench::BenchOptions sized =
      parseBenchOptions({"--quick", "--size", "320x180", "--map", "256x256", "--repeat", "3"});
  CHECK(sized.screenWidth == 320);
  CHECK(sized.mapWidth == 256);
  CHECK(sized.repeat == 3);
  const crep::bench::BenchOptions full = parseBenchOptions({});
  CHECK(full.screenWidth == 1920);
  CHECK(full.mapWidth == 1024);
  CHECK(full.repeat == 5);
}

TEST_CASE("bench --backend: opengl by default, an unknown backend is a usage error naming the option") {
  CHECK(parseBenchOptions({}).backend == "opengl");
  CHECK(parseBenchOptions({"--backend", "opengl"}).backend == "opengl");
  std::string message;
  try {
    (void)parseBenchOptions({"--backend", "metal"});
  } catch (const crep::tool::UsageError& e) {
    message = e.what();
  }
  CHECK(message.find("--backend") != std::string::npos);
  CHECK(message.find("metal") != std::string::npos);
  CHECK(crep::bench::benchHelp().find("--backend") != std::string::npos);
}
