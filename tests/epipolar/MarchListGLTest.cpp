// RectifiedMarchPass on GPU work lists (FrameAttribs::list, crep/scatter/gpu_sample_list.h): the marched
// samples of epipolar sampling (Yusov 2012, Sec. 6.4). A list of every pixel centre gives the per-pixel
// pass's output bit for bit (tree and brute force); a list of arbitrary continuous positions matches the
// CPU minMaxMarch at those samples (crep::screenRay's rays) within the GPU-vs-CPU march tolerance of
// MarchGLTest; only the entries' texels are written; an empty list writes nothing. The lists are filled
// from the CPU here (header, then the entries).
#include "epipolar_test_util.h"
#include "scatter/local_light_util.h"
#include "support/gl_fixture.h"
#include "support/image_check.h"

#include <crep/core/gl.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/gpu_sample_list.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kWidth = 160, kHeight = 90;        // camera image
constexpr int kMapWidth = 256, kMapHeight = 128; // projective map (4 splits of 64 columns)

/// A scene with its projective rectified map rendered on the GPU (MarchGLTest's fixture).
struct SceneMaps {
  scenes::Scene scene;
  std::shared_ptr<const ProjectiveLayout> layout;
  gl::Handle mapTexture, cameraTexture;
  RectifiedMap map;
  Image cameraDepth;
};

SceneMaps renderScene(const std::string& name) {
  SceneMaps s{scenes::makeScene(name, static_cast<double>(kWidth) / kHeight), {}, {}, {}, {}, {}};
  RectifyOptions options;
  options.splits = 4;
  Rectification r = rectify(s.scene.camera, s.scene.sun, options);
  INFO(name << ": " << r.message);
  REQUIRE(r.projective());
  scenes::SceneRenderer renderer(s.scene.mesh);
  s.mapTexture = scenes::createDepthTexture(kMapWidth, kMapHeight);
  for (int k = 0; k < r.splitCount(); ++k) {
    const SplitViewport v = r.splitViewport(k, kMapWidth, kMapHeight);
    renderer.renderDepth(r.splits[static_cast<std::size_t>(k)].rectClipFromWorld, s.mapTexture.get(), v.layer,
                         v.x, v.y, v.width, v.height, {.depthClamp = true});
  }
  s.layout = std::make_shared<const ProjectiveLayout>(std::move(r));
  s.map = makeRectifiedMap(s.layout, scenes::readDepthTexture(s.mapTexture.get(), kMapWidth, kMapHeight));
  s.cameraTexture = scenes::createDepthTexture(kWidth, kHeight);
  renderer.renderDepth(s.scene.camera.clipFromWorld(), s.cameraTexture.get(), 0, 0, 0, kWidth, kHeight);
  s.cameraDepth = scenes::readDepthTexture(s.cameraTexture.get(), kWidth, kHeight);
  return s;
}

/// A work list whose coordinates texture is width x height (x, y, d, z per texel) and whose entries are
/// `texels`, written from the CPU: header (ceil(count / 64), 1, 1, count), then x | y << 16 per entry.
struct TestList {
  gl::Handle buffer, coordinates, output;
  gpu::SampleList list;
};

TestList makeList(int width, int height, const std::vector<float>& coordinates,
                  const std::vector<glm::ivec2>& texels) {
  TestList t;
  t.buffer = gpu::createSampleListBuffer(width * height);
  t.coordinates = gl::createTexture2D(GL_RGBA32F, width, height);
  glTextureSubImage2D(t.coordinates.get(), 0, 0, 0, width, height, GL_RGBA, GL_FLOAT, coordinates.data());
  t.output = gl::createTexture2D(GL_RGBA32F, width, height);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float fill[4] = {nan, nan, nan, nan};
  glClearTexImage(t.output.get(), 0, GL_RGBA, GL_FLOAT, fill);
  const auto count = static_cast<std::uint32_t>(texels.size());
  std::vector<std::uint32_t> data{(count + 63) / 64, 1, 1, count};
  for (const glm::ivec2& p : texels)
    data.push_back(static_cast<std::uint32_t>(p.x) | (static_cast<std::uint32_t>(p.y) << 16));
  glNamedBufferSubData(t.buffer.get(), 0, static_cast<GLsizeiptr>(data.size() * 4), data.data());
  t.list = {t.buffer.get(), t.coordinates.get(), t.output.get(), width, height, width * height};
  return t;
}

