// The froxel fill of the prefiltered evaluation (EvaluatePass::FrameAttribs::froxels; CPU reference
// crep::evaluateFroxels; crep/prefilter/prefilter.h "Froxel volumes"): Klehm et al. 2014's per-ray
// evaluation at the sample points of a frustum-aligned volume (Wronski 2014).
//
// Set-up: the "boxes" scene seen by a reversed-Z camera with an infinite far plane ([0, 1] clip depth, the
// scene camera's pose, field of view and integration far): its depth-buffer values d = near / Z hold view
// depths to float precision (relative 6e-8), so a camera depth texture holding a slice's depth gives the
// per-pixel evaluation the same ray end as the volume (a standard depth buffer near 1 would lose up to
// 6e-8 Z / near of it). Map 256 x 64, 2 splits x 2 prefilter regions; grid 32 x 18 x 16 (camera image of
// the same 32 x 18 for the per-pixel runs).
#include "common/error_checks.h"
#include "common/gl_fixture.h"
#include "common/gl_util.h"
#include "common/image_check.h"

#include "common/prefilter_gpu.h"

#include <crep/core/error.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/prefilter/prefilter.h>
#include <crep/scatter/froxel_grid.h>
#include <crep/scatter/ray.h>
#include <crep/support/image_compare.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kMapW = 256, kMapH = 64, kSplits = 2;
constexpr int kGridW = 32, kGridH = 18, kGridD = 16;

/// The camera of `c` (pose, fovY, aspect, near, integration far) with a reversed-Z infinite projection.
Camera reversedInfinite(const Camera& c) {
  const double f = 1.0 / std::tan(0.5 * c.fovY());
  glm::dmat4 P(0.0); // column-major: P[column][row]
  P[0][0] = f / c.aspect();
  P[1][1] = f;
  P[2][3] = -1.0;     // clip w = -z_view = Z
  P[3][2] = c.near(); // clip z = near: depth = near / Z
  return Camera::fromMatrices(c.viewFromWorld(), P, ClipDepth::ZeroToOne, c.far());
}

struct FroxelScene {
  scenes::Scene scene;
  Camera camera;
  std::shared_ptr<const ProjectiveLayout> layout;
  gl::Handle mapTexture;
  RectifiedMap map;
};

/// The boxes scene's rectified map for the reversed-Z camera (an empty map: every texel at depth 1).
FroxelScene makeScene(bool empty = false) {
  scenes::Scene scene = scenes::makeScene("boxes", double(kGridW) / kGridH);
  const Camera camera = reversedInfinite(scene.camera);
  FroxelScene s{std::move(scene), camera, {}, {}, {}};
  RectifyOptions options;
  options.splits = kSplits;
  Rectification r = rectify(s.camera, s.scene.sun, options);
  INFO(r.message);
  REQUIRE(r.projective());
  s.layout = std::make_shared<const ProjectiveLayout>(std::move(r));
  s.mapTexture = scenes::createDepthTexture(kMapW, kMapH, "rectified map size");
  const float one = 1.0f;
  glClearTexImage(s.mapTexture.get(), 0, GL_DEPTH_COMPONENT, GL_FLOAT, &one);
  if (!empty) {
    scenes::SceneRenderer renderer(s.scene.mesh);
    for (int k = 0; k < s.layout->regionCount(); ++k) {
      const SplitViewport v = s.layout->rectification().splitViewport(k, kMapW, kMapH);
      renderer.renderDepth(s.layout->rectification().splits[static_cast<std::size_t>(k)].rectClipFromWorld,
                           s.mapTexture.get(), v.layer, v.x, v.y, v.width, v.height, {.depthClamp = true});
    }
  }
  s.map = makeRectifiedMap(s.layout, scenes::readDepthTexture(s.mapTexture.get(), kMapW, kMapH));
  return s;
}

const FroxelScene& boxes() {
  static const FroxelScene s = makeScene();
  return s;
}

