// EvaluatePass on GPU work lists (FrameAttribs::list, crep/scatter/gpu_sample_list.h): the prefiltered
// evaluation of epipolar sampling's marched samples and corrections (Yusov 2012, Sec. 6.4 and 6.7). A list of
// every pixel centre gives the per-pixel pass's output bit for bit (projective and epipolar layouts, default
// options and the near-plane correction); a list of some pixels writes those texels only. The lists are
// filled from the CPU (common/sample_list_util.h: header, then the entries).
#include "common/analytic_reference.h"
#include "common/error_checks.h"
#include "common/gl_fixture.h"
#include "common/gl_scene_maps.h"
#include "common/local_light_scene.h"
#include "common/sample_list_util.h"

#include <crep/core/error.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/resample.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/gpu_sample_list.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kWidth = 160, kHeight = 90, kShadowSize = 512, kMapWidth = 256;

/// The colonnade scene: camera depth and its light's shadow map rasterized, the shadow map read back for
/// resampleShadowMap.
struct Scene {
  scenes::Scene scene = scenes::makeScene("colonnade", static_cast<double>(kWidth) / kHeight);
  gl::Handle cameraTexture;
  Image cameraDepth, shadow;
  glm::dmat4 lightMatrix{1.0};

  Scene() {
    scenes::SceneRenderer renderer(scene.mesh);
    cameraTexture = scenes::createDepthTexture(kWidth, kHeight);
    renderer.renderDepth(scene.camera.clipFromWorld(), cameraTexture.get(), 0, 0, 0, kWidth, kHeight);
    cameraDepth = scenes::readDepthTexture(cameraTexture.get(), kWidth, kHeight);
    lightMatrix = scenes::standardLightClipFromWorld(scene.sun, scene.boundsMin, scene.boundsMax);
    const gl::Handle shadowTexture = scenes::createDepthTexture(kShadowSize, kShadowSize);
    renderer.renderDepth(lightMatrix, shadowTexture.get(), 0, 0, 0, kShadowSize, kShadowSize,
                         {.depthClamp = true});
    shadow = scenes::readDepthTexture(shadowTexture.get(), kShadowSize, kShadowSize);
  }
};

/// The per-pixel output and the list's output of the same evaluation.
struct Outputs {
  Image perPixel, listed;
};

/// The list runs with `info`, the per-pixel pass with `pixelInfo` (default: `info`).
Outputs evaluateBoth(const Scene& s, const std::shared_ptr<const RectifiedLayout>& layout, int H,
                     const EvaluatePass::CreateInfo& info, const TestList& list,
                     const EvaluatePass::CreateInfo* pixelInfo = nullptr, bool textured = false) {
  const RectifiedMap map = resampleShadowMap(layout, kMapWidth, H, s.shadow, s.lightMatrix);
  const gl::Handle mapTexture = gl::createTexture2D(GL_R32F, kMapWidth, H);
  glTextureSubImage2D(mapTexture.get(), 0, 0, 0, kMapWidth, H, GL_RED, GL_FLOAT, map.depth.data().data());
  PrefilterPass::CreateInfo pi;
  pi.mapWidth = kMapWidth;
  pi.mapHeight = H;
  PrefilterPass prefilterPass(pi);
  PrefilterPass::FrameAttribs pf;
  pf.rectifiedDepth = mapTexture.get();
  pf.layout = layout.get();
  pf.medium = &s.scene.medium;
  gl::Handle colors;
  if (textured) { // a light texture's colour map: a smooth colour gradient over the map's texels
    std::vector<float> rgba;
    for (int j = 0; j < H; ++j)
      for (int i = 0; i < kMapWidth; ++i)
        rgba.insert(rgba.end(), {0.5f + 0.5f * i / kMapWidth, 1.0f - 0.5f * j / H, 0.75f, 1.0f});
    colors = gl::createTexture2D(GL_RGBA32F, kMapWidth, H);
    glTextureSubImage2D(colors.get(), 0, 0, 0, kMapWidth, H, GL_RGBA, GL_FLOAT, rgba.data());
    pf.lightColors = colors.get();
  }
  prefilterPass.run(pf);

  EvaluatePass pixelPass(pixelInfo ? *pixelInfo : info);
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
  EvaluatePass::FrameAttribs f;
  f.cameraDepth = s.cameraTexture.get();
  f.output = out.get();
  f.camera = &s.scene.camera;
  f.light = &s.scene.sun;
  f.medium = &s.scene.medium;
  f.layout = layout.get();
  f.basis = prefilterPass.filteredBasis();
  pixelPass.run(f);
  EvaluatePass pass(info);
  // The list: no camera depth (the image size given instead), output ignored.
  f.cameraDepth = 0;
  f.list = &list.list;
  f.imageWidth = kWidth;
  f.imageHeight = kHeight;
  pass.run(f);
  return {gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba),
          gl::readTexture(list.output.get(), kWidth, kHeight, gl::TexelData::Rgba)};
}