/// The coordinates of every pixel centre of a camera depth image (z: not read by the pass, 0 here).
std::vector<float> pixelCoordinates(const Image& depth) {
  std::vector<float> c;
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x)
      c.insert(c.end(), {x + 0.5f, y + 0.5f, depth.at(x, y), 0.0f});
  return c;
}

/// Runs the pass per pixel (list == null) or on `list`; returns the output (the list's when given).
Image runMarch(const SceneMaps& s, const RectifiedMarchPass::Mode mode, const TestList* list,
               std::uint32_t lightColors = 0) {
  MinMaxTreePass trees({kMapWidth, kMapHeight});
  trees.run(s.mapTexture.get());
  RectifiedMarchPass pass({kMapWidth, kMapHeight, mode});
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
  RectifiedMarchPass::FrameAttribs f;
  f.layout = s.layout.get();
  f.camera = &s.scene.camera;
  f.light = &s.scene.sun;
  f.medium = &s.scene.medium;
  f.rectifiedDepth = s.mapTexture.get();
  f.minMaxBuffer = trees.treeBuffer();
  f.lightColors = lightColors;
  if (list) {
    f.list = &list->list;
    f.imageWidth = kWidth;
    f.imageHeight = kHeight;
  } else {
    f.cameraDepth = s.cameraTexture.get();
    f.output = out.get();
  }
  pass.run(f);
  return list ? gl::readTexture(list->output.get(), list->list.width, list->list.height, gl::TexelData::Rgba)
              : gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba);
}

bool sameBits(float a, float b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

int bitDifferences(const Image& a, const Image& b) {
  REQUIRE(a.data().size() == b.data().size());
  int differ = 0;
  for (std::size_t i = 0; i < a.data().size(); ++i)
    if (std::memcmp(&a.data()[i], &b.data()[i], sizeof(float)) != 0) ++differ;
  return differ;
}

} // namespace

TEST_CASE("march list GL: a list of every pixel centre gives the per-pixel march bit for bit") {
  CREP_REQUIRE_GL();
  const SceneMaps s = renderScene("terrain");
  std::vector<glm::ivec2> all;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      all.push_back({x, y});
  // Entries in a scrambled order: the result does not depend on it.
  std::shuffle(all.begin(), all.end(), std::mt19937(3));
  for (const auto mode : {RectifiedMarchPass::Mode::MinMaxTree, RectifiedMarchPass::Mode::BruteForce}) {
    CAPTURE(static_cast<int>(mode));
    const TestList list = makeList(kWidth, kHeight, pixelCoordinates(s.cameraDepth), all);
    const Image perPixel = runMarch(s, mode, nullptr);
    const Image listed = runMarch(s, mode, &list);
    CHECK(gpu::sampleListCount(list.buffer.get()) == kWidth * kHeight);
    CHECK(bitDifferences(listed, perPixel) == 0);
    CHECK(compareImages(perPixel, perPixel).nanCount == 0);
  }
}

TEST_CASE("march list GL: a list of continuous positions matches the CPU min/max march at those samples") {
  CREP_REQUIRE_GL();
  const SceneMaps s = renderScene("colonnade");
  // 64 x 8 list texels at random continuous positions (a few beyond the border), each with the depth of the
  // pixel it falls in (the point sampling of epipolar sampling's coordinates).
  constexpr int kListWidth = 64, kListHeight = 8;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::vector<float> coordinates;
  std::vector<ScreenSample> samples;
  std::vector<glm::ivec2> texels;
  for (int y = 0; y < kListHeight; ++y)
    for (int x = 0; x < kListWidth; ++x) {
      const float px = static_cast<float>(uni(rng) * kWidth), py = static_cast<float>(uni(rng) * kHeight);
      const int qx = std::clamp(static_cast<int>(px), 0, kWidth - 1),
                qy = std::clamp(static_cast<int>(py), 0, kHeight - 1);
      const float d = s.cameraDepth.at(qx, qy);
      coordinates.insert(coordinates.end(), {px, py, d, 0.0f});
      samples.push_back({px, py, d});
      texels.push_back({x, y});
    }
  const TestList list = makeList(kListWidth, kListHeight, coordinates, texels);
  const Image gpu = runMarch(s, RectifiedMarchPass::Mode::MinMaxTree, &list);
  const MinMaxTrees trees(s.map.depth);
  const MarchResult cpu =
      minMaxMarch(s.map, trees, samples, kWidth, kHeight, s.scene.camera, s.scene.sun, s.scene.medium);
  Image gpuRow(kListWidth * kListHeight, 1, 4); // the list texels in sample order
  for (int i = 0; i < kListWidth * kListHeight; ++i)
    for (int c = 0; c < 4; ++c)
      gpuRow.at(i, 0, c) = gpu.at(i % kListWidth, i / kListWidth, c);
  // MarchGLTest's GPU-vs-CPU tolerance (float ray depth and distances: a texel within rounding of z_r may
  // flip).
  const ImageMetrics m = rgbMetrics(gpuRow, cpu.scattering);
  report("colonnade, 512 continuous samples: GPU list vs CPU minMaxMarch", m);
  CHECK(m.nanCount == 0);
  CHECK(m.peak > 0.0);
  ImageTolerance t;
  t.relativeRmse = 1e-3;
  t.maxAbsError = 0.02 * m.peak;
  t.overThreshold = 1e-4 * m.peak;
  t.maxFractionOver = 0.01;
  CHECK(checkImage(rgb(gpuRow), rgb(cpu.scattering), t, "epipolar_march_list_vs_cpu"));
}