PrefilterOptions prefilterOptions(StorageFormat format = StorageFormat::RGBA32F) {
  PrefilterOptions o;
  o.regionsPerSplit = 2;
  o.format = format;
  return o;
}

/// Number of samples that differ at all between two images of the same shape.
long long differingSamples(const Image& a, const Image& b) {
  REQUIRE(a.sameShape(b));
  long long n = 0;
  for (std::size_t i = 0; i < a.data().size(); ++i)
    n += a.data()[i] != b.data()[i] ? 1 : 0;
  return n;
}

/// Runs `pass` with a froxel target only.
void fill(EvaluatePass& pass, const FroxelScene& s, const FilteredBasisView& basis, std::uint32_t volume,
          const FroxelGrid& grid, const glm::dvec3& jitter, const RectifiedLayout* layout = nullptr) {
  EvaluatePass::FrameAttribs f;
  f.camera = &s.camera;
  f.light = &s.scene.sun;
  f.medium = &s.scene.medium;
  f.layout = layout != nullptr ? layout : s.layout.get();
  f.basis = basis;
  f.froxels = {volume, grid, jitter};
  pass.run(f);
}

FroxelGrid smallGrid() {
  FroxelGrid g;
  g.width = kGridW;
  g.height = kGridH;
  g.depth = kGridD;
  return g;
}

/// Compares with maxAbs and relative RMSE bounds relative to the reference's peak (RGB and A together).
ImageMetrics check(const Image& actual, const Image& reference, double maxAbsOfPeak, double relativeRmse,
                   const std::string& name) {
  double peak = 0.0;
  for (int y = 0; y < reference.height(); ++y)
    for (int x = 0; x < reference.width(); ++x)
      for (int c = 0; c < 3; ++c)
        peak = std::max(peak, static_cast<double>(std::abs(reference.at(x, y, c))));
  ImageTolerance t;
  t.maxAbsError = maxAbsOfPeak * peak;
  t.relativeRmse = relativeRmse;
  const ImageCheckResult r = evaluateImage(actual, reference, t, name);
  MESSAGE(std::string(name + ": " + r.message));
  CHECK_MESSAGE(r.passed, r.message);
  return r.metrics;
}

} // namespace

TEST_CASE("prefilter froxels: the fill equals the per-pixel evaluation at the cell centres") {
  CREP_REQUIRE_GL();
  const FroxelScene& s = boxes();
  const FroxelGrid grid = smallGrid();
  const FroxelDepthRange range = froxelDepthRange(grid, s.camera, "test");
  const FilteredBasis cpu = prefilter(s.map, s.scene.medium, prefilterOptions());
  const UploadedBasis basis = uploadBasis(cpu, StorageFormat::RGBA32F);
  for (const int option : {0, 1, 2}) {
    // 0: defaults (scattering prefix table), 1: near-plane correction (the direct path), 2: no table.
    EvaluatePass::CreateInfo info;
    info.options.nearPlaneCorrection = option == 1;
    if (option == 2) info.options.visibilityTableSamples = 0;
    const std::string name = std::string("froxel_vs_pixels_") + (option == 0   ? "prefix"
                                                                 : option == 1 ? "nearplane"
                                                                               : "no_table");
    EvaluatePass pass(info);
    const gl::Handle volume = createVolume(grid);
    fill(pass, s, basis.view, volume.get(), grid, glm::dvec3(0.0));
    const Image filled = readVolume(volume.get(), grid);
    // Per slice: a camera image of the grid's size whose depth buffer holds the slice's centre depth
    // (froxel_grid.h: Z = near (far / near)^((z + 0.5) / D), computed here in double).
    const gl::Handle output = gl::createTexture2D(GL_RGBA32F, kGridW, kGridH);
    Image perPixel(kGridW, kGridH * kGridD, 4);
    for (int z = 0; z < kGridD; ++z) {
      const double Z = range.near * std::pow(range.far / range.near, (z + 0.5) / kGridD);
      const Image depth(kGridW, kGridH, 1, static_cast<float>(s.camera.depthBufferValue(Z)));
      const gl::Handle depthTexture = uploadR32F(depth);
      EvaluatePass::FrameAttribs f;
      f.cameraDepth = depthTexture.get();
      f.output = output.get();
      f.camera = &s.camera;
      f.light = &s.scene.sun;
      f.medium = &s.scene.medium;
      f.layout = s.layout.get();
      f.basis = basis.view;
      pass.run(f);
      const Image p = readRgbaTexture(output.get(), kGridW, kGridH);
      for (int y = 0; y < kGridH; ++y)
        for (int x = 0; x < kGridW; ++x)
          for (int c = 0; c < 4; ++c)
            perPixel.at(x, z * kGridH + y, c) = p.at(x, y, c);
    }
    // The same shader code on the same rays; only the ray's end differs in float: Z from the depth value
    // (near / d) or from the slice coordinate (near exp2(w log2(far / near))), both within a few float ulps
    // (relative ~1e-6 of the distance). The in-scattering changes by at most about that relative amount
    // where it is smooth; a ray end sitting on a texel boundary of the basis moves the bilinear weight by
    // the same fraction of a texel. Bounds: max |d| <= 1e-5 of the peak, relative RMSE <= 2e-6.
    check(filled, perPixel, 1e-5, 2e-6, name);
  }
}

