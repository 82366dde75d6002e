// gpu::GlBackend's GPU timers (crep/gpu/gl_backend.h): the deferred spans (endTimerDeferred, timerResult)
// with their ids, pending results, forgotten ids, reused queries and the bound on pending spans; the
// blocking endTimer beside them; cancelTimer leaving no GL_TIME_ELAPSED query active.
#include "common/gl_fixture.h"

#include <crep/gpu/gl.h>
#include <crep/gpu/gl_backend.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cmath>
#include <optional>
#include <vector>

using namespace crep;

namespace {

/// The GL_TIME_ELAPSED query active in the context, 0 when none.
GLint activeTimeQuery() {
  GLint query = -1;
  glGetQueryiv(GL_TIME_ELAPSED, GL_CURRENT_QUERY, &query);
  return query;
}

/// Some GPU work inside a span: a clear of a 256 x 256 RGBA32F texture.
void work(const gl::Handle& texture) {
  const float value[4] = {1, 2, 3, 4};
  glClearTexImage(texture.get(), 0, GL_RGBA, GL_FLOAT, value);
}

gl::Handle workTexture() {
  gl::Handle texture = gl::createTexture(GL_TEXTURE_2D);
  glTextureStorage2D(texture.get(), 1, GL_RGBA32F, 256, 256);
  return texture;
}

bool finiteNonNegative(const std::optional<double>& ms) {
  return ms.has_value() && std::isfinite(*ms) && *ms >= 0.0;
}

} // namespace

TEST_CASE("GlBackend deferred timers: ids, pending then a result once, forgotten ids read 0, queries "
          "reused") {
  CREP_REQUIRE_GL();
  gpu::GlBackend b;
  const gl::Handle texture = workTexture();
  // No span begun: no id; 0 and unknown ids read 0.
  CHECK(b.endTimerDeferred() == 0);
  CHECK(b.timerResult(0) == 0.0);
  CHECK(b.timerResult(12345) == 0.0);

  b.beginTimer();
  const GLint first = activeTimeQuery();
  CHECK(first != 0);
  work(texture);
  const gpu::TimerId a = b.endTimerDeferred();
  CHECK(activeTimeQuery() == 0); // ended: the next span (or the caller's query) may begin
  b.beginTimer();
  const GLint second = activeTimeQuery();
  CHECK(second != 0);
  CHECK(second != first); // the first is pending: not reused
  work(texture);
  const gpu::TimerId c = b.endTimerDeferred();
  CHECK(a != 0);
  CHECK(c > a);
  CHECK(b.pendingTimers() == 2);

  // Before the GPU is done a result is pending or there; asking never waits.
  const std::optional<double> early = b.timerResult(a);
  CHECK((!early.has_value() || finiteNonNegative(early)));
  glFinish(); // the test waits: every result is available now
  const std::optional<double> ra = early ? early : b.timerResult(a);
  const std::optional<double> rc = b.timerResult(c);
  MESSAGE("deferred spans: " << ra.value_or(-1.0) << " ms, " << rc.value_or(-1.0) << " ms");
  CHECK(finiteNonNegative(ra));
  CHECK(finiteNonNegative(rc));
  CHECK(b.pendingTimers() == 0);
  // Returned once, then forgotten.
  CHECK(b.timerResult(a) == 0.0);
  CHECK(b.timerResult(c) == 0.0);

  // A read query is reused by the next span.
  b.beginTimer();
  const GLint reused = activeTimeQuery();
  CHECK((reused == first || reused == second));
  const gpu::TimerId d = b.endTimerDeferred();
  CHECK(d > c);
  // The blocking timer beside the deferred one: it waits and reads its own span only.
  b.beginTimer();
  work(texture);
  const double blocking = b.endTimer();
  CHECK(std::isfinite(blocking));
  CHECK(blocking >= 0.0);
  CHECK(b.pendingTimers() == 1);
  CHECK(finiteNonNegative(b.timerResult(d))); // endTimer finished: d's result is there
  CHECK(activeTimeQuery() == 0);
}

TEST_CASE("GlBackend timers: cancelTimer and nested spans leave no query active") {
  CREP_REQUIRE_GL();
  gpu::GlBackend b;
  const gl::Handle texture = workTexture();
  b.beginTimer();
  work(texture);
  CHECK(activeTimeQuery() != 0);
  b.cancelTimer(); // a stage that threw
  CHECK(activeTimeQuery() == 0);
  CHECK(b.endTimerDeferred() == 0); // nothing to end
  CHECK(b.endTimer() == 0.0);
  b.cancelTimer(); // twice: a no-op
  CHECK(activeTimeQuery() == 0);

  // Spans do not nest: a second beginTimer() cancels the first.
  b.beginTimer();
  b.beginTimer();
  CHECK(activeTimeQuery() != 0);
  const gpu::TimerId id = b.endTimerDeferred();
  CHECK(id != 0);
  CHECK(b.pendingTimers() == 1);
  CHECK(activeTimeQuery() == 0);
  glFinish();
  CHECK(finiteNonNegative(b.timerResult(id)));

  // The caller's own GL_TIME_ELAPSED query may begin after a cancelled span.
  b.beginTimer();
  b.cancelTimer();
  const gl::Handle own = gl::createQuery(GL_TIME_ELAPSED);
  glBeginQuery(GL_TIME_ELAPSED, own.get());
  glEndQuery(GL_TIME_ELAPSED);
}

TEST_CASE("GlBackend deferred timers: beyond kMaxPendingTimers pending, the oldest are dropped and read 0") {
  CREP_REQUIRE_GL();
  gpu::GlBackend b;
  constexpr std::size_t extra = 10;
  std::vector<gpu::TimerId> ids;
  for (std::size_t i = 0; i < gpu::GlBackend::kMaxPendingTimers + extra; ++i) {
    b.beginTimer();
    ids.push_back(b.endTimerDeferred());
  }
  CHECK(b.pendingTimers() == gpu::GlBackend::kMaxPendingTimers);
  // The dropped ones read 0 at once, pending or not, and stay unknown.
  for (std::size_t i = 0; i < extra; ++i)
    CHECK(b.timerResult(ids[i]) == 0.0);
  CHECK(b.pendingTimers() == gpu::GlBackend::kMaxPendingTimers);
  glFinish();
  int results = 0;
  for (std::size_t i = extra; i < ids.size(); ++i)
    results += finiteNonNegative(b.timerResult(ids[i])) ? 1 : 0;
  CHECK(results == int(gpu::GlBackend::kMaxPendingTimers));
  CHECK(b.pendingTimers() == 0);
  CHECK(activeTimeQuery() == 0);
}
