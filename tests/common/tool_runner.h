// Runs the built crep tool as a user would (tests of tests/tool/).
#pragma once

#include <initializer_list>
#include <string>
#include <vector>

namespace crep::test {

struct ToolResult {
  int status = -1;    ///< exit status, -1 if it did not exit normally
  std::string output; ///< stdout + stderr
};

/// Runs `<crep> <args>` through the shell (args are shell words) and captures its output.
ToolResult runCrep(const std::string& args);

/// Checks a failed run: the exit status, every one of `mentions` in the output, no "unexpected error" (an
/// exception the tool did not name).
void expectFailure(const ToolResult& r, int status, std::initializer_list<std::string> mentions);

/// How runCrepArgv runs the tool.
struct RunOptions {
  std::string workingDirectory;         ///< empty: the test's own
  long long fileSizeLimitBytes = -1;    ///< RLIMIT_FSIZE of the tool (SIGXFSZ ignored: writes fail), -1: none
  double timeoutSeconds = 120.0;        ///< then the tool is killed (SIGKILL) and `timedOut` set
  std::vector<std::string> environment; ///< "NAME=value" added to (or replacing in) the test's environment
  /// Non-empty: the tool is killed (SIGKILL) as soon as its output contains this text (`stopped` set), for
  /// long commands whose first part is what a test checks.
  std::string stopWhenOutputContains;
};

struct ArgvResult {
  int status = -1;       ///< exit status if it exited normally, else -1
  int signal = 0;        ///< the signal that ended it, 0 if it exited
  bool timedOut = false; ///< killed after RunOptions::timeoutSeconds
  bool stopped = false;  ///< killed when its output contained RunOptions::stopWhenOutputContains
  std::string output;    ///< stdout + stderr, interleaved as written
};

/// Runs the tool with exactly these arguments (no shell: any bytes but NUL), stdin from /dev/null.
ArgvResult runCrepArgv(const std::vector<std::string>& args, const RunOptions& options = {});

} // namespace crep::test
