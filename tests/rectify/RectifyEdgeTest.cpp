// Edge cases, continuity near the fallback switch, reference rays (Sec. 3.2), distances, Eq. 12, the
// JSON form and input validation of the projective rectification.
#include <crep/core/error.h>
#include <crep/rectify/json.h>
#include <crep/rectify/rectify.h>

#include "rectify/rectify_checks.h"

#include <doctest/doctest.h>

#include <cstdlib>
#include <stdexcept>
#include <utility>

using namespace crep;
using namespace crep::test;

namespace {

const Camera kCamera =
    Camera::lookAt({0, 1, 5}, {0, 0, 0}, {0, 1, 0}, glm::radians(60.0), 16.0 / 9.0, 0.1, 100.0);

RectifyOptions onlyImpossible() {
  RectifyOptions o;
  o.maxSpanDegrees = 180.0;
  o.minEpipoleAngleDegrees = 0.0;
  return o;
}

/// All properties on one directional configuration (the sweep checks of RectifyTest.cpp).
void checkDirectional(const Camera& cam, const Rectification& r, const glm::dvec3& l, std::uint64_t seed) {
  REQUIRE(r.projective());
  std::mt19937_64 rng(seed);
  Worst w;
  const glm::dvec3 c = cam.position();
  for (int i = 0; i < 20; ++i)
    checkProjective(
        r, cam, rng, [&](const glm::dvec3& p, double t) { return p + t * glm::length(p - c) * l; },
        [](const glm::dvec3&) { return true; }, w);
  report("edge case", w, 0.0, false);
}

/// A direction rotated by `angle` away from `dir` in the plane of dir and `away`.
glm::dvec3 rotateAway(const glm::dvec3& dir, const glm::dvec3& away, double angle) {
  const glm::dvec3 t = glm::normalize(away - glm::dot(away, dir) * dir);
  return std::cos(angle) * dir + std::sin(angle) * t;
}

/// A minimal JSON reader for the toJson test (objects keep their key order).
struct Json {
  enum Type { Null, Bool, Number, String, Array, Object } type = Null;
  double number = 0.0;
  std::string text;
  std::vector<Json> items;
  std::vector<std::pair<std::string, Json>> members;
  const Json& at(const std::string& key) const {
    for (const auto& [k, v] : members)
      if (k == key) return v;
    throw std::runtime_error("missing key " + key);
  }
};

struct JsonReader {
  const std::string& s;
  std::size_t i = 0;
  void ws() {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\n' || s[i] == '\t' || s[i] == '\r'))
      ++i;
  }
  void expect(char c) {
    ws();
    if (i >= s.size() || s[i] != c)
      throw std::runtime_error(std::string("expected ") + c + " at " + std::to_string(i));
    ++i;
  }
  std::string string() {
    expect('"');
    std::string out;
    while (i < s.size() && s[i] != '"')
      out += s[i++]; // toJson emits no escapes
    expect('"');
    return out;
  }
  Json value() {
    ws();
    Json v;
    if (s[i] == '{') {
      v.type = Json::Object;
      expect('{');
      ws();
      if (s[i] == '}') {
        ++i;
        return v;
      }
      do {
        std::string key = string();
        expect(':');
        v.members.emplace_back(std::move(key), value());
        ws();
      } while (s[i] == ',' && ++i);
      expect('}');
    } else if (s[i] == '[') {
      v.type = Json::Array;
      expect('[');
      ws();
      if (s[i] == ']') {
        ++i;
        return v;
      }
      do {
        v.items.push_back(value());
        ws();
      } while (s[i] == ',' && ++i);
      expect(']');
    } else if (s[i] == '"') {
      v.type = Json::String;
      v.text = string();
    } else {
      v.type = Json::Number;
      char* end = nullptr;
      v.number = std::strtod(s.c_str() + i, &end);
      if (end == s.c_str() + i) throw std::runtime_error("bad value at " + std::to_string(i));
      i = static_cast<std::size_t>(end - s.c_str());
    }
    return v;
  }
};

Json parseJson(const std::string& text) {
  JsonReader reader{text};
  Json v = reader.value();
  reader.ws();
  if (reader.i != text.size()) throw std::runtime_error("trailing characters");
  return v;
}

} // namespace

