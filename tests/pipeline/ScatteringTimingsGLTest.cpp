// crep::Scattering's stage timings (CreateInfo::stageTimings, blockingTimings): without blockingTimings a
// frame never waits for the GPU (no finish, no blocking timer, no read-back through its backend; its spans
// still pending when run() returns) and a later frame reports its GPU times (FrameResult::gpuTimes: the
// earlier frame's stages by name, its local lights); with blockingTimings each stage's GPU time is in the
// same frame. The backend is a GlBackend behind a wrapper that counts the calls that wait.
#include "common/gl_fixture.h"
#include "pipeline/scattering_frame.h"

#include <crep/core/error.h>
#include <crep/gpu/gl_backend.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cmath>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

/// Every call forwarded to a GlBackend; the calls that wait for the GPU counted.
class CountingBackend : public gpu::Backend {
public:
  std::string_view name() const override { return gl.name(); }
  gpu::BackendKind kind() const override { return gl.kind(); }
  int maxTextureSize() const override { return gl.maxTextureSize(); }
  int maxArrayLayers() const override { return gl.maxArrayLayers(); }
  int max3DTextureSize() const override { return gl.max3DTextureSize(); }
  gpu::ComputeLimits computeLimits() const override { return gl.computeLimits(); }
  gpu::TextureDesc describe(gpu::TextureId t) const override { return gl.describe(t); }
  std::size_t bufferBytes(gpu::BufferId b) const override { return gl.bufferBytes(b); }
  void prepareProgram(const std::string& p, std::span<const ShaderDefine> d) override {
    gl.prepareProgram(p, d);
  }
  gpu::TextureId createTexture(const gpu::TextureDesc& d) override { return gl.createTexture(d); }
  void destroyTexture(gpu::TextureId t) override { gl.destroyTexture(t); }
  gpu::BufferId createBuffer(std::size_t n, std::string_view l) override { return gl.createBuffer(n, l); }
  void destroyBuffer(gpu::BufferId b) override { gl.destroyBuffer(b); }
  void writeBuffer(gpu::BufferId b, std::size_t o, std::span<const std::byte> bytes) override {
    gl.writeBuffer(b, o, bytes);
  }
  void writeTexture(gpu::TextureId t, std::span<const float> texels) override { gl.writeTexture(t, texels); }
  std::vector<std::byte> readBuffer(gpu::BufferId b, std::size_t o, std::size_t n) override {
    ++reads;
    return gl.readBuffer(b, o, n);
  }
  std::vector<float> readTexture(gpu::TextureId t) override {
    ++reads;
    return gl.readTexture(t);
  }
  void dispatch(const gpu::Dispatch& d) override { gl.dispatch(d); }
  void finish() override {
    ++finishes;
    gl.finish();
  }
  void beginTimer() override { gl.beginTimer(); }
  double endTimer() override {
    ++blockingTimers;
    return gl.endTimer();
  }
  void cancelTimer() noexcept override { gl.cancelTimer(); }
  gpu::TimerId endTimerDeferred() override {
    ++deferredTimers;
    return gl.endTimerDeferred();
  }
  std::optional<double> timerResult(gpu::TimerId id) override { return gl.timerResult(id); }

  void reset() { finishes = reads = blockingTimers = deferredTimers = 0; }
  int waits() const { return finishes + reads + blockingTimers; }

  gpu::GlBackend gl;
  int finishes = 0, reads = 0, blockingTimers = 0, deferredTimers = 0;
};

GLint activeTimeQuery() {
  GLint query = -1;
  glGetQueryiv(GL_TIME_ELAPSED, GL_CURRENT_QUERY, &query);
  return query;
}

Scattering::CreateInfo countedInfo(CountingBackend& b) {
  Scattering::CreateInfo info = smallInfo();
  info.backend = &b;
  return info;
}

/// A spot light in view of the colonnade (on its epipolar layout: shadow pass, resample, prefilter,
/// evaluation, epipole block).
SpotLight spotInView(const Camera& c) {
  return spotToward(c, c.position() + 9.0 * c.forward() + 1.5 * c.up() - 1.0 * c.right());
}

