// The GPU prefilter and evaluation passes (crep/prefilter/gpu_pass.h) against the CPU reference
// (crep/prefilter/prefilter.h) on the same inputs: the rectified map and camera depth of a built-in
// scene rendered once on the GPU, the GPU passes reading those textures, the CPU reading them back.
// Sizes are deliberately not multiples of the workgroup sizes: map 250 x 37 (rows per workgroup 64,
// 16, 7), screen 161 x 93 (8 x 8 and 5 x 3 workgroups).
//
// Tolerances (measured on Mesa llvmpipe 22.3, LLVM 15; the measured values are printed by each test):
//   filtered basis, stored values e = 0.5 + 0.5 F in [0, 1]:
//     RGBA32F  |e_gpu - e_cpu| <= 4e-6 everywhere (measured <= 1.02e-6 over every M and configuration): the
//              float prefix filter and float weights against double; Fourier angles are reduced in
//              double on both sides (scattering.glsl), so the error does not grow with the harmonic.
//     RGBA16F  both sides round to the nearest binary16; a float/double difference next to a rounding
//              boundary moves one value by one half ulp: |d| <= ulp16(e) + 1e-6, and at most 0.1% of
//              the values differ at all (measured ~0.01%).
//     RGBA8    the same with one quantization step: |d| <= 1/255 + 1e-6, at most 0.1% differ (~0.002%).
//   scattering image (RGB radiance, A transmittance), against crep::evaluate of the CPU basis:
//     float formats, bilinear: max |d| <= 2e-5 peak, relative RMSE <= 2e-6 (measured ~2e-7 / 1e-7).
//     RGBA8, bilinear: llvmpipe filters unorm8 texels in 8-bit fixed point and returns the filtered value
//     rounded to 8 bits (checked: a 0 | 1/255 texel pair filters to exactly 0 or 1/255), the CPU in
//     double. Bound: half a step of e is a step 1/255 of F, times sum_j |a_j| (2.1 for M = 32) in the
//     visibility: 8.2e-3 of the peak. Asserted: max |d| <= 1e-2 peak, relative RMSE <= 2e-3 (measured
//     max |d| from 5e-4 (boxes) to 1.6e-3 (colonnade) of the peak, relative RMSE 1.5e-4 .. 5.4e-4). This is
//     the hardware filtering the paper uses, not an error of the pass: with GL_NEAREST, or an RGBA16F /
//     RGBA32F basis, the same evaluation matches to float precision.
//     nearest sampling: a row or column index can flip where float and double disagree on which side
//     of a texel boundary a ray lies; at most 0.5% of the samples may differ by more than 2e-5 peak.
#include "common/error_checks.h"
#include "common/gl_fixture.h"
#include "common/image_check.h"

#include "common/prefilter_gpu.h"

#include <crep/core/error.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/support/image_compare.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kMapW = kBoxesMapW, kMapH = kBoxesMapH, kScreenW = kBoxesScreenW, kScreenH = kBoxesScreenH;

FilteredBasis cpuPrefilter(const GpuScene& s, const PrefilterPass::CreateInfo& info,
                           double extinctionOverride = -1.0, const RectifiedMap* map = nullptr) {
  const RectifiedMap& m = map != nullptr ? *map : s.map;
  return extinctionOverride >= 0.0 ? prefilter(m, extinctionOverride, info.options)
                                   : prefilter(m, s.scene.medium, info.options);
}

/// Checks the GPU basis against the CPU one with the format's tolerance; returns the difference.
BasisDifference checkBasis(const PrefilterPass& pass, const FilteredBasis& cpu, const std::string& what) {
  const PrefilterPass::CreateInfo& info = pass.createInfo();
  const std::vector<float> gpu =
      readTextureArray(pass.filteredBasisTexture(), info.mapWidth, info.mapHeight, pass.layers());
  REQUIRE(gpu.size() == cpu.texels.size());
  const FormatTolerance tolerance{info.options.format};
  const BasisDifference d = compareBasis(gpu, cpu, tolerance);
  // Values that differ at all (beyond float noise) for the quantized formats.
  const BasisDifference changed = compareBasis(gpu, cpu, [](float) { return 1e-6; });
  MESSAGE(what << ": " << describe(d) << "; " << changed.over << " of " << cpu.texels.size()
               << " differ by > 1e-6");
  CHECK(d.over == 0);
  if (info.options.format != StorageFormat::RGBA32F)
    CHECK(static_cast<double>(changed.over) <= 1e-3 * static_cast<double>(cpu.texels.size()));
  return d;
}

