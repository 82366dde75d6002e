// gpu::FrameTimers (crep/gpu/frame_timers.h) on a backend whose timer results the test hands out: a
// frame's times only once all its spans have resolved, the latest such frame, each once; spans asked in
// order and never again once returned; discarded and dropped frames; and gpu::Backend's default deferred
// timer (cancelTimer, id 0, 0.0).
#include <crep/gpu/backend.h>
#include <crep/gpu/frame_timers.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <map>
#include <optional>
#include <vector>

using namespace crep;

namespace {

/// A backend that measures nothing but timers: results are set by the test, asked ids are recorded.
class FakeTimerBackend : public gpu::Backend {
public:
  std::string_view name() const override { return "fake"; }
  int maxTextureSize() const override { return 1; }
  int maxArrayLayers() const override { return 1; }
  gpu::ComputeLimits computeLimits() const override { return {}; }
  gpu::TextureDesc describe(gpu::TextureId) const override { return {}; }
  std::size_t bufferBytes(gpu::BufferId) const override { return 0; }
  void prepareProgram(const std::string&, std::span<const ShaderDefine>) override {}
  gpu::TextureId createTexture(const gpu::TextureDesc&) override { return 1; }
  void destroyTexture(gpu::TextureId) override {}
  gpu::BufferId createBuffer(std::size_t, std::string_view) override { return 1; }
  void destroyBuffer(gpu::BufferId) override {}
  void writeBuffer(gpu::BufferId, std::size_t, std::span<const std::byte>) override {}
  void writeTexture(gpu::TextureId, std::span<const float>) override {}
  std::vector<std::byte> readBuffer(gpu::BufferId, std::size_t, std::size_t) override {
    ++reads;
    return {};
  }
  std::vector<float> readTexture(gpu::TextureId) override {
    ++reads;
    return {};
  }
  void dispatch(const gpu::Dispatch&) override {}
  void finish() override { ++finishes; }
  void cancelTimer() noexcept override { ++cancels; }

  /// Deferred timers: an id per span; results pending until resolve().
  gpu::TimerId span() {
    const gpu::TimerId id = next++;
    pending[id] = std::nullopt;
    return id;
  }
  void resolve(gpu::TimerId id, double ms) { pending[id] = ms; }
  std::optional<double> timerResult(gpu::TimerId id) override {
    asked.push_back(id);
    const auto it = pending.find(id);
    if (it == pending.end()) return 0.0;
    if (!it->second) return std::nullopt;
    const double ms = *it->second;
    pending.erase(it); // forgotten once returned
    return ms;
  }

  std::map<gpu::TimerId, std::optional<double>> pending;
  std::vector<gpu::TimerId> asked;
  gpu::TimerId next = 1;
  int finishes = 0, reads = 0, cancels = 0;
};

/// gpu::Backend's defaults for the timers: nothing overridden but the pure virtual calls.
class PlainBackend : public FakeTimerBackend {
public:
  std::optional<double> timerResult(gpu::TimerId id) override { return gpu::Backend::timerResult(id); }
};

} // namespace

TEST_CASE("FrameTimers: a frame's times once all its spans resolved, in the order added, reported once") {
  FakeTimerBackend b;
  gpu::FrameTimers timers;
  CHECK_FALSE(timers.poll(b).has_value());
  const gpu::TimerId s0 = b.span(), s1 = b.span();
  timers.add(s0);
  timers.add(0); // a span the backend measures none of: 0 ms
  timers.add(s1);
  timers.endFrame(7);
  CHECK(timers.pendingFrames() == 1);
  CHECK_FALSE(timers.poll(b).has_value());
  b.resolve(s0, 1.5);
  CHECK_FALSE(timers.poll(b).has_value()); // s1 pending
  b.resolve(s1, 2.5);
  b.asked.clear();
  const std::optional<gpu::FrameTimers::Times> t = timers.poll(b);
  REQUIRE(t.has_value());
  CHECK(t->frame == 7);
  CHECK(t->milliseconds == std::vector<double>{1.5, 0.0, 2.5});
  // s0 was returned by an earlier poll: not asked again.
  CHECK(b.asked == std::vector<gpu::TimerId>{s1});
  CHECK(timers.pendingFrames() == 0);
  CHECK_FALSE(timers.poll(b).has_value());
  CHECK(b.finishes == 0);
  CHECK(b.reads == 0);
}

TEST_CASE(
    "FrameTimers: the latest resolved frame, earlier ones skipped, and a pending span stops its frame's "
    "asking") {
  FakeTimerBackend b;
  gpu::FrameTimers timers;
  const gpu::TimerId a = b.span(), c = b.span(), d = b.span(), e = b.span();
  timers.add(a);
  timers.add(c);
  timers.endFrame(1);
  timers.add(d);
  timers.endFrame(2);
  timers.add(e);
  timers.endFrame(3);
  b.resolve(d, 4.0);
  b.resolve(e, 5.0);
  // Frame 1 pending at a: c is not asked; frames 2 and 3 resolved: the latest, 3, is reported and every
  // frame before it forgotten.
  const std::optional<gpu::FrameTimers::Times> t = timers.poll(b);
  CHECK(b.asked == std::vector<gpu::TimerId>{a, d, e});
  REQUIRE(t.has_value());
  CHECK(t->frame == 3);
  CHECK(t->milliseconds == std::vector<double>{5.0});
  CHECK(timers.pendingFrames() == 0);
  b.resolve(a, 1.0);
  b.resolve(c, 1.0);
  CHECK_FALSE(timers.poll(b).has_value());
}

TEST_CASE(
    "FrameTimers: a discarded frame's spans are never asked, and beyond kMaxPendingFrames the oldest is "
    "dropped") {
  FakeTimerBackend b;
  gpu::FrameTimers timers;
  const gpu::TimerId thrown = b.span();
  timers.add(thrown);
  timers.discardFrame(); // the frame threw
  const gpu::TimerId kept = b.span();
  timers.add(kept);
  timers.endFrame(0);
  b.resolve(thrown, 9.0);
  b.resolve(kept, 3.0);
  const std::optional<gpu::FrameTimers::Times> t = timers.poll(b);
  REQUIRE(t.has_value());
  CHECK(t->milliseconds == std::vector<double>{3.0});
  CHECK(b.asked == std::vector<gpu::TimerId>{kept});

  std::vector<gpu::TimerId> first;
  for (std::size_t f = 1; f <= gpu::FrameTimers::kMaxPendingFrames + 1; ++f) {
    const gpu::TimerId id = b.span();
    if (f == 1) first.push_back(id);
    timers.add(id);
    timers.endFrame(f);
  }
  CHECK(timers.pendingFrames() == gpu::FrameTimers::kMaxPendingFrames);
  b.asked.clear();
  CHECK_FALSE(timers.poll(b).has_value());
  CHECK(std::find(b.asked.begin(), b.asked.end(), first[0]) == b.asked.end()); // frame 1 dropped
}

TEST_CASE("gpu::Backend's default deferred timer: cancels the span, id 0, result 0, no finish") {
  PlainBackend b;
  b.beginTimer();
  CHECK(b.endTimerDeferred() == 0);
  CHECK(b.cancels == 1);
  CHECK(b.finishes == 0);
  CHECK(b.timerResult(0) == 0.0);
  CHECK(b.timerResult(5) == 0.0);
  // The blocking default still finishes.
  b.beginTimer();
  CHECK(b.endTimer() == 0.0);
  CHECK(b.finishes == 1);
}
