// crep::Scattering when a frame fails, and inputs checked at the door. Whatever run() throws (the caster
// callback throws or raises a GL error, a wrong texture, a call from inside its own callback), afterwards:
// no GL_TIME_ELAPSED query is active, no GL error is pending, the caller's raster state is as it was, the
// same object's next frame equals the frame before the failure bit for bit, and a new object works. A
// moved-from object is valid but empty. Textures of the wrong target, format class, or aliasing the output
// are named; a light texture's non-finite texels read as 0 (the GPU's rule), and one scaled by 1e6 scales
// the prefiltered frame by 1e6 (no half-float clipping).
#include "common/gl_fixture.h"
#include "common/gl_util.h"
#include "pipeline/scattering_frame.h"

#include <crep/core/error.h>
#include <crep/gpu/gl_state.h>
#include <crep/pipeline/rectified_shadow_pass.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/gpu_light_texture.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

using namespace crep;
using namespace crep::test;

namespace {

/// The parameter an InvalidArgument names, the message of any other crep::Error, or "no exception".
std::string failureOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.parameter();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no exception";
}

bool sameBits(const Image& a, const Image& b) {
  return a.data().size() == b.data().size() &&
         std::memcmp(a.data().data(), b.data().data(), a.data().size_bytes()) == 0;
}

/// After a failed run(): no query active, no error pending, the raster state as `before`.
void checkContextClean(const gl::RasterState& before) {
  GLint query = -1;
  glGetQueryiv(GL_TIME_ELAPSED, GL_CURRENT_QUERY, &query);
  CHECK(query == 0);
  CHECK(gl::drainErrors().empty());
  const std::string changed = before.firstDifference(gl::RasterState::read());
  CHECK_MESSAGE(changed.empty(), changed);
}

/// GL errors the test provokes on purpose are expected, not failures of the test case.
struct ExpectGlErrors {
  ScopedGlDebugCallback quiet{[](const GlDebugMessage&) {}};
};

/// A light texture over the colonnade's sun: left half warm, right half cool (8 x 8).
Image windowTexture(float scale) {
  Image t(8, 8, 4, 1.0f);
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i)
      for (int c = 0; c < 3; ++c)
        t.at(i, j, c) = scale * (i < 4 ? 1.0f - 0.3f * float(c) : 0.2f + 0.4f * float(c));
  return t;
}

} // namespace

TEST_CASE("Scattering failure guarantee: a callback that throws or raises a GL error, and a call from inside "
          "drawCasters, leave the context clean and the next frames right") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  Scattering scattering(smallInfo());
  for (const bool sunInView : {false, true}) {
    CAPTURE(sunInView);
    if (sunInView) f.lightToward(1.0, 0.25, 0.2); // epipolar: its standard map drawn with the callback
    scattering.run(f.attribs(true, false));
    const Image good = f.read();
    const gl::RasterState before = gl::RasterState::read();

    Scattering::FrameAttribs throwing = f.attribs(true, false);
    throwing.drawCasters = [](const glm::dmat4&) {
      throw std::runtime_error("engine: out of vertex memory");
    };
    CHECK(failureOf([&] { scattering.run(throwing); }) == "engine: out of vertex memory");
    checkContextClean(before);
    scattering.run(f.attribs(true, false));
    CHECK(sameBits(f.read(), good));

    {
      const ExpectGlErrors expected;
      Scattering::FrameAttribs erring = f.attribs(true, false);
      erring.drawCasters = [&](const glm::dmat4& m) {
        glBindTexture(GL_TEXTURE_2D, 0x7fffffffu); // not a name: GL_INVALID_OPERATION
        f.renderer.drawDepth(m);
      };
      const std::string message = failureOf([&] { scattering.run(erring); });
      MESSAGE(message);
      CHECK(message.find("GL_INVALID_OPERATION") != std::string::npos);
    }
    checkContextClean(before);
    scattering.run(f.attribs(true, false));
    CHECK(sameBits(f.read(), good));

    Scattering::FrameAttribs reentrant = f.attribs(true, false);
    reentrant.drawCasters = [&](const glm::dmat4&) { scattering.run(f.attribs(true, false)); };
    CHECK(failureOf([&] { scattering.run(reentrant); }) == "Scattering::run");
    checkContextClean(before);
    scattering.run(f.attribs(true, false));
    CHECK(sameBits(f.read(), good));

    Scattering fresh(smallInfo());
    fresh.run(f.attribs(true, false));
    CHECK(sameBits(f.read(), good));
  }

  // The caller's own pending error is named, not blamed on the library, and the frame is not run.
  {
    const ExpectGlErrors expected;
    glBindTexture(GL_TEXTURE_2D, 0x7fffffffu);
  }
  const std::string pending = failureOf([&] { scattering.run(f.attribs(true, false)); });
  MESSAGE(pending);
  CHECK(pending.find("pending before the call") != std::string::npos);
  CHECK(pending.find("GL_INVALID_OPERATION") != std::string::npos);
  CHECK_NOTHROW(scattering.run(f.attribs(true, false)));
}

