// The source tree as the tests that read it see it (DocNamesTest, HouseRulesTest): its root and the
// library modules, in layering order (docs/ARCHITECTURE.md, tests/check_layering.cmake).
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace crep::test {

inline const std::filesystem::path kSourceRoot = CREP_SOURCE_DIR;

inline const std::vector<std::string> kLibraryModules = {"core",     "gpu",       "rectify",  "scatter",
                                                         "epipolar", "prefilter", "pipeline", "atmosphere",
                                                         "postfx",   "vulkan"};

/// The whole file, bytes as stored; empty if it cannot be read.
inline std::string readSourceFile(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

} // namespace crep::test