TEST_CASE("prefilter froxels: GPU fill equals the CPU reference, with and without jitter") {
  CREP_REQUIRE_GL();
  const FroxelScene& s = boxes();
  for (const StorageFormat format : {StorageFormat::RGBA32F, StorageFormat::RGBA8}) {
    const FilteredBasis cpu = prefilter(s.map, s.scene.medium, prefilterOptions(format));
    const UploadedBasis basis = uploadBasis(cpu, format);
    EvaluatePass pass(EvaluatePass::CreateInfo{});
    for (const int variant : {0, 1, 2}) {
      // 0: centres, 1: froxelJitter(7) (Halton), 2: jitter and an own depth range inside the camera's.
      FroxelGrid grid = smallGrid();
      glm::dvec3 jitter(0.0);
      if (variant >= 1) jitter = froxelJitter(7);
      if (variant == 2) {
        grid.nearDepth = 2.0 * s.camera.near();
        grid.farDepth = 0.6 * s.camera.far();
        jitter = glm::dvec3(-0.5, 0.5, 0.3);
      }
      const std::string name =
          std::string("froxel_cpu_") + storageFormatToken(format) + "_" + std::to_string(variant);
      const gl::Handle volume = createVolume(grid, format == StorageFormat::RGBA8 ? GL_RGBA16F : GL_RGBA32F);
      fill(pass, s, basis.view, volume.get(), grid, jitter);
      const Image reference = evaluateFroxels(cpu, grid, jitter, s.camera, s.scene.sun, s.scene.medium, {});
      // The per-pixel evaluation's tolerances (PrefilterGpuGLTest.cpp): float basis 2e-5 of the peak and
      // relative RMSE 2e-6 (float against double); RGBA8, llvmpipe filters unorm8 texels in 8-bit fixed
      // point: 1e-2 and 2e-3. The RGBA8 case writes an RGBA16F volume: binary16 rounds by 2^-11 relative
      // (4.9e-4), which the RGBA8 bounds cover.
      if (format == StorageFormat::RGBA8)
        check(readVolume(volume.get(), grid), reference, 1e-2, 2e-3, name);
      else
        check(readVolume(volume.get(), grid), reference, 2e-5, 2e-6, name);
    }
  }
}