struct EvalTolerance {
  double maxAbs; ///< relative to the peak of the reference
  double relativeRmse;
  double fractionOver = 0.0; ///< samples allowed beyond maxAbs (nearest sampling)
};

EvalTolerance evalTolerance(StorageFormat basisFormat, Sampling sampling) {
  if (sampling == Sampling::Nearest) return {2e-5, 1e-3, 5e-3};
  if (basisFormat == StorageFormat::RGBA8) return {1e-2, 2e-3};
  return {2e-5, 2e-6};
}

gl::Handle runEvaluate(const GpuScene& s, const EvaluatePass::CreateInfo& info,
                       const FilteredBasisView& basis) {
  EvaluatePass pass(info);
  gl::Handle out = createTexture2D(info.outputFormat == StorageFormat::RGBA16F ? GL_RGBA16F : GL_RGBA32F,
                                   kScreenW, kScreenH);
  pass.run(sunEvaluation(s, basis, out.get()));
  return out;
}

/// GPU evaluation image against the CPU one (`name` names the artifacts written on failure).
ImageMetrics checkEvaluation(const Image& gpu, const Image& cpu, const EvalTolerance& t,
                             const std::string& name) {
  double peak = 0.0;
  for (float v : cpu.data())
    peak = std::max(peak, static_cast<double>(std::abs(v)));
  ImageTolerance tolerance;
  tolerance.relativeRmse = t.relativeRmse;
  if (t.fractionOver > 0.0) {
    tolerance.overThreshold = t.maxAbs * peak;
    tolerance.maxFractionOver = t.fractionOver;
  } else {
    tolerance.maxAbsError = t.maxAbs * peak;
  }
  const ImageCheckResult r = evaluateImage(gpu, cpu, tolerance, name);
  MESSAGE(name << ": " << r.message);
  CHECK_MESSAGE(r.passed, r.message);
  return r.metrics;
}

Image cpuEvaluate(const GpuScene& s, const FilteredBasis& basis, const EvaluatePass::CreateInfo& info) {
  const EvaluateOptions o = info.options; // the same rule on both sides
  return evaluate(basis, s.cameraDepth, s.scene.camera, s.scene.sun, s.scene.medium, o);
}

PrefilterPass::CreateInfo baseInfo() {
  PrefilterPass::CreateInfo info;
  info.mapWidth = kMapW;
  info.mapHeight = kMapH;
  return info;
}

} // namespace

TEST_CASE("prefilter GPU: the filtered basis equals the CPU reference in every storage format") {
  CREP_REQUIRE_GL();
  const GpuScene& s = boxesGpuScene();
  for (const StorageFormat format : {StorageFormat::RGBA32F, StorageFormat::RGBA16F, StorageFormat::RGBA8}) {
    PrefilterPass::CreateInfo info = baseInfo();
    info.options.format = format;
    const PrefilterPass pass = runPrefilter(s, info);
    checkBasis(pass, cpuPrefilter(s, info), std::string("M = 32, ") + storageFormatToken(format));
  }
}