TEST_CASE("Scattering failure guarantee: a moved-from object is valid but empty") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  Scattering a(smallInfo());
  a.run(f.attribs(true, false));
  const Image good = f.read();
  const std::size_t bytes = a.memoryBytes();
  Scattering b(std::move(a));
  CHECK(failureOf([&] { a.run(f.attribs(true, false)); }) == "Scattering"); // NOLINT(bugprone-use-after-move)
  CHECK(a.memoryBytes() == 0);                                              // NOLINT(bugprone-use-after-move)
  CHECK(a.createInfo().width == Scattering::CreateInfo{}.width);            // NOLINT(bugprone-use-after-move)
  CHECK(b.memoryBytes() == bytes);
  b.run(f.attribs(true, false));
  CHECK(sameBits(f.read(), good));
  a = std::move(b);
  a.run(f.attribs(true, false));
  CHECK(sameBits(f.read(), good));

  RectifiedShadowPass pass({256, 128});
  RectifiedShadowPass moved(std::move(pass));
  const Rectification r = rectify(f.scene.camera, f.scene.sun);
  CHECK(failureOf([&] {
          pass.run({&r, [](int, const glm::dmat4&) {}}); // NOLINT(bugprone-use-after-move)
        }) == "RectifiedShadowPass");
  PrefilterPass::CreateInfo prefilterInfo;
  prefilterInfo.mapWidth = prefilterInfo.mapHeight = 64;
  PrefilterPass prefilter(prefilterInfo);
  PrefilterPass prefilter2(std::move(prefilter));
  CHECK(prefilter.memoryBytes() == 0); // NOLINT(bugprone-use-after-move)
  CHECK(failureOf([&] { prefilter.run({}); }) == "PrefilterPass");
  EvaluatePass evaluate({});
  EvaluatePass evaluate2(std::move(evaluate));
  CHECK(evaluate.memoryBytes() == 0); // NOLINT(bugprone-use-after-move)
  CHECK(failureOf([&] { evaluate.run({}); }) == "EvaluatePass");
}

