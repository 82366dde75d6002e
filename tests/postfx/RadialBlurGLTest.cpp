// RadialBlurPass (crep/postfx/gpu_radial_blur.h) against its CPU reference crep::radialBlur on a small
// analytic frame (a ground plane with a row of pillars, the sun in view), full and reduced source
// resolution, odd workgroup sizes, both modes; a sun behind the camera adds exactly nothing; NaN depth stays
// finite; the block's std140 offsets; bad input names the field.
#include "common/analytic_scene.h"
#include "common/error_checks.h"
#include "common/gl_fixture.h"
#include "common/gl_util.h"

#include <crep/core/error.h>
#include <crep/gpu/shader_library.h>
#include <crep/postfx/gpu_radial_blur.h>
#include <crep/postfx/radial_blur.h>
#include <crep/support/image_compare.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cmath>
#include <cstddef>
#include <string>

using namespace crep;
using crep::test::requireNamed;
using crep::test::resourceProperty;
using crep::test::uploadR32F;

namespace {

/// Ground depth with a row of pillars (geometry at view depth ~12 over the lower 70% of some columns).
Image pillarDepth(const Camera& camera, int w, int h) {
  Image depth = test::groundDepth(camera, w, h);
  const float pillar = static_cast<float>(test::depthBufferValue(camera, 12.0));
  for (int y = 0; y < h * 7 / 10; ++y)
    for (int x = 0; x < w; ++x)
      if (x % 11 < 3) depth.at(x, y) = std::min(depth.at(x, y), pillar);
  return depth;
}

Image runGpu(const RadialBlurPass::CreateInfo& info, const Image& depth, const Camera& camera,
             const DirectionalLight& light, const Medium& medium) {
  RadialBlurPass pass(info);
  const gl::Handle depthTexture = uploadR32F(depth);
  const gl::Handle output = gl::createTexture2D(GL_RGBA32F, depth.width(), depth.height());
  RadialBlurPass::FrameAttribs f;
  f.camera = &camera;
  f.light = &light;
  f.medium = &medium;
  f.cameraDepth = depthTexture.get();
  f.output = output.get();
  pass.run(f);
  return gl::readTexture(output.get(), depth.width(), depth.height(), gl::TexelData::Rgba);
}

/// The sun at NDC (x, y) of the camera (the light travels toward the camera).
DirectionalLight sunAt(const Camera& camera, double x, double y) {
  return DirectionalLight(-camera.rayDirection(x, y), glm::dvec3(2.0, 1.8, 1.5));
}

} // namespace

TEST_CASE("RadialBlurPass: GPU equals the CPU reference on a pillar frame with the sun in view") {
  CREP_REQUIRE_GL();
  const int w = 64, h = 36;
  const Camera camera = test::groundCamera(w, h);
  const Medium medium = test::colouredMedium();
  const Image depth = pillarDepth(camera, w, h);
  struct Case {
    double sunX, sunY;
    int sourceScale, workgroup, samples;
    double decay;
    RadialBlurMode mode;
  };
  const RadialBlurMode source = RadialBlurMode::SourceRadiance, fraction = RadialBlurMode::OcclusionFraction;
  for (const Case c : {Case{0.2, 0.4, 1, 8, 48, 0.97, source}, Case{-0.5, 0.1, 2, 5, 33, 1.0, source},
                       Case{1.2, 0.6, 3, 16, 20, 0.9, source}, // off screen: fade 0.648
                       Case{0.2, 0.4, 1, 8, 48, 0.97, fraction}, Case{-0.3, 0.2, 2, 8, 24, 1.0, fraction}}) {
    CAPTURE(static_cast<int>(c.mode));
    CAPTURE(c.sunX);
    CAPTURE(c.sourceScale);
    const DirectionalLight light = sunAt(camera, c.sunX, c.sunY);
    RadialBlurPass::CreateInfo info;
    info.options.samples = c.samples;
    info.options.decay = c.decay;
    info.options.density = 0.9;
    info.options.exposure = 1.2;
    info.options.weight = 0.8;
    info.options.sourceScale = c.sourceScale;
    info.options.mode = c.mode;
    info.workgroupSize = c.workgroup;
    const Image gpu = runGpu(info, depth, camera, light, medium);
    const Image cpu = radialBlur(depth, camera, light, medium, info.options);
    // Float vs double and the hardware bilinear filter: llvmpipe measured < 1e-6 relative RMSE; GPUs
    // filter with about 8 fractional bits in the weights, so a sample across a sky / pillar edge can be
    // off by 1/512 of the step (averaged over n + 1 samples): 0.5% relative RMSE on RGB, 2% of the peak at
    // any pixel. A: float exp of the same ray, 1e-5.
    CompareOptions three;
    three.channels = 3;
    const ImageMetrics m = compareImages(gpu, cpu, three);
    MESSAGE(std::string("radial GPU vs CPU: " + describe(m)));
    CHECK(m.nanCount + m.infCount == 0);
    CHECK(m.relativeRmse < 5e-3);
    CHECK(m.maxAbsError < 0.02 * m.peak);
    double alpha = 0.0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        alpha = std::max(alpha, static_cast<double>(std::abs(gpu.at(x, y, 3) - cpu.at(x, y, 3))));
    CHECK(alpha < 1e-5);
    CHECK(m.peak > 0.0); // the sun adds something
  }
}

