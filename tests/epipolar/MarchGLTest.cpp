// The marches on the built-in scenes: projective rectified maps rasterized with the split matrices
// (SceneRenderer, GL_DEPTH_CLAMP), camera depth rasterized too. CPU: the min/max march equals the brute-force
// march of the same map to float precision, with fewer steps on terrain than on forest. GPU (compute passes
// on llvmpipe): trees bit-identical to the CPU's, tree march = brute-force march, both against the CPU
// reference; the world-space march pass against the CPU world-space march.
#include "common/analytic_reference.h"
#include "common/gl_fixture.h"
#include "common/gl_scene_maps.h"
#include "common/image_check.h"

#include <crep/core/error.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/gpu/gl.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cmath>
#include <map>
#include <string>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kWidth = 160, kHeight = 90;        // camera image
constexpr int kMapWidth = 256, kMapHeight = 128; // rectified map (4 splits of 64 columns)

/// The scene and its GPU-rendered map at the sizes above (common/gl_scene_maps.h).
SceneMaps renderScene(const std::string& name) {
  return renderSceneMaps(name, kWidth, kHeight, kMapWidth, kMapHeight);
}

struct GpuMarch {
  Image scattering, steps;
};

GpuMarch gpuMarch(const SceneMaps& s, RectifiedMarchPass::Mode mode) {
  MinMaxTreePass trees({kMapWidth, kMapHeight});
  trees.run(s.mapTexture.get());
  RectifiedMarchPass pass({kMapWidth, kMapHeight, mode});
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight),
                   steps = gl::createTexture2D(GL_R32F, kWidth, kHeight);
  RectifiedMarchPass::FrameAttribs f = marchAttribs(s, trees.treeBuffer());
  f.cameraDepth = s.cameraTexture.get();
  f.output = out.get();
  f.stepsOutput = steps.get();
  pass.run(f);
  return {gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba),
          gl::readTexture(steps.get(), kWidth, kHeight, gl::TexelData::Red)};
}

} // namespace

TEST_CASE(
    "epipolar march GL: min/max march equals brute force on the built-in scenes, fewer steps on terrain") {
  CREP_REQUIRE_GL();
  std::map<std::string, double> treeSteps;
  for (const std::string name : {"colonnade", "forest", "terrain", "boxes"}) {
    CAPTURE(name);
    const SceneMaps s = renderScene(name);
    const MarchResult tree = minMaxMarch(s.map, s.cameraDepth, s.scene.camera, s.scene.sun, s.scene.medium);
    const MarchResult brute =
        bruteForceMarch(s.map, s.cameraDepth, s.scene.camera, s.scene.sun, s.scene.medium);
    const double rel = maxRelativeDifference(tree.scattering, brute.scattering, 1e-6);
    const ImageMetrics m = compareImages(tree.scattering, brute.scattering);
    // Equal lit sets, sums grouped differently in double, stored as float: at most one float ulp.
    CHECK(rel < 1e-6);
    CHECK(m.maxAbsError <= 1e-6 * m.peak);
    const MarchResult empty =
        bruteForceMarch(makeRectifiedMap(s.layout, Image(kMapWidth, kMapHeight, 1, 1.0f)), s.cameraDepth,
                        s.scene.camera, s.scene.sun, s.scene.medium);
    const double shadowed = 1.0 - rgbMetrics(tree.scattering, Image(kWidth, kHeight, 4)).rmse /
                                      rgbMetrics(empty.scattering, Image(kWidth, kHeight, 4)).rmse;
    MESSAGE(name << ": tree vs brute max relative difference " << rel << "; mean steps per pixel: tree "
                 << tree.meanSteps() << " (max " << tree.maxSteps() << "), brute force " << brute.meanSteps()
                 << " (max " << brute.maxSteps() << "); shadowed fraction of the RMS radiance " << shadowed);
    CHECK(tree.meanSteps() < brute.meanSteps());
    // The default views of terrain and boxes have little shadow in the medium (0.1% of the RMS radiance),
    // colonnade 20%, forest 5%.
    CHECK(shadowed > 5e-4);
    // Against the world-space march of a standard 512^2 shadow map (a reference that does not depend on
    // the rectification; 64 sections): both maps' discretization. Measured relative RMSE: colonnade 2.3%,
    // forest 3.6%, terrain 0.29%, boxes 0.29% (1024^2 and 128 sections: 1.4%, 3.0%, 0.29%, 0.29%).
    scenes::SceneRenderer renderer(s.scene.mesh);
    const glm::dmat4 lightMatrix =
        scenes::standardLightClipFromWorld(s.scene.sun, s.scene.boundsMin, s.scene.boundsMax);
    WorldMarchOptions wo;
    wo.steps = 64;
    wo.bias = 1e-4;
    const MarchResult world =
        worldSpaceMarch(renderer.renderDepthImage(lightMatrix, 512, 512, {.depthClamp = true}), lightMatrix,
                        s.cameraDepth, s.scene.camera, s.scene.sun, s.scene.medium, wo);
    ImageTolerance t;
    t.relativeRmse = 0.05;
    CHECK(checkImage(rgb(tree.scattering), rgb(world.scattering), t, "epipolar_rectified_vs_world_" + name));
    report(name + " rectified min/max march vs world-space march",
           rgbMetrics(tree.scattering, world.scattering));
    treeSteps[name] = tree.meanSteps();
  }
  CHECK(treeSteps["terrain"] < treeSteps["forest"]);
}