TEST_CASE("prefilter froxels: jitter moves the sample points by the given fraction of a cell") {
  CREP_REQUIRE_GL();
  const FroxelScene& s = boxes();
  const FilteredBasis cpu = prefilter(s.map, s.scene.medium, prefilterOptions());
  const UploadedBasis basis = uploadBasis(cpu, StorageFormat::RGBA32F);
  EvaluatePass pass(EvaluatePass::CreateInfo{});
  // Cell (x, y, z) of a W x H x D grid jittered by +-1/4 samples (x + 0.5 +- 0.25) / W = (2 x + 1.5 +- 0.5)
  // / (2 W): the centre of cell 2 x + 1 (+) or 2 x (-) of the grid twice as fine over the same depth range,
  // exactly (a factor 2 is exact in float), so the two volumes agree bit for bit there.
  const FroxelGrid grid = smallGrid();
  FroxelGrid fine = grid;
  fine.width *= 2;
  fine.height *= 2;
  fine.depth *= 2;
  const gl::Handle fineVolume = createVolume(fine);
  fill(pass, s, basis.view, fineVolume.get(), fine, glm::dvec3(0.0));
  const Image fineImage = readVolume(fineVolume.get(), fine);
  for (const double j : {0.25, -0.25}) {
    const gl::Handle volume = createVolume(grid);
    fill(pass, s, basis.view, volume.get(), grid, glm::dvec3(j));
    const Image jittered = readVolume(volume.get(), grid);
    const int offset = j > 0.0 ? 1 : 0;
    long long differ = 0;
    for (int z = 0; z < grid.depth; ++z)
      for (int y = 0; y < grid.height; ++y)
        for (int x = 0; x < grid.width; ++x)
          for (int c = 0; c < 4; ++c)
            if (jittered.at(x, z * grid.height + y, c) !=
                fineImage.at(2 * x + offset, (2 * z + offset) * fine.height + 2 * y + offset, c))
              ++differ;
    CAPTURE(j);
    CHECK(differ == 0);
  }
  // And the Halton jitter of a frame against the CPU reference's sample rays (froxelSampleRay): the
  // jittered fill differs from the unjittered one and matches the reference (tolerance as above).
  const glm::dvec3 jitter = froxelJitter(3);
  const gl::Handle volume = createVolume(grid);
  fill(pass, s, basis.view, volume.get(), grid, jitter);
  const Image jittered = readVolume(volume.get(), grid);
  const Image reference = evaluateFroxels(cpu, grid, jitter, s.camera, s.scene.sun, s.scene.medium);
  const Image centres = evaluateFroxels(cpu, grid, glm::dvec3(0.0), s.camera, s.scene.sun, s.scene.medium);
  check(jittered, reference, 2e-5, 2e-6, "froxel_halton_jitter");
  const ImageMetrics moved = compareImages(jittered, centres);
  MESSAGE(std::string("jittered vs centres: " + describe(moved)));
  CHECK(moved.relativeRmse > 1e-3); // the samples did move (a third of a cell and more in each axis)
  // The sample ray of a jittered cell ends at the view depth of its jittered slice coordinate.
  const FroxelDepthRange range = froxelDepthRange(grid, s.camera, "test");
  const PixelRay ray = froxelSampleRay(s.camera, range, grid, jitter, 3, 4, 5, false);
  const double w = (5 + 0.5 + jitter.z) / grid.depth;
  CHECK(glm::dot(ray.direction, s.camera.forward()) * ray.surface ==
        doctest::Approx(range.near * std::pow(range.far / range.near, w)).epsilon(1e-12));
  const glm::dvec3 expected = s.camera.rayDirection(2.0 * (3 + 0.5 + jitter.x) / grid.width - 1.0,
                                                    2.0 * (4 + 0.5 + jitter.y) / grid.height - 1.0);
  CHECK(glm::length(ray.direction - expected) < 1e-15);
}

