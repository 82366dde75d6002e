// Private validation helpers shared by the core types.
#pragma once

#include <crep/core/error.h>

#include <cmath>
#include <string>

#include <glm/glm.hpp>

namespace crep::detail {

/// Every component finite and >= 0 (colours, coefficients).
inline void requireNonNegativeVec3(const char* parameter, const glm::dvec3& v, const char* requirement) {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(v[i]) || v[i] < 0.0) invalid(parameter, formatValue(v), requirement);
}

} // namespace crep::detail