struct Layouts {
  std::string name;
  std::shared_ptr<const RectifiedLayout> layout;
  int height;
};

std::vector<Layouts> layoutsOf(const Scene& s) {
  RectifyOptions ro;
  ro.splits = 4;
  const auto projective = std::make_shared<const ProjectiveLayout>(rectify(s.scene.camera, s.scene.sun, ro));
  const auto epipolar = std::make_shared<const EpipolarLayout>(s.scene.camera, s.scene.sun, kWidth, kHeight);
  return {{"projective", projective, 128}, {"epipolar", epipolar, epipolar->sliceCount()}};
}

} // namespace

TEST_CASE("evaluate list GL: a list of every pixel gives the per-pixel evaluation bit for bit") {
  CREP_REQUIRE_GL();
  const Scene s;
  const std::vector<glm::ivec2> all = texelsWhere(kWidth, kHeight);
  for (const Layouts& l : layoutsOf(s))
    for (const bool near : {false, true}) { // the default table path and the direct near-plane path
      CAPTURE(l.name);
      CAPTURE(near);
      EvaluatePass::CreateInfo info;
      info.options.nearPlaneCorrection = near;
      const TestList list = makePixelList(s.cameraDepth, all);
      const Outputs r = evaluateBoth(s, l.layout, l.height, info, list);
      int nan = 0;
      for (const float v : r.perPixel.data())
        if (std::isnan(v)) ++nan;
      CHECK(nan == 0);
      CHECK(bitDifferences(r.listed, r.perPixel) == 0);
      CHECK(rgbMetrics(r.perPixel, r.perPixel).peak > 0.0);
    }
}

TEST_CASE("evaluate list GL: a list writes its entries only") {
  CREP_REQUIRE_GL();
  const Scene s;
  const auto entry = [](int x, int y) { return (x * 5 + y * 11) % 7 == 0; };
  const std::vector<glm::ivec2> some = texelsWhere(kWidth, kHeight, entry);
  for (const Layouts& l : layoutsOf(s)) {
    CAPTURE(l.name);
    const TestList list = makePixelList(s.cameraDepth, some);
    const Outputs r = evaluateBoth(s, l.layout, l.height, {}, list);
    const ListWrites w = listWrites(r.listed, r.perPixel, entry);
    MESSAGE(l.name << ": " << some.size() << " entries of " << kWidth * kHeight << " texels");
    CHECK(w.nanAtEntries == 0);
    CHECK(w.writtenElsewhere == 0);
    CHECK(w.differ == 0);
  }
}

TEST_CASE("evaluate list GL: the list variant composes with the pass's options and formats") {
  CREP_REQUIRE_GL();
  const Scene s;
  const std::vector<glm::ivec2> all = texelsWhere(kWidth, kHeight);
  const Layouts projective = layoutsOf(s)[0];
  struct Case {
    const char* name;
    EvaluatePass::CreateInfo info;
  };
  std::vector<Case> cases(6);
  cases[0].name = "no table (direct path)";
  cases[0].info.options.visibilityTableSamples = 0;
  cases[1].name = "visibility table without the prefix";
  cases[1].info.options.scatteringPrefix = false;
  cases[2].name = "nearest sampling";
  cases[2].info.options.sampling = Sampling::Nearest;
  cases[3].name = "memory limit (benchmark variant)";
  cases[3].info.memoryLimit = true;
  cases[4].name = "RGBA16F output format (the list still writes RGBA32F)";
  cases[4].info.outputFormat = StorageFormat::RGBA16F;
  cases[5].name = "light texture (textured basis, scattering prefix table)";
  for (const Case& c : cases) {
    CAPTURE(c.name);
    const bool textured = &c == &cases[5];
    const TestList list = makePixelList(s.cameraDepth, all);
    // The per-pixel reference in RGBA32F: the list's output format.
    EvaluatePass::CreateInfo pixelInfo = c.info;
    pixelInfo.outputFormat = StorageFormat::RGBA32F;
    const Outputs r =
        evaluateBoth(s, projective.layout, projective.height, c.info, list, &pixelInfo, textured);
    CHECK(bitDifferences(r.listed, r.perPixel) == 0);
    if (textured) CHECK(rgbMetrics(r.perPixel, r.perPixel).peak > 0.0);
  }
}