TEST_CASE("prefilter froxels: an unoccluded homogeneous medium matches the closed form at the samples") {
  CREP_REQUIRE_GL();
  const FroxelScene s = makeScene(true); // nothing occludes: every map texel at depth 1
  const FroxelGrid grid = smallGrid();
  const FroxelDepthRange range = froxelDepthRange(grid, s.camera, "test");
  const FilteredBasis cpu = prefilter(s.map, s.scene.medium, prefilterOptions());
  const UploadedBasis basis = uploadBasis(cpu, StorageFormat::RGBA32F);
  EvaluatePass pass(EvaluatePass::CreateInfo{});
  const gl::Handle volume = createVolume(grid);
  fill(pass, s, basis.view, volume.get(), grid, glm::dvec3(0.0));
  const Image filled = readVolume(volume.get(), grid);
  // The closed form (Eq. 1 with V = 1, crep::unshadowedScattering) on a camera image of the grid's size
  // whose depth buffer holds each slice's centre depth: the same rays and ends.
  Image truth(kGridW, kGridH * kGridD, 4);
  for (int z = 0; z < kGridD; ++z) {
    const double Z = range.near * std::pow(range.far / range.near, (z + 0.5) / kGridD);
    const Image depth(kGridW, kGridH, 1, static_cast<float>(s.camera.depthBufferValue(Z)));
    const Image t = unshadowedScattering(depth, s.camera, s.scene.sun, s.scene.medium);
    for (int y = 0; y < kGridH; ++y)
      for (int x = 0; x < kGridW; ++x)
        for (int c = 0; c < 4; ++c)
          truth.at(x, z * kGridH + y, c) = t.at(x, y, c);
  }
  // The prefilter's own error on an empty map: every receiver at map depth 1 lies beyond each ray's depth,
  // and the truncated Fourier series of a step at 1 - m (depth margin m = 1/16, M = 32) reconstructs V = 1
  // only up to its ringing near the map's far end. crep::evaluate's empty-scene test (PrefilterTest.cpp,
  // "ground truth (a)") measured the same rule per pixel: max |d| 4.5% of the peak, relative RMSE 8.4e-3.
  // Bounds on RGB: max |d| <= 5% of the peak, relative RMSE <= 1.5e-2. The transmittance A = exp(-sbar s) is
  // exact up to float: |d| <= 1e-5.
  CompareOptions rgb;
  rgb.channels = 3;
  const ImageMetrics m = compareImages(filled, truth, rgb);
  MESSAGE(std::string("froxel fill vs closed form (RGB): " + describe(m)));
  CHECK(m.nanCount + m.infCount == 0);
  CHECK(m.maxAbsError <= 5e-2 * m.peak);
  CHECK(m.relativeRmse <= 1.5e-2);
  double alpha = 0.0;
  for (int y = 0; y < truth.height(); ++y)
    for (int x = 0; x < truth.width(); ++x)
      alpha = std::max(alpha, static_cast<double>(std::abs(filled.at(x, y, 3) - truth.at(x, y, 3))));
  CHECK(alpha <= 1e-5);
}

TEST_CASE(
    "prefilter froxels: a textured basis (constant light colour c) fills c times the untextured volume") {
  CREP_REQUIRE_GL();
  const FroxelScene& s = boxes();
  // The GPU prefilter, untextured and with a constant colour map c (prefilter.h, "Light textures": a constant
  // texture gives cbar = c and the untextured bases bit for bit), then the froxel fill of each: the
  // CREP_LIGHT_TEXTURE froxel variant weighs each region's visibility by cbar = c per channel, so the
  // radiance is c times the untextured one. c is exact in binary16 and a power of two per channel, so only
  // the order of the float products differs, and scaling by powers of two is exact (measured: bit for
  // bit): |d| <= 1e-6 of the peak; the transmittance is the same.
  PrefilterPass::CreateInfo info;
  info.mapWidth = kMapW;
  info.mapHeight = kMapH;
  info.options = prefilterOptions(StorageFormat::RGBA8);
  PrefilterPass plainPass(info), texturedPass(info);
  plainPass.run({.rectifiedDepth = s.mapTexture.get(), .layout = s.layout.get(), .medium = &s.scene.medium});
  const glm::vec4 c(0.5f, 0.25f, 2.0f, 1.0f);
  const gl::Handle colors = gl::createTexture2D(GL_RGBA32F, kMapW, kMapH);
  glClearTexImage(colors.get(), 0, GL_RGBA, GL_FLOAT, &c.x);
  texturedPass.run({.rectifiedDepth = s.mapTexture.get(),
                    .layout = s.layout.get(),
                    .medium = &s.scene.medium,
                    .lightColors = colors.get()});
  REQUIRE(texturedPass.filteredBasis().textured);
  const FroxelGrid grid = smallGrid();
  const glm::dvec3 jitter = froxelJitter(11);
  for (const int samples : {128, 0}) { // the scattering prefix table, and no table
    EvaluatePass::CreateInfo e;
    e.options.visibilityTableSamples = samples;
    EvaluatePass pass(e);
    const gl::Handle plainVolume = createVolume(grid), texturedVolume = createVolume(grid);
    fill(pass, s, plainPass.filteredBasis(), plainVolume.get(), grid, jitter);
    fill(pass, s, texturedPass.filteredBasis(), texturedVolume.get(), grid, jitter);
    Image expected = readVolume(plainVolume.get(), grid);
    for (int y = 0; y < expected.height(); ++y)
      for (int x = 0; x < expected.width(); ++x)
        for (int ch = 0; ch < 3; ++ch)
          expected.at(x, y, ch) *= c[ch];
    check(readVolume(texturedVolume.get(), grid), expected, 1e-6, 1e-6,
          "froxel_textured_constant_" + std::to_string(samples));
  }
}