std::string stageNames(const std::vector<Scattering::Stage>& stages) {
  std::string names;
  for (const Scattering::Stage& s : stages)
    names += s.name + "; ";
  return names;
}

} // namespace

TEST_CASE("Scattering timings without blockingTimings: a frame never finishes, reads back or waits for a "
          "timer") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  const SpotLight spot = spotInView(f.scene.camera);
  struct Variant {
    const char* name;
    Scattering::Sampling sampling;
    double scale;
    bool spot;
  };
  for (const Variant& v : {Variant{"per pixel, a spot in view", Scattering::Sampling::PerPixel, 1.0, true},
                           Variant{"epipolar sampling", Scattering::Sampling::Epipolar, 1.0, false},
                           Variant{"evaluation scale 0.5", Scattering::Sampling::PerPixel, 0.5, false}}) {
    CAPTURE(std::string(v.name));
    CountingBackend b;
    Scattering::CreateInfo info = countedInfo(b);
    info.sampling = v.sampling;
    info.epipolarSampling.slices = 128;
    info.epipolarSampling.samples = 64;
    info.evaluationScale = v.scale;
    REQUIRE(info.stageTimings);
    REQUIRE_FALSE(info.blockingTimings); // the default
    Scattering scattering(info);
    Scattering::FrameAttribs a = f.attribs(true, true);
    if (v.spot) a.spotLights = std::span<const SpotLight>(&spot, 1);
    for (std::uint64_t frame = 0; frame < 3; ++frame) {
      b.reset();
      const Scattering::FrameResult r = scattering.run(a);
      MESSAGE(v.name << ", frame " << frame << ": " << stageNames(r.stages));
      CHECK(r.frame == frame);
      CHECK(b.finishes == 0);
      CHECK(b.reads == 0);
      CHECK(b.blockingTimers == 0);
      CHECK(b.deferredTimers == int(r.stages.size())); // every stage timed, none waited for
      CHECK(activeTimeQuery() == 0);
      if (frame == 0) // nothing of the frame was read in run(): every span is still the backend's
        CHECK(b.gl.pendingTimers() == r.stages.size());
      for (const Scattering::Stage& s : r.stages) {
        CHECK(s.gpuMilliseconds == 0.0); // arrives with a later frame
        CHECK(s.wallMilliseconds > 0.0); // the CPU time to record it
      }
      for (const Scattering::LightResult& l : r.localLights)
        CHECK(l.gpuMilliseconds == 0.0);
      // The sampling's counts are a read-back: not without blockingTimings.
      CHECK(r.sampling.validSamples == 0);
      CHECK(r.sampling.marchedSamples == 0);
    }
    checkStages(scattering.run(a));
  }
}

TEST_CASE("Scattering timings without blockingTimings: gpuTimes name an earlier frame, its stages and local "
          "lights") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  const SpotLight spot = spotInView(f.scene.camera);
  gpu::GlBackend backend;
  Scattering::CreateInfo info = smallInfo();
  info.backend = &backend;
  Scattering scattering(info);
  // Frames with and without the spot: their stages differ, so the names say which frame is reported.
  const auto frameAttribs = [&](std::uint64_t frame) {
    Scattering::FrameAttribs a = f.attribs(true, true);
    if (frame % 2 == 0) a.spotLights = std::span<const SpotLight>(&spot, 1);
    return a;
  };
  std::vector<Scattering::FrameResult> results;
  std::uint64_t lastReported = 0;
  bool reported = false;
  for (std::uint64_t frame = 0; frame < 6; ++frame) {
    CAPTURE(frame);
    if (frame >= 3) glFinish(); // the test waits: every earlier frame's times are there
    results.push_back(scattering.run(frameAttribs(frame)));
    const Scattering::FrameResult& r = results.back();
    CHECK(r.frame == frame);
    if (frame == 0) CHECK_FALSE(r.gpuTimes.has_value()); // no earlier frame
    if (!r.gpuTimes) {
      CHECK(frame < 3);
      continue;
    }
    const Scattering::GpuTimes& t = *r.gpuTimes;
    CHECK(t.frame < frame);
    CHECK((!reported || t.frame > lastReported)); // each frame once at most, in order
    if (frame >= 3) CHECK(t.frame == frame - 1);  // after a finish: the latest earlier frame
    reported = true;
    lastReported = t.frame;
    const Scattering::FrameResult& earlier = results[t.frame];
    REQUIRE(t.stages.size() == earlier.stages.size());
    double lightSum = 0.0;
    for (std::size_t i = 0; i < t.stages.size(); ++i) {
      CHECK(t.stages[i].name == earlier.stages[i].name);
      CHECK(t.stages[i].wallMilliseconds == earlier.stages[i].wallMilliseconds);
      CHECK(std::isfinite(t.stages[i].gpuMilliseconds));
      CHECK(t.stages[i].gpuMilliseconds >= 0.0);
      if (t.stages[i].name.rfind("local light: ", 0) == 0) lightSum += t.stages[i].gpuMilliseconds;
    }
    REQUIRE(t.localLights.size() == earlier.localLights.size());
    CHECK(t.localLights.size() == (t.frame % 2 == 0 ? 1u : 0u));
    if (!t.localLights.empty()) CHECK(t.localLights[0] == doctest::Approx(lightSum));
    CHECK(t.totalMilliseconds() >= lightSum);
    std::string times;
    for (const Scattering::Stage& s : t.stages)
      times += s.name + " " + std::to_string(s.gpuMilliseconds) + " ms; ";
    MESSAGE("frame " << frame << " reports frame " << t.frame << ": " << times);
  }
  CHECK(reported);
}

