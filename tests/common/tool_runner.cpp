#include "common/tool_runner.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <stdexcept>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace crep::test {

ToolResult runCrep(const std::string& args) {
#ifdef CREP_TOOL_PATH
  const std::string command = std::string("'") + CREP_TOOL_PATH + "' " + args + " 2>&1";
  ToolResult r;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) throw std::runtime_error("popen failed for: " + command);
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), static_cast<int>(buf.size()), pipe))
    r.output += buf.data();
  const int raw = pclose(pipe);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
#else
  throw std::runtime_error("runCrep(" + args + "): built without the crep tool (CREP_BUILD_TOOLS=OFF)");
#endif
}

void expectFailure(const ToolResult& r, int status, std::initializer_list<std::string> mentions) {
  INFO(r.output);
  CHECK(r.status == status);
  for (const std::string& m : mentions)
    CHECK(r.output.find(m) != std::string::npos);
  CHECK(r.output.find("unexpected error") == std::string::npos);
}

ArgvResult runCrepArgv(const std::vector<std::string>& args, const RunOptions& options) {
#ifdef CREP_TOOL_PATH
  // Everything the child needs is prepared before fork (only async-signal-safe calls after it).
  std::vector<std::string> argvStrings = {CREP_TOOL_PATH};
  argvStrings.insert(argvStrings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argvStrings)
    argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> envStrings;
  for (char** e = environ; *e; ++e) {
    const std::string entry = *e;
    bool replaced = false;
    for (const std::string& add : options.environment)
      replaced = replaced || entry.substr(0, entry.find('=') + 1) == add.substr(0, add.find('=') + 1);
    if (!replaced) envStrings.push_back(entry);
  }
  envStrings.insert(envStrings.end(), options.environment.begin(), options.environment.end());
  std::vector<char*> envp;
  for (std::string& e : envStrings)
    envp.push_back(e.data());
  envp.push_back(nullptr);

  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0)
    throw std::runtime_error("pipe2 failed: " + std::string(std::strerror(errno)));
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed: " + std::string(std::strerror(errno)));
  if (pid == 0) {
    const int devNull = open("/dev/null", O_RDONLY);
    if (devNull >= 0) dup2(devNull, 0);
    dup2(fds[1], 1);
    dup2(fds[1], 2);
    if (!options.workingDirectory.empty() && chdir(options.workingDirectory.c_str()) != 0) _exit(126);
    if (options.fileSizeLimitBytes >= 0) {
      signal(SIGXFSZ, SIG_IGN); // writes beyond the limit fail with EFBIG instead of killing the tool
      const rlimit limit{static_cast<rlim_t>(options.fileSizeLimitBytes),
                         static_cast<rlim_t>(options.fileSizeLimitBytes)};
      setrlimit(RLIMIT_FSIZE, &limit);
    }
    execve(argv[0], argv.data(), envp.data());
    _exit(127);
  }
  close(fds[1]);
  ArgvResult r;
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(static_cast<long long>(options.timeoutSeconds * 1000.0));
  std::array<char, 4096> buf{};
  bool open = true;
  while (open) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      kill(pid, SIGKILL);
      r.timedOut = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (ready < 0 && errno != EINTR) break;
    if (ready <= 0) continue;
    const ssize_t n = read(fds[0], buf.data(), buf.size());
    if (n > 0) {
      r.output.append(buf.data(), static_cast<std::size_t>(n));
      if (!options.stopWhenOutputContains.empty() &&
          r.output.find(options.stopWhenOutputContains) != std::string::npos) {
        kill(pid, SIGKILL);
        r.stopped = true;
        break;
      }
    } else if (n == 0 || errno != EINTR) {
      open = false;
    }
  }
  close(fds[0]);
  int raw = 0;
  while (waitpid(pid, &raw, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(raw)) r.status = WEXITSTATUS(raw);
  if (WIFSIGNALED(raw)) r.signal = WTERMSIG(raw);
  return r;
#else
  (void)options;
  throw std::runtime_error("runCrepArgv: built without the crep tool (CREP_BUILD_TOOLS=OFF)");
#endif
}

} // namespace crep::test
