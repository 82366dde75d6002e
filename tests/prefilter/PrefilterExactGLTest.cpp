// VisibilityReconstruction::Exact on the GPU (crep/prefilter/gpu_pass.h) against the CPU reference: the
// prefilter pass writes the map's depths, the cumulative weights and the blocks' depth ranges, and the
// evaluation (every table path, both samplings, the near-plane correction) gives crep::evaluate's image of
// the CPU basis, on the boxes scene's map of 250 x 37 texels (10 prefilter regions of 25 texels) and a 161 x
// 93 screen.
//
// Tolerances (measured on Mesa llvmpipe 22.3; each test prints its figures):
//   depths and block ranges: bit for bit (copies); cumulative weights: |d| <= 1e-5 (float against double;
//   measured 1.8e-7).
//   evaluation: the depth test compares the ray's depth, float on the GPU and double on the CPU, with the
//   texels' depths; a texel within float rounding of a ray's depth can flip, which moves that pixel by the
//   texel's share. At most 0.5% of the samples may differ by more than 1e-4 of the peak, and the relative
//   RMSE stays below 1e-5 (measured: none over, 9.1e-8 on every path).
#include "common/analytic_reference.h"
#include "common/error_checks.h"
#include "common/gl_fixture.h"
#include "common/gl_util.h"
#include "common/image_check.h"
#include "common/prefilter_gpu.h"

#include <crep/core/error.h>
#include <crep/prefilter/gpu_pass.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kMapW = kBoxesMapW, kMapH = kBoxesMapH, kScreenW = kBoxesScreenW, kScreenH = kBoxesScreenH;

PrefilterPass::CreateInfo exactInfo() {
  PrefilterPass::CreateInfo info;
  info.mapWidth = kMapW;
  info.mapHeight = kMapH;
  info.options.regionsPerSplit = 5;
  info.options.reconstruction = VisibilityReconstruction::Exact;
  return info;
}

} // namespace

TEST_CASE("prefilter GPU, exact reconstruction: depths, cumulative weights and block ranges equal the CPU") {
  CREP_REQUIRE_GL();
  const GpuScene& s = boxesGpuScene();
  const PrefilterPass::CreateInfo info = exactInfo();
  const PrefilterPass pass = runPrefilter(s, info);
  CHECK(pass.layers() == 2);
  CHECK(pass.filteredBasis().reconstruction == VisibilityReconstruction::Exact);
  const FilteredBasis cpu = prefilter(s.map, s.scene.medium, info.options);
  const std::vector<float> gpu = readTextureArray(pass.filteredBasisTexture(), kMapW, kMapH, 2);
  REQUIRE(gpu.size() == std::size_t(kMapW) * kMapH * 8);
  int depthsDiffer = 0;
  double worstMix = 0.0;
  for (std::size_t i = 0; i < cpu.depth.size(); ++i) {
    depthsDiffer += gpu[4 * i] != cpu.depth[i];
    worstMix = std::max(worstMix, static_cast<double>(std::abs(gpu[4 * i + 1] - cpu.weight[i]))); // RG32F
  }
  // Layer 1: each block of 8 texels of a region (the last one partial: n = 25) has its (min, max) depth at
  // texel (region n + block).
  const int n = kMapW / cpu.regions;
  int blocksWrong = 0;
  for (int j = 0; j < kMapH; ++j)
    for (int r = 0; r < cpu.regions; ++r)
      for (int b = 0; b * 8 < n; ++b) {
        float lo = 2.0f, hi = -1.0f;
        for (int i = b * 8; i < std::min(n, b * 8 + 8); ++i) {
          lo = std::min(lo, s.map.depth.at(r * n + i, j));
          hi = std::max(hi, s.map.depth.at(r * n + i, j));
        }
        const std::size_t t = (std::size_t(kMapH + j) * kMapW + std::size_t(r * n + b)) * 4;
        blocksWrong += gpu[t] != lo || gpu[t + 1] != hi;
      }
  MESSAGE("depths that differ: " << depthsDiffer << ", largest cumulative weight difference " << worstMix
                                 << ", blocks wrong: " << blocksWrong);
  CHECK(depthsDiffer == 0);
  CHECK(worstMix <= 1e-5);
  CHECK(blocksWrong == 0);
}

