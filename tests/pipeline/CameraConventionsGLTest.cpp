// Engine camera conventions end to end on the GPU (on the CPU: Camera::fromMatrices in
// tests/core/CameraTest.cpp): the same scene and the same prefiltered basis evaluated through
//   (a) the tools' GL camera (symmetric, [-1, 1] clip depth, finite far, depth cleared to 1),
//   (b) the engine matrices of a reversed-Z, [0, 1] clip depth camera with an infinite far plane and
//       maxDistance = (a)'s far plane, its depth buffer holding near / Z (cleared to 0),
//   (c) (a) with a one-pixel jitter in x (an off-centre projection): its pixel x sees (a)'s pixel x + 1,
//   (d) the left half of (a)'s frustum (an asymmetric frustum, half the width): (a)'s left half.
// Every image must equal (a)'s pixels to float precision: the conventions change how rays and depths are
// read, never the scattering. The world march (crep::WorldMarchPass, march.glsl) is checked the same way
// for (b). Last, (d) on an epipolar frame (the sun in view) through crep::Scattering, against the
// world-space reference.
#include "common/gl_fixture.h"
#include "common/image_check.h"

#include "common/prefilter_gpu.h"
#include "pipeline/scattering_frame.h"

#include <crep/pipeline/scattering.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/scatter/gpu_world_march.h>

#include <epoxy/gl.h>

#include <doctest/doctest.h>

#include <cmath>
#include <limits>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kW = 96, kH = 54, kMapSize = 256;

Image evaluateWith(EvaluatePass& pass, const GpuScene& s, const PrefilterPass& prefilter,
                   const Camera& camera, const Image& depth) {
  const gl::Handle depthTexture = uploadR32F(depth);
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
  const GpuScene s = renderGpuScene("colonnade", kMapSize, kMapSize, 4, kW, kH);
  const Camera& gl = s.scene.camera;
  PrefilterPass::CreateInfo pi;
  pi.mapWidth = kMapSize;
  pi.mapHeight = kMapSize;
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
    const gl::Handle depthTexture = uploadR32F(depth);
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
    b.shadowMap = shadow.get();
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

namespace {

/// Crops the left `width` columns of an image.
Image leftColumns(const Image& image, int width) {
  Image out(width, image.height(), image.channels());
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < image.channels(); ++c)
        out.at(x, y, c) = image.at(x, y, c);
  return out;
}

/// One crep::Scattering frame (its own standard shadow map through drawCasters) and the world-space
/// reference march of the same camera against that map.
struct AsymmetricFrame {
  Scattering::FrameResult result;
  Image ours, reference;
  Image sceneMapMarch; ///< the world march against one 1024^2 map fitted to the scene (camera-independent)
  Image sameMapMarch;  ///< the brute-force march over the frame's own rectified map
};

AsymmetricFrame scatterAndReference(const scenes::Scene& scene, scenes::SceneRenderer& renderer,
                                    const Camera& camera, const Image& cameraDepth) {
  const int width = cameraDepth.width(), height = cameraDepth.height();
  const gl::Handle depth = uploadR32F(cameraDepth);
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, width, height);
  Scattering::CreateInfo info;
  info.width = width;
  info.height = height;
  info.mapSize = 1024; // as the sun-in-view tests: the epipolar slices resolve the shafts near the sun
  info.ownShadowMapSize = 1024;
  Scattering scattering(info);
  Scattering::FrameAttribs a;
  a.camera = &camera;
  a.light = &scene.sun;
  a.medium = &scene.medium;
  a.cameraDepth = depth.get();
  a.output = out.get();
  a.drawCasters = [&](const glm::dmat4& clipFromWorld) { renderer.drawDepth(clipFromWorld); };
  AsymmetricFrame f;
  f.result = scattering.run(a);
  f.ours = readRgbaTexture(out.get(), width, height);
  {
    const Scattering::FrameResult::RectifiedMapView& m = f.result.rectifiedMap;
    RectifiedMarchPass brute({m.width, m.height, RectifiedMarchPass::Mode::BruteForce});
    const gl::Handle marched = gl::createTexture2D(GL_RGBA32F, width, height);
    RectifiedMarchPass::FrameAttribs c;
    c.layout = m.layout.get();
    c.camera = &camera;
    c.light = &scene.sun;
    c.medium = &scene.medium;
    c.cameraDepth = depth.get();
    c.rectifiedDepth = m.texture;
    c.output = marched.get();
    brute.run(c);
    f.sameMapMarch = readRgbaTexture(marched.get(), width, height);
  }

  // The reference marches the standard shadow map the frame used (epipolar frames: the one Scattering
  // rendered with drawCasters, fitted to this camera's frustum): near the sun, view rays run along light
  // rays and a different map's texels would change the answer itself.
  REQUIRE(f.result.shadowMap.texture != 0);
  const gl::Handle ref = gl::createTexture2D(GL_RGBA32F, width, height);
  static WorldMarchPass march({{.steps = 256, .refinements = 12}});
  WorldMarchPass::FrameAttribs b;
  b.camera = &camera;
  b.light = &scene.sun;
  b.medium = &scene.medium;
  b.cameraDepth = depth.get();
  b.shadowMap = f.result.shadowMap.texture;
  b.lightClipFromWorld = f.result.shadowMap.lightClipFromWorld;
  b.bias = f.result.shadowMap.bias;
  b.output = ref.get();
  march.run(b);
  f.reference = readRgbaTexture(ref.get(), width, height);
  const glm::dmat4 light = scenes::standardLightClipFromWorld(scene.sun, scene.boundsMin, scene.boundsMax);
  const gl::Handle shadow = scenes::createDepthTexture(1024, 1024);
  renderer.renderDepth(light, shadow.get(), 0, 0, 0, 1024, 1024, {.depthClamp = true});
  b.shadowMap = shadow.get();
  b.lightClipFromWorld = light;
  b.bias = 1e-4;
  march.run(b);
  f.sceneMapMarch = readRgbaTexture(ref.get(), width, height);
  return f;
}

} // namespace