TEST_CASE("rectify: light parallel to the world up vector") {
  for (const glm::dvec3 l : {glm::dvec3(0, -1, 0), glm::dvec3(0, 1, 0)}) {
    const Rectification r = rectify(kCamera, DirectionalLight(l));
    CHECK(r.status == RectifyStatus::Projective);
    checkDirectional(kCamera, r, l, 1);
  }
}

TEST_CASE("rectify: light exactly along and exactly against the view direction") {
  for (const double s : {1.0, -1.0}) {
    const glm::dvec3 l = s * kCamera.forward();
    for (const RectifyOptions& o : {RectifyOptions{}, onlyImpossible()}) {
      const Rectification r = rectify(kCamera, DirectionalLight(l), o);
      CHECK(r.status == RectifyStatus::Fallback);
      CHECK(r.reason == FallbackReason::ViewRayParallelToLight);
      CHECK(r.measure == 180.0);
      CHECK(r.epipoleAngle == 0.0);
      CHECK(r.splits.empty());
      CHECK_THROWS_AS(r.toRectified(glm::dvec3(0.0)), InvalidArgument);
    }
  }
}

TEST_CASE("rectify: epipole exactly on a screen corner and just off it") {
  for (const glm::dvec2 corner :
       {glm::dvec2(1, 1), glm::dvec2(-1, 1), glm::dvec2(-1, -1), glm::dvec2(1, -1)}) {
    for (const double s : {1.0, -1.0}) { // epipole and anti-epipole
      const glm::dvec3 d = kCamera.rayDirection(corner.x, corner.y);
      // On the corner: the corner's view ray is parallel to the light.
      const Rectification on = rectify(kCamera, DirectionalLight(s * d), onlyImpossible());
      CHECK(on.reason == FallbackReason::ViewRayParallelToLight);
      // Just off screen, 1e-3 rad outward along the diagonal: possible, very non-linear.
      const glm::dvec3 out = kCamera.rayDirection(corner.x * 1.01, corner.y * 1.01);
      const glm::dvec3 off = s * rotateAway(d, out, 1e-3);
      CHECK(viewConeMargin(kCamera, s * off) < 0.0);
      const Rectification r = rectify(kCamera, DirectionalLight(off), onlyImpossible());
      CHECK(r.status == RectifyStatus::Projective);
      CHECK(r.epipoleAngle == doctest::Approx(glm::degrees(1e-3)).epsilon(1e-3));
      checkDirectional(kCamera, r, off, 2);
      // With the default thresholds it falls back, with the measure that decided.
      const Rectification d0 = rectify(kCamera, DirectionalLight(off));
      CHECK(d0.status == RectifyStatus::Fallback);
      CHECK((d0.reason == FallbackReason::NonLinearity || d0.reason == FallbackReason::EpipoleTooClose));
      CHECK(std::isfinite(d0.measure));
    }
  }
}

TEST_CASE("rectify: camera looking straight down") {
  const Camera cam =
      Camera::lookAt({0, 10, 0}, {0, 0, 0}, {0, 0, -1}, glm::radians(60.0), 16.0 / 9.0, 0.1, 100.0);
  const glm::dvec3 l = glm::normalize(glm::dvec3(1, -0.3, 0.2));
  const Rectification r = rectify(cam, DirectionalLight(l));
  CHECK(r.status == RectifyStatus::Projective);
  checkDirectional(cam, r, l, 3);
  // Sun straight down: parallel to the central view ray.
  CHECK(rectify(cam, DirectionalLight({0, -1, 0})).reason == FallbackReason::ViewRayParallelToLight);
}