TEST_CASE("prefilter GPU: bases 4, 6, 30 and 128, partial base groups, odd and prime workgroup sizes") {
  CREP_REQUIRE_GL();
  const GpuScene& s = boxesGpuScene();
  // M = 6 and 30 leave the last RGBA layer half used (its other channels store F = 0); 12 bases per
  // invocation do not divide 32 or 128, 128 exceeds M = 30: the last group of a row is partial.
  struct Config {
    int bases, perInvocation, baseGroupsPerWorkgroup;
  };
  for (const Config c : {Config{4, 4, 1}, Config{6, 4, 2}, Config{30, 128, 1}, Config{32, 12, 1},
                         Config{128, 4, 3}, Config{128, 12, 2}}) {
    const int bases = c.bases;
    CAPTURE(bases);
    CAPTURE(c.perInvocation);
    PrefilterPass::CreateInfo info = baseInfo();
    info.options.format = StorageFormat::RGBA32F;
    info.options.bases = bases;
    info.options.basesPerInvocation = c.perInvocation;
    info.workgroupRows = 7;
    info.workgroupBaseGroups = c.baseGroupsPerWorkgroup;
    const PrefilterPass pass = runPrefilter(s, info);
    const FilteredBasis cpu = cpuPrefilter(s, info);
    checkBasis(pass, cpu,
               "M = " + std::to_string(bases) + ", " + std::to_string(c.perInvocation) +
                   " per invocation, RGBA32F");
    EvaluatePass::CreateInfo e;
    e.bases = bases;
    e.workgroupWidth = 5;
    e.workgroupHeight = 3;
    const gl::Handle out = runEvaluate(s, e, pass.filteredBasis());
    checkEvaluation(readRgbaTexture(out.get(), kScreenW, kScreenH), cpuEvaluate(s, cpu, e),
                    evalTolerance(info.options.format, e.options.sampling),
                    "prefilter_gpu_eval_M" + std::to_string(bases) + "_b" + std::to_string(c.perInvocation));
  }
}

TEST_CASE("prefilter GPU: every regionsPerSplit x basesPerInvocation configuration gives the CPU result") {
  CREP_REQUIRE_GL();
  const GpuScene& s = boxesGpuScene();
  // W = 250 with K = 2 splits: P in {1, 5, 25} (R = 2, 10, 50 regions of 125, 25, 5 texels).
  for (const int perSplit : {1, 5, 25}) {
    Image first;
    for (const int perInvocation : {4, 8, 16, 32}) {
      PrefilterPass::CreateInfo info = baseInfo();
      info.options.format = StorageFormat::RGBA32F;
      info.options.regionsPerSplit = perSplit;
      info.options.basesPerInvocation = perInvocation;
      info.workgroupRows = perInvocation == 8 ? 64 : 16;
      info.workgroupBaseGroups = perInvocation == 4 ? 2 : 1;
      info.workgroupRegions = perSplit == 5 ? 3 : 1;
      const std::string name =
          "P = " + std::to_string(perSplit) + ", bases per invocation " + std::to_string(perInvocation);
      CAPTURE(name);
      const PrefilterPass pass = runPrefilter(s, info);
      const FilteredBasis cpu = cpuPrefilter(s, info);
      checkBasis(pass, cpu, name);
      EvaluatePass::CreateInfo e;
      const gl::Handle out = runEvaluate(s, e, pass.filteredBasis());
      const Image gpu = readRgbaTexture(out.get(), kScreenW, kScreenH);
      checkEvaluation(gpu, cpuEvaluate(s, cpu, e), evalTolerance(info.options.format, e.options.sampling),
                      "prefilter_gpu_eval_P" + std::to_string(perSplit) + "_b" +
                          std::to_string(perInvocation));
      // The bases per invocation only change how the work is split: the same image to float noise.
      if (first.empty()) {
        first = gpu;
      } else {
        const ImageMetrics m = compareImages(gpu, first);
        CHECK_MESSAGE(m.maxAbsError <= 1e-5 * m.peak, describe(m));
      }
    }
  }
}

TEST_CASE("prefilter GPU: every weight mode, the sigma -> 0 limit and a thick medium") {
  CREP_REQUIRE_GL();
  const GpuScene& s = boxesGpuScene();
  const WeightMode modes[] = {WeightMode::Exact, WeightMode::ConstantStep, WeightMode::ConstantRatio,
                              WeightMode::AverageVisibility};
  // Scalar weight extinctions: the scene's medium, 0 (the phi series limit), 0.4 / world unit (the
  // view reaches ~30 units: an optical depth of ~12 at the far end, weights down to e^-12).
  for (const double extinction : {-1.0, 0.0, 0.4}) {
    for (const WeightMode mode : modes) {
      PrefilterPass::CreateInfo info = baseInfo();
      info.options.format = StorageFormat::RGBA32F;
      info.options.weights = mode;
      info.options.regionsPerSplit = 5;
      const std::string name = std::string(weightModeToken(mode)) + ", extinction " +
                               (extinction < 0.0 ? std::string("of the medium") : std::to_string(extinction));
      CAPTURE(name);
      const PrefilterPass pass = runPrefilter(s, info, extinction);
      const FilteredBasis cpu = cpuPrefilter(s, info, extinction);
      checkBasis(pass, cpu, name);
      EvaluatePass::CreateInfo e;
      e.options.nearPlaneCorrection = true; // uses the weight totals of the mode
      const gl::Handle out = runEvaluate(s, e, pass.filteredBasis());
      checkEvaluation(readRgbaTexture(out.get(), kScreenW, kScreenH), cpuEvaluate(s, cpu, e),
                      evalTolerance(info.options.format, e.options.sampling),
                      std::string("prefilter_gpu_eval_") + weightModeToken(mode) + "_" +
                          std::to_string(extinction));
    }
  }
}

