#include "support/tool_runner.h"

#include <array>
#include <cstdio>
#include <stdexcept>
#include <sys/wait.h>

namespace crep::test {

ToolResult runCrep(const std::string& args) {
#ifdef CREP_TOOL_PATH
  const std::string command = std::string("'") + CREP_TOOL_PATH + "' " + args + " 2>&1";
  ToolResult r;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) throw std::runtime_error("popen failed for: " + command);
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), static_cast<int>(buf.size()), pipe)) r.output += buf.data();
  const int raw = pclose(pipe);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
#else
  throw std::runtime_error("runCrep(" + args + "): built without the crep tool (CREP_BUILD_TOOLS=OFF)");
#endif
}

} // namespace crep::test
