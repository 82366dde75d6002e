// The epipolar fallback on the GPU and on the built-in scenes: the resampling pass against the CPU
// resampling, the marches on the epipolar layout against the CPU, the fallback against the projective
// pipeline where both are valid, and a light sweep through the view direction (epipole across the screen,
// then behind the camera) with the projective path where it is valid and the fallback (plus the epipole
// block) elsewhere: finite images, close to the world-space reference, no flash at the switch.
#include "common/analytic_reference.h"
#include "common/gl_fixture.h"
#include "common/image_check.h"
#include "common/map_agreement.h"

#include <crep/core/error.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/epipolar/resample.h>
#include <crep/gpu/gl.h>
#include <crep/gpu/shader_library.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kWidth = 160, kHeight = 90;
constexpr int kShadowSize = 1024;

/// A scene on the GPU: its renderer, camera depth and standard shadow map.
struct GpuScene {
  explicit GpuScene(scenes::Scene s) : scene(std::move(s)), renderer(scene.mesh) {
    cameraDepth = scenes::createDepthTexture(kWidth, kHeight);
    renderer.renderDepth(scene.camera.clipFromWorld(), cameraDepth.get(), 0, 0, 0, kWidth, kHeight);
    cameraImage = scenes::readDepthTexture(cameraDepth.get(), kWidth, kHeight);
    shadow = scenes::createDepthTexture(kShadowSize, kShadowSize);
    setLight(scene.sun);
  }
  void setLight(const DirectionalLight& light) {
    scene.sun = light;
    lightMatrix = scenes::standardLightClipFromWorld(light, scene.boundsMin, scene.boundsMax);
    renderer.renderDepth(lightMatrix, shadow.get(), 0, 0, 0, kShadowSize, kShadowSize, {.depthClamp = true});
  }
  Image shadowImage() const { return scenes::readDepthTexture(shadow.get(), kShadowSize, kShadowSize); }

  scenes::Scene scene;
  scenes::SceneRenderer renderer;
  gl::Handle cameraDepth, shadow;
  Image cameraImage;
  glm::dmat4 lightMatrix{1.0};
};

/// The passes of one map size, built once (building the programs is what costs on llvmpipe).
struct Passes {
  Passes(int W, int H)
      : trees({W, H}), tree({W, H, RectifiedMarchPass::Mode::MinMaxTree}),
        brute({W, H, RectifiedMarchPass::Mode::BruteForce}), resample({W, H}) {}
  MinMaxTreePass trees;
  RectifiedMarchPass tree, brute;
  ShadowResamplePass resample;
};

Passes& passes(int W, int H) {
  static std::map<std::pair<int, int>, std::unique_ptr<Passes>> cache;
  auto& p = cache[{W, H}];
  if (!p) p = std::make_unique<Passes>(W, H);
  return *p;
}

/// The GPU min/max march of a rectified map texture.
Image gpuMarch(const GpuScene& g, const RectifiedLayout& layout, GLuint map, int W, int H,
               RectifiedMarchPass::Mode mode = RectifiedMarchPass::Mode::MinMaxTree) {
  Passes& p = passes(W, H);
  p.trees.run(map);
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
  RectifiedMarchPass::FrameAttribs f;
  f.layout = &layout;
  f.camera = &g.scene.camera;
  f.light = &g.scene.sun;
  f.medium = &g.scene.medium;
  f.cameraDepth = g.cameraDepth.get();
  f.rectifiedDepth = map;
  f.minMaxBuffer = p.trees.treeBuffer();
  f.output = out.get();
  (mode == RectifiedMarchPass::Mode::MinMaxTree ? p.tree : p.brute).run(f);
  return gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba);
}