TEST_CASE(
    "prefilter froxels: one run with both targets, and a reused table, give the separate runs' results") {
  CREP_REQUIRE_GL();
  const FroxelScene& s = boxes();
  const FilteredBasis cpu = prefilter(s.map, s.scene.medium, prefilterOptions());
  const UploadedBasis basis = uploadBasis(cpu, StorageFormat::RGBA32F);
  const FroxelGrid grid = smallGrid();
  const glm::dvec3 jitter = froxelJitter(5);
  const Image depth(kGridW, kGridH, 1, static_cast<float>(s.camera.depthBufferValue(3.0)));
  const gl::Handle depthTexture = uploadR32F(depth);
  EvaluatePass pass(EvaluatePass::CreateInfo{});
  EvaluatePass::FrameAttribs f;
  f.cameraDepth = depthTexture.get();
  f.camera = &s.camera;
  f.light = &s.scene.sun;
  f.medium = &s.scene.medium;
  f.layout = s.layout.get();
  f.basis = basis.view;
  // Separately: the per-pixel image, then the volume alone (building its own table).
  const gl::Handle outputAlone = gl::createTexture2D(GL_RGBA32F, kGridW, kGridH);
  const gl::Handle volumeAlone = createVolume(grid);
  f.output = outputAlone.get();
  pass.run(f);
  fill(pass, s, basis.view, volumeAlone.get(), grid, jitter);
  // Together in one run (one table, two dispatches).
  const gl::Handle outputBoth = gl::createTexture2D(GL_RGBA32F, kGridW, kGridH);
  const gl::Handle volumeBoth = createVolume(grid);
  f.output = outputBoth.get();
  f.froxels = {volumeBoth.get(), grid, jitter};
  pass.run(f);
  // The volume again from the table of that run (FrameAttribs::reuseTable), without the per-pixel target.
  const gl::Handle volumeReused = createVolume(grid);
  f.output = 0;
  f.cameraDepth = 0;
  f.froxels = {volumeReused.get(), grid, jitter};
  f.reuseTable = true;
  pass.run(f);
  // The same programs on the same inputs: bit for bit.
  const Image alone = readVolume(volumeAlone.get(), grid);
  CHECK(differingSamples(readVolume(volumeBoth.get(), grid), alone) == 0);
  CHECK(differingSamples(readVolume(volumeReused.get(), grid), alone) == 0);
  CHECK(differingSamples(readRgbaTexture(outputBoth.get(), kGridW, kGridH),
                         readRgbaTexture(outputAlone.get(), kGridW, kGridH)) == 0);
  // A reused table of another basis texture is refused.
  const UploadedBasis other = uploadBasis(cpu, StorageFormat::RGBA32F);
  f.basis = other.view;
  CHECK_THROWS_WITH_AS(pass.run(f), doctest::Contains("EvaluatePass::FrameAttribs.reuseTable"),
                       InvalidArgument);
}

