// Checks of the errors the library throws for bad input: the InvalidArgument names the parameter (field
// path) the caller got wrong.
#pragma once

#include <crep/core/error.h>

#include <doctest/doctest.h>

#include <functional>
#include <optional>
#include <string>

namespace crep::test {

/// The error of type E that `f` throws, or nullopt when `f` returns (other errors pass).
template <class E, class F>
std::optional<E> thrown(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e;
  }
  return std::nullopt;
}

/// The parameter of the InvalidArgument `f` throws, or "no exception" when it returns (other errors pass).
template <class F>
std::string invalidParameter(F&& f) {
  const std::optional<InvalidArgument> e = thrown<InvalidArgument>(f);
  return e ? e->parameter() : "no exception";
}

/// `f` throws an InvalidArgument whose parameter is `parameter` (and, with `inMessage`, whose message
/// names it).
template <class F>
void requireNamed(F&& f, const std::string& parameter, bool inMessage = false) {
  try {
    f();
    FAIL("no exception for " << parameter);
  } catch (const InvalidArgument& e) {
    CHECK(e.parameter() == parameter);
    if (inMessage) CHECK(std::string(e.what()).find(parameter) != std::string::npos);
  }
}

/// `f` throws an InvalidArgument whose parameter is `parameter` and whose message names it.
template <class F>
void requireNamedInMessage(F&& f, const std::string& parameter) {
  requireNamed(f, parameter, true);
}

/// `run` throws an InvalidArgument whose message names `field` (the message is printed when it does not).
inline void requireMessageNames(const std::string& field, const std::function<void()>& run) {
  CAPTURE(field);
  bool named = false;
  try {
    run();
  } catch (const InvalidArgument& e) {
    named = std::string(e.what()).find(field) != std::string::npos;
    if (!named) MESSAGE(std::string(std::string("message: ") + e.what()));
  }
  CHECK(named);
}

} // namespace crep::test
