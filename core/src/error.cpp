#include <crep/core/error.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

#include <glm/glm.hpp>

namespace crep {

InvalidArgument::InvalidArgument(std::string parameter, const std::string& value,
                                 const std::string& requirement)
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
std::string formatValue(long long v) {
  return std::to_string(v);
}
std::string formatValue(const glm::dvec3& v) {
  return "(" + formatValue(v.x) + ", " + formatValue(v.y) + ", " + formatValue(v.z) + ")";
}
} // namespace detail

void invalid(std::string parameter, const std::string& value, const std::string& requirement) {
  throw InvalidArgument(std::move(parameter), value, requirement);
}

void requireFinite(std::string_view parameter, double value) {
  if (!std::isfinite(value)) invalid(std::string(parameter), detail::formatValue(value), "must be finite");
}
void requireFinite(std::string_view parameter, const glm::dvec3& value) {
  if (!std::isfinite(value.x) || !std::isfinite(value.y) || !std::isfinite(value.z))
    invalid(std::string(parameter), detail::formatValue(value), "components must be finite");
}
void requireFinite(std::string_view parameter, const glm::dmat4& value) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(value[c][r]))
        invalid(std::string(parameter), detail::formatValue(value[c][r]), "must be finite");
}
void requirePositive(std::string_view parameter, double value) {
  if (!std::isfinite(value) || !(value > 0.0))
    invalid(std::string(parameter), detail::formatValue(value), "must be finite and > 0");
}
void requireNonNegative(std::string_view parameter, double value) {
  if (!std::isfinite(value) || value < 0.0)
    invalid(std::string(parameter), detail::formatValue(value), "must be finite and >= 0");
}

} // namespace crep