TEST_CASE("evaluate list GL: bad list attributes get a named InvalidArgument") {
  CREP_REQUIRE_GL();
  const Scene s;
  const Layouts projective = layoutsOf(s)[0];
  const RectifiedMap map = resampleShadowMap(projective.layout, kMapWidth, 128, s.shadow, s.lightMatrix);
  const gl::Handle mapTexture = gl::createTexture2D(GL_R32F, kMapWidth, 128);
  glTextureSubImage2D(mapTexture.get(), 0, 0, 0, kMapWidth, 128, GL_RED, GL_FLOAT, map.depth.data().data());
  PrefilterPass::CreateInfo pi;
  pi.mapWidth = kMapWidth;
  pi.mapHeight = 128;
  PrefilterPass prefilterPass(pi);
  PrefilterPass::FrameAttribs pf;
  pf.rectifiedDepth = mapTexture.get();
  pf.layout = projective.layout.get();
  pf.medium = &s.scene.medium;
  prefilterPass.run(pf);
  const TestList list = makePixelList(s.cameraDepth, {{1, 2}});
  EvaluatePass pass({});
  EvaluatePass::FrameAttribs f;
  f.camera = &s.scene.camera;
  f.light = &s.scene.sun;
  f.medium = &s.scene.medium;
  f.layout = projective.layout.get();
  f.basis = prefilterPass.filteredBasis();
  f.list = &list.list;
  const auto parameter = [&](const EvaluatePass::FrameAttribs& a) {
    return invalidParameter([&] { pass.run(a); });
  };
  CHECK(parameter(f) == "EvaluatePass::FrameAttribs.cameraDepth"); // no image size from anywhere
  f.imageHeight = kHeight;
  CHECK(parameter(f) == "EvaluatePass::FrameAttribs.imageWidth/imageHeight");
  f.imageWidth = kWidth;
  CHECK(parameter(f) == "no exception");
  gpu::SampleList wrong = list.list;
  wrong.height = 7;
  f.list = &wrong;
  CHECK(parameter(f) == "EvaluatePass::FrameAttribs.list.coordinates");
  wrong = list.list;
  wrong.buffer = 0;
  CHECK(parameter(f) == "EvaluatePass::FrameAttribs.list.buffer");
  wrong = list.list;
  wrong.output = 0;
  CHECK(parameter(f) == "EvaluatePass::FrameAttribs.list.output");
  // The image size of the camera depth instead.
  f.list = &list.list;
  f.imageWidth = f.imageHeight = 0;
  f.cameraDepth = s.cameraTexture.get();
  CHECK(parameter(f) == "no exception");
  const Image out = gl::readTexture(list.output.get(), kWidth, kHeight, gl::TexelData::Rgba);
  CHECK(std::isfinite(out.at(1, 2, 0)));
  CHECK(std::isnan(out.at(2, 1, 0)));
}

TEST_CASE("evaluate list GL: the list variant composes with a local light (spot)") {
  CREP_REQUIRE_GL();
  constexpr int W = 512, H = 256;
  const SpotMaps spot = uploadSpotMaps(kWidth, kHeight, W, H);
  PrefilterPass::CreateInfo pi;
  pi.mapWidth = W;
  pi.mapHeight = H;
  pi.options.regionsPerSplit = 2;
  PrefilterPass prefilterPass(pi);
  PrefilterPass::FrameAttribs pf;
  pf.rectifiedDepth = spot.mapTexture.get();
  pf.layout = spot.layout.get();
  pf.medium = &spot.medium;
  pf.localLight = &spot.light;
  prefilterPass.run(pf);
  for (const bool prefixTable : {true, false}) {
    CAPTURE(prefixTable);
    EvaluatePass::CreateInfo info;
    info.options.scatteringPrefix = prefixTable;
    EvaluatePass pass(info);
    const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
    EvaluatePass::FrameAttribs f;
    f.cameraDepth = spot.depthTexture.get();
    f.output = out.get();
    f.camera = &spot.camera;
    f.medium = &spot.medium;
    f.layout = spot.layout.get();
    f.basis = prefilterPass.filteredBasis();
    f.localLight = &spot.light;
    checkListEqualsPerPixel(spot.depth, out.get(), [&](const gpu::SampleList* list) {
      f.list = list; // the image size from cameraDepth
      pass.run(f);
    });
  }
}
