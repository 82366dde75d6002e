// The shared checks of crep/core/error.h: invalid() and the require* helpers throw InvalidArgument naming
// the parameter, with the offending value in the message.
#include <crep/core/error.h>

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <string>

#include <glm/glm.hpp>

using namespace crep;

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// The InvalidArgument `f` throws (fails the test when it throws nothing or something else).
template <class F>
InvalidArgument thrown(const F& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e;
  }
  FAIL("no InvalidArgument thrown");
  return InvalidArgument("", "", "");
}

} // namespace

TEST_CASE("invalid() throws InvalidArgument naming the parameter, its value and the requirement") {
  const InvalidArgument e = thrown([] { invalid("Pass::FrameAttribs.layout", "null", "must be set"); });
  CHECK(e.parameter() == "Pass::FrameAttribs.layout");
  CHECK(std::string(e.what()) == "crep: invalid Pass::FrameAttribs.layout = null (must be set)");
}

TEST_CASE("requireFinite rejects NaN and infinities of scalars, vectors and matrices, naming the parameter") {
  CHECK_NOTHROW(requireFinite("x", 1.5));
  CHECK_NOTHROW(requireFinite("v", glm::dvec3(1.0, -2.0, 0.0)));
  CHECK_NOTHROW(requireFinite("m", glm::dmat4(2.0)));
  for (const double bad : {kNan, kInf, -kInf}) {
    CAPTURE(bad);
    CHECK(thrown([&] { requireFinite("Owner.x", bad); }).parameter() == "Owner.x");
    for (int i = 0; i < 3; ++i) {
      glm::dvec3 v(1.0);
      v[i] = bad;
      const InvalidArgument e = thrown([&] { requireFinite("Owner.v", v); });
      CHECK(e.parameter() == "Owner.v");
      CHECK(std::string(e.what()).find(detail::formatValue(v)) != std::string::npos);
    }
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) {
        glm::dmat4 m(1.0);
        m[c][r] = bad;
        const InvalidArgument e = thrown([&] { requireFinite(std::string("Owner.m"), m); });
        CHECK(e.parameter() == "Owner.m");
        CHECK(std::string(e.what()).find("= " + detail::formatValue(bad) + " (must be finite)") !=
              std::string::npos);
      }
  }
}

TEST_CASE("requirePositive and requireNonNegative reject NaN, infinities and values out of range") {
  CHECK_NOTHROW(requirePositive("p", 1e-300));
  CHECK_NOTHROW(requireNonNegative("n", 0.0));
  for (const double bad : {kNan, kInf, -kInf, 0.0, -1.0})
    CHECK(thrown([&] { requirePositive("Owner.p", bad); }).parameter() == "Owner.p");
  for (const double bad : {kNan, kInf, -kInf, -1e-300})
    CHECK(thrown([&] { requireNonNegative("Owner.n", bad); }).parameter() == "Owner.n");
}

TEST_CASE("formatValue of a vector lists its components") {
  CHECK(detail::formatValue(glm::dvec3(1.0, -0.5, kNan)) == "(1, -0.5, nan)");
}
