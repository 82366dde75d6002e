// The post effects on gpu::VulkanBackend (lavapipe, validation on) against the same passes on the GL backend
// (llvmpipe), the same inputs uploaded to both: Mitchell 2007's radial blur (both modes) on the sunset
// scene's camera depth (the sun in view), Wronski 2014's froxel fog (ESM shadowing, temporal reprojection
// over frames, apply; Mode::Prefiltered on a given volume), and the tone mapping (Reinhard et
// al. 2002's log-average with adaptation, several operators, RGBA32F and RGBA8 outputs) on an HDR image. Bar:
// relative RMSE <= 1e-4 between the backends, and for RGBA8 output at most one 8-bit step anywhere.
#include "common/gl_fixture.h"
#include "common/vulkan_fixture.h"

#include <crep/gpu/gl_backend.h>
#include <crep/postfx/gpu_froxel_fog.h>
#include <crep/postfx/gpu_radial_blur.h>
#include <crep/postfx/gpu_tone_mapping.h>
#include <crep/scenes/engine_frame.h>
#include <crep/scenes/scene.h>
#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

using namespace crep;

namespace {

/// Relative RMSE of `a` against `b` over the RGB of RGBA floats; `largest` the largest |a - b|.
double relativeRmse(const std::vector<float>& a, const std::vector<float>& b, double& largest) {
  REQUIRE(a.size() == b.size());
  double squared = 0.0, reference = 0.0;
  largest = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (i % 4 == 3) continue;
    const double d = static_cast<double>(a[i]) - b[i];
    squared += d * d;
    reference += static_cast<double>(b[i]) * b[i];
    largest = std::max(largest, std::abs(d));
  }
  return std::sqrt(squared / std::max(reference, 1e-30));
}

} // namespace

TEST_CASE("Vulkan backend: RadialBlurPass gives GL's image in both modes (sunset, the sun in view)") {
  CREP_REQUIRE_GL();
  constexpr int w = 160, h = 90;
  const scenes::Scene scene = scenes::makeScene("sunset", static_cast<double>(w) / h);
  const scenes::EngineMaps maps = scenes::renderEngineMaps(scene, w, h, 256, 64);
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  gpu::GlBackend gl;
  for (const RadialBlurMode mode : {RadialBlurMode::SourceRadiance, RadialBlurMode::OcclusionFraction}) {
    const auto runOn = [&](gpu::Backend& b) {
      gpu::Texture depth(b, {gpu::TextureType::Texture2D, gpu::Format::Depth32F, w, h, 1, "depth"});
      b.writeTexture(depth.id(), maps.cameraDepth.data());
      gpu::Texture out(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, w, h, 1, "radial"});
      RadialBlurPass::CreateInfo info;
      info.options.mode = mode;
      info.backend = &b;
      RadialBlurPass pass(info);
      pass.run({&scene.camera, &scene.sun, &scene.medium, depth.id(), out.id()});
      return b.readTexture(out.id());
    };
    const std::vector<float> a = runOn(vk), b = runOn(gl);
    double largest = 0.0;
    const double e = relativeRmse(a, b, largest);
    MESSAGE(std::string(mode == RadialBlurMode::SourceRadiance ? "source radiance" : "occlusion fraction")
            << ": Vulkan vs GL relative RMSE " << e << ", max |difference| " << largest);
    CHECK(std::none_of(a.begin(), a.end(), [](float v) { return !std::isfinite(v); }));
    CHECK(e <= 1e-4);
  }
  crep::test::checkNoValidationMessages(vk);
}

TEST_CASE("Vulkan backend: ToneMapPass gives GL's display image and adaptation state") {
  CREP_REQUIRE_GL();
  constexpr int w = 97, h = 61; // not multiples of the reduction's tile
  // An HDR frame: a dim gradient, a bright disc (a sun at 500), a NaN pixel the log-average skips.
  std::vector<float> hdr(static_cast<std::size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* p = &hdr[(static_cast<std::size_t>(y) * w + x) * 4];
      const float g = 0.02f + 0.8f * static_cast<float>(x) / w,
                  sun = std::hypot(x - 70.0, y - 40.0) < 6.0 ? 500.0f : 0.0f;
      p[0] = g + sun;
      p[1] = 0.5f * g + sun;
      p[2] = 0.2f + 0.3f * static_cast<float>(y) / h + sun;
      p[3] = 1.0f;
    }
  hdr[(30 * w + 10) * 4] = std::numeric_limits<float>::quiet_NaN();
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  gpu::GlBackend gl;
  for (const ToneMapOperator op :
       {ToneMapOperator::Reinhard, ToneMapOperator::Uncharted2, ToneMapOperator::AdaptiveLogarithmic})
    for (const gpu::Format format : {gpu::Format::RGBA32F, gpu::Format::RGBA8}) {
      struct Result {
        std::vector<float> image;
        gpu::ToneMapState state;
      };
      const auto runOn = [&](gpu::Backend& b) {
        gpu::Texture in(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, w, h, 1, "hdr"});
        b.writeTexture(in.id(), hdr);
        gpu::Texture out(b, {gpu::TextureType::Texture2D, format, w, h, 1, "display"});
        ToneMapPass::CreateInfo info;
        info.options.op = op;
        info.options.autoExposure = true;
        info.backend = &b;
        ToneMapPass pass(info);
        // Two frames: the first sets the adapted luminance, the second adapts toward it over dt.
        pass.run({in.id(), out.id(), 0.0, true});
        pass.run({in.id(), out.id(), 0.25, false});
        return Result{b.readTexture(out.id()), pass.readState()};
      };
      const Result a = runOn(vk), b = runOn(gl);
      double largest = 0.0;
      const double e = relativeRmse(a.image, b.image, largest);
      const std::string name =
          std::string(toneMapOperatorName(op)) + (format == gpu::Format::RGBA8 ? ", RGBA8" : ", RGBA32F");
      MESSAGE(name << ": Vulkan vs GL relative RMSE " << e << ", max |difference| " << largest
                   << "; adapted luminance " << a.state.adaptedLuminance << " vs "
                   << b.state.adaptedLuminance);
      CHECK(e <= 1e-4);
      if (format == gpu::Format::RGBA8) CHECK(largest <= 1.0 / 255.0 + 1e-6);
      CHECK(a.state.valid == 1);
      CHECK(std::abs(a.state.adaptedLuminance - b.state.adaptedLuminance) <= 1e-5 * b.state.adaptedLuminance);
    }
  crep::test::checkNoValidationMessages(vk);
}

