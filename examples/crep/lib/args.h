// Minimal command-line option parsing for the crep tool: `--name value` or `--name=value`, flags
// without values, typed getters that validate and name the option in their errors.
//
// Values are parsed strictly, the whole text and nothing else (no leading or trailing spaces, no '+'):
//   integer  optional '-', then decimal digits: "12", "-3" (not "+12", " 12", "0x10", "1e3")
//   number   optional '-', decimal digits with an optional fraction and exponent: "1", "-0.5", ".5",
//            "2.", "1e-3", "6.5E+2" (not hexadecimal floats "0x10", "inf", "nan", "+1", " 1")
//   vec3     three numbers separated by single commas, no spaces: "0,1,-2.5"
//   size     WIDTHxHEIGHT, decimal digits only on both sides: "640x360" (not " 640x360", "+640x+360")
// Out-of-range values (1e999, integers beyond the option's range) are errors naming the option.
#pragma once

#include <limits>
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
  /// in `valued` or `flags`), a missing value or a repeated option. A value given as the next argument
  /// must not start with "--" ("--out --debug-gl" forgot the value); such a value is written --name=VALUE.
  Args(const std::vector<std::string>& argv, const std::set<std::string>& valued,
       const std::set<std::string>& flags);

  bool has(const std::string& name) const { return values_.count(name) != 0; }
  std::string string(const std::string& name, const std::string& fallback) const;
  int integer(const std::string& name, int fallback, int min, int max) const;
  double number(const std::string& name, double fallback) const; ///< finite
  /// A finite number in [min, max].
  double number(const std::string& name, double fallback, double min, double max) const;
  glm::dvec3 vec3(const std::string& name, const glm::dvec3& fallback) const; ///< "x,y,z", finite
  /// "WxH" with both in [1, max] and W * H <= maxPixels.
  glm::ivec2 size(const std::string& name, glm::ivec2 fallback, int max,
                  long long maxPixels = std::numeric_limits<long long>::max()) const;

private:
  std::map<std::string, std::string> values_;
};

} // namespace crep::tool