TEST_CASE("rectify: near 1e-4 with far 1e4") {
  const Camera cam = Camera::lookAt({3, 2, 1}, {0, 1, -4}, {0, 1, 0}, glm::radians(75.0), 1.5, 1e-4, 1e4);
  std::mt19937_64 rng(0x1e4);
  int projective = 0;
  for (int i = 0; i < 200; ++i) {
    const glm::dvec3 l = randomUnit(rng);
    RectifyOptions o;
    o.splits = 1 + i % 8;
    o.scheme = static_cast<SplitScheme>(i % 3);
    const Rectification r = rectify(cam, DirectionalLight(l), o);
    if (!r.projective()) continue;
    ++projective;
    checkDirectional(cam, r, l, 4 + static_cast<std::uint64_t>(i));
    CHECK(r.frame.axisMax / r.frame.axisMin > 1e7); // the 1e8 depth ratio is there
  }
  CHECK(projective > 100);
}

TEST_CASE("rectify: continuity as the light sweeps toward the degenerate cone") {
  // 8 sweeps: the light turns in steps of 2e-4 rad from a direction orthogonal to an on-screen view
  // ray toward it, until the result falls back. Fixed world probes inside the frustum must move
  // continuously in the map. Stated bound: any normalized coordinate changes by at most 20 x the
  // rotation in radians per step (measured: 3.8), also at the last step before the switch.
  std::mt19937_64 rng(0xc0417);
  std::vector<glm::dvec3> probes;
  for (int i = 0; i < 32; ++i)
    probes.push_back(kCamera.position() +
                     kCamera.rayDirection(uniform(rng, -0.95, 0.95), uniform(rng, -0.95, 0.95)) *
                         logUniform(rng, 0.2, 90.0));
  const double step = 2e-4;
  double worstStep = 0.0, worstLast = 0.0, worstMeasureStep = 0.0;
  int switches = 0;
  for (int sweep = 0; sweep < 8; ++sweep) {
    const glm::dvec3 b = kCamera.rayDirection(uniform(rng, -0.9, 0.9), uniform(rng, -0.9, 0.9));
    const glm::dvec3 a = glm::normalize(glm::cross(b, randomUnit(rng)));
    std::vector<RectPoint> prev;
    double prevSpan = 0.0, prevEpipole = 0.0, last = 0.0;
    for (int i = 0; i * step < 0.5 * std::numbers::pi; ++i) {
      const double theta = i * step;
      const Rectification r = rectify(kCamera, DirectionalLight(std::cos(theta) * a + std::sin(theta) * b));
      if (!r.projective()) {
        CHECK(i > 0);
        CHECK(r.reason != FallbackReason::ViewRayParallelToLight); // a threshold switches first
        ++switches;
        worstLast = std::max(worstLast, last);
        break;
      }
      std::vector<RectPoint> cur;
      for (const auto& p : probes)
        cur.push_back(r.toRectified(p));
      if (!prev.empty()) {
        double d = 0.0;
        for (std::size_t k = 0; k < cur.size(); ++k)
          d = std::max({d, std::abs(cur[k].column - prev[k].column), std::abs(cur[k].row - prev[k].row),
                        std::abs(cur[k].depth - prev[k].depth)});
        worstStep = std::max(worstStep, d);
        last = d;
        worstMeasureStep =
            std::max({worstMeasureStep, std::abs(r.span - prevSpan), std::abs(r.epipoleAngle - prevEpipole)});
      }
      prev = cur;
      prevSpan = r.span;
      prevEpipole = r.epipoleAngle;
    }
  }
  MESSAGE("continuity: worst change of a normalized coordinate per radian of light rotation "
          << worstStep / step << ", at the last step before the switch " << worstLast / step
          << "; worst change of the measures " << worstMeasureStep / glm::degrees(step) << " deg per deg");
  CHECK(switches == 8);
  CHECK(worstStep / step < 20.0);
  CHECK(worstLast / step < 20.0);
  CHECK(worstMeasureStep / glm::degrees(step) < 20.0); // the measures are continuous too
}

