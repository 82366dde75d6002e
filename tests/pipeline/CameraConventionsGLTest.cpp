// Engine camera conventions end to end on the GPU (issue "engine conventions", part 2): the same scene and
// the same prefiltered basis evaluated through
//   (a) the tools' GL camera (symmetric, [-1, 1] clip depth, finite far, depth cleared to 1),
//   (b) the engine matrices of a reversed-Z, [0, 1] clip depth camera with an infinite far plane and
//       maxDistance = (a)'s far plane, its depth buffer holding near / Z (cleared to 0),
//   (c) (a) with a one-pixel jitter in x (an off-centre projection): its pixel x sees (a)'s pixel x + 1,
//   (d) the left half of (a)'s frustum (an asymmetric frustum, half the width): (a)'s left half.
// Every image must equal (a)'s pixels to float precision: the conventions change how rays and depths are
// read, never the scattering. The world march (crep::WorldMarchPass, march.glsl) is checked the same way
// for (b).
#include "support/gl_fixture.h"
#include "support/image_check.h"

#include "../prefilter/prefilter_gpu_util.h"

#include <crep/prefilter/gpu_pass.h>
#include <crep/scatter/gpu_world_march.h>

#include <epoxy/gl.h>

#include <doctest/doctest.h>

#include <cmath>
#include <limits>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kW = 96, kH = 54, kMap = 256;

gl::Handle uploadDepth(const Image& depth) {
  gl::Handle t = gl::createTexture2D(GL_R32F, depth.width(), depth.height());
  std::vector<float> row(static_cast<std::size_t>(depth.width()));
  for (int y = 0; y < depth.height(); ++y) {
    for (int x = 0; x < depth.width(); ++x)
      row[std::size_t(x)] = depth.at(x, y, 0);
    glTextureSubImage2D(t.get(), 0, 0, y, depth.width(), 1, GL_RED, GL_FLOAT, row.data());
  }
  return t;
}

Image evaluateWith(EvaluatePass& pass, const GpuScene& s, const PrefilterPass& prefilter,
                   const Camera& camera, const Image& depth) {
  const gl::Handle depthTexture = uploadDepth(depth);
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, depth.width(), depth.height());
  pass.run({depthTexture.get(), out.get(), &camera, &s.scene.sun, &s.scene.medium, s.layout.get(),
            prefilter.filteredBasis()});
  return readRgbaTexture(out.get(), depth.width(), depth.height());
}

/// Largest |a - b| over RGB of a's pixel (x, y) and b's pixel (x + dx, y), for x in [0, width), relative to
/// b's peak.
double worstRelative(const Image& a, const Image& b, int dx, int width) {
  double worst = 0.0, peak = 0.0;
  for (float v : b.data())
    peak = std::max(peak, double(std::abs(v)));
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c)
        worst = std::max(worst, double(std::abs(a.at(x, y, c) - b.at(x + dx, y, c))));
  return worst / peak;
}

} // namespace