TEST_CASE("Scattering timings without blockingTimings: a frame that throws is never reported") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  CountingBackend b;
  Scattering scattering(countedInfo(b));
  CHECK(scattering.run(f.attribs(true, true)).frame == 0);
  Scattering::FrameAttribs bad = f.attribs(true, true);
  bad.drawCasters = [](const glm::dmat4&) { throw std::runtime_error("the engine's casters failed"); };
  CHECK_THROWS_AS(scattering.run(bad), std::runtime_error);
  CHECK(activeTimeQuery() == 0); // the throwing stage's span cancelled
  glFinish();
  const Scattering::FrameResult r = scattering.run(f.attribs(true, true));
  CHECK(r.frame == 2);
  REQUIRE(r.gpuTimes.has_value());
  CHECK(r.gpuTimes->frame == 0);
  glFinish();
  const Scattering::FrameResult next = scattering.run(f.attribs(true, true));
  REQUIRE(next.gpuTimes.has_value());
  CHECK(next.gpuTimes->frame == 2);
}

TEST_CASE("Scattering timings with blockingTimings: every stage's GPU time in the same frame") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  const SpotLight spot = spotInView(f.scene.camera);
  for (const Scattering::Sampling sampling :
       {Scattering::Sampling::PerPixel, Scattering::Sampling::Epipolar}) {
    CountingBackend b;
    Scattering::CreateInfo info = countedInfo(b);
    info.blockingTimings = true;
    info.sampling = sampling;
    info.epipolarSampling.slices = 128;
    info.epipolarSampling.samples = 64;
    Scattering scattering(info);
    Scattering::FrameAttribs a = f.attribs(true, true);
    a.spotLights = std::span<const SpotLight>(&spot, 1);
    for (int frame = 0; frame < 2; ++frame) {
      b.reset();
      const Scattering::FrameResult r = scattering.run(a);
      checkStages(r);
      CHECK_FALSE(r.gpuTimes.has_value());
      CHECK(b.blockingTimers == int(r.stages.size()));
      CHECK(b.deferredTimers == 0);
      CHECK(b.gl.pendingTimers() == 0);
      REQUIRE(r.localLights.size() == 1);
      double lightSum = 0.0;
      std::string times;
      for (const Scattering::Stage& s : r.stages) {
        if (s.name.rfind("local light: ", 0) == 0) lightSum += s.gpuMilliseconds;
        times += s.name + " " + std::to_string(s.gpuMilliseconds) + " ms; ";
      }
      MESSAGE("GPU times in the frame: " << times);
      CHECK(r.localLights[0].gpuMilliseconds == doctest::Approx(lightSum));
      if (sampling == Scattering::Sampling::Epipolar) {
        CHECK(r.sampling.validSamples > 0); // read back: blockingTimings
        CHECK(r.sampling.marchedSamples > 0);
      }
    }
  }
}
