// The atmosphere's passes on gpu::VulkanBackend (lavapipe, validation on) against gpu::GlBackend (llvmpipe):
// AtmosphereTablesPass computed on each (the orders method with three orders, Hillaire's multiple
// scattering LUT, one order, half-float tables), then AtmospherePass in every shafts mode on the terrain
// scene's camera depth and rectified map, each backend reading its own tables. Bar: relative RMSE <= 1e-4
// between the backends, the bound for the frame.
#include "common/atmosphere_tables.h"
#include "common/gl_fixture.h"
#include "common/gl_scene_maps.h"
#include "common/vulkan_fixture.h"

#include <crep/atmosphere/atmosphere.h>
#include <crep/atmosphere/gpu_pass.h>
#include <crep/atmosphere/gpu_tables.h>
#include <crep/core/error.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/gpu/gl_backend.h>
#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

using namespace crep;

namespace {

constexpr int kWidth = 64, kHeight = 36, kMapWidth = 256, kMapHeight = 128;

/// Relative RMSE of a against b over every value (b's energy); the plain RMSE where b is all zero.
double relativeRmse(const std::vector<float>& a, const std::vector<float>& b) {
  REQUIRE(a.size() == b.size());
  double squared = 0.0, reference = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double d = static_cast<double>(a[i]) - b[i];
    squared += d * d;
    reference += static_cast<double>(b[i]) * b[i];
  }
  return reference > 0.0 ? std::sqrt(squared / reference)
                         : std::sqrt(squared / static_cast<double>(a.size()));
}

std::vector<float> flat(const Image& image) {
  return {image.data().begin(), image.data().end()};
}

/// Each table of `t` by name (the optical depth's huge values through the planet would hide the others).
std::vector<std::pair<std::string, std::vector<float>>> eachTable(const AtmosphereTables& t) {
  std::vector<std::pair<std::string, std::vector<float>>> out = {{"optical depth", flat(t.opticalDepth)},
                                                                 {"single", t.single.rgba},
                                                                 {"single Mie", t.singleMie.rgba},
                                                                 {"higher orders", t.higherOrders.rgba},
                                                                 {"ambient", flat(t.ambient)}};
  if (t.multipleScatteringLut.width() > 0)
    out.emplace_back("multiple scattering LUT", flat(t.multipleScatteringLut));
  return out;
}

/// The terrain frame's inputs uploaded to one backend: camera depth, rectified map and its trees, and (c)'s
/// prefiltered input.
struct BackendFrame {
  gpu::Texture depth, map, prefiltered;
  MinMaxTreePass trees;
  BackendFrame(gpu::Backend& b, const test::SceneMaps& s, const std::vector<float>& prefilteredTexels)
      : depth(b, {gpu::TextureType::Texture2D, gpu::Format::Depth32F, kWidth, kHeight, 1, "camera depth"}),
        map(b, {gpu::TextureType::Texture2D, gpu::Format::R32F, kMapWidth, kMapHeight, 1, "rectified map"}),
        prefiltered(b,
                    {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, kWidth, kHeight, 1, "prefiltered"}),
        trees({.mapWidth = kMapWidth, .mapHeight = kMapHeight, .backend = &b}) {
    b.writeTexture(depth.id(), s.cameraDepth.data());
    b.writeTexture(map.id(), s.map.depth.data());
    b.writeTexture(prefiltered.id(), prefilteredTexels);
    trees.run(map.id());
  }
};

struct PassOutput {
  std::vector<float> inscattering, transmittance;
};

PassOutput runPass(gpu::Backend& b, const AtmosphereTablesPass& tables, const BackendFrame& frame,
                   const test::SceneMaps& s, AtmosphereShafts shafts, AtmosphereSingleScattering single) {
  AtmospherePass::CreateInfo info;
  info.shafts = shafts;
  info.options.integrationSteps = 16;
  info.options.skySteps = 8;
  info.options.single = single;
  info.mapWidth = kMapWidth;
  info.mapHeight = kMapHeight;
  info.backend = &b;
  AtmospherePass pass(info);
  const gpu::Texture out(b,
                         {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, kWidth, kHeight, 1, "output"});
  const gpu::Texture tr(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, kWidth, kHeight, 1, "trans"});
  AtmospherePlacement place;
  place.metersPerUnit = 50.0;
  place.originAltitude = 200.0;
  AtmospherePass::FrameAttribs a;
  a.tables = &tables;
  a.placement = &place;
  a.camera = &s.scene.camera;
  a.sun = &s.scene.sun;
  a.cameraDepth = frame.depth.id();
  a.layout = s.layout.get();
  a.rectifiedDepth = frame.map.id();
  a.minMaxBuffer = frame.trees.treeBuffer();
  a.prefiltered = frame.prefiltered.id();
  a.proxyMedium = &s.scene.medium;
  a.output = out.id();
  a.transmittanceOutput = tr.id();
  pass.run(a);
  return {b.readTexture(out.id()), b.readTexture(tr.id())};
}

} // namespace