TEST_CASE("prefilter GPU: evaluation equals the CPU evaluation for every format, sampling and option") {
  CREP_REQUIRE_GL();
  const GpuScene& s = boxesGpuScene();
  for (const StorageFormat format : {StorageFormat::RGBA32F, StorageFormat::RGBA16F, StorageFormat::RGBA8}) {
    PrefilterPass::CreateInfo info = baseInfo();
    info.options.format = format;
    info.options.regionsPerSplit = 5;
    const FilteredBasis cpu = cpuPrefilter(s, info);
    const PrefilterPass pass = runPrefilter(s, info);
    // The CPU basis uploaded as it is: only the evaluation differs.
    const UploadedBasis uploaded = uploadBasis(cpu, format);
    for (const Sampling sampling : {Sampling::Bilinear, Sampling::Nearest})
      for (const int option : {0, 1, 2, 3, 4}) {
        // 0: defaults (scattering prefix), 1: near-plane correction, 2: Lanczos and RGBA16F output, 3: the
        // per-region loop over the visibility table, 4: no table (every region from the basis).
        EvaluatePass::CreateInfo e;
        e.options.sampling = sampling;
        e.options.nearPlaneCorrection = option == 1;
        e.options.ringing = option == 2 ? RingingFilter::Lanczos : RingingFilter::None;
        e.options.scatteringPrefix = option != 3;
        if (option == 4) e.options.visibilityTableSamples = 0;
        e.outputFormat = option == 2 ? StorageFormat::RGBA16F : StorageFormat::RGBA32F;
        const std::string name = std::string("prefilter_gpu_eval_") + storageFormatToken(format) +
                                 (sampling == Sampling::Nearest ? "_nearest" : "_bilinear") +
                                 (option == 1   ? "_nearplane"
                                  : option == 2 ? "_lanczos_rgba16f"
                                  : option == 3 ? "_per_region_table"
                                  : option == 4 ? "_no_table"
                                                : "");
        CAPTURE(name);
        EvalTolerance t = evalTolerance(format, sampling);
        if (e.outputFormat == StorageFormat::RGBA16F) {
          // The output itself is rounded to binary16: 2^-11 relative per sample.
          t.maxAbs = std::max(t.maxAbs, 1e-3);
          t.relativeRmse = std::max(t.relativeRmse, 5e-4);
        }
        const Image reference = cpuEvaluate(s, cpu, e);
        const gl::Handle fromCpuBasis = runEvaluate(s, e, uploaded.view);
        checkEvaluation(readRgbaTexture(fromCpuBasis.get(), kScreenW, kScreenH), reference, t,
                        name + "_cpu_basis");
        const gl::Handle fromGpuBasis = runEvaluate(s, e, pass.filteredBasis());
        if (format != StorageFormat::RGBA32F) {
          // A stored value one step off (see the basis test) moves a few pixels by up to a step times
          // sum |a_k| (< 2.5 for M = 32).
          t.fractionOver = std::max(t.fractionOver, 5e-3);
          t.relativeRmse = std::max(t.relativeRmse, 2e-3);
        }
        checkEvaluation(readRgbaTexture(fromGpuBasis.get(), kScreenW, kScreenH), reference, t, name);
      }
  }
}