TEST_CASE("rectify: reference rays (Sec. 3.2) against brute force") {
  std::mt19937_64 rng(0x3e2);
  int rows = 0;
  for (int i = 0; i < 300; ++i) {
    const Camera cam = randomCamera(rng);
    const glm::dvec3 l = randomUnit(rng);
    const Rectification r = rectify(cam, DirectionalLight(l));
    if (!r.projective()) continue;
    for (int j = 0; j < 4; ++j) {
      const double row = uniform(rng, 0.02, 0.98);
      const RowReference bis = r.rowReference(row, ReferenceRay::Bisectrix);
      const RowReference opt = r.rowReference(row, ReferenceRay::Optimal);
      ++rows;
      CHECK(bis.kMin <= bis.kRef);
      CHECK(bis.kRef <= bis.kMax);
      CHECK(bis.kMax <= 1.0);
      CHECK(bis.ratioMin <= 1.0);
      CHECK(bis.ratioMax >= 1.0);
      CHECK(opt.ratioMin * opt.ratioMax == doctest::Approx(1.0).epsilon(1e-12)); // c_min^-1 == c_max
      CHECK(opt.error() <= bis.error() * (1 + 1e-12));
      CHECK(opt.kRef == doctest::Approx(std::sqrt(opt.kMin * opt.kMax)).epsilon(1e-12));
      // Brute force: the rays of the row are exactly the view rays of depth in [depthLo, depthHi].
      const auto margin = [&](double depth) { return viewConeMargin(cam, r.viewRayDirection(row, depth)); };
      CHECK(margin(bis.depthLo + 1e-6 * (bis.depthHi - bis.depthLo)) >= -1e-9);
      CHECK(margin(bis.depthHi - 1e-6 * (bis.depthHi - bis.depthLo)) >= -1e-9);
      CHECK(margin(bis.depthLo - 1e-6) < 0.0);
      CHECK(margin(bis.depthHi + 1e-6) < 0.0);
      // k = sine of the angle to the light, over the row's rays; the world step ratio to the reference
      // ray is column-independent (directional light) and spans [1/ratioMax, 1/ratioMin].
      double kLo = 2, kHi = -1, sLo = 1e300, sHi = -1;
      for (int s = 0; s <= 400; ++s) {
        const double depth = bis.depthLo + (bis.depthHi - bis.depthLo) * s / 400.0;
        const glm::dvec3 w = r.viewRayDirection(row, depth);
        const double k = glm::length(w - glm::dot(w, l) * l);
        kLo = std::min(kLo, k);
        kHi = std::max(kHi, k);
        const double c1 = uniform(rng, 0, 1), c2 = uniform(rng, 0, 1);
        const double q1 = r.rayDistance(row, bis.depth, c1) / r.rayDistance(row, depth, c1);
        const double q2 = r.rayDistance(row, bis.depth, c2) / r.rayDistance(row, depth, c2);
        CHECK(q1 == doctest::Approx(q2).epsilon(1e-10));
        sLo = std::min(sLo, q1);
        sHi = std::max(sHi, q1);
      }
      CHECK(bis.kMin == doctest::Approx(kLo).epsilon(1e-9));
      CHECK(bis.kMax == doctest::Approx(kHi).epsilon(1e-4)); // the orthogonal ray may fall between samples
      CHECK(sLo == doctest::Approx(1.0 / bis.ratioMax).epsilon(1e-9));
      CHECK(sHi == doctest::Approx(1.0 / bis.ratioMin).epsilon(1e-4));
      // The reference ray lies in the row, between its extreme rays.
      CHECK(bis.depth >= bis.depthLo - 1e-12);
      CHECK(bis.depth <= bis.depthHi + 1e-12);
      CHECK(glm::length(bis.direction - r.viewRayDirection(row, bis.depth)) < 1e-12);
    }
  }
  CHECK(rows > 600);
}

