// RectifiedMarchPass on GPU work lists (FrameAttribs::list, crep/scatter/gpu_sample_list.h): the marched
// samples of epipolar sampling (Yusov 2012, Sec. 6.4). A list of every pixel centre gives the per-pixel
// pass's output bit for bit (tree and brute force); a list of arbitrary continuous positions matches the
// CPU minMaxMarch at those samples (crep::screenRay's rays) within the GPU-vs-CPU march tolerance of
// MarchGLTest; only the entries' texels are written; an empty list writes nothing. The lists are filled
// from the CPU (common/sample_list_util.h: header, then the entries).
#include "common/analytic_reference.h"
#include "common/error_checks.h"
#include "common/gl_fixture.h"
#include "common/gl_scene_maps.h"
#include "common/image_check.h"
#include "common/local_light_scene.h"
#include "common/sample_list_util.h"

#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/gpu/gl.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/gpu_sample_list.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kWidth = 160, kHeight = 90;        // camera image
constexpr int kMapWidth = 256, kMapHeight = 128; // projective map (4 splits of 64 columns)

/// The scene and its GPU-rendered map at the sizes above (common/gl_scene_maps.h).
SceneMaps renderScene(const std::string& name) {
  return renderSceneMaps(name, kWidth, kHeight, kMapWidth, kMapHeight);
}

/// Runs the pass per pixel (list == null) or on `list`; returns the output (the list's when given).
Image runMarch(const SceneMaps& s, const RectifiedMarchPass::Mode mode, const TestList* list,
               std::uint32_t lightColors = 0) {
  MinMaxTreePass trees({kMapWidth, kMapHeight});
  trees.run(s.mapTexture.get());
  RectifiedMarchPass pass({kMapWidth, kMapHeight, mode});
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
  RectifiedMarchPass::FrameAttribs f = marchAttribs(s, trees.treeBuffer());
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

} // namespace

TEST_CASE("march list GL: a list of every pixel centre gives the per-pixel march bit for bit") {
  CREP_REQUIRE_GL();
  const SceneMaps s = renderScene("terrain");
  std::vector<glm::ivec2> all = texelsWhere(kWidth, kHeight);
  // Entries in a scrambled order: the result does not depend on it.
  std::shuffle(all.begin(), all.end(), std::mt19937(3));
  for (const auto mode : {RectifiedMarchPass::Mode::MinMaxTree, RectifiedMarchPass::Mode::BruteForce}) {
    CAPTURE(static_cast<int>(mode));
    const TestList list = makePixelList(s.cameraDepth, all);
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
  const TestList list = makeTestList(kListWidth, kListHeight, coordinates, texels);
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
  const auto entry = [](int x, int y) { return (x * 7 + y * 3) % 5 == 0; };
  const std::vector<glm::ivec2> some = texelsWhere(kWidth, kHeight, entry);
  const TestList list = makePixelList(s.cameraDepth, some);
  const Image out = runMarch(s, RectifiedMarchPass::Mode::MinMaxTree, &list);
  const ListWrites w = listWrites(out, perPixel, entry);
  MESSAGE(some.size() << " entries of " << kWidth * kHeight << " texels");
  CHECK(w.nanAtEntries == 0);
  CHECK(w.writtenElsewhere == 0);
  CHECK(w.differ == 0);

  const TestList empty = makePixelList(s.cameraDepth, {});
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
  const TestList list = makeTestList(8, 4, std::vector<float>(8 * 4 * 4, 0.5f), {{0, 0}});
  MinMaxTreePass trees({kMapWidth, kMapHeight});
  trees.run(s.mapTexture.get());
  RectifiedMarchPass pass({kMapWidth, kMapHeight, RectifiedMarchPass::Mode::MinMaxTree});
  RectifiedMarchPass::FrameAttribs f = marchAttribs(s, trees.treeBuffer());
  f.list = &list.list;
  const auto parameter = [&](const RectifiedMarchPass::FrameAttribs& a) {
    return invalidParameter([&] { pass.run(a); });
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
  const std::vector<glm::ivec2> all = texelsWhere(kWidth, kHeight);
  for (const auto mode : {RectifiedMarchPass::Mode::MinMaxTree, RectifiedMarchPass::Mode::BruteForce}) {
    CAPTURE(static_cast<int>(mode));
    const TestList list = makePixelList(s.cameraDepth, all);
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
  const SpotMaps spot = uploadSpotMaps(kWidth, kHeight, W, H);
  MinMaxTreePass trees({W, H});
  trees.run(spot.mapTexture.get());
  for (const auto mode : {RectifiedMarchPass::Mode::MinMaxTree, RectifiedMarchPass::Mode::BruteForce}) {
    CAPTURE(static_cast<int>(mode));
    RectifiedMarchPass pass({W, H, mode});
    const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
    RectifiedMarchPass::FrameAttribs a;
    a.layout = spot.layout.get();
    a.camera = &spot.camera;
    a.medium = &spot.medium;
    a.cameraDepth = spot.depthTexture.get();
    a.rectifiedDepth = spot.mapTexture.get();
    a.minMaxBuffer = trees.treeBuffer();
    a.output = out.get();
    a.localLight = &spot.light;
    checkListEqualsPerPixel(spot.depth, out.get(), [&](const gpu::SampleList* list) {
      a.list = list; // the image size from cameraDepth
      pass.run(a);
    });
  }
}
