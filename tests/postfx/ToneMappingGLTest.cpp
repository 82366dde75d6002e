// ToneMapPass (crep/postfx/gpu_tone_mapping.h) against its CPU reference (crep/postfx/tone_mapping.h):
// the blocks' offsets, the GPU log-average luminance vs luminanceStats, every operator's image vs
// toneMapImage per pixel (RGBA32F, RGBA8, sRGB-encoded), manual exposure, light adaptation's time
// constant and frame-rate independence on the GPU state, NaN/Inf pixels, the GL state left behind and bad
// input named.
#include "common/error_checks.h"
#include "common/gl_fixture.h"
#include "common/gl_util.h"

#include <crep/core/error.h>
#include <crep/gpu/gl.h>
#include <crep/gpu/shader_library.h>
#include <crep/postfx/gpu_tone_mapping.h>
#include <crep/postfx/tone_mapping.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

using namespace crep;
using crep::test::invalidParameter;
using crep::test::resourceProperty;
using crep::test::uploadRgba;

namespace {

/// A deterministic HDR image: luminances log-uniform over [1e-3, 1e3], varied chromaticities, a few
/// black pixels. Sizes that are not multiples of the reduction tile exercise the edges.
Image hdrImage(int width, int height, std::uint32_t seed = 1) {
  Image image(width, height, 4, 1.0f);
  std::uint32_t state = seed;
  const auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / double(1u << 24);
  };
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double L = std::pow(10.0, -3.0 + 6.0 * next());
      const glm::dvec3 tint(0.2 + next(), 0.2 + next(), 0.2 + next());
      const bool black = (x * 7 + y * 13) % 97 == 0;
      for (int c = 0; c < 3; ++c)
        image.at(x, y, c) = black ? 0.0f : static_cast<float>(L * tint[c]);
    }
  return image;
}

/// A constant RGB image (A = 1).
Image constantImage(int width, int height, const glm::vec3& rgb) {
  Image image(width, height, 4, 1.0f);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c)
        image.at(x, y, c) = rgb[c];
  return image;
}

double maxAbsDifference(const Image& a, const Image& b, int channels) {
  double worst = 0.0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x)
      for (int c = 0; c < channels; ++c)
        worst = std::max(worst, std::abs(double(a.at(x, y, c)) - double(b.at(x, y, c))));
  return worst;
}

/// %.4g of a value (figures in the test log).
std::string fmt(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4g", v);
  return buffer;
}

} // namespace

TEST_CASE("ToneMapPass: the blocks have the std140 / std430 offsets of their GLSL twins") {
  CREP_REQUIRE_GL();
  const gl::Handle adapt = buildProgram({{ShaderStage::Compute, "passes/postfx/luminance_adapt.comp", {}}});
  const GLuint p = adapt.get();
  CHECK(resourceProperty(p, GL_UNIFORM_BLOCK, "CrepToneMapBlock", GL_BUFFER_DATA_SIZE) ==
        static_cast<GLint>(sizeof(gpu::ToneMapParams)));
  CHECK(resourceProperty(p, GL_UNIFORM, "crep_toneMap.curve", GL_OFFSET) ==
        static_cast<GLint>(offsetof(gpu::ToneMapParams, curve)));
  CHECK(resourceProperty(p, GL_UNIFORM, "crep_toneMap.adaptation", GL_OFFSET) ==
        static_cast<GLint>(offsetof(gpu::ToneMapParams, adaptation)));
  CHECK(resourceProperty(p, GL_UNIFORM, "crep_toneMap.flags", GL_OFFSET) ==
        static_cast<GLint>(offsetof(gpu::ToneMapParams, flags)));
  CHECK(resourceProperty(p, GL_UNIFORM, "crep_toneMap.sizes", GL_OFFSET) ==
        static_cast<GLint>(offsetof(gpu::ToneMapParams, sizes)));
  CHECK(resourceProperty(p, GL_BUFFER_VARIABLE, "crep_partials[0].logSum", GL_OFFSET) ==
        static_cast<GLint>(offsetof(gpu::LuminancePartial, logSum)));
  CHECK(resourceProperty(p, GL_BUFFER_VARIABLE, "crep_partials[0].count", GL_OFFSET) ==
        static_cast<GLint>(offsetof(gpu::LuminancePartial, count)));
  CHECK(resourceProperty(p, GL_BUFFER_VARIABLE, "crep_partials[0].logSum", GL_TOP_LEVEL_ARRAY_STRIDE) ==
        static_cast<GLint>(sizeof(gpu::LuminancePartial)));
  const char* stateMembers[] = {"adaptedLuminance", "targetLuminance", "exposureScale", "valid"};
  const std::size_t stateOffsets[] = {
      offsetof(gpu::ToneMapState, adaptedLuminance), offsetof(gpu::ToneMapState, targetLuminance),
      offsetof(gpu::ToneMapState, exposureScale), offsetof(gpu::ToneMapState, valid)};
  for (int i = 0; i < 4; ++i) {
    CAPTURE(stateMembers[i]);
    CHECK(resourceProperty(p, GL_BUFFER_VARIABLE, std::string("crep_state.") + stateMembers[i], GL_OFFSET) ==
          static_cast<GLint>(stateOffsets[i]));
  }
  CHECK(resourceProperty(p, GL_SHADER_STORAGE_BLOCK, "CrepToneMapStateBlock", GL_BUFFER_DATA_SIZE) ==
        static_cast<GLint>(sizeof(gpu::ToneMapState)));
}