TEST_CASE("epipolar march GL: GPU trees are bit-identical to the CPU trees") {
  CREP_REQUIRE_GL();
  const SceneMaps s = renderScene("forest");
  MinMaxTreePass pass({kMapWidth, kMapHeight});
  pass.run(s.mapTexture.get());
  const MinMaxTrees cpu(s.map.depth);
  const std::vector<float> gpu = pass.readNodes();
  REQUIRE(gpu.size() == cpu.data().size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < gpu.size(); ++i)
    differ += gpu[i] != cpu.data()[i];
  CHECK(differ == 0);
  CHECK(pass.levels() == 8);
  // A width that is not a power of two (the last node of a level covers fewer texels).
  const int W = 200, H = 5;
  Image depth(W, H, 1);
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i)
      depth.at(i, j) = static_cast<float>(((i * 37 + j * 11) % 101) / 100.0);
  const gl::Handle texture = gl::createTexture2D(GL_R32F, W, H);
  glTextureSubImage2D(texture.get(), 0, 0, 0, W, H, GL_RED, GL_FLOAT, depth.data().data());
  MinMaxTreePass odd({W, H});
  odd.run(texture.get());
  const std::vector<float> oddGpu = odd.readNodes();
  const MinMaxTrees oddCpu(depth);
  REQUIRE(oddGpu.size() == oddCpu.data().size());
  CHECK(std::equal(oddGpu.begin(), oddGpu.end(), oddCpu.data().begin()));
  // Rows of 10 levels (1024 texels, and 1000: not a power of two): the build's first phase then covers
  // levels 1-4 per invocation (glsl/passes/epipolar/minmax_build.comp), the rest with a barrier per level.
  for (const int wide : {1024, 1000}) {
    CAPTURE(wide);
    Image row(wide, 3, 1);
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < wide; ++i)
        row.at(i, j) = static_cast<float>(((i * 7919 + j * 104729) % 1009) / 1008.0);
    const gl::Handle rowTexture = gl::createTexture2D(GL_R32F, wide, 3);
    glTextureSubImage2D(rowTexture.get(), 0, 0, 0, wide, 3, GL_RED, GL_FLOAT, row.data().data());
    MinMaxTreePass rowPass({wide, 3});
    rowPass.run(rowTexture.get());
    CHECK(rowPass.levels() == 10);
    const std::vector<float> rowGpu = rowPass.readNodes();
    const MinMaxTrees rowCpu(row);
    REQUIRE(rowGpu.size() == rowCpu.data().size());
    CHECK(std::equal(rowGpu.begin(), rowGpu.end(), rowCpu.data().begin()));
  }
}

