// Private validation helpers shared by the core types.
#pragma once

#include <crep/core/error.h>

#include <cmath>
#include <string>

#include <glm/glm.hpp>

namespace crep::detail {

inline std::string formatVec3(const glm::dvec3& v) {
  std::string s = "(";
  s += formatValue(v.x);
  s += ", ";
  s += formatValue(v.y);
  s += ", ";
  s += formatValue(v.z);
  s += ")";
  return s;
}

inline void requireFiniteVec3(const char* parameter, const glm::dvec3& v) {
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    throw InvalidArgument(parameter, formatVec3(v), "components must be finite");
}

/// Every component finite and >= 0 (colours, coefficients).
inline void requireNonNegativeVec3(const char* parameter, const glm::dvec3& v, const char* requirement) {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(v[i]) || v[i] < 0.0) throw InvalidArgument(parameter, formatVec3(v), requirement);
}

} // namespace crep::detail