TEST_CASE("ToneMapPass: the GPU log-average luminance equals the CPU one") {
  CREP_REQUIRE_GL();
  ToneMapPass pass(ToneMapPass::CreateInfo{});
  for (const glm::ivec2 size :
       {glm::ivec2(1, 1), glm::ivec2(63, 65), glm::ivec2(200, 130), glm::ivec2(960, 540)}) {
    CAPTURE(size.x);
    CAPTURE(size.y);
    const Image hdr = hdrImage(size.x, size.y, static_cast<std::uint32_t>(size.x * 31 + size.y));
    const gl::Handle input = uploadRgba(hdr);
    const gl::Handle output = gl::createTexture2D(GL_RGBA8, size.x, size.y);
    pass.run({input.get(), output.get(), 0.0, true});
    const gpu::ToneMapState s = pass.readState();
    const double cpu = *luminanceStats(hdr).logAverage();
    MESSAGE((std::string("log-average ") + std::to_string(size.x) + "x" + std::to_string(size.y) + ": GPU " +
             fmt(s.targetLuminance) + ", CPU " + fmt(cpu) + ", relative " +
             fmt(std::abs(s.targetLuminance / cpu - 1.0))));
    // Float logs (relative error ~1e-7 each) summed in a different order than the CPU's double sum: the
    // mean of up to 518400 terms of magnitude <= 9.3 moves by ~1e-6 absolute, which is the relative error
    // of exp(mean). 2e-5 leaves room for GPUs whose log is a few ulp less accurate than llvmpipe's.
    CHECK(s.targetLuminance == doctest::Approx(cpu).epsilon(2e-5));
    CHECK(s.valid == 1);
    CHECK(s.adaptedLuminance == s.targetLuminance); // reset: no lag
    CHECK(s.exposureScale == doctest::Approx(0.18 / cpu).epsilon(2e-5));
  }
}

