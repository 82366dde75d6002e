// RectifiedShadowPass (crep/pipeline/rectified_shadow_pass.h): the split pass an engine runs through a
// draw callback. It must give exactly the map of an independent per-split rendering (SceneRenderer::
// renderDepth: its own scissored clear and draw per viewport), stay exact when the callback clears (the
// scissor keeps the clear inside its split; the same loop without the scissor wipes the splits drawn
// before, which the negative control shows), leave the caller's raster state as it was, and reject bad
// input by name.
#include "common/error_checks.h"
#include "common/gl_fixture.h"

#include <crep/core/error.h>
#include <crep/pipeline/rectified_shadow_pass.h>
#include <crep/rectify/rectify.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <epoxy/gl.h>

#include <doctest/doctest.h>

#include <cstddef>
#include <string>

using namespace crep;
using crep::test::invalidParameter;
using namespace crep::scenes;

namespace {

constexpr int kW = 256, kH = 128;

int differingTexels(const Image& a, const Image& b) {
  int n = 0;
  for (std::size_t i = 0; i < a.data().size(); ++i)
    if (a.data()[i] != b.data()[i]) ++n;
  return n;
}

} // namespace

TEST_CASE("RectifiedShadowPass: the split pass equals per-split rendering, and a clear in the callback stays "
          "in its split") {
  CREP_REQUIRE_GL();
  const Scene scene = makeScene("colonnade", 16.0 / 9.0);
  RectifyOptions options;
  options.splits = 8;
  const Rectification r = rectify(scene.camera, scene.sun, options);
  REQUIRE(r.projective());
  SceneRenderer renderer(scene.mesh);

  // Reference: each split rendered on its own (renderDepth clears its viewport with a scissor and draws).
  const gl::Handle reference = createDepthTexture(kW, kH);
  for (int k = 0; k < r.splitCount(); ++k) {
    const SplitViewport v = r.splitViewport(k, kW, kH);
    renderer.renderDepth(r.splits[std::size_t(k)].rectClipFromWorld, reference.get(), 0, v.x, v.y, v.width,
                         v.height, {.depthClamp = true});
  }
  const Image expected = readDepthTexture(reference.get(), kW, kH);
  int covered = 0;
  for (float d : expected.data())
    covered += d < 1.0f ? 1 : 0;
  REQUIRE(covered > kW * kH / 10); // the casters cover the map: a wiped split would show

  RectifiedShadowPass pass({kW, kH});
  // (a) Into the pass's own D32F texture.
  pass.run({&r, [&](int, const glm::dmat4& m) { renderer.drawDepth(m); }});
  REQUIRE(pass.depthTexture() != 0);
  CHECK(differingTexels(readDepthTexture(pass.depthTexture(), kW, kH), expected) == 0);
  CHECK(pass.memoryBytes() == std::size_t(kW) * kH * 4);
  // (b) Into the caller's texture, with a clear of the whole depth buffer in the callback before each split:
  // the pass's scissor keeps it inside the split.
  const gl::Handle own = createDepthTexture(kW, kH);
  int calls = 0;
  pass.run({&r,
            [&](int split, const glm::dmat4& m) {
              CHECK(split == calls++);
              glClear(GL_DEPTH_BUFFER_BIT);
              renderer.drawDepth(m);
            },
            own.get()});
  CHECK(calls == r.splitCount());
  CHECK(differingTexels(readDepthTexture(own.get(), kW, kH), expected) == 0);

  // Negative control: the loop the former docs described (viewport, clear, draw per split, no scissor)
  // keeps only the last split.
  {
    const gl::Handle naive = createDepthTexture(kW, kH);
    const gl::Handle fb = gl::createFramebuffer();
    glNamedFramebufferTexture(fb.get(), GL_DEPTH_ATTACHMENT, naive.get(), 0);
    glNamedFramebufferDrawBuffer(fb.get(), GL_NONE);
    glBindFramebuffer(GL_FRAMEBUFFER, fb.get());
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glEnable(GL_DEPTH_CLAMP);
    for (int k = 0; k < r.splitCount(); ++k) {
      const SplitViewport v = r.splitViewport(k, kW, kH);
      glViewport(v.x, v.y, v.width, v.height);
      glClearDepth(1.0);
      glClear(GL_DEPTH_BUFFER_BIT);
      renderer.drawDepth(r.splits[std::size_t(k)].rectClipFromWorld);
    }
    glDisable(GL_DEPTH_CLAMP);
    glDisable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    const int wiped = differingTexels(readDepthTexture(naive.get(), kW, kH), expected);
    MESSAGE("per-split glClear without a scissor: " << wiped << " of " << kW * kH << " texels lost");
    CHECK(wiped > covered / 2);
  }
}

