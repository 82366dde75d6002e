// Minimal command-line option parsing for the crep tool: `--name value` or `--name=value`, flags
// without values, typed getters that validate and name the option in their errors.
#pragma once

#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace crep::tool {

/// A command-line error; main() prints it and exits with status 2.
class UsageError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

class Args {
public:
  /// `flags` are options that take no value. Throws UsageError for an unknown option (anything not
  /// in `valued` or `flags`), a missing value or a repeated option.
  Args(const std::vector<std::string>& argv, const std::set<std::string>& valued,
       const std::set<std::string>& flags);

  bool has(const std::string& name) const { return values_.count(name) != 0; }
  std::string string(const std::string& name, const std::string& fallback) const;
  int integer(const std::string& name, int fallback, int min, int max) const;
  double number(const std::string& name, double fallback) const;              ///< finite
  glm::dvec3 vec3(const std::string& name, const glm::dvec3& fallback) const; ///< "x,y,z", finite
  /// "WxH" with both in [1, max].
  glm::ivec2 size(const std::string& name, glm::ivec2 fallback, int max) const;

private:
  std::map<std::string, std::string> values_;
};

} // namespace crep::tool