TEST_CASE("ToneMapPass: every operator's image equals toneMapImage per pixel") {
  CREP_REQUIRE_GL();
  const Image hdr = hdrImage(150, 100);
  const gl::Handle input = uploadRgba(hdr);
  const gl::Handle out32 = gl::createTexture2D(GL_RGBA32F, hdr.width(), hdr.height());
  const gl::Handle out8 = gl::createTexture2D(GL_RGBA8, hdr.width(), hdr.height());
  const double cpuScale = 0.18 / *luminanceStats(hdr).logAverage();
  for (const ToneMapOperator op : kToneMapOperators)
    for (const double saturation : {1.0, 0.6}) {
      const std::string opName = toneMapOperatorName(op);
      CAPTURE(opName);
      CAPTURE(saturation);
      ToneMapPass::CreateInfo info;
      info.options.op = op;
      info.options.saturation = saturation;
      info.options.whitePoint = 4.0;
      ToneMapPass pass(info);
      pass.run({input.get(), out32.get(), 1.0 / 60.0, false});
      const double scale = pass.readState().exposureScale;
      CHECK(scale == doctest::Approx(cpuScale).epsilon(2e-5)); // as in the log-average case
      // The GPU's own scale: the comparison isolates the curves.
      const Image expected = toneMapImage(hdr, scale, info.options);
      const Image gpu32 = gl::readTexture(out32.get(), hdr.width(), hdr.height(), gl::TexelData::Rgba);
      const double err32 = maxAbsDifference(gpu32, expected, 4);
      MESSAGE((std::string(toneMapOperatorName(op)) + " s=" + fmt(saturation) +
               ": max |GPU - CPU| (RGBA32F) = " + fmt(err32)));
      // Float evaluation of the same formulas on values in [0, 1]: a few ulp of the result plus the
      // curves' condition (pow 2.2 of Filmic ALU, (rgb / Y)^s): measured <= ~1e-6 on llvmpipe; 2e-5 for
      // GPUs' approximate exp / log / pow (2^-21 relative on typical hardware).
      CHECK(err32 <= 2e-5);
      pass.run({input.get(), out8.get(), 1.0 / 60.0, false});
      const Image gpu8 = gl::readTexture(out8.get(), hdr.width(), hdr.height(), gl::TexelData::Rgba);
      // 8-bit unorm: GL leaves the rounding of the conversion to the implementation, so one code step
      // (1/255), plus the float error above.
      CHECK(maxAbsDifference(gpu8, expected, 4) <= 1.0 / 255.0 + 2e-5);
    }
}

TEST_CASE("ToneMapPass: sRGB-encoded output, manual exposure and an RGBA16F input") {
  CREP_REQUIRE_GL();
  const Image hdr = hdrImage(70, 40, 7);
  const gl::Handle input = uploadRgba(hdr);
  const gl::Handle out32 = gl::createTexture2D(GL_RGBA32F, hdr.width(), hdr.height());
  ToneMapPass::CreateInfo info;
  info.options.op = ToneMapOperator::ModifiedReinhard;
  info.options.autoExposure = false;
  info.options.exposure = 2.5;
  info.encodeSrgb = true;
  ToneMapPass pass(info);
  pass.run({input.get(), out32.get(), 0.0, false});
  Image expected = toneMapImage(hdr, 2.5, info.options);
  for (int y = 0; y < expected.height(); ++y)
    for (int x = 0; x < expected.width(); ++x)
      for (int c = 0; c < 3; ++c)
        expected.at(x, y, c) = static_cast<float>(srgbEncode(expected.at(x, y, c)));
  const Image gpu = gl::readTexture(out32.get(), hdr.width(), hdr.height(), gl::TexelData::Rgba);
  // The sRGB curve's slope is at most 12.92: the linear tolerance of the operator case times 12.92.
  CHECK(maxAbsDifference(gpu, expected, 4) <= 12.92 * 2e-5);
  CHECK(pass.readState().valid == 0); // manual exposure runs no reduction

  // RGBA16F input: the same image rounded to half precision on the CPU first.
  const gl::Handle input16 = uploadRgba(hdr, GL_RGBA16F);
  const Image stored16 = gl::readTexture(input16.get(), hdr.width(), hdr.height(), gl::TexelData::Rgba);
  ToneMapPass::CreateInfo linear;
  linear.options.op = ToneMapOperator::Reinhard;
  ToneMapPass pass16(linear);
  pass16.run({input16.get(), out32.get(), 0.0, true});
  const double logAverage = *luminanceStats(stored16).logAverage();
  CHECK(pass16.readState().targetLuminance == doctest::Approx(logAverage).epsilon(2e-5));
  const Image gpu16 = gl::readTexture(out32.get(), hdr.width(), hdr.height(), gl::TexelData::Rgba);
  CHECK(maxAbsDifference(gpu16, toneMapImage(stored16, pass16.readState().exposureScale, linear.options),
                         4) <= 2e-5);
}