TEST_CASE("prefilter GPU: a float map with exact 0 and 1 depths and random content, other scenes") {
  CREP_REQUIRE_GL();
  const GpuScene& s = boxesGpuScene();
  // Random depths in a GL_R32F texture (the pass reads channel r of any format), a fifth of them
  // exactly 0 (caster clamped in front) or 1 (nothing): the texelBasisDepth end rules.
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  Image depth(kMapW, kMapH, 1);
  for (float& v : depth.data()) {
    const float r = uniform(rng);
    v = r < 0.1f ? 0.0f : r < 0.2f ? 1.0f : uniform(rng);
  }
  const gl::Handle texture = createTexture2D(GL_R32F, kMapW, kMapH);
  glTextureSubImage2D(texture.get(), 0, 0, 0, kMapW, kMapH, GL_RED, GL_FLOAT, depth.data().data());
  const RectifiedMap map = makeRectifiedMap(s.layout, depth);
  PrefilterPass::CreateInfo info = baseInfo();
  info.options.format = StorageFormat::RGBA32F;
  info.options.regionsPerSplit = 5;
  checkBasis(runPrefilter(s, info, -1.0, texture.get()), cpuPrefilter(s, info, -1.0, &map),
             "random R32F map");

  // The other built-in scenes at other sizes (K = 4 splits, R = 8 regions).
  for (const char* name : {"colonnade", "forest", "terrain"}) {
    const GpuScene other = renderGpuScene(name, 136, 45, 4, 97, 61);
    PrefilterPass::CreateInfo o;
    o.mapWidth = 136;
    o.mapHeight = 45;
    o.options.regionsPerSplit = 2;
    const PrefilterPass pass = runPrefilter(other, o);
    const FilteredBasis cpu = cpuPrefilter(other, o);
    checkBasis(pass, cpu, std::string(name) + ", RGBA8");
    EvaluatePass e({});
    const gl::Handle out = createTexture2D(GL_RGBA32F, 97, 61);
    e.run(sunEvaluation(other, pass.filteredBasis(), out.get()));
    EvalTolerance t = evalTolerance(o.options.format, Sampling::Bilinear);
    t.fractionOver = 5e-3; // one stored value one step off (see the basis test) moves a few pixels
    checkEvaluation(readRgbaTexture(out.get(), 97, 61),
                    evaluate(cpu, other.cameraDepth, other.scene.camera, other.scene.sun, other.scene.medium),
                    t, std::string("prefilter_gpu_eval_") + name);
  }
}

// ---------------------------------------------------------------------------------------------------
// Errors

namespace {

template <class F>
std::string glErrorMessage(F&& f) {
  const std::optional<GlError> e = thrown<GlError>(f);
  return e ? e->what() : "(no GlError)";
}

} // namespace