TEST_CASE("RadialBlurPass: a sun behind the camera adds exactly nothing and NaN depth stays finite") {
  CREP_REQUIRE_GL();
  const int w = 40, h = 24;
  const Camera camera = test::groundCamera(w, h);
  const Medium medium = test::colouredMedium();
  const Image depth = pillarDepth(camera, w, h);
  RadialBlurPass::CreateInfo info;
  {
    const DirectionalLight behind(camera.forward() + glm::dvec3(0.1, -0.3, 0.0));
    const Image gpu = runGpu(info, depth, camera, behind, medium);
    const Image cpu = radialBlur(depth, camera, behind, medium, info.options);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        for (int c = 0; c < 3; ++c)
          REQUIRE(gpu.at(x, y, c) == 0.0f);
        CHECK(gpu.at(x, y, 3) == doctest::Approx(cpu.at(x, y, 3)).epsilon(1e-5));
      }
  }
  {
    Image nanDepth = depth;
    for (int x = 0; x < w; x += 3)
      nanDepth.at(x, h / 2) = std::nanf("");
    const Image gpu = runGpu(info, nanDepth, camera, sunAt(camera, 0.0, 0.3), medium);
    for (const float v : gpu.data())
      REQUIRE(std::isfinite(v));
    // NaN is the sky (the documented GPU rule): the pixel's transmittance is the far plane's.
    Image skyDepth = depth;
    skyDepth.at(0, h / 2) = 1.0f;
    const Image cpu = radialBlur(skyDepth, camera, sunAt(camera, 0.0, 0.3), medium, info.options);
    CHECK(gpu.at(0, h / 2, 3) == doctest::Approx(cpu.at(0, h / 2, 3)).epsilon(1e-5));
  }
}

TEST_CASE("RadialBlurPass: the block has the std140 offsets of its GLSL twin") {
  CREP_REQUIRE_GL();
  const gl::Handle program = buildProgram({{ShaderStage::Compute, "passes/postfx/radial_blur.comp", {}}});
  const GLuint block = glGetProgramResourceIndex(program.get(), GL_UNIFORM_BLOCK, "CrepRadialBlurBlock");
  REQUIRE(block != GL_INVALID_INDEX);
  const GLenum sizeProperty = GL_BUFFER_DATA_SIZE;
  GLint size = 0;
  glGetProgramResourceiv(program.get(), GL_UNIFORM_BLOCK, block, 1, &sizeProperty, 1, nullptr, &size);
  CHECK(static_cast<std::size_t>(size) == sizeof(gpu::RadialBlurParams));
  const std::pair<const char*, std::size_t> members[] = {
      {"crep_radial.light", offsetof(gpu::RadialBlurParams, light)},
      {"crep_radial.shape", offsetof(gpu::RadialBlurParams, shape)},
      {"crep_radial.info", offsetof(gpu::RadialBlurParams, info)},
  };
  for (const auto& [name, offset] : members) {
    CAPTURE(std::string(name));
    const GLint actual = resourceProperty(program.get(), GL_UNIFORM, name, GL_OFFSET);
    REQUIRE(actual >= 0);
    CHECK(static_cast<std::size_t>(actual) == offset);
  }
}

TEST_CASE("RadialBlurPass: bad input names the field") {
  CREP_REQUIRE_GL();
  const int w = 16, h = 8;
  const Camera camera = test::groundCamera(w, h);
  const Medium medium = test::colouredMedium();
  const DirectionalLight light = sunAt(camera, 0.0, 0.2);
  {
    RadialBlurPass::CreateInfo info;
    info.options.decay = 1.5;
    requireNamed([&] { RadialBlurPass p(info); }, "RadialBlurPass::CreateInfo.options.decay");
    info = {};
    info.options.samples = 0;
    requireNamed([&] { RadialBlurPass p(info); }, "RadialBlurPass::CreateInfo.options.samples");
    info = {};
    info.options.density = std::nan("");
    requireNamed([&] { RadialBlurPass p(info); }, "RadialBlurPass::CreateInfo.options.density");
    info = {};
    info.workgroupSize = 33;
    requireNamed([&] { RadialBlurPass p(info); }, "RadialBlurPass::CreateInfo.workgroupSize");
  }
  RadialBlurPass pass({});
  const gl::Handle depth = uploadR32F(Image(w, h, 1, 1.0f));
  const gl::Handle output = gl::createTexture2D(GL_RGBA32F, w, h);
  const gl::Handle small = gl::createTexture2D(GL_RGBA32F, w / 2, h);
  const gl::Handle rgba8 = gl::createTexture2D(GL_RGBA8, w, h);
  RadialBlurPass::FrameAttribs good;
  good.camera = &camera;
  good.light = &light;
  good.medium = &medium;
  good.cameraDepth = depth.get();
  good.output = output.get();
  CHECK_NOTHROW(pass.run(good));
  auto f = good;
  f.camera = nullptr;
  requireNamed([&] { pass.run(f); }, "RadialBlurPass::FrameAttribs.camera");
  f = good;
  f.light = nullptr;
  requireNamed([&] { pass.run(f); }, "RadialBlurPass::FrameAttribs.light");
  f = good;
  f.medium = nullptr;
  requireNamed([&] { pass.run(f); }, "RadialBlurPass::FrameAttribs.medium");
  f = good;
  f.cameraDepth = 0;
  requireNamed([&] { pass.run(f); }, "RadialBlurPass::FrameAttribs.cameraDepth");
  f = good;
  f.cameraDepth = rgba8.get(); // not a depth format
  requireNamed([&] { pass.run(f); }, "RadialBlurPass::FrameAttribs.cameraDepth");
  f = good;
  f.output = 0;
  requireNamed([&] { pass.run(f); }, "RadialBlurPass::FrameAttribs.output");
  f = good;
  f.output = small.get(); // wrong size
  requireNamed([&] { pass.run(f); }, "RadialBlurPass::FrameAttribs.output");
  f = good;
  f.output = rgba8.get(); // wrong format
  requireNamed([&] { pass.run(f); }, "RadialBlurPass::FrameAttribs.output");
}