TEST_CASE("rectify: closed-form distances along the reference ray and Eq. 12") {
  const glm::dvec3 l = glm::normalize(glm::dvec3(1, -0.3, 0.2));
  for (const int K : {1, 4}) {
    RectifyOptions o;
    o.splits = K;
    const Rectification r = rectify(kCamera, DirectionalLight(l), o);
    REQUIRE(r.projective());
    for (const double row : {0.1, 0.5, 0.9}) {
      const RowReference ref = r.rowReference(row);
      double prev = 0.0;
      for (int i = 0; i <= 256; ++i) {
        const double column = i / 256.0;
        const double t = r.referenceDistance(row, column);
        const glm::dvec3 p = r.toWorld(column, row, ref.depth);
        CHECK(t == doctest::Approx(glm::length(p - kCamera.position())).epsilon(1e-12));
        CHECK(t > prev); // strictly increasing along the row
        prev = t;
        CHECK(std::isfinite(t));
      }
      // Eq. 12: d from the first three texel centres of split k (defined independently here).
      for (int k = 0; k < K; ++k) {
        const int n = 256;
        double t[3];
        for (int i = 0; i < 3; ++i)
          t[i] = glm::length(r.toWorld((k + (i + 0.5) / n) / K, row, ref.depth) - kCamera.position());
        CHECK(r.texelStepRatio(row, k, n) == doctest::Approx((t[2] - t[1]) / (t[1] - t[0])).epsilon(1e-9));
        CHECK(r.texelStepRatio(row, k, n) > 1.0); // steps grow away from the camera
      }
    }
  }
}

TEST_CASE("rectify: layouts, viewports and light rays") {
  const glm::dvec3 l = glm::normalize(glm::dvec3(1, -0.3, 0.2));
  RectifyOptions o;
  o.splits = 4;
  o.layout = SplitLayout::Regions;
  const Rectification regions = rectify(kCamera, DirectionalLight(l), o);
  o.layout = SplitLayout::Layers;
  const Rectification layers = rectify(kCamera, DirectionalLight(l), o);
  for (int k = 0; k < 4; ++k) {
    const SplitViewport v = regions.splitViewport(k, 1024, 512);
    CHECK(v.layer == 0);
    CHECK(v.x == 256 * k);
    CHECK(v.width == 256);
    CHECK(v.height == 512);
    CHECK(regions.splits[static_cast<std::size_t>(k)].columnBegin == k / 4.0);
    const SplitViewport w = layers.splitViewport(k, 1024, 512);
    CHECK(w.layer == k);
    CHECK(w.x == 0);
    CHECK(w.width == 1024);
    // Same matrices: the layout only says where a split is stored.
    CHECK(regions.splits[static_cast<std::size_t>(k)].rectClipFromWorld ==
          layers.splits[static_cast<std::size_t>(k)].rectClipFromWorld);
  }
  CHECK_THROWS_AS(regions.splitViewport(0, 1001, 512), InvalidArgument); // not a multiple of K
  CHECK_THROWS_AS(regions.splitViewport(4, 1024, 512), InvalidArgument);
  CHECK_THROWS_AS(regions.splitViewport(0, 1024, 0), InvalidArgument);
  // Light rays of map positions: every point maps back to the same (column, row).
  std::mt19937_64 rng(9);
  for (int i = 0; i < 100; ++i) {
    const double column = uniform(rng, 0, 1), row = uniform(rng, 0, 1);
    const LightRay ray = regions.lightRay(column, row);
    CHECK(glm::length(ray.direction - l) < 1e-15);
    for (const double t : {-50.0, 0.0, 10.0, 80.0}) {
      const RectPoint q = regions.toRectified(ray.origin + t * ray.direction);
      CHECK(q.column == doctest::Approx(column).epsilon(1e-10));
      CHECK(q.row == doctest::Approx(row).epsilon(1e-10));
    }
  }
  // Spot light rays start at the light.
  const SpotLight spot({.position = {3, 5, 0},
                        .direction = {-0.5, -1, 0},
                        .innerConeAngle = glm::radians(30.0),
                        .outerConeAngle = glm::radians(40.0),
                        .range = 30.0});
  const Rectification rs = rectify(kCamera, spot);
  REQUIRE(rs.projective());
  const LightRay sr = rs.lightRay(0.5, 0.5);
  CHECK(glm::length(sr.origin - spot.position()) < 1e-12);
  const RectPoint q = rs.toRectified(sr.origin + 7.0 * sr.direction);
  CHECK(q.column == doctest::Approx(0.5).epsilon(1e-10));
  CHECK(q.row == doctest::Approx(0.5).epsilon(1e-10));
}