/// The projective path: the rectified map rasterized with the split matrices, marched on the GPU.
Image projectivePath(const GpuScene& g, const Rectification& r, int W = 256, int H = 128) {
  const gl::Handle map = scenes::createDepthTexture(W, H);
  for (int k = 0; k < r.splitCount(); ++k) {
    const SplitViewport v = r.splitViewport(k, W, H);
    // GL_DEPTH_CLAMP keeps the casters between the light and the frustum (rectify.h).
    const_cast<scenes::SceneRenderer&>(g.renderer)
        .renderDepth(r.splits[static_cast<std::size_t>(k)].rectClipFromWorld, map.get(), v.layer, v.x, v.y,
                     v.width, v.height, {.depthClamp = true});
  }
  const ProjectiveLayout layout(r);
  return gpuMarch(g, layout, map.get(), W, H);
}

/// The fallback path: the standard shadow map resampled into the epipolar layout on the GPU, marched on the
/// GPU, and the epipole block marched in world space.
Image fallbackPath(const GpuScene& g, const EpipolarLayout& layout, int W = 512) {
  const int H = layout.sliceCount();
  const gl::Handle map = gl::createTexture2D(GL_R32F, W, H);
  ShadowResamplePass& resample = passes(W, H).resample;
  ShadowResamplePass::FrameAttribs r;
  r.layout = &layout;
  r.shadowMap = g.shadow.get();
  r.lightClipFromWorld = g.lightMatrix;
  r.output = map.get();
  resample.run(r);
  Image image = gpuMarch(g, layout, map.get(), W, H);
  if (const auto e = layout.epipolePixel(); e && layout.epipoleBlockRadiusPixels() > 0.0) {
    const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
    glTextureSubImage2D(out.get(), 0, 0, 0, kWidth, kHeight, GL_RGBA, GL_FLOAT, image.data().data());
    static WorldMarchPass block({128, 12});
    WorldMarchPass::FrameAttribs f;
    f.camera = &g.scene.camera;
    f.light = &g.scene.sun;
    f.medium = &g.scene.medium;
    f.cameraDepth = g.cameraDepth.get();
    f.shadowMap = g.shadow.get();
    f.lightClipFromWorld = g.lightMatrix;
    f.bias = 1e-4;
    f.output = out.get();
    f.blockCenter = *e;
    f.blockRadius = layout.epipoleBlockRadiusPixels();
    block.run(f);
    image = gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba);
  }
  return image;
}

/// The world-space reference march of the standard shadow map (CPU).
Image reference(const GpuScene& g, const Image& shadow, int steps = 128) {
  WorldMarchOptions o;
  o.steps = steps;
  o.bias = 1e-4;
  return worldSpaceMarch(shadow, g.lightMatrix, g.cameraImage, g.scene.camera, g.scene.sun, g.scene.medium, o)
      .scattering;
}

/// The same reference with the GPU world-space march pass (tested against the CPU in MarchGLTest).
Image gpuReference(const GpuScene& g) {
  static WorldMarchPass pass({128, 12});
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
  WorldMarchPass::FrameAttribs f;
  f.camera = &g.scene.camera;
  f.light = &g.scene.sun;
  f.medium = &g.scene.medium;
  f.cameraDepth = g.cameraDepth.get();
  f.shadowMap = g.shadow.get();
  f.lightClipFromWorld = g.lightMatrix;
  f.bias = 1e-4;
  f.output = out.get();
  pass.run(f);
  return gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba);
}

long long nonFinite(const Image& image) {
  long long n = 0;
  for (float v : image.data())
    n += std::isfinite(v) ? 0 : 1;
  return n;
}

} // namespace