TEST_CASE(
    "Vulkan backend: FroxelFog gives GL's image and volume over three frames with temporal reprojection "
    "(ESM mode, and Mode::Prefiltered on a given integrated volume)") {
  CREP_REQUIRE_GL();
  constexpr int w = 128, h = 72;
  const scenes::Scene scene = scenes::makeScene("forest", static_cast<double>(w) / h);
  const scenes::EngineMaps maps = scenes::renderEngineMaps(scene, w, h, 512, 64);
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  gpu::GlBackend gl;
  for (const FroxelFog::Mode mode : {FroxelFog::Mode::Esm, FroxelFog::Mode::Prefiltered}) {
    struct Result {
      std::vector<float> image, volume;
    };
    const auto runOn = [&](gpu::Backend& b) {
      const scenes::EngineFrame engine(b, scene, maps);
      gpu::Texture out(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, w, h, 1, "fog"});
      FroxelFog::CreateInfo info;
      info.grid.width = 32;
      info.grid.height = 18;
      info.grid.depth = 24;
      info.density.noiseAmplitude = 0.3;
      // RGBA32F volumes: the port's bar is for float storage. With the default RGBA16F a value one float ulp
      // apart on the two backends may round to neighbouring halves (2^-11 relative): measured 2e-5 (ESM).
      info.format = 0x8814; // GL_RGBA32F
      info.backend = &b;
      FroxelFog fog(info);
      // Three frames of a camera moving sideways: the history reprojected and blended.
      Camera previous = scene.camera;
      for (int frame = 0; frame < 3; ++frame) {
        const Camera camera = Camera::lookAt(scene.camera.position() + 0.05 * frame * scene.camera.right(),
                                             scene.camera.position() + scene.camera.forward() +
                                                 0.05 * frame * scene.camera.right(),
                                             scene.camera.up(), scene.camera.fovY(), scene.camera.aspect(),
                                             scene.camera.near(), scene.camera.far());
        if (mode == FroxelFog::Mode::Prefiltered) {
          // The integrated volume as a fill would leave it (crep::Scattering's froxels; its own agreement is
          // tests/vulkan/ScatteringVulkanGLTest.cpp): the same smooth values on both backends.
          std::vector<float> cells;
          for (int z = 0; z < info.grid.depth; ++z)
            for (int y = 0; y < info.grid.height; ++y)
              for (int x = 0; x < info.grid.width; ++x) {
                const float d = static_cast<float>(z + 1) / static_cast<float>(info.grid.depth);
                const float shaft =
                    0.5f + 0.5f * std::sin(0.4f * static_cast<float>(x + 2 * frame) + 0.2f * y);
                cells.insert(cells.end(),
                             {0.2f * d * shaft, 0.15f * d * shaft, 0.1f * d, std::exp(-1.5f * d)});
              }
          b.writeTexture(fog.currentVolume(), cells);
        }
        FroxelFog::FrameAttribs f;
        f.mode = mode;
        f.camera = &camera;
        f.light = &scene.sun;
        f.medium = &scene.medium;
        f.cameraDepth = engine.attribs(0).cameraDepth;
        f.shadowMap = engine.attribs(0).shadowMap->texture;
        f.lightClipFromWorld = maps.sunClipFromWorld;
        f.output = out.id();
        f.frameIndex = frame;
        f.previousCamera = frame > 0 ? &previous : nullptr;
        fog.run(f);
        previous = camera;
      }
      return Result{b.readTexture(out.id()), b.readTexture(fog.volume())};
    };
    const Result a = runOn(vk), b = runOn(gl);
    double largest = 0.0, largestVolume = 0.0;
    const double e = relativeRmse(a.image, b.image, largest),
                 v = relativeRmse(a.volume, b.volume, largestVolume);
    MESSAGE(std::string(mode == FroxelFog::Mode::Esm ? "ESM" : "prefiltered")
            << ": Vulkan vs GL relative RMSE, image " << e << " (max " << largest << "), volume " << v
            << " (max " << largestVolume << ")");
    CHECK(std::none_of(a.image.begin(), a.image.end(), [](float x) { return !std::isfinite(x); }));
    CHECK(e <= 1e-4);
    CHECK(v <= 1e-4);
  }
  crep::test::checkNoValidationMessages(vk);
}
