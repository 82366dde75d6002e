// The benchmark variants of the passes (CreateInfo::memoryLimit: the pass stripped to its memory traffic,
// crep bench's "limits"): they must move exactly the bytes of the real passes, or the ratios they give mean
// nothing. The write-only prefilter writes every layer of every texel (the map depth, raw); the fetch-only
// evaluation fetches M / 4 layers per prefilter region a ray crosses, which a basis of constant texels
// turns into a count: with every stored value e = 1 (decoded F = 2 e - 1 = 1) a pixel's sum is
// layers x regions crossed without the region visibility table, and (regions crossed - 1) table fetches
// (the table's write-only pass writes 1) + layers with it; compared with the regions counted on the CPU by
// the layout (the rule of crep::evaluate: the surface point's region, all before it crossed).
#include "common/gl_fixture.h"
#include "common/prefilter_gpu.h"

#include <crep/gpu/gl.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/scatter/ray.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace crep;
using namespace crep::test;

TEST_CASE("memory-limit variants: the write-only prefilter writes every layer, the fetch-only evaluation "
          "fetches M / 4 layers per region crossed") {
  CREP_REQUIRE_GL();
  constexpr int kMapW = 256, kMapH = 64, kScreenW = 160, kScreenH = 90, kSplits = 4, kP = 2, kBases = 32;
  const GpuScene s = renderGpuScene("boxes", kMapW, kMapH, kSplits, kScreenW, kScreenH);
  // An empty map (depth 1 everywhere) as R32F.
  const gl::Handle empty = gl::createTexture2D(GL_R32F, kMapW, kMapH);
  const std::vector<float> ones(std::size_t(kMapW) * kMapH, 1.0f);
  glTextureSubImage2D(empty.get(), 0, 0, 0, kMapW, kMapH, GL_RED, GL_FLOAT, ones.data());

  PrefilterPass::CreateInfo pi;
  pi.mapWidth = kMapW;
  pi.mapHeight = kMapH;
  pi.options.bases = kBases;
  pi.options.format = StorageFormat::RGBA32F;
  pi.options.regionsPerSplit = kP;
  pi.memoryLimit = true;
  PrefilterPass writeOnly(pi);
  writeOnly.run({empty.get(), s.layout.get(), &s.scene.medium});
  const int layers = layerCount(kBases);
  for (int l = 0; l < layers; ++l) {
    const Image layer =
        gl::readTexture(writeOnly.filteredBasisTexture(), kMapW, kMapH, gl::TexelData::Rgba, l);
    float lo = 1e30f, hi = -1e30f;
    for (float v : layer.data()) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    CAPTURE(l);
    CHECK(lo == 1.0f); // every texel of every layer written with the map's depth
    CHECK(hi == 1.0f);
  }

  for (const int tableSamples : {0, 128}) {
    CAPTURE(tableSamples);
    EvaluatePass::CreateInfo ei;
    ei.bases = kBases;
    ei.options.visibilityTableSamples = tableSamples;
    ei.memoryLimit = true;
    EvaluatePass fetchOnly(ei);
    const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kScreenW, kScreenH);
    fetchOnly.run({s.depthTexture.get(), out.get(), &s.scene.camera, &s.scene.sun, &s.scene.medium,
                   s.layout.get(), writeOnly.filteredBasis()});
    const Image sums = gl::readTexture(out.get(), kScreenW, kScreenH, gl::TexelData::Rgba);
    int mismatched = 0, total = 0;
    double meanRegions = 0.0;
    for (int y = 0; y < kScreenH; ++y)
      for (int x = 0; x < kScreenW; ++x) {
        const PixelRay ray = pixelRay(s.scene.camera, s.cameraDepth, x, y);
        const RectPoint hit = s.layout->toRectified(s.scene.camera.position() + ray.surface * ray.direction);
        const int q =
            std::min(static_cast<int>(std::floor(std::clamp(hit.splitColumn, 0.0, 1.0) * kP)), kP - 1);
        const int regions = hit.split * kP + q + 1;
        meanRegions += regions;
        ++total;
        const double fetched = tableSamples > 0 ? sums.at(x, y, 0) - layers + 1 : sums.at(x, y, 0) / layers;
        if (std::abs(fetched - regions) > 1e-3) ++mismatched;
        // A float mapping on a region boundary may land one region off; never more.
        CHECK(std::abs(fetched - regions) <= 1.0 + 1e-3);
      }
    MESSAGE("regions crossed per pixel " << meanRegions / total << "; GPU count differs from the CPU's at "
                                         << mismatched << " of " << total << " pixels");
    CHECK(mismatched <= total / 200);
  }
}