TEST_CASE("epipolar GL: the resampling pass matches the CPU resampling (epipolar and projective layouts)") {
  CREP_REQUIRE_GL();
  GpuScene g(scenes::makeScene("colonnade", static_cast<double>(kWidth) / kHeight));
  const Image shadow = g.shadowImage();
  const auto epipolar = std::make_shared<const EpipolarLayout>(g.scene.camera, g.scene.sun, kWidth, kHeight);
  RectifyOptions ro;
  ro.splits = 4;
  const auto projective = std::make_shared<const ProjectiveLayout>(rectify(g.scene.camera, g.scene.sun, ro));
  for (const auto& [name, layout, H] : {std::tuple<std::string, std::shared_ptr<const RectifiedLayout>, int>{
                                            "epipolar", epipolar, epipolar->sliceCount()},
                                        {"projective", projective, 128}}) {
    CAPTURE(name);
    const int W = 256;
    const RectifiedMap cpu = resampleShadowMap(layout, W, H, shadow, g.lightMatrix);
    const gl::Handle map = gl::createTexture2D(GL_R32F, W, H);
    ShadowResamplePass pass({W, H});
    ShadowResamplePass::FrameAttribs f;
    f.layout = layout.get();
    f.shadowMap = g.shadow.get();
    f.lightClipFromWorld = g.lightMatrix;
    f.output = map.get();
    pass.run(f);
    const Image gpu = gl::readTexture(map.get(), W, H, gl::TexelData::Red);
    // Measured: epipolar 2 texels > 1e-3, mean 2.8e-7; projective 0 texels, mean 3.2e-8 (max 4e-4 next to
    // the camera, where the depth slope Z / X is computed from small X in float).
    crep::test::checkResampledMap(name, gpu.data(), cpu.depth);
    // With a tree buffer the pass also writes the map's min/max tree levels 1..lowLevels (one work group
    // per row): the same map bit for bit, and after completeUpperLevels() the nodes MinMaxTreePass::run()
    // builds from the map, bit for bit.
    MinMaxTreePass fromMap({W, H}), fused({W, H});
    fromMap.run(map.get());
    const gl::Handle fusedMap = gl::createTexture2D(GL_R32F, W, H);
    f.output = fusedMap.get();
    f.minMaxBuffer = fused.treeBuffer();
    pass.run(f);
    fused.completeUpperLevels();
    const Image fusedImage = gl::readTexture(fusedMap.get(), W, H, gl::TexelData::Red);
    CHECK(std::equal(fusedImage.data().begin(), fusedImage.data().end(), gpu.data().begin()));
    const std::vector<float> a = fromMap.readNodes(), b = fused.readNodes();
    REQUIRE(a.size() == b.size());
    CHECK(MinMaxTreePass::lowLevels(W) == 2);
    CHECK(std::equal(a.begin(), a.end(), b.begin()));
  }
  // Odd widths and the 1024-texel rows of crep::Scattering's default map (4 low levels per invocation).
  for (const int W : {1024, 200}) {
    CAPTURE(W);
    const int H = epipolar->sliceCount();
    ShadowResamplePass pass({W, H});
    MinMaxTreePass fromMap({W, H}), fused({W, H});
    const gl::Handle plain = gl::createTexture2D(GL_R32F, W, H),
                     withTrees = gl::createTexture2D(GL_R32F, W, H);
    ShadowResamplePass::FrameAttribs f{epipolar.get(), g.shadow.get(), g.lightMatrix, plain.get()};
    pass.run(f);
    fromMap.run(plain.get());
    f.output = withTrees.get();
    f.minMaxBuffer = fused.treeBuffer();
    pass.run(f);
    fused.completeUpperLevels();
    const Image p = gl::readTexture(plain.get(), W, H, gl::TexelData::Red),
                q = gl::readTexture(withTrees.get(), W, H, gl::TexelData::Red);
    CHECK(std::equal(p.data().begin(), p.data().end(), q.data().begin()));
    const std::vector<float> a = fromMap.readNodes(), b = fused.readNodes();
    CHECK(std::equal(a.begin(), a.end(), b.begin()));
  }
  // A buffer too small for the map, or a map too narrow for low levels, is named.
  ShadowResamplePass narrow({64, epipolar->sliceCount()});
  MinMaxTreePass narrowTrees({64, epipolar->sliceCount()});
  const gl::Handle narrowMap = gl::createTexture2D(GL_R32F, 64, epipolar->sliceCount());
  ShadowResamplePass::FrameAttribs bad{epipolar.get(), g.shadow.get(), g.lightMatrix, narrowMap.get(),
                                       narrowTrees.treeBuffer()};
  CHECK_THROWS_WITH_AS(narrow.run(bad), doctest::Contains("ShadowResamplePass::FrameAttribs.minMaxBuffer"),
                       InvalidArgument);
  CHECK_THROWS_WITH_AS(narrowTrees.completeUpperLevels(),
                       doctest::Contains("MinMaxTreePass::CreateInfo.mapWidth"), InvalidArgument);
  ShadowResamplePass wide({256, epipolar->sliceCount()});
  const gl::Handle wideMap = gl::createTexture2D(GL_R32F, 256, epipolar->sliceCount());
  bad.output = wideMap.get();
  CHECK_THROWS_WITH_AS(wide.run(bad), doctest::Contains("must be a MinMaxTreePass::treeBuffer()"),
                       InvalidArgument);
}

