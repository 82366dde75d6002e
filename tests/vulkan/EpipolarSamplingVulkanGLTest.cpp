// Yusov's epipolar sampling stages (crep/epipolar/gpu_epipolar_sampling.h) on gpu::VulkanBackend (lavapipe,
// validation on) and gpu::GlBackend (llvmpipe), stage by stage on the same inputs: the sunset's camera depth
// with the sun in view (lines wrapping around an epipole on screen) and the forest's (epipole off screen).
// Each stage after the first is fed the same values on both backends, so only its own arithmetic differs.
#include "common/gl_fixture.h"
#include "common/vulkan_fixture.h"

#include <crep/core/error.h>
#include <crep/epipolar/gpu_epipolar_sampling.h>
#include <crep/gpu/gl_backend.h>
#include <crep/scenes/engine_frame.h>
#include <crep/scenes/scene.h>
#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

using namespace crep;

namespace {

constexpr int kWidth = 320, kHeight = 180;

/// What one backend's stages produced.
struct Stages {
  std::vector<float> coordinates, unshadowed, sources, interpolated, unwarped, target;
  EpipolarSamplingPass::Statistics statistics;
};

/// Relative RMSE of a against b (b's energy), and the count of values that differ at all.
std::pair<double, long long> compare(const std::vector<float>& a, const std::vector<float>& b) {
  REQUIRE(a.size() == b.size());
  double squared = 0.0, reference = 0.0;
  long long differing = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double d = static_cast<double>(a[i]) - b[i];
    squared += d * d;
    reference += static_cast<double>(b[i]) * b[i];
    differing += a[i] != b[i];
  }
  return {reference > 0.0 ? std::sqrt(squared / reference) : std::sqrt(squared), differing};
}

/// The samples' values written before the interpolation: the same smooth pattern on both backends.
std::vector<float> sampleValues(const EpipolarSamplingOptions& o) {
  std::vector<float> v(static_cast<std::size_t>(o.samples) * static_cast<std::size_t>(o.slices) * 4);
  for (std::size_t i = 0; i < v.size(); ++i)
    v[i] = 1.0f + 0.5f * std::sin(0.001f * static_cast<float>(i));
  return v;
}

Stages runStages(gpu::Backend& b, const scenes::Scene& scene, const scenes::EngineMaps& maps,
                 const EpipolarSamplingOptions& o) {
  const scenes::EngineFrame engine(b, scene, maps);
  gpu::Texture output(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, kWidth, kHeight, 1, "output"});
  const Scattering::FrameAttribs f = engine.attribs(output.id());
  EpipolarSamplingPass pass({.width = kWidth, .height = kHeight, .options = o, .backend = &b});
  const EpipolarSamplingPass::FrameAttribs s{f.camera, f.light, f.medium, f.cameraDepth, f.output};
  Stages out;
  pass.placeSamples(s);
  pass.refine();
  out.coordinates = b.readTexture(pass.coordinatesTexture());
  out.unshadowed = b.readTexture(pass.unshadowedTexture());
  out.sources = b.readTexture(pass.sourcesTexture());
  b.writeTexture(pass.sampleTexture(), sampleValues(o)); // the evaluator's stand-in
  pass.interpolate();
  out.interpolated = b.readTexture(pass.sampleTexture());
  // The pixels left to the correction lists are not written: zeros on both backends.
  const auto clear = [&](std::uint32_t texture) {
    b.writeTexture(texture, std::vector<float>(b.readTexture(texture).size(), 0.0f));
  };
  clear(o.downscale > 1 ? pass.targetTexture() : f.output);
  pass.unwarp(s);
  out.unwarped = b.readTexture(o.downscale > 1 ? pass.targetTexture() : f.output);
  if (o.downscale > 1) {
    clear(f.output);
    pass.upscale(s);
    out.target = b.readTexture(f.output);
  }
  out.statistics = pass.statistics();
  return out;
}

} // namespace