TEST_CASE("prefilter GPU: invalid create infos throw errors naming the parameter") {
  CREP_REQUIRE_GL();
  const auto prefilterWith = [](auto change) {
    return [change] {
      PrefilterPass::CreateInfo info = baseInfo();
      change(info);
      PrefilterPass pass(info);
    };
  };
  using Info = PrefilterPass::CreateInfo;
  CHECK(invalidParameter(prefilterWith([](Info& i) { i.mapWidth = 0; })) ==
        "PrefilterPass::CreateInfo.mapWidth");
  CHECK(invalidParameter(prefilterWith([](Info& i) { i.mapHeight = -3; })) ==
        "PrefilterPass::CreateInfo.mapHeight");
  CHECK(invalidParameter(prefilterWith([](Info& i) { i.options.bases = 0; })) ==
        "PrefilterPass::CreateInfo.options.bases");
  CHECK(invalidParameter(prefilterWith([](Info& i) { i.options.bases = 31; })) ==
        "PrefilterPass::CreateInfo.options.bases");
  CHECK(invalidParameter(prefilterWith([](Info& i) { i.options.bases = 130; })) ==
        "PrefilterPass::CreateInfo.options.bases");
  CHECK(invalidParameter(prefilterWith([](Info& i) { i.options.bases = 256; })) ==
        "PrefilterPass::CreateInfo.options.bases");
  CHECK(invalidParameter(prefilterWith([](Info& i) { i.options.basesPerInvocation = 6; })) ==
        "PrefilterPass::CreateInfo.options.basesPerInvocation");
  CHECK(invalidParameter(prefilterWith([](Info& i) { i.options.basesPerInvocation = 132; })) ==
        "PrefilterPass::CreateInfo.options.basesPerInvocation");
  CHECK(invalidParameter(prefilterWith([](Info& i) { i.options.basesPerInvocation = 2; })) ==
        "PrefilterPass::CreateInfo.options.basesPerInvocation");
  CHECK(invalidParameter(prefilterWith([](Info& i) { i.options.regionsPerSplit = 0; })) ==
        "PrefilterPass::CreateInfo.options.regionsPerSplit");
  CHECK(invalidParameter(prefilterWith([](Info& i) { i.options.depthMargin = 0.3; })) ==
        "PrefilterPass::CreateInfo.options.depthMargin");
  CHECK(invalidParameter(prefilterWith([](Info& i) { i.options.depthMargin = std::nan(""); })) ==
        "PrefilterPass::CreateInfo.options.depthMargin");
  CHECK(invalidParameter(prefilterWith([](Info& i) { i.workgroupRows = 0; })) ==
        "PrefilterPass::CreateInfo.workgroupRows");
  CHECK(invalidParameter(prefilterWith([](Info& i) { i.options.format = static_cast<StorageFormat>(7); })) ==
        "PrefilterPass::CreateInfo.options.format");

  // Implementation limits: the message names the parameter and the limit.
  const int maxSize = gl::maxTextureSize();
  std::string message = glErrorMessage(prefilterWith([&](Info& i) { i.mapWidth = maxSize + 1; }));
  CHECK_MESSAGE(message.find("PrefilterPass::CreateInfo.mapWidth") != std::string::npos, message);
  CHECK_MESSAGE(message.find("GL_MAX_TEXTURE_SIZE") != std::string::npos, message);
  message = glErrorMessage(prefilterWith([&](Info& i) { i.mapHeight = maxSize + 1; }));
  CHECK_MESSAGE(message.find("PrefilterPass::CreateInfo.mapHeight") != std::string::npos, message);
  message = glErrorMessage(prefilterWith([](Info& i) { i.workgroupRows = 4096; }));
  CHECK_MESSAGE(message.find("PrefilterPass::CreateInfo.workgroupRows") != std::string::npos, message);
  message = glErrorMessage(prefilterWith([](Info& i) {
    i.workgroupRows = 64;
    i.workgroupRegions = 64;
  }));
  CHECK_MESSAGE(message.find("GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS") != std::string::npos, message);
  // ceil(128 / 4) = 32 layers at most: the array-layer limit (>= 256 by the GL spec) cannot be reached
  // through a valid M; the check exists for completeness.
  CHECK(gl::maxArrayTextureLayers() >= 32);

  const auto evaluateWith = [](auto change) {
    return [change] {
      EvaluatePass::CreateInfo info;
      change(info);
      EvaluatePass pass(info);
    };
  };
  using EInfo = EvaluatePass::CreateInfo;
  CHECK(invalidParameter(evaluateWith([](EInfo& i) { i.bases = 3; })) == "EvaluatePass::CreateInfo.bases");
  CHECK(invalidParameter(evaluateWith([](EInfo& i) { i.bases = 132; })) == "EvaluatePass::CreateInfo.bases");
  CHECK(invalidParameter(evaluateWith([](EInfo& i) { i.outputFormat = StorageFormat::RGBA8; })) ==
        "EvaluatePass::CreateInfo.outputFormat");
  CHECK(invalidParameter(evaluateWith([](EInfo& i) { i.workgroupHeight = 0; })) ==
        "EvaluatePass::CreateInfo.workgroupHeight");
  message = glErrorMessage(evaluateWith([](EInfo& i) { i.workgroupWidth = 2048; }));
  CHECK_MESSAGE(message.find("EvaluatePass::CreateInfo.workgroupWidth") != std::string::npos, message);
}