TEST_CASE("epipolar GL: GPU marches on the epipolar layout agree with the CPU marches") {
  CREP_REQUIRE_GL();
  GpuScene g(scenes::makeScene("forest", static_cast<double>(kWidth) / kHeight));
  // Light from behind-left and above: the anti-epipole is on screen.
  const glm::dvec3 towardLight =
      glm::normalize(-g.scene.camera.forward() - 0.3 * g.scene.camera.right() + 0.4 * g.scene.camera.up());
  g.setLight(DirectionalLight(-towardLight, g.scene.sun.irradiance()));
  const EpipolarLayout layout(g.scene.camera, g.scene.sun, kWidth, kHeight);
  REQUIRE(layout.epipoleOnScreen());
  REQUIRE(layout.epipoleKind() == EpipoleKind::AntiEpipole);
  const int W = 256, H = layout.sliceCount();
  const auto shared = std::make_shared<const EpipolarLayout>(layout);
  const RectifiedMap map = resampleShadowMap(shared, W, H, g.shadowImage(), g.lightMatrix);
  const gl::Handle texture = gl::createTexture2D(GL_R32F, W, H);
  glTextureSubImage2D(texture.get(), 0, 0, 0, W, H, GL_RED, GL_FLOAT, map.depth.data().data());
  const Image tree = gpuMarch(g, layout, texture.get(), W, H);
  const Image brute = gpuMarch(g, layout, texture.get(), W, H, RectifiedMarchPass::Mode::BruteForce);
  const MarchResult cpu = minMaxMarch(map, g.cameraImage, g.scene.camera, g.scene.sun, g.scene.medium);
  const MarchResult cpuBrute =
      bruteForceMarch(map, g.cameraImage, g.scene.camera, g.scene.sun, g.scene.medium);
  CHECK(maxRelativeDifference(cpu.scattering, cpuBrute.scattering, 1e-6) < 1e-6);
  MESSAGE("epipolar layout, " << H << " slices: mean steps tree " << cpu.meanSteps() << ", brute force "
                              << cpuBrute.meanSteps());
  const ImageMetrics same = rgbMetrics(tree, brute);
  report("GPU tree vs GPU brute force (epipolar)", same);
  CHECK(same.relativeRmse < 1e-5);
  const ImageMetrics vsCpu = rgbMetrics(tree, cpu.scattering);
  report("GPU tree vs CPU (epipolar)", vsCpu);
  // Float slice mapping (atan, border position) moves a few pixels to the neighbouring slice row.
  ImageTolerance t;
  t.relativeRmse = 0.01;
  t.overThreshold = 0.01 * vsCpu.peak;
  t.maxFractionOver = 0.02;
  CHECK(checkImage(rgb(tree), rgb(cpu.scattering), t, "epipolar_gpu_march_epipolar_vs_cpu"));
}