TEST_CASE("prefilter froxels: bad targets throw errors naming the field") {
  CREP_REQUIRE_GL();
  const FroxelScene& s = boxes();
  const FilteredBasis cpu = prefilter(s.map, s.scene.medium, prefilterOptions());
  const UploadedBasis basis = uploadBasis(cpu, StorageFormat::RGBA32F);
  EvaluatePass pass(EvaluatePass::CreateInfo{});
  const FroxelGrid grid = smallGrid();
  const gl::Handle volume = createVolume(grid);
  const auto run = [&](std::uint32_t v, FroxelGrid g, glm::dvec3 j) {
    return [&, v, g, j] { fill(pass, s, basis.view, v, g, j); };
  };
  // No target at all: output 0 and volume 0 -> the per-pixel targets are required.
  requireMessageNames("EvaluatePass::FrameAttribs.cameraDepth", run(0, grid, glm::dvec3(0.0)));
  FroxelGrid bad = grid;
  bad.depth = 0;
  requireMessageNames("EvaluatePass::FrameAttribs.froxels.grid.depth",
                      run(volume.get(), bad, glm::dvec3(0.0)));
  bad = grid;
  bad.farDepth = std::nan("");
  requireMessageNames("EvaluatePass::FrameAttribs.froxels.grid.farDepth",
                      run(volume.get(), bad, glm::dvec3(0.0)));
  requireMessageNames("EvaluatePass::FrameAttribs.froxels.jitter",
                      run(volume.get(), grid, glm::dvec3(0.0, std::nan(""), 0.0)));
  requireMessageNames("EvaluatePass::FrameAttribs.froxels.jitter",
                      run(volume.get(), grid, glm::dvec3(0.7, 0.0, 0.0)));
  // Wrong size, wrong format, wrong target, not a texture.
  bad = grid;
  bad.depth = kGridD + 1;
  requireMessageNames("EvaluatePass::FrameAttribs.froxels.volume", run(volume.get(), bad, glm::dvec3(0.0)));
  const gl::Handle rgba8 = createVolume(grid, GL_RGBA8);
  requireMessageNames("EvaluatePass::FrameAttribs.froxels.volume", run(rgba8.get(), grid, glm::dvec3(0.0)));
  const gl::Handle flat = gl::createTexture2D(GL_RGBA32F, kGridW, kGridH);
  requireMessageNames("EvaluatePass::FrameAttribs.froxels.volume", run(flat.get(), grid, glm::dvec3(0.0)));
  requireMessageNames("EvaluatePass::FrameAttribs.froxels.volume", run(987654, grid, glm::dvec3(0.0)));
  // A table reused that was never built for this pass.
  EvaluatePass fresh(EvaluatePass::CreateInfo{});
  requireMessageNames("EvaluatePass::FrameAttribs.reuseTable", [&] {
    EvaluatePass::FrameAttribs f;
    f.camera = &s.camera;
    f.light = &s.scene.sun;
    f.medium = &s.scene.medium;
    f.layout = s.layout.get();
    f.basis = basis.view;
    f.froxels = {volume.get(), grid, glm::dvec3(0.0)};
    f.reuseTable = true;
    fresh.run(f);
  });
  // CPU reference: the same checks with its own names.
  bad = grid;
  bad.width = -1;
  CHECK_THROWS_WITH_AS(evaluateFroxels(cpu, bad, glm::dvec3(0.0), s.camera, s.scene.sun, s.scene.medium),
                       doctest::Contains("evaluateFroxels.grid.width"), InvalidArgument);
  CHECK_THROWS_WITH_AS(
      evaluateFroxels(cpu, grid, glm::dvec3(INFINITY, 0.0, 0.0), s.camera, s.scene.sun, s.scene.medium),
      doctest::Contains("evaluateFroxels.jitter"), InvalidArgument);
}