TEST_CASE("march list GL: only the entries are written, and an empty list writes nothing") {
  CREP_REQUIRE_GL();
  const SceneMaps s = renderScene("terrain");
  const Image perPixel = runMarch(s, RectifiedMarchPass::Mode::MinMaxTree, nullptr);
  std::vector<glm::ivec2> some;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      if ((x * 7 + y * 3) % 5 == 0) some.push_back({x, y});
  const TestList list = makeList(kWidth, kHeight, pixelCoordinates(s.cameraDepth), some);
  const Image out = runMarch(s, RectifiedMarchPass::Mode::MinMaxTree, &list);
  int nanAtEntries = 0, writtenElsewhere = 0, differ = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const bool entry = (x * 7 + y * 3) % 5 == 0;
      for (int c = 0; c < 4; ++c) {
        const float v = out.at(x, y, c);
        if (entry && std::isnan(v)) ++nanAtEntries;
        if (!entry && !std::isnan(v)) ++writtenElsewhere;
        if (entry && !sameBits(v, perPixel.at(x, y, c))) ++differ;
      }
    }
  MESSAGE(some.size() << " entries of " << kWidth * kHeight << " texels");
  CHECK(nanAtEntries == 0);
  CHECK(writtenElsewhere == 0);
  CHECK(differ == 0);

  const TestList empty = makeList(kWidth, kHeight, pixelCoordinates(s.cameraDepth), {});
  const Image none = runMarch(s, RectifiedMarchPass::Mode::BruteForce, &empty);
  int written = 0;
  for (const float v : none.data())
    if (!std::isnan(v)) ++written;
  CHECK(written == 0);
  CHECK(gpu::sampleListCount(empty.buffer.get()) == 0);
}

TEST_CASE("march list GL: bad list attributes get a named InvalidArgument") {
  CREP_REQUIRE_GL();
  const SceneMaps s = renderScene("terrain");
  const TestList list = makeList(8, 4, std::vector<float>(8 * 4 * 4, 0.5f), {{0, 0}});
  MinMaxTreePass trees({kMapWidth, kMapHeight});
  trees.run(s.mapTexture.get());
  RectifiedMarchPass pass({kMapWidth, kMapHeight, RectifiedMarchPass::Mode::MinMaxTree});
  RectifiedMarchPass::FrameAttribs f;
  f.layout = s.layout.get();
  f.camera = &s.scene.camera;
  f.light = &s.scene.sun;
  f.medium = &s.scene.medium;
  f.rectifiedDepth = s.mapTexture.get();
  f.minMaxBuffer = trees.treeBuffer();
  f.list = &list.list;
  const auto parameter = [&](const RectifiedMarchPass::FrameAttribs& a) {
    try {
      pass.run(a);
    } catch (const InvalidArgument& e) {
      return e.parameter();
    }
    return std::string("no exception");
  };
  // No image size and no camera depth.
  CHECK(parameter(f) == "RectifiedMarchPass::FrameAttribs.cameraDepth");
  f.imageWidth = kWidth;
  CHECK(parameter(f) == "RectifiedMarchPass::FrameAttribs.imageWidth/imageHeight");
  f.imageHeight = kHeight;
  CHECK(parameter(f) == "no exception");
  gpu::SampleList wrong = list.list;
  wrong.width = 16; // not the textures' size
  f.list = &wrong;
  CHECK(parameter(f) == "RectifiedMarchPass::FrameAttribs.list.coordinates");
  wrong = list.list;
  wrong.buffer = 0;
  CHECK(parameter(f) == "RectifiedMarchPass::FrameAttribs.list.buffer");
  // The image size taken from the camera depth instead.
  f.list = &list.list;
  f.imageWidth = f.imageHeight = 0;
  f.cameraDepth = s.cameraTexture.get();
  CHECK(parameter(f) == "no exception");
}