TEST_CASE("epipolar GL: fallback against the projective pipeline on the built-in scenes") {
  CREP_REQUIRE_GL();
  for (const std::string name : {"colonnade", "forest", "terrain", "boxes"}) {
    CAPTURE(name);
    GpuScene g(scenes::makeScene(name, static_cast<double>(kWidth) / kHeight));
    RectifyOptions ro;
    ro.splits = 4;
    const Rectification r = rectify(g.scene.camera, g.scene.sun, ro);
    REQUIRE(r.projective());
    const Image projective = projectivePath(g, r);
    const EpipolarLayout layout(g.scene.camera, g.scene.sun, kWidth, kHeight);
    const Image fallback = fallbackPath(g, layout);
    const Image ref = reference(g, g.shadowImage());
    const ImageMetrics m = rgbMetrics(fallback, projective);
    const ImageMetrics fr = rgbMetrics(fallback, ref), pr = rgbMetrics(projective, ref);
    MESSAGE(name << ": relative RMSE fallback vs projective " << m.relativeRmse
                 << "; vs the world-space reference: "
                 << "fallback " << fr.relativeRmse << ", projective " << pr.relativeRmse << " ("
                 << layout.sliceCount() << " slices x 512, projective 256 x 128, standard map 1024^2)");
    // Measured: colonnade 1.5e-2, forest 2.8e-2, terrain 2.9e-3, boxes 3.0e-3 (against the world-space
    // reference: fallback 0.64%, 1.6%, 0.17%, 0.13%; projective 1.4%, 3.0%, 0.29%, 0.29%).
    ImageTolerance t;
    t.relativeRmse = 0.06;
    CHECK(checkImage(rgb(fallback), rgb(projective), t, "epipolar_fallback_vs_projective_" + name));
    CHECK(nonFinite(fallback) == 0);
  }
}

TEST_CASE("epipolar GL: a light sweep through the view direction gives finite images without flashes") {
  CREP_REQUIRE_GL();
  GpuScene g(scenes::makeScene("colonnade", static_cast<double>(kWidth) / kHeight));
  const Camera& c = g.scene.camera;
  RectifyOptions ro;
  ro.splits = 4;
  // The direction toward the light turns in the plane of forward and right, 20 degrees above it: the epipole
  // enters the screen from the left, crosses it, leaves it on the right, goes to infinity (light axis
  // parallel to the image plane) and comes back as the anti-epipole (light behind the camera).
  std::vector<Image> images, refs;
  std::vector<std::string> paths;
  const int steps = 17;
  for (int s = 0; s < steps; ++s) {
    const double theta = glm::radians(-80.0 + 240.0 * s / (steps - 1));
    const glm::dvec3 towardLight =
        glm::normalize(std::cos(theta) * c.forward() + std::sin(theta) * c.right() + 0.36 * c.up());
    g.setLight(DirectionalLight(-towardLight, g.scene.sun.irradiance()));
    const Rectification r = rectify(c, g.scene.sun, ro);
    if (r.projective()) {
      images.push_back(projectivePath(g, r));
      paths.push_back("projective");
    } else {
      EpipolarOptions eo;
      eo.slices =
          2 * (kWidth + kHeight); // the most the automatic rule gives: one set of passes for the sweep
      const EpipolarLayout layout(c, g.scene.sun, kWidth, kHeight, eo);
      images.push_back(fallbackPath(g, layout));
      paths.push_back(std::string("fallback (") + reasonToken(r.reason) +
                      (layout.epipoleOnScreen() ? ", epipole on screen)" : ")"));
    }
    refs.push_back(gpuReference(g));
    CHECK(nonFinite(images.back()) == 0);
  }
  int switches = 0, fallbacks = 0;
  double worstVsRef = 0.0, worstExcess = 0.0;
  for (int s = 0; s < steps; ++s) {
    const ImageMetrics vsRef =
        rgbMetrics(images[static_cast<std::size_t>(s)], refs[static_cast<std::size_t>(s)]);
    worstVsRef = std::max(worstVsRef, vsRef.relativeRmse);
    fallbacks += paths[static_cast<std::size_t>(s)] != "projective";
    std::string line = "step " + std::to_string(s) + ": " + paths[static_cast<std::size_t>(s)] +
                       ", relative RMSE vs world-space reference " + std::to_string(vsRef.relativeRmse);
    if (s > 0) {
      // Neighbour difference of the method's images against the reference's own change between the steps.
      const std::size_t i = static_cast<std::size_t>(s);
      const ImageMetrics dm = rgbMetrics(images[i], images[i - 1]);
      const ImageMetrics dr = rgbMetrics(refs[i], refs[i - 1]);
      const bool sw = (paths[i] == "projective") != (paths[i - 1] == "projective");
      switches += sw;
      line += "; change from the previous step: RMS " + std::to_string(dm.rmse) + " (reference " +
              std::to_string(dr.rmse) + ")" + (sw ? " [switch]" : "");
      // A flash: a change far beyond the reference's own change between the two light directions.
      const double rms = dr.rmse / std::max(dr.relativeRmse, 1e-30); // RMS radiance of the reference
      worstExcess = std::max(worstExcess, (dm.rmse - dr.rmse) / rms);
      CHECK(dm.rmse <= dr.rmse + 0.02 * rms); // measured: at most 0.13% of the RMS radiance
    }
    MESSAGE(line);
    CHECK(vsRef.relativeRmse < 0.05); // measured: at most 1.7% (projective steps), fallback 0.6-1.4%
  }
  MESSAGE("worst relative RMSE against the reference over the sweep: "
          << worstVsRef
          << "; largest neighbour change beyond the reference's, relative to its RMS: " << worstExcess);
  CHECK(switches >= 2);
  CHECK(fallbacks >= 3);
}

