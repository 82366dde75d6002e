#include <crep/core/error.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace crep {

InvalidArgument::InvalidArgument(std::string parameter, const std::string& value, const std::string& requirement)
    : Error("crep: invalid " + parameter + " = " + value + " (" + requirement + ")"),
      parameter_(std::move(parameter)) {}

namespace detail {
std::string formatValue(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  // Shorter form when it round-trips.
  char shortBuf[64];
  std::snprintf(shortBuf, sizeof shortBuf, "%.6g", v);
  if (std::strtod(shortBuf, nullptr) == v) return shortBuf;
  return buf;
}
std::string formatValue(long long v) { return std::to_string(v); }
} // namespace detail

void requireFinite(const char* parameter, double value) {
  if (!std::isfinite(value)) throw InvalidArgument(parameter, detail::formatValue(value), "must be finite");
}
void requirePositive(const char* parameter, double value) {
  if (!std::isfinite(value) || !(value > 0.0))
    throw InvalidArgument(parameter, detail::formatValue(value), "must be finite and > 0");
}
void requireNonNegative(const char* parameter, double value) {
  if (!std::isfinite(value) || value < 0.0)
    throw InvalidArgument(parameter, detail::formatValue(value), "must be finite and >= 0");
}

} // namespace crep
