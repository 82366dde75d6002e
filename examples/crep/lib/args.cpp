#include "args.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <system_error>

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
    if (name.empty())
      throw UsageError("unexpected argument '" + a + "' (options are --name VALUE, --name=VALUE or --flag)");
    if (flags.count(name)) {
      if (hasValue) throw UsageError("option --" + name + " takes no value");
      value = "1";
    } else if (valued.count(name)) {
      if (!hasValue) {
        if (i + 1 >= argv.size()) throw UsageError("option --" + name + " needs a value");
        // "--out --debug-gl" is a forgotten value, not a file named "--debug-gl": a value that starts with
        // "--" must be attached (--out=--name).
        if (argv[i + 1].starts_with("--"))
          throw UsageError("option --" + name + " needs a value, got the option '" + argv[i + 1] +
                           "' (write --" + name + "=VALUE for a value that starts with --)");
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

bool isDigit(char c) {
  return std::isdigit(static_cast<unsigned char>(c)) != 0;
}

/// Skips decimal digits from `i`; returns how many.
std::size_t digits(const std::string& s, std::size_t& i) {
  const std::size_t start = i;
  while (i < s.size() && isDigit(s[i]))
    ++i;
  return i - start;
}

/// '-'? digits (args.h).
bool isStrictInteger(const std::string& s) {
  std::size_t i = s.starts_with('-') ? 1 : 0;
  return digits(s, i) > 0 && i == s.size();
}

/// '-'? (digits ('.' digits?)? | '.' digits) ([eE] [+-]? digits)? (args.h).
bool isStrictNumber(const std::string& s) {
  std::size_t i = s.starts_with('-') ? 1 : 0;
  std::size_t mantissa = digits(s, i);
  if (i < s.size() && s[i] == '.') {
    ++i;
    mantissa += digits(s, i);
  }
  if (mantissa == 0) return false;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    if (digits(s, i) == 0) return false;
  }
  return i == s.size();
}

/// "0.001", "1e30" (as the help texts write them).
std::string shortNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  std::string s = buf;
  if (const auto e = s.find("e+"); e != std::string::npos) s.erase(e + 1, 1);
  return s;
}

double parseDouble(const std::string& option, const std::string& text) {
  double v = 0.0;
  if (!isStrictNumber(text))
    throw UsageError(
        "option --" + option + ": '" + text +
        "' is not a decimal number (digits, optional '-', fraction and exponent: e.g. 0.5, 2e-3)");
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec == std::errc::result_out_of_range || end != text.data() + text.size() || !std::isfinite(v))
    throw UsageError("option --" + option + ": '" + text + "' is out of range (beyond what a double holds)");
  return v;
}

} // namespace

int Args::integer(const std::string& name, int fallback, int min, int max) const {
  const auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  const std::string& text = it->second;
  const std::string range = "[" + std::to_string(min) + ", " + std::to_string(max) + "]";
  if (!isStrictInteger(text))
    throw UsageError("option --" + name + ": '" + text + "' is not an integer (decimal digits, in " + range +
                     ")");
  long long v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec == std::errc::result_out_of_range || end != text.data() + text.size() || v < min || v > max)
    throw UsageError("option --" + name + ": " + text + " is outside " + range);
  return static_cast<int>(v);
}

double Args::number(const std::string& name, double fallback) const {
  const auto it = values_.find(name);
  return it == values_.end() ? fallback : parseDouble(name, it->second);
}

double Args::number(const std::string& name, double fallback, double min, double max) const {
  const auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  const double v = parseDouble(name, it->second);
  if (!(v >= min && v <= max))
    throw UsageError("option --" + name + ": " + it->second + " is outside [" + shortNumber(min) + ", " +
                     shortNumber(max) + "]");
  return v;
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

glm::ivec2 Args::size(const std::string& name, glm::ivec2 fallback, int max, long long maxPixels) const {
  const auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  const std::string& text = it->second;
  const std::string needs = "option --" + name + ": '" + text +
                            "' needs WIDTHxHEIGHT (decimal digits, e.g. " + "640x360) with each in [1, " +
                            std::to_string(max) + "]";
  const auto x = text.find('x');
  if (x == std::string::npos) throw UsageError(needs);
  glm::ivec2 s;
  for (int i = 0; i < 2; ++i) {
    const std::string part = i == 0 ? text.substr(0, x) : text.substr(x + 1);
    std::size_t end = 0;
    if (digits(part, end) == 0 || end != part.size()) throw UsageError(needs);
    long long v = 0;
    const auto [ptr, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
    if (ec != std::errc() || ptr != part.data() + part.size() || v < 1 || v > max) throw UsageError(needs);
    s[i] = static_cast<int>(v);
  }
  if (static_cast<long long>(s.x) * s.y > maxPixels)
    throw UsageError("option --" + name + ": " + text + " has " +
                     std::to_string(static_cast<long long>(s.x) * s.y) + " pixels, more than " +
                     std::to_string(maxPixels));
  return s;
}

} // namespace crep::tool