TEST_CASE("ToneMapPass: adaptation reaches exp(-1) of the gap after tau, independent of the frame rate") {
  CREP_REQUIRE_GL();
  const int size = 32;
  const float L0 = 2.0f, L1 = 0.05f;
  const gl::Handle bright = uploadRgba(constantImage(size, size, glm::vec3(L0)));
  const gl::Handle dark = uploadRgba(constantImage(size, size, glm::vec3(L1)));
  const gl::Handle output = gl::createTexture2D(GL_RGBA8, size, size);
  // The log-average of a constant image of luminance L is delta + L (Reinhard et al. 2002, Eq. 1).
  const double t0 = 1e-4 + L0, t1 = 1e-4 + L1;
  const double tau = 0.25;
  const auto adaptFor = [&](double seconds, double dt) {
    ToneMapPass::CreateInfo info;
    info.options.adaptationTau = tau;
    ToneMapPass pass(info);
    pass.run({bright.get(), output.get(), 0.0, false}); // the first frame sets the state
    CHECK(pass.readState().adaptedLuminance == doctest::Approx(t0).epsilon(1e-6));
    const int frames = static_cast<int>(std::lround(seconds / dt));
    for (int i = 0; i < frames; ++i)
      pass.run({dark.get(), output.get(), dt, false});
    return pass.readState();
  };
  const gpu::ToneMapState atTau = adaptFor(tau, 1.0 / 120.0);
  // After tau the remaining gap is exp(-1) of the initial one (float state: 30 float steps).
  const double gap = (atTau.adaptedLuminance - t1) / (t0 - t1);
  MESSAGE((std::string("gap after tau: ") + fmt(gap) + " (exp(-1) = " + fmt(std::exp(-1.0)) + ")"));
  CHECK(gap == doctest::Approx(std::exp(-1.0)).epsilon(1e-5));
  CHECK(atTau.targetLuminance == doctest::Approx(t1).epsilon(1e-6));
  CHECK(atTau.exposureScale == doctest::Approx(0.18 / atTau.adaptedLuminance).epsilon(1e-6));
  // 0.5 s in frames of 1/30 s and of 1/120 s: the same state up to float rounding (15 vs 60 float steps
  // of a value ~1: a few ulp each) and the closed form.
  const gpu::ToneMapState at30 = adaptFor(0.5, 1.0 / 30.0), at120 = adaptFor(0.5, 1.0 / 120.0);
  const double closed = t1 + (t0 - t1) * std::exp(-0.5 / tau);
  CHECK(at30.adaptedLuminance == doctest::Approx(at120.adaptedLuminance).epsilon(1e-5));
  CHECK(at30.adaptedLuminance == doctest::Approx(closed).epsilon(1e-5));
  // The CPU reference takes the same path.
  LightAdaptation cpu;
  cpu.update(LuminanceStats{std::log(t0), 1}, 0.0, tau);
  double adapted = 0.0;
  for (int i = 0; i < 15; ++i)
    adapted = cpu.update(LuminanceStats{std::log(t1), 1}, 1.0 / 30.0, tau);
  CHECK(at30.adaptedLuminance == doctest::Approx(adapted).epsilon(1e-5));
}

TEST_CASE("ToneMapPass: NaN / Inf pixels are skipped by the log-average and written black, reset jumps to "
          "the target") {
  CREP_REQUIRE_GL();
  Image hdr = hdrImage(100, 70, 3);
  const LuminanceStats clean = luminanceStats(hdr);
  // Poison a tenth of the pixels, none of them counted by the CPU reference afterwards.
  const float bad[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                       -std::numeric_limits<float>::infinity()};
  for (int i = 0; i < 700; ++i)
    hdr.at((i * 37) % 100, (i * 11) % 70, i % 3) = bad[i % 3];
  const LuminanceStats poisoned = luminanceStats(hdr);
  CHECK(poisoned.count < clean.count);
  const gl::Handle input = uploadRgba(hdr);
  const gl::Handle output = gl::createTexture2D(GL_RGBA32F, hdr.width(), hdr.height());
  ToneMapPass pass(ToneMapPass::CreateInfo{});
  pass.run({input.get(), output.get(), 0.0, false});
  const gpu::ToneMapState s = pass.readState();
  CHECK(std::isfinite(s.targetLuminance));
  CHECK(s.targetLuminance == doctest::Approx(*poisoned.logAverage()).epsilon(2e-5));
  const Image gpu = gl::readTexture(output.get(), hdr.width(), hdr.height(), gl::TexelData::Rgba);
  CHECK(maxAbsDifference(gpu, toneMapImage(hdr, s.exposureScale, ToneMapOptions{}), 4) <= 2e-5);
  for (int i = 0; i < 700; ++i)
    for (int c = 0; c < 3; ++c)
      CHECK(gpu.at((i * 37) % 100, (i * 11) % 70, c) == 0.0f);

  // A frame without a finite pixel keeps the state; resetAdaptation jumps to the new frame's average.
  const gl::Handle allNan =
      uploadRgba(constantImage(16, 16, glm::vec3(std::numeric_limits<float>::quiet_NaN())));
  const gl::Handle small = gl::createTexture2D(GL_RGBA8, 16, 16);
  pass.run({allNan.get(), small.get(), 0.5, false});
  CHECK(pass.readState().adaptedLuminance == s.adaptedLuminance);
  CHECK(pass.readState().valid == 1);
  const gl::Handle grey = uploadRgba(constantImage(16, 16, glm::vec3(0.7f)));
  pass.run({grey.get(), small.get(), 1e-3, true});
  CHECK(pass.readState().adaptedLuminance == doctest::Approx(0.7 + 1e-4).epsilon(1e-6));
  // The GL state the header documents.
  GLint program = -1, ssbo = -1, ubo = -1, texture = -1;
  glGetIntegerv(GL_CURRENT_PROGRAM, &program);
  glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, 1, &ssbo);
  glGetIntegeri_v(GL_UNIFORM_BUFFER_BINDING, 0, &ubo);
  glActiveTexture(GL_TEXTURE0);
  glGetIntegerv(GL_TEXTURE_BINDING_2D, &texture);
  CHECK(program == 0);
  CHECK(ssbo == 0);
  CHECK(ubo == 0);
  CHECK(texture == 0);
}

