#pragma once

#include <string>
#include <vector>

namespace crep::tool {

/// The built-in commands (others register through command_registry.h). Each command takes its arguments
/// (after the command name) and returns the process exit status.
int renderCommand(const std::vector<std::string>& args);
int scatterCommand(const std::vector<std::string>& args);
int compareCommand(const std::vector<std::string>& args);
int rectifyCommand(const std::vector<std::string>& args);

} // namespace crep::tool