TEST_CASE("epipolar GL: bad input to the passes") {
  CREP_REQUIRE_GL();
  const auto glError = [](const auto& f) {
    try {
      f();
    } catch (const InvalidArgument& e) {
      return "InvalidArgument " + e.parameter();
    } catch (const GlError&) {
      return std::string("GlError");
    }
    return std::string("no exception");
  };
  const int limit = gl::maxTextureSize();
  CHECK(glError([] {
          MinMaxTreePass({0, 16});
        }) == "InvalidArgument MinMaxTreePass::CreateInfo.mapWidth/mapHeight");
  CHECK(glError([&] { MinMaxTreePass({limit + 1, 16}); }) == "GlError");
  CHECK(glError([] {
          RectifiedMarchPass({16, -1});
        }) == "InvalidArgument RectifiedMarchPass::CreateInfo.mapWidth/mapHeight");
  CHECK(glError([&] { RectifiedMarchPass({16, limit + 1}); }) == "GlError");
  CHECK(glError([] {
          ShadowResamplePass({0, 0});
        }) == "InvalidArgument ShadowResamplePass::CreateInfo.mapWidth/mapHeight");
  CHECK(glError([&] { ShadowResamplePass({limit * 2, 8}); }) == "GlError");
  CHECK(glError([] { WorldMarchPass({0, 4}); }) == "InvalidArgument WorldMarchOptions.steps");

  GpuScene g(scenes::makeScene("boxes", static_cast<double>(kWidth) / kHeight));
  const EpipolarLayout layout(g.scene.camera, g.scene.sun, kWidth, kHeight);
  const int H = layout.sliceCount();
  ShadowResamplePass resample({64, H});
  ShadowResamplePass::FrameAttribs f;
  f.layout = &layout;
  f.shadowMap = g.shadow.get();
  f.lightClipFromWorld = g.lightMatrix;
  const gl::Handle wrongFormat = gl::createTexture2D(GL_RGBA32F, 64, H);
  f.output = wrongFormat.get();
  CHECK(glError([&] { resample.run(f); }) == "InvalidArgument ShadowResamplePass::FrameAttribs.output");
  const gl::Handle out = gl::createTexture2D(GL_R32F, 64, H);
  f.output = out.get();
  // The shadow map's size is read from the texture: a texture that is not 2D, or no texture, is named.
  const gl::Handle layered = gl::createTexture(GL_TEXTURE_2D_ARRAY);
  glTextureStorage3D(layered.get(), 1, GL_R32F, kShadowSize, kShadowSize, 2);
  for (const GLuint bad : {layered.get(), 0u}) {
    f.shadowMap = bad;
    CHECK(glError([&] { resample.run(f); }) == "InvalidArgument ShadowResamplePass::FrameAttribs.shadowMap");
  }
  f.shadowMap = g.shadow.get();
  f.lightClipFromWorld = g.scene.camera.clipFromWorld();
  CHECK(glError([&] { resample.run(f); }) == "InvalidArgument lightClipFromWorld");
  ShadowResamplePass wrongHeight({64, H + 1});
  f.lightClipFromWorld = g.lightMatrix;
  CHECK(glError([&] { wrongHeight.run(f); }) ==
        "InvalidArgument ShadowResamplePass::CreateInfo.mapWidth/mapHeight");

  // NaN in GPU depth inputs (documented handling, gpu_march.h). Depth textures clamp uploads to [0, 1],
  // so the NaN inputs are GL_R32F textures, which the passes accept as well.
  const gl::Handle nanShadow = gl::createTexture2D(GL_R32F, 64, 64);
  const std::vector<float> nans(static_cast<std::size_t>(kWidth) * kHeight, std::nanf(""));
  glTextureSubImage2D(nanShadow.get(), 0, 0, 0, 64, 64, GL_RED, GL_FLOAT, nans.data());
  f.shadowMap = nanShadow.get();
  resample.run(f);
  const Image resampled = gl::readTexture(out.get(), 64, H, gl::TexelData::Red);
  CHECK(nonFinite(resampled) == 0);
  CHECK(*std::min_element(resampled.data().begin(), resampled.data().end()) == 1.0f); // NaN texels are empty
  gl::Handle nanCamera = gl::createTexture2D(GL_R32F, kWidth, kHeight);
  glTextureSubImage2D(nanCamera.get(), 0, 0, 0, kWidth, kHeight, GL_RED, GL_FLOAT, nans.data());
  g.cameraDepth = std::move(nanCamera);
  const Image marched = gpuMarch(g, layout, out.get(), 64, H);
  CHECK(nonFinite(marched) == 0);
  // A NaN camera depth is the sky: the ray ends at the far plane (transmittance exp(-sbar far / cos)).
  const glm::dvec3 sigma = g.scene.medium.extinction();
  const glm::dvec3 v = g.scene.camera.rayDirection(2.0 * 80.5 / kWidth - 1.0, 2.0 * 45.5 / kHeight - 1.0);
  const double sky = g.scene.camera.far() / glm::dot(v, g.scene.camera.forward());
  CHECK(marched.at(80, 45, 3) ==
        doctest::Approx(std::exp(-(sigma.x + sigma.y + sigma.z) / 3.0 * sky)).epsilon(1e-4));
}