TEST_CASE("epipolar march GL: a block marches exactly the pixels of its disc, nothing else") {
  CREP_REQUIRE_GL();
  const SceneMaps s = renderScene("forest");
  MinMaxTreePass trees({kMapWidth, kMapHeight});
  trees.run(s.mapTexture.get());
  const GpuMarch whole = gpuMarch(s, RectifiedMarchPass::Mode::MinMaxTree);
  RectifiedMarchPass pass({kMapWidth, kMapHeight, RectifiedMarchPass::Mode::MinMaxTree});
  const glm::dvec2 centre(150.3, 20.7); // the disc crosses the right edge
  const double radius = 17.5;
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
  const float sentinel[4] = {-7.0f, -7.0f, -7.0f, -7.0f};
  glClearTexImage(out.get(), 0, GL_RGBA, GL_FLOAT, sentinel);
  RectifiedMarchPass::FrameAttribs f = marchAttribs(s, trees.treeBuffer());
  f.cameraDepth = s.cameraTexture.get();
  f.output = out.get();
  f.blockCenter = centre;
  f.blockRadius = radius;
  pass.run(f);
  const Image block = gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba);
  int inside = 0, insideDiffer = 0, outsideWritten = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const bool in = std::hypot(x + 0.5 - centre.x, y + 0.5 - centre.y) <= radius;
      inside += in;
      for (int c = 0; c < 4; ++c) {
        if (in)
          insideDiffer += block.at(x, y, c) != whole.scattering.at(x, y, c);
        else
          outsideWritten += block.at(x, y, c) != -7.0f;
      }
    }
  MESSAGE(inside << " pixels in the disc");
  CHECK(inside > 500);
  CHECK(insideDiffer == 0);
  CHECK(outsideWritten == 0);
  // A disc off the image writes nothing; a block with a work list, or a non-finite one, is refused.
  f.blockCenter = glm::dvec2(-100.0, -100.0);
  pass.run(f);
  CHECK(gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba).at(0, 0, 0) == -7.0f);
  f.blockRadius = std::nan("");
  CHECK_THROWS_WITH_AS(pass.run(f),
                       doctest::Contains("RectifiedMarchPass::FrameAttribs.blockCenter/blockRadius"),
                       InvalidArgument);
}

TEST_CASE("epipolar march GL: GPU tree and brute-force marches agree with each other and with the CPU") {
  CREP_REQUIRE_GL();
  for (const std::string name : {"terrain", "colonnade"}) {
    CAPTURE(name);
    const SceneMaps s = renderScene(name);
    const GpuMarch tree = gpuMarch(s, RectifiedMarchPass::Mode::MinMaxTree);
    const GpuMarch brute = gpuMarch(s, RectifiedMarchPass::Mode::BruteForce);
    const MarchResult cpu = minMaxMarch(s.map, s.cameraDepth, s.scene.camera, s.scene.sun, s.scene.medium);
    // Same float operations on the same lit texels, summed in different groups: float rounding only.
    const ImageMetrics same = rgbMetrics(tree.scattering, brute.scattering);
    report(name + " GPU tree vs GPU brute force", same);
    CHECK(same.relativeRmse < 1e-5);
    CHECK(same.maxAbsError < 1e-5 * same.peak);
    // Against the CPU (double): the ray depth z_r and the distances in float. A texel whose depth is
    // within float rounding of z_r may flip (the surface the ray ends on is in the map too), which moves
    // one texel's section. Measured: terrain relative RMSE 2e-6 / max abs 3e-7 (peak 0.35).
    const ImageMetrics vsCpu = rgbMetrics(tree.scattering, cpu.scattering);
    report(name + " GPU tree vs CPU", vsCpu);
    ImageTolerance t;
    t.relativeRmse = 1e-3;
    t.maxAbsError = 0.02 * vsCpu.peak;
    t.overThreshold = 1e-4 * vsCpu.peak;
    t.maxFractionOver = 0.01;
    CHECK(checkImage(rgb(tree.scattering), rgb(cpu.scattering), t, "epipolar_gpu_tree_vs_cpu_" + name));
    // Steps: the same traversal, so the same counts except where a comparison flipped.
    const ImageMetrics steps = compareImages(tree.steps, cpu.steps);
    MESSAGE(name << ": GPU steps differ from the CPU's at " << steps.fractionOver * 100.0
                 << "% of the pixels; mean steps GPU " << cpu.meanSteps());
    CompareOptions o;
    o.overThreshold = 0.5;
    CHECK(compareImages(tree.steps, cpu.steps, o).fractionOver < 0.01);
    CHECK(compareImages(brute.steps, tree.steps).meanAbsError > 1.0); // brute force does more
  }
}