TEST_CASE("Vulkan backend: the epipolar sampling stages give GL's results") {
  CREP_REQUIRE_GL();
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  gpu::GlBackend gl;
  for (const std::string name : {"sunset", "forest"}) {
    scenes::Scene scene = scenes::makeScene(name, static_cast<double>(kWidth) / kHeight);
    const scenes::EngineMaps maps = scenes::renderEngineMaps(scene, kWidth, kHeight, 512, 256);
    for (const int downscale : {1, 2}) {
      CAPTURE(name);
      CAPTURE(downscale);
      EpipolarSamplingOptions o;
      o.slices = 256;
      o.samples = 128;
      o.downscale = downscale;
      const Stages a = runStages(vk, scene, maps, o), b = runStages(gl, scene, maps, o);
      const auto [coordinates, coordinatesDiffering] = compare(a.coordinates, b.coordinates);
      const auto [unshadowed, unshadowedDiffering] = compare(a.unshadowed, b.unshadowed);
      const auto [sources, sourcesDiffering] = compare(a.sources, b.sources);
      const auto [interpolated, interpolatedDiffering] = compare(a.interpolated, b.interpolated);
      const auto [unwarped, unwarpedDiffering] = compare(a.unwarped, b.unwarped);
      MESSAGE(name << ", downscale " << downscale << ", Vulkan vs GL relative RMSE (values differing): "
                   << "coordinates " << coordinates << " (" << coordinatesDiffering << "), unshadowed "
                   << unshadowed << " (" << unshadowedDiffering << "), sources " << sources << " ("
                   << sourcesDiffering << "), interpolated " << interpolated << " (" << interpolatedDiffering
                   << "), unwarped " << unwarped << " (" << unwarpedDiffering << "); samples to march "
                   << a.statistics.marchedSamples << ", pixels to correct " << a.statistics.correctedPixels);
      CHECK(coordinates <= 1e-6); // float rounding of the line positions
      CHECK(unshadowed <= 1e-5);  // and of the unshadowed in-scattering there
      CHECK(sourcesDiffering == 0);
      CHECK(interpolatedDiffering == 0);
      CHECK(unwarped <= 1e-6);
      CHECK(a.statistics.validSamples == b.statistics.validSamples);
      CHECK(a.statistics.marchedSamples == b.statistics.marchedSamples);
      CHECK(a.statistics.correctedPixels == b.statistics.correctedPixels);
      CHECK(a.statistics.marchedSamples > 0);
      if (downscale > 1) {
        const auto [upscaled, upscaledDiffering] = compare(a.target, b.target);
        MESSAGE("upscaled " << upscaled << " (" << upscaledDiffering << "), full-resolution corrections "
                            << a.statistics.correctedFullPixels);
        CHECK(upscaled <= 1e-6);
        CHECK(a.statistics.correctedFullPixels == b.statistics.correctedFullPixels);
      }
    }
  }
  crep::test::checkNoValidationMessages(vk);
}

TEST_CASE("Vulkan backend: epipolar sampling names bad input") {
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  EpipolarSamplingOptions o;
  o.slices = 64;
  o.samples = 64;
  EpipolarSamplingPass pass({.width = 64, .height = 32, .options = o, .backend = &vk});
  const scenes::Scene scene = scenes::makeScene("sunset", 2.0);
  gpu::Texture depth(vk, {gpu::TextureType::Texture2D, gpu::Format::Depth32F, 64, 32, 1, "depth"});
  gpu::Texture colour(vk, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, 64, 32, 1, "colour"});
  gpu::Texture small(vk, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, 32, 32, 1, "small"});
  EpipolarSamplingPass::FrameAttribs f{&scene.camera, &scene.sun, &scene.medium, depth.id(), colour.id()};
  pass.placeSamples(f);
  EpipolarSamplingPass::FrameAttribs bad = f;
  bad.cameraDepth = colour.id(); // not a depth format
  CHECK_THROWS_WITH_AS(pass.placeSamples(bad),
                       doctest::Contains("EpipolarSamplingPass::FrameAttribs.cameraDepth"), InvalidArgument);
  bad = f;
  bad.output = small.id();
  CHECK_THROWS_WITH_AS(pass.unwarp(bad), doctest::Contains("EpipolarSamplingPass::FrameAttribs.output"),
                       InvalidArgument);
  bad = f;
  bad.output = 4242; // no texture of this backend
  CHECK_THROWS_WITH_AS(pass.placeSamples(bad), doctest::Contains("EpipolarSamplingPass::FrameAttribs.output"),
                       InvalidArgument);
  EpipolarSamplingPass moved = std::move(pass);
  CHECK_THROWS_WITH_AS(pass.placeSamples(f), doctest::Contains("EpipolarSamplingPass"), InvalidArgument);
  CHECK_THROWS_WITH_AS(pass.refine(), doctest::Contains("EpipolarSamplingPass"), InvalidArgument);
  CHECK(pass.statistics().marchedSamples == 0);
  moved.placeSamples(f);
  moved.refine();
  CHECK(moved.statistics().validSamples > 0);
  crep::test::checkNoValidationMessages(vk);
}
