#include "args.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace crep::tool {

Args::Args(const std::vector<std::string>& argv, const std::set<std::string>& valued,
           const std::set<std::string>& flags) {
  for (std::size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (a.rfind("--", 0) != 0) throw UsageError("unexpected argument '" + a + "' (options start with --)");
    std::string name = a.substr(2), value;
    bool hasValue = false;
    if (const auto eq = name.find('='); eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      hasValue = true;
    }
    if (flags.count(name)) {
      if (hasValue) throw UsageError("option --" + name + " takes no value");
      value = "1";
    } else if (valued.count(name)) {
      if (!hasValue) {
        if (i + 1 >= argv.size()) throw UsageError("option --" + name + " needs a value");
        value = argv[++i];
      }
    } else {
      throw UsageError("unknown option --" + name);
    }
    if (values_.count(name)) throw UsageError("option --" + name + " given twice");
    values_[name] = value;
  }
}

std::string Args::string(const std::string& name, const std::string& fallback) const {
  const auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

namespace {
double parseDouble(const std::string& option, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v))
    throw UsageError("option --" + option + ": '" + text + "' is not a finite number");
  return v;
}
} // namespace

int Args::integer(const std::string& name, int fallback, int min, int max) const {
  const auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  errno = 0;
  char* end = nullptr;
  const long v = std::strtol(it->second.c_str(), &end, 10);
  if (it->second.empty() || end != it->second.c_str() + it->second.size() || errno == ERANGE)
    throw UsageError("option --" + name + ": '" + it->second + "' is not an integer");
  if (v < min || v > max)
    throw UsageError("option --" + name + ": " + it->second + " is outside [" + std::to_string(min) + ", " +
                     std::to_string(max) + "]");
  return static_cast<int>(v);
}

double Args::number(const std::string& name, double fallback) const {
  const auto it = values_.find(name);
  return it == values_.end() ? fallback : parseDouble(name, it->second);
}

glm::dvec3 Args::vec3(const std::string& name, const glm::dvec3& fallback) const {
  const auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  glm::dvec3 v;
  std::string rest = it->second;
  for (int i = 0; i < 3; ++i) {
    const auto comma = rest.find(',');
    if ((i < 2) != (comma != std::string::npos))
      throw UsageError("option --" + name + ": '" + it->second + "' is not x,y,z");
    v[i] = parseDouble(name, rest.substr(0, comma));
    rest = comma == std::string::npos ? "" : rest.substr(comma + 1);
  }
  return v;
}

glm::ivec2 Args::size(const std::string& name, glm::ivec2 fallback, int max) const {
  const auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  const auto x = it->second.find('x');
  if (x == std::string::npos)
    throw UsageError("option --" + name + ": '" + it->second + "' is not WIDTHxHEIGHT");
  glm::ivec2 s;
  for (int i = 0; i < 2; ++i) {
    const std::string part = i == 0 ? it->second.substr(0, x) : it->second.substr(x + 1);
    errno = 0;
    char* end = nullptr;
    const long v = std::strtol(part.c_str(), &end, 10);
    if (part.empty() || end != part.c_str() + part.size() || errno == ERANGE || v < 1 || v > max)
      throw UsageError("option --" + name + ": '" + it->second + "' needs WIDTHxHEIGHT with each in [1, " +
                       std::to_string(max) + "]");
    s[i] = static_cast<int>(v);
  }
  return s;
}

} // namespace crep::tool