TEST_CASE("rectify: toJson is the object of `crep rectify`") {
  const glm::dvec3 l = glm::normalize(glm::dvec3(1, -0.3, 0.2));
  RectifyOptions o;
  o.splits = 3;
  const Rectification r = rectify(kCamera, DirectionalLight(l), o);
  const Json j = parseJson(toJson(r));
  REQUIRE(j.type == Json::Object);
  // Exactly these keys, in this order.
  std::vector<std::string> keys;
  for (const auto& [k, v] : j.members)
    keys.push_back(k);
  CHECK(keys == std::vector<std::string>{"status", "reason", "measure", "threshold", "splits"});
  CHECK(j.at("status").text == "projective");
  CHECK(j.at("reason").text == "none");
  CHECK(j.at("measure").number == r.measure); // 17 significant digits: exact round trip
  CHECK(j.at("threshold").number == r.threshold);
  const Json& splits = j.at("splits");
  REQUIRE(splits.type == Json::Array);
  REQUIRE(splits.items.size() == 3);
  for (std::size_t k = 0; k < 3; ++k) {
    const Json& sj = splits.items[k];
    REQUIRE(sj.type == Json::Object);
    REQUIRE(sj.members.size() == 2);
    const Json& m = sj.at("rectClipFromWorld");
    REQUIRE(m.items.size() == 16);
    for (int c = 0; c < 4; ++c) // column-major, as GLSL's mat4 constructor and glUniformMatrix4fv
      for (int row = 0; row < 4; ++row)
        CHECK(m.items[static_cast<std::size_t>(4 * c + row)].number == r.splits[k].rectClipFromWorld[c][row]);
    const Json& range = sj.at("range");
    REQUIRE(range.items.size() == 2);
    CHECK(range.items[0].number == r.splits[k].rangeBegin);
    CHECK(range.items[1].number == r.splits[k].rangeEnd);
  }
  const std::string fallback = toJson(rectify(kCamera, DirectionalLight(kCamera.forward())));
  CHECK(
      fallback ==
      R"({"status": "fallback", "reason": "view-ray-parallel-to-light", "measure": 180, "threshold": 150, "splits": []})");
}

