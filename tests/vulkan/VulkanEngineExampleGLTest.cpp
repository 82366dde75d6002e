// The Vulkan engine example (examples/vulkan_engine/) driven as crep-vulkan-engine drives it, on built-in
// scenes: its own instance (validation with synchronization validation), device and depth pre-pass, per
// frame crepuscular's plan (Scattering::plan, ClipConvention::Vulkan) whose shadow maps the engine
// rasterizes with its own graphics pipeline on lavapipe (the plan's matrices as a push constant, its
// viewports and scissors), crepuscular recorded into each frame's command buffer, one submission per frame,
// three in flight, a strafing camera. Checked against the GL front door (llvmpipe) drawing the same casters
// with drawCasters (the scene's mesh through crep_scenes' renderer), the same camera and lights, and the
// engine's camera depth uploaded to GL, so that only the shadow maps' path differs: relative RMSE of the
// in-scattering (RGB) and of the transmittance (A) at most 1e-5, for forest (projective: the plan's
// rectified map; colonnade likewise), sunset (sun in view: epipolar, the plan's standard map) and
// colonnade-night (three spots).
// Also: the library submits nothing and waits for nothing while the frames are recorded (counted through
// the loader it was given), and the layer says nothing. And one plan pass rasterized by the engine in
// Vulkan's clip convention against GL rasterizing the same pass in OpenGL's.
#include "common/gl_fixture.h"
#include "common/vulkan_fixture.h"

#include <app.h>
#include <scene_world.h>

#include <crep/gpu/gl_backend.h>
#include <crep/pipeline/scattering.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>
#include <crep/support/image_compare.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

using namespace crep;
using crep::test::LoaderSpy;

namespace {

constexpr std::uint32_t kWidth = 320, kHeight = 180;
constexpr int kMapSize = 512, kOwnShadowMapSize = 1024;
constexpr int kFrames = 10;

Image imageOf(const std::vector<float>& texels, int width, int height, int channels) {
  Image image(width, height, channels);
  REQUIRE(texels.size() == image.data().size());
  std::copy(texels.begin(), texels.end(), image.data().begin());
  return image;
}

Scattering::CreateInfo smallSettings() {
  Scattering::CreateInfo settings;
  // The 1e-5 goal between the backends (docs/BACKENDS.md) holds for the Fourier series, which is smooth in
  // the maps' values. The exact reconstruction tests each texel's depth against the ray's, so the maps' float
  // differences between the rasterizers flip a few texels: 1.6e-5 (colonnade) and 1.9e-5 (forest) there,
  // measured with the default settings (docs/BACKENDS.md).
  settings.prefilter.reconstruction = VisibilityReconstruction::Fourier;
  settings.mapSize = kMapSize;
  settings.ownShadowMapSize = kOwnShadowMapSize;
  return settings;
}

/// Texels of two depth maps that differ, by how many units in the last place (both are non-negative floats:
/// their bit patterns order as the values do), and where only one holds the clear value (coverage).
struct DepthDiff {
  long long differing = 0, over1e5 = 0, coverage = 0;
  std::int64_t medianUlps = 0, p999Ulps = 0, maxUlps = 0;
  double maxAbs = 0.0;
};
DepthDiff depthDiff(const std::vector<float>& a, const std::vector<float>& b, float clear = 1.0f) {
  REQUIRE(a.size() == b.size());
  DepthDiff d;
  std::vector<std::int64_t> ulps;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (std::bit_cast<std::uint32_t>(a[k]) == std::bit_cast<std::uint32_t>(b[k])) continue;
    ++d.differing;
    ulps.push_back(std::abs(std::int64_t(std::bit_cast<std::int32_t>(a[k])) -
                            std::int64_t(std::bit_cast<std::int32_t>(b[k]))));
    const double abs = std::abs(double(a[k]) - double(b[k]));
    d.maxAbs = std::max(d.maxAbs, abs);
    d.over1e5 += abs > 1e-5 ? 1 : 0;
    d.coverage += (a[k] == clear) != (b[k] == clear) ? 1 : 0;
  }
  std::sort(ulps.begin(), ulps.end());
  if (!ulps.empty()) {
    d.medianUlps = ulps[ulps.size() / 2];
    d.p999Ulps = ulps[ulps.size() * 999 / 1000];
    d.maxUlps = ulps.back();
  }
  return d;
}