TEST_CASE("ToneMapPass: bad options and frame attributes name the field") {
  CREP_REQUIRE_GL();
  ToneMapPass::CreateInfo badInfo;
  badInfo.options.whitePoint = std::nan("");
  CHECK(invalidParameter([&] { ToneMapPass p(badInfo); }) == "ToneMapPass::CreateInfo.options.whitePoint");
  badInfo = {};
  badInfo.options.middleGrey = 0.0;
  CHECK(invalidParameter([&] { ToneMapPass p(badInfo); }) == "ToneMapPass::CreateInfo.options.middleGrey");

  ToneMapPass pass(ToneMapPass::CreateInfo{});
  const gl::Handle input = uploadRgba(hdrImage(8, 8));
  const gl::Handle output = gl::createTexture2D(GL_RGBA8, 8, 8);
  const gl::Handle wrongSize = gl::createTexture2D(GL_RGBA8, 8, 9);
  const gl::Handle wrongOutFormat = gl::createTexture2D(GL_RGBA16F, 8, 8);
  const gl::Handle wrongInFormat = gl::createTexture2D(GL_R32F, 8, 8);
  const auto run = [&](ToneMapPass::FrameAttribs f) { return invalidParameter([&] { pass.run(f); }); };
  CHECK(run({0, output.get(), 0.0, false}) == "ToneMapPass::FrameAttribs.input");
  CHECK(run({wrongInFormat.get(), output.get(), 0.0, false}) == "ToneMapPass::FrameAttribs.input");
  CHECK(run({input.get(), 0, 0.0, false}) == "ToneMapPass::FrameAttribs.output");
  CHECK(run({input.get(), input.get(), 0.0, false}) == "ToneMapPass::FrameAttribs.output");
  CHECK(run({input.get(), wrongSize.get(), 0.0, false}) == "ToneMapPass::FrameAttribs.output");
  CHECK(run({input.get(), wrongOutFormat.get(), 0.0, false}) == "ToneMapPass::FrameAttribs.output");
  CHECK(run({input.get(), output.get(), -0.01, false}) == "ToneMapPass::FrameAttribs.dt");
  CHECK(run({input.get(), output.get(), std::numeric_limits<double>::infinity(), false}) ==
        "ToneMapPass::FrameAttribs.dt");
  ToneMapOptions bad;
  bad.saturation = 9.0;
  CHECK(invalidParameter([&] { pass.setOptions(bad); }) == "ToneMapPass::options.saturation");
  // A good frame still runs after the rejected ones, and setOptions switches the operator.
  ToneMapOptions log;
  log.op = ToneMapOperator::Logarithmic;
  pass.setOptions(log);
  CHECK(pass.options().op == ToneMapOperator::Logarithmic);
  CHECK(run({input.get(), output.get(), 0.0, false}) == "no exception");
}