TEST_CASE("epipolar world march GL: the GPU pass agrees with the CPU world-space march") {
  CREP_REQUIRE_GL();
  const scenes::Scene scene = scenes::makeScene("boxes", static_cast<double>(kWidth) / kHeight);
  scenes::SceneRenderer renderer(scene.mesh);
  const glm::dmat4 lightMatrix =
      scenes::standardLightClipFromWorld(scene.sun, scene.boundsMin, scene.boundsMax);
  const int S = 512;
  const gl::Handle shadow = scenes::createDepthTexture(S, S);
  renderer.renderDepth(lightMatrix, shadow.get(), 0, 0, 0, S, S, {.depthClamp = true});
  const gl::Handle camera = scenes::createDepthTexture(kWidth, kHeight);
  renderer.renderDepth(scene.camera.clipFromWorld(), camera.get(), 0, 0, 0, kWidth, kHeight);
  const Image shadowDepth = scenes::readDepthTexture(shadow.get(), S, S);
  const Image cameraDepth = scenes::readDepthTexture(camera.get(), kWidth, kHeight);
  const double bias = 1e-4;

  WorldMarchOptions o;
  o.steps = 64;
  o.refinements = 12;
  o.bias = bias;
  const MarchResult cpu =
      worldSpaceMarch(shadowDepth, lightMatrix, cameraDepth, scene.camera, scene.sun, scene.medium, o);

  WorldMarchPass pass({64, 12});
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight),
                   steps = gl::createTexture2D(GL_R32F, kWidth, kHeight);
  WorldMarchPass::FrameAttribs f;
  f.camera = &scene.camera;
  f.light = &scene.sun;
  f.medium = &scene.medium;
  f.cameraDepth = camera.get();
  f.shadowMap = shadow.get();
  f.lightClipFromWorld = lightMatrix;
  f.bias = bias;
  f.output = out.get();
  f.stepsOutput = steps.get();
  pass.run(f);
  const Image gpu = gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba);
  const ImageMetrics m = rgbMetrics(gpu, cpu.scattering);
  report("boxes: GPU world march vs CPU", m);
  // Float ray positions move a sample across a shadow-map texel edge now and then: the change point then
  // lands in a neighbouring section. Measured: relative RMSE 1e-4.
  ImageTolerance t;
  t.relativeRmse = 2e-3;
  t.overThreshold = 1e-3 * m.peak;
  t.maxFractionOver = 0.02;
  CHECK(checkImage(rgb(gpu), rgb(cpu.scattering), t, "epipolar_gpu_world_march"));
  CHECK(cpu.meanSteps() > 65.0); // N + 1 lookups plus the bisections

  // The epipole block: only the pixels within the radius are written.
  const gl::Handle blockOut = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
  const float minusOne[4] = {-1.0f, -1.0f, -1.0f, -1.0f};
  glClearTexImage(blockOut.get(), 0, GL_RGBA, GL_FLOAT, minusOne);
  f.output = blockOut.get();
  f.stepsOutput = 0;
  f.blockCenter = {40.0, 30.0};
  f.blockRadius = 10.0;
  pass.run(f);
  const Image block = gl::readTexture(blockOut.get(), kWidth, kHeight, gl::TexelData::Rgba);
  int inside = 0, wrong = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const bool in = glm::length(glm::dvec2(x + 0.5, y + 0.5) - f.blockCenter) <= f.blockRadius;
      inside += in;
      if (in != (block.at(x, y, 3) >= 0.0f)) ++wrong;
      if (in && block.at(x, y, 0) != gpu.at(x, y, 0)) ++wrong;
    }
  CHECK(inside > 300);
  CHECK(wrong == 0);
}