TEST_CASE("march list GL: the list variant composes with a light texture's colour map") {
  CREP_REQUIRE_GL();
  const SceneMaps s = renderScene("terrain");
  // A smooth colour gradient over the map's texels (crep::lightColorMap's role).
  std::vector<float> rgba;
  for (int j = 0; j < kMapHeight; ++j)
    for (int i = 0; i < kMapWidth; ++i)
      rgba.insert(rgba.end(), {0.5f + 0.5f * i / kMapWidth, 1.0f - 0.5f * j / kMapHeight, 0.75f, 1.0f});
  const gl::Handle colors = gl::createTexture2D(GL_RGBA32F, kMapWidth, kMapHeight);
  glTextureSubImage2D(colors.get(), 0, 0, 0, kMapWidth, kMapHeight, GL_RGBA, GL_FLOAT, rgba.data());
  std::vector<glm::ivec2> all;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      all.push_back({x, y});
  for (const auto mode : {RectifiedMarchPass::Mode::MinMaxTree, RectifiedMarchPass::Mode::BruteForce}) {
    CAPTURE(static_cast<int>(mode));
    const TestList list = makeList(kWidth, kHeight, pixelCoordinates(s.cameraDepth), all);
    const Image perPixel = runMarch(s, mode, nullptr, colors.get());
    const Image listed = runMarch(s, mode, &list, colors.get());
    CHECK(bitDifferences(listed, perPixel) == 0);
    // The colours do change the result.
    CHECK(bitDifferences(perPixel, runMarch(s, mode, nullptr)) > 0);
  }
}

TEST_CASE("march list GL: the list variant composes with a local light (spot)") {
  CREP_REQUIRE_GL();
  constexpr int W = 512, H = 256;
  const Camera camera = groundCamera(kWidth, kHeight);
  const Image depth = groundDepth(camera, kWidth, kHeight);
  const Medium medium = colouredMedium();
  RectifyOptions ro;
  ro.splits = 8;
  const SpotLight spot = analyticSpot();
  const LocalLight light = LocalLight::spot(spot);
  const auto layout = std::make_shared<const ProjectiveLayout>(rectify(camera, spot, ro));
  const RectifiedMap map = castRectifiedMap(layout, W, H, wallHitFromLight);
  const gl::Handle mapTexture = gl::createTexture2D(GL_R32F, W, H);
  glTextureSubImage2D(mapTexture.get(), 0, 0, 0, W, H, GL_RED, GL_FLOAT, map.depth.data().data());
  const gl::Handle depthTexture = gl::createTexture2D(GL_R32F, kWidth, kHeight);
  glTextureSubImage2D(depthTexture.get(), 0, 0, 0, kWidth, kHeight, GL_RED, GL_FLOAT, depth.data().data());
  MinMaxTreePass trees({W, H});
  trees.run(mapTexture.get());
  std::vector<glm::ivec2> all;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      all.push_back({x, y});
  for (const auto mode : {RectifiedMarchPass::Mode::MinMaxTree, RectifiedMarchPass::Mode::BruteForce}) {
    CAPTURE(static_cast<int>(mode));
    RectifiedMarchPass pass({W, H, mode});
    const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
    RectifiedMarchPass::FrameAttribs a;
    a.layout = layout.get();
    a.camera = &camera;
    a.medium = &medium;
    a.cameraDepth = depthTexture.get();
    a.rectifiedDepth = mapTexture.get();
    a.minMaxBuffer = trees.treeBuffer();
    a.output = out.get();
    a.localLight = &light;
    pass.run(a);
    const TestList list = makeList(kWidth, kHeight, pixelCoordinates(depth), all);
    a.list = &list.list; // the image size from cameraDepth
    pass.run(a);
    const Image perPixel = gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba);
    const Image listed = gl::readTexture(list.output.get(), kWidth, kHeight, gl::TexelData::Rgba);
    CHECK(bitDifferences(listed, perPixel) == 0);
    CHECK(rgbMetrics(perPixel, perPixel).peak > 0.0);
  }
}