/// GL's rasterization of a plan pass in ClipConvention::OpenGL, as the front door's drawCasters path draws
/// it: the target cleared once, then per split its viewport and scissor box, depth clamp, LESS, no culling.
std::vector<float> glPassMap(scenes::SceneRenderer& renderer, const ShadowPass& pass) {
  const gl::Handle texture = scenes::createDepthTexture(pass.width, pass.height);
  GLuint framebuffer = 0;
  glCreateFramebuffers(1, &framebuffer);
  glNamedFramebufferTexture(framebuffer, GL_DEPTH_ATTACHMENT, texture.get(), 0);
  glNamedFramebufferDrawBuffer(framebuffer, GL_NONE);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  const float clear = static_cast<float>(pass.clearDepth);
  glClearNamedFramebufferfv(framebuffer, GL_DEPTH, 0, &clear);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(pass.compare == DepthCompare::Less ? GL_LESS : GL_GREATER);
  glDepthMask(GL_TRUE);
  if (pass.depthClamp) glEnable(GL_DEPTH_CLAMP);
  glDisable(GL_CULL_FACE);
  glEnable(GL_SCISSOR_TEST);
  for (const ShadowPass::Split& s : pass.splits) {
    glViewport(s.viewport.x, s.viewport.y, s.viewport.width, s.viewport.height);
    glScissor(s.scissor.x, s.scissor.y, s.scissor.width, s.scissor.height);
    renderer.drawDepth(s.clipFromWorld);
  }
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_DEPTH_CLAMP);
  glDisable(GL_DEPTH_TEST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDeleteFramebuffers(1, &framebuffer);
  const Image map = scenes::readDepthTexture(texture.get(), pass.width, pass.height);
  return {map.data().begin(), map.data().end()};
}

} // namespace