TEST_CASE("prefilter GPU, exact reconstruction: evaluation equals the CPU on every table path and sampling") {
  CREP_REQUIRE_GL();
  const GpuScene& s = boxesGpuScene();
  const PrefilterPass::CreateInfo info = exactInfo();
  const PrefilterPass pass = runPrefilter(s, info);
  const FilteredBasis cpu = prefilter(s.map, s.scene.medium, info.options);
  for (const Sampling sampling : {Sampling::Bilinear, Sampling::Nearest})
    for (const int option : {0, 1, 3, 4}) {
      // 0: defaults (scattering prefix), 1: near-plane correction, 3: the per-region loop over the visibility
      // table, 4: no table (every region walked).
      EvaluatePass::CreateInfo e;
      e.reconstruction = VisibilityReconstruction::Exact;
      e.options.sampling = sampling;
      e.options.nearPlaneCorrection = option == 1;
      e.options.scatteringPrefix = option != 3;
      if (option == 4) e.options.visibilityTableSamples = 0;
      const std::string name = std::string("prefilter_exact_gpu_") +
                               (sampling == Sampling::Nearest ? "nearest" : "bilinear") + "_option" +
                               std::to_string(option);
      CAPTURE(name);
      EvaluatePass evaluatePass(e);
      const gl::Handle out = createTexture2D(GL_RGBA32F, kScreenW, kScreenH);
      evaluatePass.run(sunEvaluation(s, pass.filteredBasis(), out.get()));
      const Image gpu = readRgbaTexture(out.get(), kScreenW, kScreenH);
      const Image reference =
          evaluate(cpu, s.cameraDepth, s.scene.camera, s.scene.sun, s.scene.medium, e.options);
      double peak = 0.0, rgbPeak = 0.0;
      for (float v : reference.data())
        peak = std::max(peak, static_cast<double>(std::abs(v)));
      for (int y = 0; y < kScreenH; ++y)
        for (int x = 0; x < kScreenW; ++x)
          rgbPeak = std::max(rgbPeak, static_cast<double>(reference.at(x, y, 0)));
      // The radiance is there to compare (not a transmittance-only image), and the Fourier image differs.
      REQUIRE(rgbPeak > 0.01 * peak);
      ImageTolerance t;
      t.relativeRmse = 1e-5;
      t.overThreshold = 1e-4 * peak;
      t.maxFractionOver = 0.005;
      const ImageCheckResult r = evaluateImage(rgb(gpu), rgb(reference), t, name); // the radiance
      MESSAGE(name << ": " << r.message);
      CHECK_MESSAGE(r.passed, r.message);
    }
}

TEST_CASE("prefilter GPU, exact reconstruction: a basis of the other kind is named") {
  CREP_REQUIRE_GL();
  const GpuScene& s = boxesGpuScene();
  PrefilterPass::CreateInfo info = exactInfo();
  info.options.reconstruction = VisibilityReconstruction::Fourier;
  const PrefilterPass pass = runPrefilter(s, info);
  EvaluatePass::CreateInfo e;
  e.reconstruction = VisibilityReconstruction::Exact;
  EvaluatePass evaluatePass(e);
  const gl::Handle out = createTexture2D(GL_RGBA32F, kScreenW, kScreenH);
  CHECK(invalidParameter([&] { evaluatePass.run(sunEvaluation(s, pass.filteredBasis(), out.get())); }) ==
        "EvaluatePass::FrameAttribs.basis.reconstruction");
  info.memoryLimit = true;
  info.options.reconstruction = VisibilityReconstruction::Exact;
  CHECK(invalidParameter([&] { PrefilterPass p(info); }) ==
        "PrefilterPass::CreateInfo.options.reconstruction");
}