TEST_CASE("prefilter GPU: invalid frames throw errors naming the field") {
  CREP_REQUIRE_GL();
  const GpuScene& s = boxesGpuScene();
  PrefilterPass pass(baseInfo());
  CHECK_THROWS_AS(pass.filteredBasis(), Error);
  const auto runWith = [&](auto change) {
    return [&, change] {
      PrefilterPass::FrameAttribs f;
      f.rectifiedDepth = s.mapTexture.get();
      f.layout = s.layout.get();
      f.medium = &s.scene.medium;
      change(f);
      pass.run(f);
    };
  };
  using Attribs = PrefilterPass::FrameAttribs;
  CHECK(invalidParameter(runWith([](Attribs& f) { f.layout = nullptr; })) ==
        "PrefilterPass::FrameAttribs.layout");
  CHECK(invalidParameter(runWith([](Attribs& f) { f.medium = nullptr; })) ==
        "PrefilterPass::FrameAttribs.medium");
  CHECK(invalidParameter(runWith([](Attribs& f) { f.rectifiedDepth = 0; })) ==
        "PrefilterPass::FrameAttribs.rectifiedDepth");
  CHECK(invalidParameter(runWith([](Attribs& f) { f.rectifiedDepth = 123456; })) ==
        "PrefilterPass::FrameAttribs.rectifiedDepth");
  const gl::Handle wrongSize = createTexture2D(GL_R32F, kMapW + 1, kMapH);
  CHECK(invalidParameter(runWith([&](Attribs& f) { f.rectifiedDepth = wrongSize.get(); })) ==
        "PrefilterPass::FrameAttribs.rectifiedDepth");
  {
    // K = 2 splits x P = 3 regions do not divide 250 columns.
    PrefilterPass::CreateInfo info = baseInfo();
    info.options.regionsPerSplit = 3;
    PrefilterPass three(info);
    PrefilterPass::FrameAttribs f;
    f.rectifiedDepth = s.mapTexture.get();
    f.layout = s.layout.get();
    f.medium = &s.scene.medium;
    CHECK(invalidParameter([&] { three.run(f); }) == "PrefilterPass::FrameAttribs.layout");
  }
  CHECK_NOTHROW(runWith([](Attribs&) {})());

  EvaluatePass eval({});
  const gl::Handle out = createTexture2D(GL_RGBA32F, kScreenW, kScreenH);
  const gl::Handle out8 = createTexture2D(GL_RGBA8, kScreenW, kScreenH);
  const gl::Handle small = createTexture2D(GL_RGBA32F, kScreenW - 1, kScreenH);
  const auto evalWith = [&](auto change) {
    return [&, change] {
      EvaluatePass::FrameAttribs f;
      f.cameraDepth = s.depthTexture.get();
      f.output = out.get();
      f.camera = &s.scene.camera;
      f.light = &s.scene.sun;
      f.medium = &s.scene.medium;
      f.layout = s.layout.get();
      f.basis = pass.filteredBasis();
      change(f);
      eval.run(f);
    };
  };
  using EFrame = EvaluatePass::FrameAttribs;
  CHECK(invalidParameter(evalWith([](EFrame& f) { f.camera = nullptr; })) ==
        "EvaluatePass::FrameAttribs.camera");
  CHECK(invalidParameter(evalWith([](EFrame& f) { f.layout = nullptr; })) ==
        "EvaluatePass::FrameAttribs.layout");
  CHECK(invalidParameter(evalWith([&](EFrame& f) { f.output = out8.get(); })) ==
        "EvaluatePass::FrameAttribs.output");
  CHECK(invalidParameter(evalWith([&](EFrame& f) { f.output = small.get(); })) ==
        "EvaluatePass::FrameAttribs.output");
  CHECK(invalidParameter(evalWith([&](EFrame& f) { f.cameraDepth = 0; })) ==
        "EvaluatePass::FrameAttribs.cameraDepth");
  CHECK(invalidParameter(evalWith([&](EFrame& f) { f.basis.bases = 16; })) ==
        "EvaluatePass::FrameAttribs.basis.bases");
  CHECK(invalidParameter(evalWith([&](EFrame& f) { f.basis.texture = s.mapTexture.get(); })) ==
        "EvaluatePass::FrameAttribs.basis.texture");
  CHECK(invalidParameter(evalWith([&](EFrame& f) { f.basis.layoutRegions = 3; })) == "layout");
  CHECK_NOTHROW(evalWith([](EFrame&) {})());
}
