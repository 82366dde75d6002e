// Runs the built crep tool as a user would (tests of tests/tool/).
#pragma once

#include <string>

namespace crep::test {

struct ToolResult {
  int status = -1;    ///< exit status, -1 if it did not exit normally
  std::string output; ///< stdout + stderr
};

/// Runs `<crep> <args>` through the shell (args are shell words) and captures its output.
ToolResult runCrep(const std::string& args);

} // namespace crep::test