TEST_CASE("rectify: invalid input throws InvalidArgument naming the parameter") {
  const DirectionalLight light(glm::dvec3(1, -0.3, 0.2));
  const auto expectInvalid = [&](RectifyOptions o, const char* parameter) {
    try {
      (void)rectify(kCamera, light, o);
      FAIL("no exception for " << parameter);
    } catch (const InvalidArgument& e) {
      CHECK(e.parameter() == parameter);
    }
  };
  RectifyOptions o;
  o.splits = 0;
  expectInvalid(o, "RectifyOptions.splits");
  o.splits = RectifyOptions::kMaxSplits + 1;
  expectInvalid(o, "RectifyOptions.splits");
  o = {};
  o.blend = 1.5;
  expectInvalid(o, "RectifyOptions.blend");
  o.blend = std::nan("");
  expectInvalid(o, "RectifyOptions.blend");
  o = {};
  for (const double bad : {0.0, -1.0, 180.5, std::nan(""), std::numeric_limits<double>::infinity()}) {
    o.maxSpanDegrees = bad;
    expectInvalid(o, "RectifyOptions.maxSpanDegrees");
  }
  o = {};
  for (const double bad : {-0.1, 90.0, std::nan("")}) {
    o.minEpipoleAngleDegrees = bad;
    expectInvalid(o, "RectifyOptions.minEpipoleAngleDegrees");
  }
  CHECK_THROWS_AS(rectifyPointLight(kCamera, {0, 3, 0}, 0.0), InvalidArgument);
  CHECK_THROWS_AS(rectifyPointLight(kCamera, {0, 3, 0}, 10.0, {}, 20.0), InvalidArgument);
  CHECK_THROWS_AS(rectifyPointLight(kCamera, {std::nan(""), 3, 0}, 10.0), InvalidArgument);
  CHECK_THROWS_AS(splitPositions(0.0, 1.0, 4, SplitScheme::Uniform, 0.5), InvalidArgument);
  // Mapping helpers on a fallback, and points the rectification cannot represent.
  const Rectification fallback = rectify(kCamera, DirectionalLight(kCamera.forward()));
  try {
    (void)fallback.rowReference(0.5);
    FAIL("no exception");
  } catch (const InvalidArgument& e) {
    CHECK(e.parameter() == "Rectification.status");
  }
  const Rectification r = rectify(kCamera, light);
  REQUIRE(r.projective());
  CHECK_THROWS_AS(r.toRectified(kCamera.position()), InvalidArgument); // X = 0
  CHECK_THROWS_AS(r.toRectified(glm::dvec3(std::nan(""))), InvalidArgument);
  CHECK_THROWS_AS(r.toWorld(std::nan(""), 0.5, 0.5), InvalidArgument);
  CHECK_THROWS_AS(r.texelStepRatio(0.5, 0, 2), InvalidArgument);
}

TEST_CASE("rectify: split positions") {
  for (const SplitScheme s : {SplitScheme::Uniform, SplitScheme::Logarithmic, SplitScheme::Blend}) {
    const std::vector<double> x = splitPositions(0.1, 100.0, 4, s, 0.5);
    REQUIRE(x.size() == 5);
    CHECK(x.front() == 0.1);
    CHECK(x.back() == 100.0);
    for (int j = 0; j < 4; ++j)
      CHECK(x[static_cast<std::size_t>(j)] < x[static_cast<std::size_t>(j) + 1]);
  }
  CHECK(splitPositions(0.1, 100.0, 4, SplitScheme::Uniform, 0.0)[2] == doctest::Approx(50.05));
  CHECK(splitPositions(0.1, 100.0, 4, SplitScheme::Logarithmic, 0.0)[2] == doctest::Approx(std::sqrt(10.0)));
  CHECK(splitPositions(0.1, 100.0, 4, SplitScheme::Blend, 0.5)[2] ==
        doctest::Approx(0.5 * 50.05 + 0.5 * std::sqrt(10.0)));
  // The split ranges of a rectification follow the scheme (directional: xh is world X).
  RectifyOptions o;
  o.splits = 4;
  o.scheme = SplitScheme::Logarithmic;
  const Rectification r = rectify(kCamera, DirectionalLight(glm::dvec3(1, -0.3, 0.2)), o);
  const std::vector<double> x =
      splitPositions(r.frame.axisMin, r.frame.axisMax, 4, SplitScheme::Logarithmic, 0.0);
  for (int k = 0; k < 4; ++k) {
    CHECK(r.splits[static_cast<std::size_t>(k)].rangeBegin ==
          doctest::Approx(x[static_cast<std::size_t>(k)]).epsilon(1e-12));
    CHECK(r.splits[static_cast<std::size_t>(k)].rangeEnd ==
          doctest::Approx(x[static_cast<std::size_t>(k) + 1]).epsilon(1e-12));
  }
}
