// Commands of the crep tool contributed by other parts of the project without examples/ knowing them:
// bench/ registers `crep bench` this way (bench/bench_command.cpp, an object library linked into the
// crep executable), so examples/ never includes or links anything of bench/. The built-in commands
// (render, scatter, compare, rectify) are dispatched by main.cpp directly.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace crep::tool {

struct Command {
  std::string name; ///< `crep <name>`
  /// `crep help` lines: the first starts with the summary (printed after the padded name), the others
  /// are option lines; each ends with '\n'.
  std::string help;
  /// Takes the arguments after the command name; returns the exit status. Throws UsageError (exit 2)
  /// or crep::Error (exit 1) like the built-in commands.
  std::function<int(const std::vector<std::string>& args)> run;
};

/// Adds a command. Throws std::logic_error for an empty or already registered name. Not thread-safe:
/// meant for static initialization (CommandRegistrar).
void registerCommand(Command command);

/// The registered commands, in registration order.
const std::vector<Command>& registeredCommands();

/// The registered command of that name, or nullptr.
const Command* findCommand(const std::string& name);

/// Registers a command during static initialization: `const CommandRegistrar registrar({...});` at
/// namespace scope of a source linked directly into the executable (an object library, so that the
/// linker keeps it).
struct CommandRegistrar {
  explicit CommandRegistrar(Command command) { registerCommand(std::move(command)); }
};

} // namespace crep::tool
