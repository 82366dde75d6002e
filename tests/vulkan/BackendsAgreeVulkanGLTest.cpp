// The same frame on both backends: each built-in scene's standard shadow map, rendered by GL, resampled
// into its rectified map with the map's min/max trees by the passes on the backend seam, once on
// gpu::GlBackend (llvmpipe) and once on gpu::VulkanBackend (lavapipe, validation on). The two maps are
// compared by relative RMSE and their largest difference; the trees of each backend are those of its map.
// RectifiedMarchPass (min/max tree march with a block, brute force) then marches the same map on both.
#include "common/gl_fixture.h"
#include "common/vulkan_fixture.h"

#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/epipolar/resample.h>
#include <crep/gpu/gl.h>
#include <crep/gpu/gl_backend.h>
#include <crep/rectify/rectify.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>
#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

using namespace crep;

namespace {

/// One backend's run of the frame: the rectified map and its trees.
struct BackendRun {
  std::vector<float> map, nodes, treesOfMap;
};

BackendRun runOn(gpu::Backend& backend, const Image& shadow, const RectifiedLayout& layout,
                 const glm::dmat4& lightMatrix, int W, int H) {
  gpu::Texture shadowMap(backend, {gpu::TextureType::Texture2D, gpu::Format::Depth32F, shadow.width(),
                                   shadow.height(), 1, "shadow map"});
  backend.writeTexture(shadowMap.id(), shadow.data());
  gpu::Texture map(backend, {gpu::TextureType::Texture2D, gpu::Format::R32F, W, H, 1, "rectified map"});
  ShadowResamplePass resample({.mapWidth = W, .mapHeight = H, .backend = &backend});
  MinMaxTreePass fused({.mapWidth = W, .mapHeight = H, .backend = &backend}),
      fromMap({.mapWidth = W, .mapHeight = H, .backend = &backend});
  ShadowResamplePass::FrameAttribs f;
  f.layout = &layout;
  f.shadowMap = shadowMap.id();
  f.lightClipFromWorld = lightMatrix;
  f.output = map.id();
  f.minMaxBuffer = fused.treeBuffer();
  resample.run(f);
  fused.completeUpperLevels();
  fromMap.run(map.id());
  return {backend.readTexture(map.id()), fused.readNodes(), fromMap.readNodes()};
}

/// The tree march (the whole image, then an epipole-block-like disc over it) and the brute-force march of
/// `map` (W x H, R32F, the same values on both backends) on `backend`: RGBA floats of both images.
std::pair<std::vector<float>, std::vector<float>> marchOn(gpu::Backend& backend, const scenes::Scene& scene,
                                                          const RectifiedLayout& layout, const Image& map,
                                                          const Image& cameraDepth) {
  const int W = map.width(), H = map.height(), w = cameraDepth.width(), h = cameraDepth.height();
  gpu::Texture mapTexture(backend, {gpu::TextureType::Texture2D, gpu::Format::R32F, W, H, 1, "map"});
  backend.writeTexture(mapTexture.id(), map.data());
  gpu::Texture depth(backend, {gpu::TextureType::Texture2D, gpu::Format::R32F, w, h, 1, "camera depth"});
  backend.writeTexture(depth.id(), cameraDepth.data());
  MinMaxTreePass trees({.mapWidth = W, .mapHeight = H, .backend = &backend});
  trees.run(mapTexture.id());
  std::vector<float> images[2];
  for (const RectifiedMarchPass::Mode mode :
       {RectifiedMarchPass::Mode::MinMaxTree, RectifiedMarchPass::Mode::BruteForce}) {
    RectifiedMarchPass march({.mapWidth = W, .mapHeight = H, .mode = mode, .backend = &backend});
    gpu::Texture out(backend, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, w, h, 1, "march"});
    RectifiedMarchPass::FrameAttribs a;
    a.layout = &layout;
    a.camera = &scene.camera;
    a.light = &scene.sun;
    a.medium = &scene.medium;
    a.cameraDepth = depth.id();
    a.rectifiedDepth = mapTexture.id();
    a.minMaxBuffer = trees.treeBuffer();
    a.output = out.id();
    march.run(a);
    if (mode == RectifiedMarchPass::Mode::MinMaxTree) { // a disc over the image's centre, marched again
      a.blockCenter = glm::dvec2(w / 2.0, h / 2.0);
      a.blockRadius = h / 4.0;
      march.run(a);
    }
    images[mode == RectifiedMarchPass::Mode::MinMaxTree ? 0 : 1] = backend.readTexture(out.id());
  }
  return {images[0], images[1]};
}