TEST_CASE("Vulkan backend: the atmosphere's tables give GL's") {
  CREP_REQUIRE_GL();
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  gpu::GlBackend gl;
  struct Case {
    const char* name;
    AtmosphereMultipleScattering method;
    int orders;
    bool half;
  };
  for (const Case c : {Case{"orders, 3 orders", AtmosphereMultipleScattering::Orders, 3, false},
                       Case{"multiple scattering LUT", AtmosphereMultipleScattering::Lut, 3, false},
                       Case{"single scattering only", AtmosphereMultipleScattering::Orders, 1, false},
                       Case{"orders, RGBA16F tables", AtmosphereMultipleScattering::Orders, 2, true}}) {
    CAPTURE(std::string(c.name));
    AtmosphereTablesPass::CreateInfo info = test::smallAtmosphereTables(3);
    info.options.multipleScattering = c.method;
    info.options.orders = c.orders;
    info.halfFloatTables = c.half;
    info.backend = &vk;
    AtmosphereTablesPass onVulkan(info);
    info.backend = &gl;
    AtmosphereTablesPass onGl(info);
    onVulkan.compute();
    onGl.compute();
    const AtmosphereTables a = onVulkan.download(), b = onGl.download();
    const auto ta = eachTable(a), tb = eachTable(b);
    REQUIRE(ta.size() == tb.size());
    std::ostringstream figures;
    double worst = 0.0;
    for (std::size_t i = 0; i < ta.size(); ++i) {
      const double e = relativeRmse(ta[i].second, tb[i].second);
      figures << ta[i].first << " " << e << ", ";
      worst = std::max(worst, e);
      CAPTURE(ta[i].first);
      CHECK(e <= 1e-4);
    }
    std::string stages;
    for (const auto& [name, ms] : onVulkan.stageTimes())
      stages += name + "; ";
    MESSAGE(std::string(c.name) << ": Vulkan vs GL relative RMSE (an all-zero table: RMSE) " << figures.str()
                                << "worst " << worst << "; stages on Vulkan: " << stages);
    CHECK(onVulkan.stageTimes().size() == onGl.stageTimes().size());
  }
  crep::test::checkNoValidationMessages(vk);
}

TEST_CASE("Vulkan backend: the atmosphere pass gives GL's image in every shafts mode") {
  CREP_REQUIRE_GL();
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  gpu::GlBackend gl;
  const test::SceneMaps s = test::renderSceneMaps("terrain", kWidth, kHeight, kMapWidth, kMapHeight);
  // (c)'s shadowed input: the GL min/max march of the scene medium, the same texels on both backends.
  std::vector<float> prefiltered;
  {
    MinMaxTreePass trees({kMapWidth, kMapHeight});
    trees.run(s.mapTexture.get());
    RectifiedMarchPass march({kMapWidth, kMapHeight, RectifiedMarchPass::Mode::MinMaxTree});
    const gpu::Texture out(gl,
                           {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, kWidth, kHeight, 1, "march"});
    RectifiedMarchPass::FrameAttribs m = test::marchAttribs(s, trees.treeBuffer());
    m.cameraDepth = s.cameraTexture.get();
    m.output = out.id();
    march.run(m);
    prefiltered = gl.readTexture(out.id());
  }
  AtmosphereTablesPass::CreateInfo info = test::smallAtmosphereTables(3);
  info.backend = &vk;
  AtmosphereTablesPass vkTables(info);
  vkTables.compute();
  info.backend = &gl;
  AtmosphereTablesPass glTables(info);
  glTables.compute();
  const BackendFrame vkFrame(vk, s, prefiltered), glFrame(gl, s, prefiltered);
  for (const AtmosphereShafts shafts :
       {AtmosphereShafts::None, AtmosphereShafts::Integrated, AtmosphereShafts::LitLengthTable,
        AtmosphereShafts::PrefilteredVisibility})
    for (const AtmosphereSingleScattering single :
         {AtmosphereSingleScattering::Table4D, AtmosphereSingleScattering::ViewTables}) {
      CAPTURE(static_cast<int>(shafts));
      CAPTURE(static_cast<int>(single));
      const PassOutput a = runPass(vk, vkTables, vkFrame, s, shafts, single),
                       b = runPass(gl, glTables, glFrame, s, shafts, single);
      const double e = relativeRmse(a.inscattering, b.inscattering),
                   t = relativeRmse(a.transmittance, b.transmittance);
      MESSAGE("shafts " << static_cast<int>(shafts) << ", single " << static_cast<int>(single)
                        << ": Vulkan vs GL relative RMSE, in-scattering " << e << ", transmittance " << t);
      CHECK(e <= 1e-4);
      CHECK(t <= 1e-4);
    }
  // Tables of another backend are named.
  AtmospherePass::CreateInfo p;
  p.backend = &vk;
  AtmospherePass pass(p);
  AtmospherePlacement place;
  AtmospherePass::FrameAttribs f;
  f.tables = &glTables;
  f.placement = &place;
  f.camera = &s.scene.camera;
  f.sun = &s.scene.sun;
  f.cameraDepth = vkFrame.depth.id();
  f.output = vkFrame.prefiltered.id();
  CHECK_THROWS_WITH_AS(pass.run(f), doctest::Contains("AtmospherePass::FrameAttribs.tables"),
                       InvalidArgument);
  AtmospherePass moved = std::move(pass);
  f.tables = &vkTables;
  CHECK_THROWS_WITH_AS(pass.run(f), doctest::Contains("AtmospherePass"), InvalidArgument);
  crep::test::checkNoValidationMessages(vk);
}
