// PrefilterPass on gpu::VulkanBackend (lavapipe, validation on): the boxes scene's rectified map, rendered
// by GL and uploaded to Vulkan, prefiltered into the filtered basis in each storage format, against the
// CPU reference with the per-format tolerance of the GL pass's test (tests/prefilter/PrefilterGpuGLTest.cpp,
// common/prefilter_gpu.h: 4e-6 for RGBA32F, one binary16 ulp, one RGBA8 step), and against the GL
// backend's basis of the same map.
#include "common/gl_fixture.h"
#include "common/prefilter_gpu.h"
#include "common/vulkan_fixture.h"

#include <crep/gpu/gl.h>
#include <crep/gpu/gl_backend.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kMapW = 250, kMapH = 37, kSplits = 2;

/// The filtered basis of `depth` by PrefilterPass on `backend`.
std::vector<float> prefilterOn(gpu::Backend& backend, const GpuScene& s,
                               const PrefilterPass::CreateInfo& base) {
  gpu::Texture map(backend,
                   {gpu::TextureType::Texture2D, gpu::Format::R32F, kMapW, kMapH, 1, "rectified map"});
  backend.writeTexture(map.id(), s.map.depth.data());
  PrefilterPass::CreateInfo info = base;
  info.backend = &backend;
  PrefilterPass pass(info);
  PrefilterPass::FrameAttribs frame;
  frame.rectifiedDepth = map.id();
  frame.layout = s.layout.get();
  frame.medium = &s.scene.medium;
  pass.run(frame);
  return backend.readTexture(pass.filteredBasisTexture());
}

} // namespace

TEST_CASE("Vulkan backend: PrefilterPass gives the CPU filtered basis in every storage format, as GL does") {
  CREP_REQUIRE_GL();
  const GpuScene s = renderGpuScene("boxes", kMapW, kMapH, kSplits, 161, 93);
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  gpu::GlBackend gl;
  for (const StorageFormat format : {StorageFormat::RGBA32F, StorageFormat::RGBA16F, StorageFormat::RGBA8}) {
    const std::string token = storageFormatToken(format);
    CAPTURE(token);
    PrefilterPass::CreateInfo info;
    info.mapWidth = kMapW;
    info.mapHeight = kMapH;
    info.options.format = format;
    const FilteredBasis cpu = prefilter(s.map, s.scene.medium, info.options);
    const std::vector<float> onVulkan = prefilterOn(vk, s, info), onGl = prefilterOn(gl, s, info);
    REQUIRE(onVulkan.size() == cpu.texels.size());
    const BasisDifference d = compareBasis(onVulkan, cpu, FormatTolerance{format});
    double squared = 0.0, reference = 0.0;
    long long differ = 0;
    for (std::size_t i = 0; i < onGl.size(); ++i) {
      const double e = static_cast<double>(onVulkan[i]) - onGl[i];
      squared += e * e;
      reference += static_cast<double>(onGl[i]) * onGl[i];
      differ += e != 0.0;
    }
    const double relativeRmse = std::sqrt(squared / reference);
    MESSAGE(token << ": against the CPU " << describe(d) << "; against GL relative RMSE " << relativeRmse
                  << ", " << differ << " of " << onGl.size() << " values differ");
    CHECK(d.over == 0);
    CHECK(relativeRmse <= 1e-4);
  }
  crep::test::checkNoValidationMessages(vk);
}