TEST_CASE("Vulkan engine example: its frames, the plan's maps rasterized by the engine, equal the GL front "
          "door drawing the same casters, with no submission or wait by the library and no validation "
          "message") {
  CREP_REQUIRE_GL();
  for (const char* name : {"forest", "colonnade", "sunset", "colonnade-night"}) {
    const std::string sceneName = name;
    CAPTURE(sceneName);
    scenes::Scene scene = scenes::makeScene(name, double(kWidth) / kHeight);
    REQUIRE(scene.pointLights.empty()); // the example's world has a sun and spots
    const Scattering::CreateInfo settings = smallSettings();

    // The engine's frames, crepuscular's Vulkan calls counted through its loader.
    LoaderSpy::reset(vkGetInstanceProcAddr);
    vkengine::App app(vkengine::worldOf(scene), {.width = kWidth,
                                                 .height = kHeight,
                                                 .engine = {.framesInFlight = 3, .validation = true},
                                                 .settings = settings,
                                                 .loader = &LoaderSpy::getInstanceProcAddr});
    const int setupStalls = LoaderSpy::stalls();
    Scattering::FrameResult last;
    for (int i = 0; i < kFrames; ++i)
      last = app.frame(i);
    CHECK(LoaderSpy::stalls() == setupStalls); // no vkQueueSubmit, fence or idle wait inside the frames
    app.finish();
    CHECK(setupStalls <= 2); // the set-up's one finish() (a submission and its fence)

    // What the engine rendered and crepuscular wrote, read back by the engine after the frames.
    vkengine::Engine& engine = app.engine();
    const ShadowPassPlan& plan = app.volumetrics().currentPlan();
    CHECK(plan.options.convention == ClipConvention::Vulkan);
    const Image vulkanOut = imageOf(engine.download(*app.images().output), kWidth, kHeight, 4);
    const std::vector<float> cameraDepth = engine.download(*app.images().cameraDepth);
    crep::test::checkNoValidationMessages(engine.validationMessages());

    // The GL front door: the same camera and lights, the engine's camera depth, the casters drawn by GL.
    scene.camera = app.camera();
    gpu::GlBackend gl;
    gpu::Texture depth(gl, {gpu::TextureType::Texture2D, gpu::Format::Depth32F, int(kWidth), int(kHeight), 1,
                            "the engine's camera depth"});
    gl.writeTexture(depth.id(), cameraDepth);
    gpu::Texture output(
        gl, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, int(kWidth), int(kHeight), 1, "GL output"});
    scenes::SceneRenderer renderer(scene.mesh);
    Scattering::CreateInfo info = settings;
    info.width = kWidth;
    info.height = kHeight;
    info.backend = &gl;
    Scattering glScattering(info);
    Scattering::FrameAttribs f;
    f.camera = &scene.camera;
    f.light = scene.hasSun ? &scene.sun : nullptr;
    f.medium = &scene.medium;
    f.cameraDepth = depth.id();
    f.output = output.id();
    f.spotLights = scene.spotLights;
    f.drawCasters = [&](const glm::dmat4& clipFromWorld) { renderer.drawDepth(clipFromWorld); };
    const ShadowPassPlan glPlan = glScattering.plan(f);
    const Scattering::FrameResult glResult = glScattering.run(f);
    const Image glOut = imageOf(gl.readTexture(output.id()), kWidth, kHeight, 4);

    // The same passes planned for both (kinds and sizes; the matrices differ by the convention).
    REQUIRE(plan.passes.size() == glPlan.passes.size());
    int rectified = 0, standard = 0;
    for (std::size_t i = 0; i < plan.passes.size(); ++i) {
      CHECK(plan.passes[i].kind == glPlan.passes[i].kind);
      CHECK(plan.passes[i].width == glPlan.passes[i].width);
      rectified += plan.passes[i].kind == ShadowPass::Kind::Rectified ? 1 : 0;
      standard += plan.passes[i].kind == ShadowPass::Kind::Standard ? 1 : 0;
      CHECK(plan.passes[i].needsMap() == (plan.passes[i].kind != ShadowPass::Kind::None));
    }
    // Where the frames differ, the suspects: the sun's map as the library sampled it (the rectified map, or
    // the epipolar map resampled from the standard one), and the maps themselves: the GL front door once more
    // on the engine's own maps (its plan in OpenGL's convention, whose maps store the same values).
    // On an epipolar frame the epipolar map is point-resampled from the standard map on each backend
    // (Klehm et al. 2014, Sec. 4.1): a texel whose source coordinate falls on a texel boundary of the
    // standard map may take the neighbouring texel on one backend (their float arithmetic differs in the
    // last bits). Such flips are counted.
    long long flips = 0, mapTexels = 0;
    std::string mapNote = "no sun map";
    if (scene.hasSun) {
      const std::vector<float> vm = app.volumetrics().backend().readTexture(last.rectifiedMap.texture);
      const std::vector<float> gm = gl.readTexture(glResult.rectifiedMap.texture);
      REQUIRE(vm.size() == gm.size());
      mapTexels = static_cast<long long>(vm.size());
      for (std::size_t k = 0; k < vm.size(); ++k)
        flips += std::abs(vm[k] - gm[k]) > 1e-4f ? 1 : 0;
      const DepthDiff d = depthDiff(vm, gm);
      mapNote = "the sun's " + std::string(layoutToken(last.layout)) +
                " map as sampled: " + std::to_string(d.differing) + " texels differ, " +
                std::to_string(flips) + " by more than 1e-4";
    }
    std::vector<gpu::Texture> engineMaps;
    std::vector<std::uint32_t> engineMapIds(plan.passes.size(), 0);
    for (const vkengine::ShadowPassTarget& t : app.volumetrics().currentTargets()) {
      const std::size_t i = static_cast<std::size_t>(t.pass - plan.passes.data());
      engineMaps.emplace_back(gl,
                              gpu::TextureDesc{gpu::TextureType::Texture2D, gpu::Format::Depth32F,
                                               int(t.image->width), int(t.image->height), 1, "engine map"});
      gl.writeTexture(engineMaps.back().id(), engine.download(*t.image));
      engineMapIds.at(i) = engineMaps.back().id();
    }
    Scattering::FrameAttribs onEngineMaps = f;
    onEngineMaps.drawCasters = {};
    const ShadowPassPlan glPlan2 = glScattering.plan(onEngineMaps);
    onEngineMaps.plan = &glPlan2;
    onEngineMaps.planMaps = engineMapIds;
    glScattering.run(onEngineMaps);
    const Image glOnEngineMaps = imageOf(gl.readTexture(output.id()), kWidth, kHeight, 4);
    const ImageMetrics same = compareImages(vulkanOut, glOnEngineMaps, {.channels = 3});
    const ImageMetrics mapsOnly = compareImages(glOnEngineMaps, glOut, {.channels = 3});

    const ImageMetrics rgb = compareImages(vulkanOut, glOut, {.channels = 3});
    Image vulkanA(kWidth, kHeight, 1), glA(kWidth, kHeight, 1);
    for (int y = 0; y < int(kHeight); ++y)
      for (int x = 0; x < int(kWidth); ++x) {
        vulkanA.at(x, y) = vulkanOut.at(x, y, 3);
        glA.at(x, y) = glOut.at(x, y, 3);
      }
    const ImageMetrics a = compareImages(vulkanA, glA);
    MESSAGE(std::string(name) << ": " << std::string(scene.hasSun ? layoutToken(last.layout) : "no sun")
                              << ", " << rectified << " rectified and " << standard
                              << " standard plan passes; Vulkan engine (plan maps) against GL (drawCasters): "
                                 "in-scattering relative RMSE "
                              << rgb.relativeRmse << " (max " << rgb.maxAbsError << " of peak " << rgb.peak
                              << "), transmittance " << a.relativeRmse << "; " << mapNote
                              << "; GL on the engine's maps against GL's own maps (the maps' path alone) "
                              << mapsOnly.relativeRmse << ", against Vulkan (the same maps) "
                              << same.relativeRmse);
    CHECK(rgb.nanCount + rgb.infCount == 0);
    // The shadow maps' path alone: the engine's maps (Vulkan's clip convention, lavapipe) in place of GL's
    // own (drawCasters, llvmpipe), everything else on GL.
    CHECK(mapsOnly.relativeRmse <= 1e-5);
    if (flips == 0) {
      CHECK(rgb.relativeRmse <= 1e-5);
      CHECK(same.relativeRmse <= 1e-5);
    } else {
      // The goal (1e-5) is missed on such a frame, on the same maps too (docs/BACKENDS.md: sunset); the
      // bound says the flipped texels, at most 0.01% of the map, are all that differs.
      CHECK(flips * 10000 <= mapTexels);
      CHECK(rgb.relativeRmse <= 3e-4);
      CHECK(same.relativeRmse <= 3e-4);
    }
    CHECK(a.relativeRmse <= 1e-5);
    CHECK(last.layout == glResult.layout);
    CHECK(last.localLights.size() == scene.spotLights.size());
    // The scene is lit: the comparison is not one of two empty images.
    CHECK(rgb.peak > 1e-3);
    if (std::string(name) == "forest") {
      CHECK(last.layout == Scattering::Layout::Projective);
      CHECK(plan.passes.at(0).kind == ShadowPass::Kind::Rectified);
    }
    if (std::string(name) == "sunset") { // the fallback: the plan's standard map of the sun
      CHECK(last.layout == Scattering::Layout::Epipolar);
      CHECK(plan.passes.at(0).kind == ShadowPass::Kind::Standard);
      CHECK(plan.passes.at(0).needsMap());
    }
    if (std::string(name) == "colonnade-night") CHECK(plan.passes.size() == scene.spotLights.size());
  }
}