TEST_CASE(
    "tone_mapping.glsl: an engine's shader calls crep_toneMapColor with the operator chosen at run time") {
  CREP_REQUIRE_GL();
  // An engine's own shader (registered like an application's embedded set): the operator is a uniform,
  // not the pass's compile-time define, so every branch of crep_toneMapCurve is compiled and selected.
  static constexpr std::string_view kSource = R"(#version 450 core
#include "crep/tone_mapping.glsl"
layout(local_size_x = 64) in;
layout(location = 0) uniform int op;
layout(std430, binding = 0) readonly buffer In { vec4 inputs[]; };
layout(std430, binding = 1) writeonly buffer Out { vec4 outputs[]; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  outputs[i] = vec4(crep_srgbEncode(crep_toneMapColor(inputs[i].rgb, inputs[i].w, op, 3.0, 1.3)), 1.0);
}
)";
  static const ShaderLibrary::File files[] = {{"tests/postfx/engine_tone_map.comp", kSource}};
  ShaderLibrary::addFiles(files);
  const gl::Handle program = buildProgram({{ShaderStage::Compute, "tests/postfx/engine_tone_map.comp", {}}});
  // rgb and the exposure scale (w) of each sample: black, grey, colours, bright, a NaN.
  std::vector<glm::vec4> inputs;
  for (int i = 0; i < 64; ++i) {
    const float L = std::pow(10.0f, -3.0f + 6.0f * static_cast<float>(i) / 63.0f);
    inputs.push_back(glm::vec4(L, 0.5f * L, 0.1f * L, i % 2 == 0 ? 1.0f : 0.37f));
  }
  inputs[0] = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  inputs[1] = glm::vec4(std::numeric_limits<float>::quiet_NaN(), 1.0f, 1.0f, 1.0f);
  gl::Handle in = gl::createBuffer(), out = gl::createBuffer();
  glNamedBufferStorage(in.get(), static_cast<GLsizeiptr>(inputs.size() * sizeof(glm::vec4)), inputs.data(),
                       0);
  glNamedBufferStorage(out.get(), static_cast<GLsizeiptr>(inputs.size() * sizeof(glm::vec4)), nullptr,
                       GL_DYNAMIC_STORAGE_BIT);
  ToneMapOptions o;
  o.whitePoint = 3.0;
  o.saturation = 1.3;
  for (const ToneMapOperator op : kToneMapOperators) {
    const std::string opName = toneMapOperatorName(op);
    CAPTURE(opName);
    o.op = op;
    glUseProgram(program.get());
    glUniform1i(0, static_cast<int>(op));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out.get());
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<glm::vec4> result(inputs.size());
    glGetNamedBufferSubData(out.get(), 0, static_cast<GLsizeiptr>(result.size() * sizeof(glm::vec4)),
                            result.data());
    double worst = 0.0;
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      const glm::dvec3 expected = toneMapColor(glm::dvec3(inputs[i]), inputs[i].w, o);
      for (int c = 0; c < 3; ++c)
        worst = std::max(worst, std::abs(double(result[i][c]) - srgbEncode(expected[c])));
    }
    // The operator case's float tolerance (2e-5) through the sRGB curve's slope (at most 12.92).
    CHECK(worst <= 12.92 * 2e-5);
  }
  gl::unbindPassState(2);
}

TEST_CASE("ToneMapPass: cost at 1280x720 (llvmpipe figure for the README)") {
  CREP_REQUIRE_GL();
  const Image hdr = hdrImage(1280, 720, 5);
  const gl::Handle input = uploadRgba(hdr);
  const gl::Handle output = gl::createTexture2D(GL_RGBA8, 1280, 720);
  ToneMapPass pass(ToneMapPass::CreateInfo{});
  pass.run({input.get(), output.get(), 0.0, true}); // builds nothing new, warms up
  // Wall clock with glFinish: llvmpipe's GL_TIME_ELAPSED does not measure its deferred rasterizer work.
  glFinish();
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 5; ++i)
    pass.run({input.get(), output.get(), 1.0 / 60.0, false});
  glFinish();
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() / 5.0;
  MESSAGE((std::string("ToneMapPass 1280x720 auto exposure, wall clock: ") + fmt(ms) +
           " ms per frame (llvmpipe)"));
  CHECK(ms > 0.0);
  CHECK(pass.readState().targetLuminance == doctest::Approx(*luminanceStats(hdr).logAverage()).epsilon(2e-5));
}