TEST_CASE("camera conventions GL: an asymmetric camera on an epipolar frame (sun in view) through "
          "crep::Scattering") {
  CREP_REQUIRE_GL();
  constexpr int W = 160, H = 90;
  scenes::Scene scene = scenes::makeScene("forest", double(W) / H);
  const Camera gl = scene.camera;
  // The sun in the left half of the view, toward the camera: the rectification is not projective.
  scene.sun = DirectionalLight(-gl.rayDirection(-0.45, 0.35), scene.sun.irradiance());
  scenes::SceneRenderer renderer(scene.mesh);
  // The left half of the frustum, at half the width: pixel x of it is pixel x of the full camera.
  glm::dmat4 half = gl.clipFromView();
  half[0][0] = 2.0 / (std::tan(0.5 * gl.fovY()) * gl.aspect());
  half[2][0] = -1.0;
  const Camera left = Camera::fromMatrices(gl.viewFromWorld(), half);
  REQUIRE_FALSE(left.symmetric());

  // One depth buffer: the asymmetric camera reads the full camera's left half (rasterizing it separately
  // would move silhouette pixels by float rounding).
  const gl::Handle depth = scenes::createDepthTexture(W, H);
  renderer.renderDepth(gl.clipFromWorld(), depth.get(), 0, 0, 0, W, H);
  const Image fullDepth = gl::readTexture(depth.get(), W, H, gl::TexelData::Depth);
  const AsymmetricFrame full = scatterAndReference(scene, renderer, gl, fullDepth);
  const AsymmetricFrame asym = scatterAndReference(scene, renderer, left, leftColumns(fullDepth, W / 2));
  REQUIRE(full.result.layout == Scattering::Layout::Epipolar);
  REQUIRE(asym.result.layout == Scattering::Layout::Epipolar);

  // The reference march reads the asymmetric camera exactly: its pixels are the full camera's left half.
  const double marchError = worstRelative(asym.sceneMapMarch, full.sceneMapMarch, 0, W / 2);
  MESSAGE("world march, asymmetric left half vs the full frustum: max |difference| " << marchError);
  CHECK(marchError < 2e-5);

  // The prefiltered frame: the epipolar layout of the asymmetric camera is built on the symmetric frustum
  // covering it, so its slices differ from the full camera's; it must be as accurate on its pixels.
  const ImageMetrics mFull = rgbMetrics(leftColumns(full.ours, W / 2), leftColumns(full.reference, W / 2));
  const ImageMetrics mAsym = rgbMetrics(asym.ours, asym.reference);
  report("full camera, left half: prefiltered (epipolar) vs world-space reference", mFull);
  report("asymmetric left-half camera: prefiltered (epipolar) vs world-space reference", mAsym);
  CHECK(mAsym.nanCount == 0);
  CHECK(mAsym.relativeRmse < 0.02);
  CHECK(mAsym.relativeRmse < 1.5 * mFull.relativeRmse + 0.002);
  // The epipole block (the min/max tree march over the frame's own epipolar map) sits on the sun's pixel of
  // the asymmetric image: inside it the frame is the exact march over that map (the brute-force march gives
  // the same visibility; sections summed in another order).
  REQUIRE(asym.result.epipoleBlockRadius > 0.0);
  const glm::dvec4 clip = left.clipFromWorld() * glm::dvec4(left.position() - scene.sun.direction(), 1.0);
  const glm::dvec2 sunPixel((clip.x / clip.w * 0.5 + 0.5) * (W / 2), (clip.y / clip.w * 0.5 + 0.5) * H);
  const double inside = 0.9 * asym.result.epipoleBlockRadius / std::hypot(double(W / 2), double(H));
  const double disc = discRelativeRmse(asym.ours, asym.sameMapMarch, sunPixel, inside);
  MESSAGE("asymmetric camera, sun at pixel (" << sunPixel.x << ", " << sunPixel.y << "), block radius "
                                              << asym.result.epipoleBlockRadius
                                              << " px: relative RMSE against the march over the same map "
                                                 "inside the block "
                                              << disc);
  CHECK(disc >= 0.0);
  CHECK(disc < 1e-4);
}