TEST_CASE("Vulkan clip convention: a plan pass rasterized by the engine with the plan's Vulkan matrices "
          "equals GL's map of the same pass with its OpenGL matrices") {
  CREP_REQUIRE_GL();
  // The sun's pass of forest (rectified, 8 splits) and of sunset (the fallback's standard map).
  for (const char* name : {"forest", "sunset"}) {
    const std::string sceneName = name;
    CAPTURE(sceneName);
    const scenes::Scene scene = scenes::makeScene(name, double(kWidth) / kHeight);
    gpu::GlBackend gl;
    Scattering::CreateInfo info = smallSettings();
    info.width = kWidth;
    info.height = kHeight;
    info.backend = &gl;
    const Scattering scattering(info);
    Scattering::FrameAttribs f;
    f.camera = &scene.camera;
    f.light = &scene.sun;
    const ShadowPass vulkanPass = scattering.plan(f, {.convention = ClipConvention::Vulkan}).passes.at(0);
    const ShadowPass glPass = scattering.plan(f, {.convention = ClipConvention::OpenGL}).passes.at(0);
    REQUIRE(vulkanPass.needsMap());
    REQUIRE(vulkanPass.splits.size() == glPass.splits.size());

    // The engine's pass on lavapipe.
    vkengine::Mesh mesh;
    mesh.positions = scene.mesh.positions;
    mesh.indices = scene.mesh.indices;
    vkengine::Engine engine(mesh, {.framesInFlight = 1, .validation = true});
    const vkengine::DepthImage& image =
        engine.createDepthImage(std::uint32_t(vulkanPass.width), std::uint32_t(vulkanPass.height));
    const vkengine::ShadowPassTarget target = vkengine::targetOf(vulkanPass, image);
    const vkengine::Engine::Frame frame = engine.beginFrame();
    engine.drawDepthPass(frame, image, target.state, target.draws);
    engine.submit(frame);
    engine.waitIdle();
    const std::vector<float> vulkanMap = engine.download(image);
    crep::test::checkNoValidationMessages(engine.validationMessages());

    // GL's on llvmpipe.
    scenes::SceneRenderer renderer(scene.mesh);
    const std::vector<float> glMap = glPassMap(renderer, glPass);

    long long covered = 0;
    for (const float d : glMap)
      covered += d < 1.0f ? 1 : 0;
    const DepthDiff d = depthDiff(vulkanMap, glMap, static_cast<float>(glPass.clearDepth));
    MESSAGE(std::string(name) << ": " << vulkanPass.splits.size() << " draws into " << vulkanPass.width
                              << "^2, " << covered << " texels covered; Vulkan (ClipConvention::Vulkan) "
                              << "against GL (ClipConvention::OpenGL): " << d.coverage
                              << " texels covered by one only, " << d.differing << " differ in depth (median "
                              << d.medianUlps << " ulps, 99.9th percentile " << d.p999Ulps << ", max "
                              << d.maxUlps << " = " << d.maxAbs << "), " << d.over1e5
                              << " by more than 1e-5");
    CHECK(covered > 0);
    // Not bit for bit, nor within one ulp: the two matrices differ in their z row only (Vulkan's is
    // 0.5 z + 0.5 w of OpenGL's), so x, y and w are the same floats and the same texels are covered;
    // the depth is the z row evaluated in float (Vulkan: z' / w; GL: 0.5 z / w + 0.5 in the viewport
    // transform), rounded differently, and more so where the row's terms cancel (world coordinates far
    // larger than the light's depth range) and where w is small (a rectified split's projection).
    CHECK(d.coverage == 0);
    // A few texels differ by more than that rounding (measured: one per pass, located by a CPU ray cast of
    // the mesh at the texel). Forest's: a triangle crossing the plane w = 0 of split 6's projection (a
    // vertex at w = -24), at depth -7.9 there, covers the texel on GL (clamped to 0) and not on Vulkan,
    // where the next surface shows (0.0323777). Sunset's: a sliver triangle (its three vertices within
    // 0.5 texel of one line), whose depth plane amplifies the rounding to 5.3e-5 on Vulkan.
    CHECK(d.over1e5 <= 2);
  }
}