TEST_CASE("epipolar GL: uniform and storage blocks match their C++ structs") {
  CREP_REQUIRE_GL();
  // Offsets of the members the driver reports for the linked programs against offsetof.
  const auto offsetOf = [](GLuint program, const std::string& name) {
    const GLuint index = glGetProgramResourceIndex(program, GL_UNIFORM, name.c_str());
    if (index == GL_INVALID_INDEX) return -1;
    const GLenum property = GL_OFFSET;
    GLint value = -1;
    glGetProgramResourceiv(program, GL_UNIFORM, index, 1, &property, 1, nullptr, &value);
    return value;
  };
  const auto blockSize = [](GLuint program, const char* block) {
    const GLuint index = glGetProgramResourceIndex(program, GL_UNIFORM_BLOCK, block);
    const GLenum property = GL_BUFFER_DATA_SIZE;
    GLint value = -1;
    glGetProgramResourceiv(program, GL_UNIFORM_BLOCK, index, 1, &property, 1, nullptr, &value);
    return value;
  };
  using gpu::EpipolarLayoutParams;
  using gpu::MarchParams;
  using gpu::ProjectiveLayoutParams;
  const gl::Handle projective =
      buildProgram({{ShaderStage::Compute, "passes/epipolar/march_rectified.comp", {{"CREP_LAYOUT", "0"}}}});
  const gl::Handle epipolar =
      buildProgram({{ShaderStage::Compute, "passes/epipolar/march_rectified.comp", {{"CREP_LAYOUT", "1"}}}});
#define CREP_CHECK_MEMBER(program, block, type, member)                                                      \
  CHECK(offsetOf(program, std::string(block) + "." #member) == static_cast<GLint>(offsetof(type, member)))
  const GLuint p = projective.get(), e = epipolar.get();
  CHECK(blockSize(p, "CrepMarchBlock") == static_cast<GLint>(sizeof(MarchParams)));
  for (const char* m : {"cameraPosition", "cameraForward", "cameraRight", "cameraUp", "lightDirection"})
    CHECK(offsetOf(p, std::string("crep_march.") + m) >= 0);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, cameraPosition);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, lightIrradiance);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, extinction);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, sizes);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, info);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, bias);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, block);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, region);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, lightClipFromWorld);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, cameraCenter);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, cameraDepth);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, lightPosition);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, lightAxis);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, lightCone);
  CREP_CHECK_MEMBER(p, "crep_march", MarchParams, lightIntensity);
  // The world march (the one pass that reads the local-light members) sees the same block.
  const gl::Handle reference =
      buildProgram({{ShaderStage::Compute, "passes/scatter/march_reference.comp", {}}});
  const GLuint w = reference.get();
  CHECK(blockSize(w, "CrepMarchBlock") == static_cast<GLint>(sizeof(MarchParams)));
  CREP_CHECK_MEMBER(w, "crep_march", MarchParams, lightClipFromWorld);
  CREP_CHECK_MEMBER(w, "crep_march", MarchParams, cameraDepth);
  CREP_CHECK_MEMBER(w, "crep_march", MarchParams, lightPosition);
  CREP_CHECK_MEMBER(w, "crep_march", MarchParams, lightAxis);
  CREP_CHECK_MEMBER(w, "crep_march", MarchParams, lightCone);
  CREP_CHECK_MEMBER(w, "crep_march", MarchParams, lightIntensity);
  CHECK(blockSize(p, "CrepProjectiveLayoutBlock") == static_cast<GLint>(sizeof(ProjectiveLayoutParams)));
  CREP_CHECK_MEMBER(p, "crep_projective", ProjectiveLayoutParams, origin);
  CREP_CHECK_MEMBER(p, "crep_projective", ProjectiveLayoutParams, slopes);
  CREP_CHECK_MEMBER(p, "crep_projective", ProjectiveLayoutParams, counts);
  CHECK(offsetOf(p, "crep_projective.splitZeta[0]") ==
        static_cast<GLint>(offsetof(ProjectiveLayoutParams, splitZeta)));
  CHECK(blockSize(e, "CrepEpipolarLayoutBlock") == static_cast<GLint>(sizeof(EpipolarLayoutParams)));
  CREP_CHECK_MEMBER(e, "crep_epipolar", EpipolarLayoutParams, origin);
  CREP_CHECK_MEMBER(e, "crep_epipolar", EpipolarLayoutParams, towardLight);
  CREP_CHECK_MEMBER(e, "crep_epipolar", EpipolarLayoutParams, cameraTan);
  CREP_CHECK_MEMBER(e, "crep_epipolar", EpipolarLayoutParams, border);
  CREP_CHECK_MEMBER(e, "crep_epipolar", EpipolarLayoutParams, arc);
  CREP_CHECK_MEMBER(e, "crep_epipolar", EpipolarLayoutParams, counts);
  CHECK(offsetOf(e, "crep_epipolar.regionFractions[0]") ==
        static_cast<GLint>(offsetof(EpipolarLayoutParams, regionFractions)));
#undef CREP_CHECK_MEMBER
}