TEST_CASE("RectifiedShadowPass: restores the caller's raster state and names bad input") {
  CREP_REQUIRE_GL();
  const Scene scene = makeScene("boxes", 16.0 / 9.0);
  const Rectification r = rectify(scene.camera, scene.sun);
  REQUIRE(r.projective());
  SceneRenderer renderer(scene.mesh);
  RectifiedShadowPass pass({kW, kH});
  const auto draw = [&](int, const glm::dmat4& m) { renderer.drawDepth(m); };

  glViewport(3, 4, 50, 60);
  glScissor(1, 2, 30, 40);
  glDisable(GL_SCISSOR_TEST);
  glEnable(GL_CULL_FACE);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_FALSE);
  glDisable(GL_DEPTH_TEST);
  pass.run({&r, draw});
  GLint viewport[4], scissor[4], func = 0, framebuffer = -1;
  GLboolean mask = GL_TRUE;
  glGetIntegerv(GL_VIEWPORT, viewport);
  glGetIntegerv(GL_SCISSOR_BOX, scissor);
  glGetIntegerv(GL_DEPTH_FUNC, &func);
  glGetBooleanv(GL_DEPTH_WRITEMASK, &mask);
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &framebuffer);
  CHECK(viewport[0] == 3);
  CHECK(viewport[3] == 60);
  CHECK(scissor[0] == 1);
  CHECK(scissor[3] == 40);
  CHECK(glIsEnabled(GL_SCISSOR_TEST) == GL_FALSE);
  CHECK(glIsEnabled(GL_CULL_FACE) == GL_TRUE);
  CHECK(glIsEnabled(GL_DEPTH_TEST) == GL_FALSE);
  CHECK(glIsEnabled(GL_DEPTH_CLAMP) == GL_FALSE);
  CHECK(func == GL_GREATER);
  CHECK(mask == GL_FALSE);
  CHECK(framebuffer == 0);
  glDisable(GL_CULL_FACE);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);

  CHECK(invalidParameter([&] {
          pass.run({nullptr, draw});
        }) == "RectifiedShadowPass::FrameAttribs.rectification");
  CHECK(invalidParameter([&] { pass.run({&r, {}}); }) == "RectifiedShadowPass::FrameAttribs.drawCasters");
  Rectification fallback = r;
  fallback.status = RectifyStatus::Fallback;
  CHECK(invalidParameter([&] {
          pass.run({&fallback, draw});
        }) == "RectifiedShadowPass::FrameAttribs.rectification");
  Rectification layers = r;
  layers.layout = SplitLayout::Layers;
  CHECK(invalidParameter([&] {
          pass.run({&layers, draw});
        }) == "RectifiedShadowPass::FrameAttribs.rectification");
  const gl::Handle small = createDepthTexture(kW / 2, kH);
  CHECK(invalidParameter([&] {
          pass.run({&r, draw, small.get()});
        }) == "RectifiedShadowPass::FrameAttribs.depthTexture");
  const gl::Handle colour = gl::createTexture2D(GL_RGBA8, kW, kH);
  CHECK(invalidParameter([&] {
          pass.run({&r, draw, colour.get()});
        }) == "RectifiedShadowPass::FrameAttribs.depthTexture");
  RectifiedShadowPass odd({kW + 1, kH});
  CHECK(invalidParameter([&] { odd.run({&r, draw}); }) == "RectifiedShadowPass::CreateInfo.mapWidth");
  CHECK(invalidParameter([&] { RectifiedShadowPass({0, kH}); }).find("RectifiedShadowPass::CreateInfo") == 0);
}