/// Relative RMSE of b against a (RGB of RGBA floats).
double relativeRmseRgb(const std::vector<float>& a, const std::vector<float>& b) {
  double squared = 0.0, reference = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (i % 4 != 3) {
      const double d = static_cast<double>(b[i]) - a[i];
      squared += d * d;
      reference += static_cast<double>(a[i]) * a[i];
    }
  return std::sqrt(squared / reference);
}

} // namespace

TEST_CASE("backends agree: a scene's rectified map and trees on OpenGL and on Vulkan") {
  CREP_REQUIRE_GL();
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  gpu::GlBackend gl;
  const int width = 320, height = 180, S = 1024, W = 256;
  for (const std::string name : {"forest", "sunset", "colonnade"}) {
    CAPTURE(name);
    const scenes::Scene scene = scenes::makeScene(name, static_cast<double>(width) / height);
    const glm::dmat4 lightMatrix =
        scenes::standardLightClipFromWorld(scene.sun, scene.boundsMin, scene.boundsMax);
    scenes::SceneRenderer renderer(scene.mesh);
    const Image shadow = renderer.renderDepthImage(lightMatrix, S, S, {.depthClamp = true});
    // The frame's layout: projective when the rectification allows it, epipolar otherwise (the sun in view).
    const Rectification rect = rectify(scene.camera, scene.sun, RectifyOptions{});
    std::unique_ptr<RectifiedLayout> layout;
    int H = 256;
    if (rect.status == RectifyStatus::Projective) {
      layout = std::make_unique<ProjectiveLayout>(rect);
    } else {
      auto epipolar = std::make_unique<EpipolarLayout>(scene.camera, scene.sun, width, height);
      H = epipolar->sliceCount();
      layout = std::move(epipolar);
    }
    const BackendRun a = runOn(gl, shadow, *layout, lightMatrix, W, H),
                     b = runOn(vk, shadow, *layout, lightMatrix, W, H);
    REQUIRE(a.map.size() == b.map.size());
    double squared = 0.0, reference = 0.0, largest = 0.0;
    int differ = 0;
    for (std::size_t i = 0; i < a.map.size(); ++i) {
      const double d = static_cast<double>(b.map[i]) - a.map[i];
      squared += d * d;
      reference += static_cast<double>(a.map[i]) * a.map[i];
      largest = std::max(largest, std::abs(d));
      differ += d != 0.0;
    }
    const double relativeRmse = std::sqrt(squared / reference);
    MESSAGE(name << " (" << std::string(rect.status == RectifyStatus::Projective ? "projective" : "epipolar")
                 << ", " << W << "x" << H << "): relative RMSE " << relativeRmse << ", max |difference| "
                 << largest << ", " << differ << " of " << a.map.size() << " texels differ");
    CHECK(relativeRmse <= 1e-4);
    // Each backend's fused trees are the trees of its own map, bit for bit.
    CHECK(a.nodes == a.treesOfMap);
    CHECK(b.nodes == b.treesOfMap);
    // RectifiedMarchPass on both backends over the same map (GL's): tree march with a block, brute force.
    Image map(W, H, 1);
    std::copy(a.map.begin(), a.map.end(), map.data().begin());
    const Image cameraDepth = renderer.renderDepthImage(scene.camera.clipFromWorld(), width, height);
    const auto [glTree, glBrute] = marchOn(gl, scene, *layout, map, cameraDepth);
    const auto [vkTree, vkBrute] = marchOn(vk, scene, *layout, map, cameraDepth);
    const double tree = relativeRmseRgb(glTree, vkTree), brute = relativeRmseRgb(glBrute, vkBrute);
    MESSAGE(name << ": RectifiedMarchPass Vulkan vs GL, relative RMSE: min/max tree march " << tree
                 << ", brute force " << brute);
    CHECK(tree <= 1e-4);
    CHECK(brute <= 1e-4);
  }
  crep::test::checkNoValidationMessages(vk);
}
