// The reduced-resolution passes (crep/pipeline/reduced_resolution.h) on gpu::VulkanBackend, validation
// on: the checkerboard downsample is the CPU rule bit for bit (min and max of the same floats) and the
// depth-aware upsample is within float rounding of the CPU rule in double, at factors 2 and 4, on a depth
// image with steps and sky; bad input is named.
#include "common/analytic_reference.h"
#include "common/vulkan_fixture.h"

#include <crep/core/error.h>
#include <crep/gpu/backend.h>
#include <crep/pipeline/reduced_resolution.h>
#include <crep/scenes/scene.h>
#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <cmath>
#include <span>
#include <utility>

using namespace crep;

namespace {

constexpr int kWidth = 96, kHeight = 64;

/// Depth-buffer values with steps every 5 and 7 pixels (view depths 2 to 60) and a sky band on top.
Image steppedDepth() {
  Image d(kWidth, kHeight, 1);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      d.at(x, y) = y >= kHeight - 6 ? 1.0f : static_cast<float>(0.9 + 0.0099 * ((x / 5 + 3 * (y / 7)) % 10));
  return d;
}

gpu::Texture texture(gpu::Backend& b, gpu::Format format, int w, int h, const char* label) {
  return gpu::Texture(b, {gpu::TextureType::Texture2D, format, w, h, 1, label});
}

Image imageOf(const std::vector<float>& texels, int w, int h, int channels) {
  Image out(w, h, channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c)
        out.at(x, y, c) = texels[(static_cast<std::size_t>(y) * w + x) * channels + c];
  return out;
}

} // namespace

TEST_CASE("Vulkan backend: the reduced-resolution downsample and upsample follow the CPU rules") {
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  const Camera camera = scenes::makeScene("colonnade", static_cast<double>(kWidth) / kHeight).camera;
  const Image depth = steppedDepth();
  gpu::Texture fullDepth = texture(vk, gpu::Format::Depth32F, kWidth, kHeight, "full depth");
  vk.writeTexture(fullDepth.id(), std::span<const float>(depth.data().data(), depth.data().size()));
  for (const int factor : {2, 4}) {
    CAPTURE(factor);
    DepthAwareResamplePass pass({.width = kWidth, .height = kHeight, .factor = factor, .backend = &vk});
    const int w = pass.lowWidth(), h = pass.lowHeight();
    gpu::Texture lowDepth = texture(vk, gpu::Format::R32F, w, h, "low depth");
    gpu::Texture low = texture(vk, gpu::Format::RGBA32F, w, h, "low");
    gpu::Texture out = texture(vk, gpu::Format::RGBA32F, kWidth, kHeight, "output");
    pass.downsample(fullDepth.id(), lowDepth.id());
    const Image gpuLowDepth = imageOf(vk.readTexture(lowDepth.id()), w, h, 1);
    const Image cpuLowDepth = downsampleDepth(depth, factor);
    int differing = 0;
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i)
        differing += gpuLowDepth.at(i, j) != cpuLowDepth.at(i, j);
    CHECK(differing == 0); // min and max of the same floats: bit-identical

    Image values(w, h, 4);
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i)
        for (int c = 0; c < 4; ++c)
          values.at(i, j, c) = static_cast<float>(1.0 + 0.5 * std::sin(0.3 * i - 0.2 * j + c));
    vk.writeTexture(low.id(), std::span<const float>(values.data().data(), values.data().size()));
    pass.upsample(low.id(), lowDepth.id(), fullDepth.id(), out.id(), camera);
    const Image gpu = imageOf(vk.readTexture(out.id()), kWidth, kHeight, 4);
    const Image cpu = depthAwareUpsample(values, cpuLowDepth, depth, camera, factor);
    const double worst = crep::test::maxRelativeDifference(gpu, cpu, 1e-3);
    MESSAGE("factor " << factor << ": upsample on Vulkan vs the CPU rule, max relative difference " << worst);
    CHECK(worst < 1e-4); // the GL pass's bound: float view depths in the weights

    // Bad input names the parameter; a moved-from pass names itself.
    CHECK_THROWS_WITH_AS(pass.downsample(low.id(), lowDepth.id()),
                         doctest::Contains("DepthAwareResamplePass::downsample.fullDepth"), InvalidArgument);
    CHECK_THROWS_WITH_AS(pass.downsample(fullDepth.id(), low.id()),
                         doctest::Contains("DepthAwareResamplePass::downsample.lowDepth"), InvalidArgument);
    CHECK_THROWS_WITH_AS(pass.upsample(low.id(), lowDepth.id(), fullDepth.id(), low.id(), camera),
                         doctest::Contains("DepthAwareResamplePass::upsample.output"), InvalidArgument);
    CHECK_THROWS_WITH_AS(pass.upsample(lowDepth.id(), lowDepth.id(), fullDepth.id(), out.id(), camera),
                         doctest::Contains("DepthAwareResamplePass::upsample.low"), InvalidArgument);
    DepthAwareResamplePass moved = std::move(pass);
    CHECK_THROWS_WITH_AS(pass.downsample(fullDepth.id(), lowDepth.id()),
                         doctest::Contains("DepthAwareResamplePass"), InvalidArgument);
    moved.downsample(fullDepth.id(), lowDepth.id());
  }
  crep::test::checkNoValidationMessages(vk);
}
