#include "command_registry.h"

#include <stdexcept>
#include <utility>

namespace crep::tool {

namespace {

// Constructed on first use: registrars run during static initialization, in no defined order.
std::vector<Command>& commands() {
  static std::vector<Command> registry;
  return registry;
}

} // namespace

void registerCommand(Command command) {
  if (command.name.empty()) throw std::logic_error("crep: registerCommand: empty command name");
  if (findCommand(command.name) != nullptr)
    throw std::logic_error("crep: registerCommand: command '" + command.name + "' is already registered");
  commands().push_back(std::move(command));
}

const std::vector<Command>& registeredCommands() {
  return commands();
}

const Command* findCommand(const std::string& name) {
  for (const Command& c : commands())
    if (c.name == name) return &c;
  return nullptr;
}

} // namespace crep::tool