TEST_CASE("camera conventions GL: reversed-Z infinite, jittered and asymmetric cameras give the same "
          "scattering") {
  CREP_REQUIRE_GL();
  const GpuScene s = renderGpuScene("colonnade", kMap, kMap, 4, kW, kH);
  const Camera& gl = s.scene.camera;
  PrefilterPass::CreateInfo pi;
  pi.mapWidth = kMap;
  pi.mapHeight = kMap;
  PrefilterPass prefilter(pi);
  prefilter.run({s.mapTexture.get(), s.layout.get(), &s.scene.medium});
  EvaluatePass evaluate({});
  const Image reference = evaluateWith(evaluate, s, prefilter, gl, s.cameraDepth);

  // (b) reversed-Z, [0, 1], infinite far, integrated to the GL camera's far plane.
  glm::dmat4 proj(0.0);
  const double ty = std::tan(0.5 * gl.fovY());
  proj[0][0] = 1.0 / (ty * gl.aspect());
  proj[1][1] = 1.0 / ty;
  proj[2][3] = -1.0;
  proj[3][2] = gl.near();
  const Camera reversed = Camera::fromMatrices(gl.viewFromWorld(), proj, ClipDepth::ZeroToOne, gl.far());
  REQUIRE(reversed.reversedZ());
  Image reversedDepth(kW, kH, 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const double d = s.cameraDepth.at(x, y, 0);
      reversedDepth.at(x, y, 0) =
          d >= 1.0 ? 0.0f : static_cast<float>(reversed.depthBufferValue(gl.linearDepth(d)));
    }
  const Image fromReversed = evaluateWith(evaluate, s, prefilter, reversed, reversedDepth);
  const double reversedError = worstRelative(fromReversed, reference, 0, kW);
  MESSAGE("reversed-Z infinite [0, 1] vs GL camera: max |difference| " << reversedError << " of the peak");
  CHECK(reversedError < 2e-5);

  // (c) a one-pixel jitter to the right: NDC x of the jittered camera = NDC x + 2 / W of the GL one.
  glm::dmat4 jittered = gl.clipFromView();
  jittered[2][0] += 2.0 / kW;
  const Camera jitter = Camera::fromMatrices(gl.viewFromWorld(), jittered);
  Image shiftedDepth(kW, kH, 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      shiftedDepth.at(x, y, 0) = s.cameraDepth.at(std::min(x + 1, kW - 1), y, 0);
  const Image fromJitter = evaluateWith(evaluate, s, prefilter, jitter, shiftedDepth);
  const double jitterError = worstRelative(fromJitter, reference, 1, kW - 1);
  MESSAGE("one-pixel jitter, undone: max |difference| " << jitterError << " of the peak");
  CHECK(jitterError < 2e-5);

  // (d) the left half of the frustum at half the width.
  glm::dmat4 half = gl.clipFromView();
  const double tx = ty * gl.aspect();
  half[0][0] = 2.0 / tx;
  half[2][0] = -1.0;
  const Camera left = Camera::fromMatrices(gl.viewFromWorld(), half);
  Image leftDepth(kW / 2, kH, 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW / 2; ++x)
      leftDepth.at(x, y, 0) = s.cameraDepth.at(x, y, 0);
  const Image fromLeft = evaluateWith(evaluate, s, prefilter, left, leftDepth);
  const double leftError = worstRelative(fromLeft, reference, 0, kW / 2);
  MESSAGE("asymmetric left half vs the symmetric frustum covering it: max |difference| " << leftError);
  CHECK(leftError < 2e-5);

  // The depth texture formats the README lists: the scene's depth rendered into D24S8 and D24 textures (read
  // as depth through a sampler2D) gives the D32F result up to the 24-bit depth quantization.
  for (const GLenum format : {GLenum(GL_DEPTH24_STENCIL8), GLenum(GL_DEPTH_COMPONENT24)}) {
    const gl::Handle depth24 = gl::createTexture2D(format, kW, kH);
    scenes::SceneRenderer renderer(s.scene.mesh);
    renderer.renderDepth(gl.clipFromWorld(), depth24.get(), 0, 0, 0, kW, kH);
    const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kW, kH);
    evaluate.run({depth24.get(), out.get(), &gl, &s.scene.sun, &s.scene.medium, s.layout.get(),
                  prefilter.filteredBasis()});
    const double error = worstRelative(readRgbaTexture(out.get(), kW, kH), reference, 0, kW);
    MESSAGE((format == GL_DEPTH24_STENCIL8 ? std::string("D24S8") : std::string("D24"))
            << " camera depth vs D32F: max |difference| " << error << " of the peak");
    CHECK(error < 2e-3);
  }

  // The world-space march reads the reversed depth buffer the same way (march.glsl).
  WorldMarchPass march({});
  const auto marchWith = [&](const Camera& camera, const Image& depth) {
    const gl::Handle depthTexture = uploadDepth(depth);
    const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kW, kH);
    const glm::dmat4 light = orthographicLightClipFromWorld(s.scene.sun, gl.frustumCorners());
    const gl::Handle shadow = scenes::createDepthTexture(512, 512);
    scenes::SceneRenderer renderer(s.scene.mesh);
    renderer.renderDepth(light, shadow.get(), 0, 0, 0, 512, 512, {.depthClamp = true});
    WorldMarchPass::FrameAttribs b;
    b.camera = &camera;
    b.light = &s.scene.sun;
    b.medium = &s.scene.medium;
    b.cameraDepth = depthTexture.get();
    b.width = kW;
    b.height = kH;
    b.shadowMap = shadow.get();
    b.shadowWidth = 512;
    b.shadowHeight = 512;
    b.lightClipFromWorld = light;
    b.output = out.get();
    march.run(b);
    return readRgbaTexture(out.get(), kW, kH);
  };
  const double marchError =
      worstRelative(marchWith(reversed, reversedDepth), marchWith(gl, s.cameraDepth), 0, kW);
  MESSAGE("world march, reversed-Z infinite vs GL camera: max |difference| " << marchError << " of the peak");
  CHECK(marchError < 2e-5);
}
