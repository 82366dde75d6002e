// Error types of crepuscular. Runtime failures (bad parameters from a user, file I/O, GL limits,
// shader compilation) are typed exceptions whose message names the parameter and its value.
// Programmer errors inside the library are assertions, not exceptions.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include <glm/fwd.hpp>

namespace crep {

/// Base of every exception thrown by crepuscular.
class Error : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// A parameter is outside its valid domain (NaN/Inf, non-positive size, near >= far, ...).
/// `parameter()` is the qualified name, e.g. "Camera.near".
class InvalidArgument : public Error {
public:
  InvalidArgument(std::string parameter, const std::string& value, const std::string& requirement);
  const std::string& parameter() const noexcept { return parameter_; }

private:
  std::string parameter_;
};

/// A file cannot be opened, read or written.
class IoError : public Error {
public:
  using Error::Error;
};

/// A file was read but its content is corrupt, truncated, empty, of the wrong layout or too large.
class FormatError : public Error {
public:
  using Error::Error;
};

/// No usable OpenGL 4.5 context (EGL missing, no surfaceless platform, context creation failed).
class GlUnavailable : public Error {
public:
  using Error::Error;
};

/// A GL call failed or a request exceeds an implementation limit (e.g. GL_MAX_TEXTURE_SIZE).
class GlError : public Error {
public:
  using Error::Error;
};

/// A shader failed to preprocess, compile or link. The log refers to real file names and lines.
class ShaderError : public Error {
public:
  using Error::Error;
};

namespace detail {
/// Formats a value for error messages (full precision for floating point).
std::string formatValue(double v);
std::string formatValue(long long v);
inline std::string formatValue(int v) {
  return formatValue(static_cast<long long>(v));
}
inline std::string formatValue(float v) {
  return formatValue(static_cast<double>(v));
}
std::string formatValue(const glm::dvec3& v); ///< "(x, y, z)"
} // namespace detail

/// Throws InvalidArgument(parameter, value, requirement): the one way the library reports a bad parameter.
[[noreturn]] void invalid(std::string parameter, const std::string& value, const std::string& requirement);

/// Throws InvalidArgument unless `value` is finite.
void requireFinite(std::string_view parameter, double value);
/// Throws InvalidArgument unless every component of `value` is finite.
void requireFinite(std::string_view parameter, const glm::dvec3& value);
/// Throws InvalidArgument unless every element of `value` is finite (the message gives the first other one).
void requireFinite(std::string_view parameter, const glm::dmat4& value);
/// Throws InvalidArgument unless `value` is finite and > 0.
void requirePositive(std::string_view parameter, double value);
/// Throws InvalidArgument unless `value` is finite and >= 0.
void requireNonNegative(std::string_view parameter, double value);

} // namespace crep