TEST_CASE("Scattering inputs at the door: target, format class and aliasing of every texture are named") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  Scattering scattering(smallInfo());
  scattering.run(f.attribs(true, false));
  const Image good = f.read();
  const gl::RasterState before = gl::RasterState::read();
  const auto named = [&](Scattering::FrameAttribs a) { return failureOf([&] { scattering.run(a); }); };

  // Targets: 3D, array and multisample textures as the output or the camera depth.
  gl::Handle volume = gl::createTexture(GL_TEXTURE_3D), array = gl::createTexture(GL_TEXTURE_2D_ARRAY),
             multisample = gl::createTexture(GL_TEXTURE_2D_MULTISAMPLE);
  glTextureStorage3D(volume.get(), 1, GL_RGBA32F, kWidth, kHeight, 2);
  glTextureStorage3D(array.get(), 1, GL_RGBA32F, kWidth, kHeight, 2);
  glTextureStorage2DMultisample(multisample.get(), 4, GL_DEPTH_COMPONENT32F, kWidth, kHeight, GL_TRUE);
  for (const GLuint t : {volume.get(), array.get()}) {
    Scattering::FrameAttribs a = f.attribs(true, false);
    a.output = t;
    CHECK(named(a) == "Scattering::FrameAttribs.output");
    a = f.attribs(true, false);
    a.cameraDepth = t;
    CHECK(named(a) == "Scattering::FrameAttribs.cameraDepth");
  }
  Scattering::FrameAttribs ms = f.attribs(true, false);
  ms.cameraDepth = multisample.get();
  CHECK(named(ms) == "Scattering::FrameAttribs.cameraDepth");

  // Camera depth formats read as garbage: colour, half float, stencil; a depth-stencil texture sampled as
  // stencil.
  for (const GLenum format :
       {GLenum(GL_RGBA8), GLenum(GL_RGBA32F), GLenum(GL_R16F), GLenum(GL_STENCIL_INDEX8)}) {
    CAPTURE(format);
    const gl::Handle wrong = gl::createTexture2D(format, kWidth, kHeight);
    Scattering::FrameAttribs a = f.attribs(true, false);
    a.cameraDepth = wrong.get();
    CHECK(named(a) == "Scattering::FrameAttribs.cameraDepth");
  }
  const gl::Handle stencilMode = gl::createTexture2D(GL_DEPTH24_STENCIL8, kWidth, kHeight);
  glTextureParameteri(stencilMode.get(), GL_DEPTH_STENCIL_TEXTURE_MODE, GL_STENCIL_INDEX);
  Scattering::FrameAttribs stencil = f.attribs(true, false);
  stencil.cameraDepth = stencilMode.get();
  const std::string stencilMessage = failureOf([&] {
    try {
      scattering.run(stencil);
    } catch (const InvalidArgument& e) {
      throw std::runtime_error(e.parameter() + ": " + e.what());
    }
  });
  CHECK(stencilMessage.find("Scattering::FrameAttribs.cameraDepth") == 0);
  CHECK(stencilMessage.find("GL_DEPTH_STENCIL_TEXTURE_MODE") != std::string::npos);

  // The output as an input.
  Scattering::FrameAttribs alias = f.attribs(true, false);
  alias.cameraDepth = alias.output;
  CHECK(named(alias) == "Scattering::FrameAttribs.output");

  // A colour shadow map (fallback frame with the engine's map).
  const gl::Handle colourMap = gl::createTexture2D(GL_RGBA8, 256, 256);
  Scattering::ShadowMap wrongMap = f.shadow;
  wrongMap.texture = colourMap.get();
  Scattering::FrameAttribs map = f.attribs(false, true);
  map.shadowMap = &wrongMap;
  CHECK(named(map) == "Scattering::FrameAttribs.shadowMap.texture");

  // Light textures of a depth or an integer format.
  for (const GLenum format : {GLenum(GL_DEPTH_COMPONENT32F), GLenum(GL_RGBA32UI)}) {
    CAPTURE(format);
    const gl::Handle wrong = gl::createTexture2D(format, 8, 8);
    const GpuLightTexture texture{wrong.get(), sunWindowMatrix(f)};
    Scattering::FrameAttribs a = f.attribs(true, false);
    a.lightTexture = &texture;
    CHECK(named(a) == "Scattering::FrameAttribs.lightTexture.texture");
  }

  // None of it left the context or the object unusable.
  checkContextClean(before);
  scattering.run(f.attribs(true, false));
  CHECK(sameBits(f.read(), good));
}

TEST_CASE(
    "Scattering light textures on the GPU: non-finite texels read as 0, and 1e6-bright textures are not "
    "clipped") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  Scattering::CreateInfo info = smallInfo();
  info.mapSize = 512;
  Scattering scattering(info);
  const auto frame = [&](const Image& texels) {
    const gl::Handle texture = uploadRgba(texels);
    const GpuLightTexture light{texture.get(), sunWindowMatrix(f)};
    Scattering::FrameAttribs a = f.attribs(true, false);
    a.lightTexture = &light;
    scattering.run(a);
    return f.read();
  };

  // NaN, +Inf and negative texels in the texture: the frame equals the one with 0 there, and is finite.
  Image poisoned = windowTexture(1.0f), zeroed = windowTexture(1.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const std::pair<int, int> bad[] = {{1, 1}, {5, 2}, {6, 6}};
  const float values[] = {nan, inf, -3.0f};
  for (int k = 0; k < 3; ++k)
    for (int c = 0; c < 3; ++c) {
      poisoned.at(bad[k].first, bad[k].second, c) = values[k];
      zeroed.at(bad[k].first, bad[k].second, c) = 0.0f;
    }
  const Image fromPoisoned = frame(poisoned), fromZeroed = frame(zeroed);
  int nonFinite = 0;
  for (float v : fromPoisoned.data())
    nonFinite += !std::isfinite(v);
  CHECK(nonFinite == 0);
  CHECK(sameBits(fromPoisoned, fromZeroed));

  // Scaled by 1e6 (beyond binary16's 65504): the in-scattering scales by 1e6.
  const Image dim = frame(windowTexture(1.0f)), bright = frame(windowTexture(1e6f));
  double worst = 0.0, peak = 0.0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      for (int c = 0; c < 3; ++c) {
        peak = std::max(peak, 1e6 * dim.at(x, y, c));
        worst = std::max(worst, std::abs(double(bright.at(x, y, c)) - 1e6 * dim.at(x, y, c)));
      }
  MESSAGE("texture x 1e6: max |bright - 1e6 dim| = " << worst / peak << " of the peak " << peak);
  CHECK(peak > 0.0);
  CHECK(worst <= 1e-5 * peak);
}
