// AtmospherePass (crep/atmosphere/gpu_pass.h) against its CPU reference crep::atmosphereImage on a
// built-in scene with a real rectified shadow map: both sides read the same tables (computed once on the
// GPU and downloaded) and the same map (rendered on the GPU, read back for the CPU trees and sections).
#include "common/analytic_reference.h"
#include "common/atmosphere_tables.h"
#include "common/error_checks.h"
#include "common/gl_fixture.h"
#include "common/gl_scene_maps.h"

#include <crep/atmosphere/atmosphere.h>
#include <crep/atmosphere/gpu_pass.h>
#include <crep/atmosphere/gpu_tables.h>
#include <crep/core/error.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/gpu/gl.h>
#include <crep/scatter/ray.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cmath>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kWidth = 64, kHeight = 36;         // camera image
constexpr int kMapWidth = 256, kMapHeight = 128; // rectified map (4 splits of 64 columns)

/// The small tables of every test here, computed once on the GPU (and read back for the CPU reference).
struct Tables {
  std::unique_ptr<AtmosphereTablesPass> pass;
  AtmosphereTables cpu;
};

Tables& tables() {
  static Tables t = [] {
    const AtmosphereTablesPass::CreateInfo info = smallAtmosphereTables(2);
    Tables r;
    r.pass = std::make_unique<AtmosphereTablesPass>(info);
    r.pass->compute();
    r.cpu = r.pass->download();
    return r;
  }();
  return t;
}

/// The terrain scene placed 200 m above sea level at 50 m per world unit: the camera's 200-unit far plane
/// spans 10 km of air.
AtmospherePlacement placement() {
  AtmospherePlacement p;
  p.metersPerUnit = 50.0;
  p.originAltitude = 200.0;
  return p;
}

struct Frame {
  SceneMaps s;
  MinMaxTrees trees;
  MinMaxTreePass gpuTrees;
  gl::Handle prefiltered; ///< the GPU min/max march of the scene medium: (c)'s shadowed input
  Image prefilteredImage;
  /// Every ray lit: an empty map (depth 1) with its trees, and a prefiltered input far above the closed
  /// form (visibility clamped to 1).
  gl::Handle emptyMap, brightPrefiltered;
  MinMaxTreePass emptyTrees;

  Frame()
      : s(renderSceneMaps("terrain", kWidth, kHeight, kMapWidth, kMapHeight)), trees(s.map.depth),
        gpuTrees({kMapWidth, kMapHeight}), emptyTrees({kMapWidth, kMapHeight}) {
    gpuTrees.run(s.mapTexture.get());
    RectifiedMarchPass march({kMapWidth, kMapHeight, RectifiedMarchPass::Mode::MinMaxTree});
    prefiltered = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
    RectifiedMarchPass::FrameAttribs m = marchAttribs(s, gpuTrees.treeBuffer());
    m.cameraDepth = s.cameraTexture.get();
    m.output = prefiltered.get();
    march.run(m);
    prefilteredImage = gl::readTexture(prefiltered.get(), kWidth, kHeight, gl::TexelData::Rgba);
    emptyMap = gl::createTexture2D(GL_R32F, kMapWidth, kMapHeight);
    const std::vector<float> ones(static_cast<std::size_t>(kMapWidth) * kMapHeight, 1.0f);
    glTextureSubImage2D(emptyMap.get(), 0, 0, 0, kMapWidth, kMapHeight, GL_RED, GL_FLOAT, ones.data());
    emptyTrees.run(emptyMap.get());
    brightPrefiltered = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
    const std::vector<float> bright(static_cast<std::size_t>(kWidth) * kHeight * 4, 1.0e6f);
    glTextureSubImage2D(brightPrefiltered.get(), 0, 0, 0, kWidth, kHeight, GL_RGBA, GL_FLOAT, bright.data());
  }
};

Frame& frame() {
  static Frame f;
  return f;
}

AtmospherePass::FrameAttribs attribs(Frame& f, const AtmospherePlacement& place, std::uint32_t output,
                                     std::uint32_t transmittance) {
  AtmospherePass::FrameAttribs a;
  a.tables = tables().pass.get();
  a.placement = &place;
  a.camera = &f.s.scene.camera;
  a.sun = &f.s.scene.sun;
  a.cameraDepth = f.s.cameraTexture.get();
  a.layout = f.s.layout.get();
  a.rectifiedDepth = f.s.mapTexture.get();
  a.minMaxBuffer = f.gpuTrees.treeBuffer();
  a.prefiltered = f.prefiltered.get();
  a.proxyMedium = &f.s.scene.medium;
  a.output = output;
  a.transmittanceOutput = transmittance;
  return a;
}

/// The CPU shadowing of every pixel for `shafts` (crep::minMaxLitSections on the CPU trees of the same map;
/// (c): prefilteredVisibility of the GPU march's texels read back).
std::vector<AtmosphereShadowing> cpuShadowing(Frame& f, AtmosphereShafts shafts) {
  std::vector<AtmosphereShadowing> out;
  if (shafts == AtmosphereShafts::None) return out;
  if (shafts == AtmosphereShafts::PrefilteredVisibility) {
    out.resize(static_cast<std::size_t>(kWidth) * kHeight);
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) {
        const PixelRay ray = pixelRay(f.s.scene.camera, f.s.cameraDepth, x, y);
        const glm::dvec3 shadowed(f.prefilteredImage.at(x, y, 0), f.prefilteredImage.at(x, y, 1),
                                  f.prefilteredImage.at(x, y, 2));
        out[static_cast<std::size_t>(y) * kWidth + x].visibility =
            prefilteredVisibility(shadowed, f.s.scene.sun, f.s.scene.medium, ray.direction, ray.surface);
      }
    return out;
  }
  for (std::vector<glm::dvec2>& sections :
       minMaxLitSections(f.s.map, f.trees, f.s.cameraDepth, f.s.scene.camera))
    out.push_back(shadowingFromSections(std::move(sections)));
  return out;
}

struct Result {
  Image inscattering, transmittance;
};

/// The pass's images; `allLit`: with the empty map and the bright prefiltered input (no shadow).
Result gpuImage(Frame& f, const AtmospherePass::CreateInfo& info, const AtmospherePlacement& place,
                bool allLit = false) {
  AtmospherePass pass(info);
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight),
                   tr = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
  AtmospherePass::FrameAttribs a = attribs(f, place, out.get(), tr.get());
  if (allLit) {
    a.rectifiedDepth = f.emptyMap.get();
    a.minMaxBuffer = f.emptyTrees.treeBuffer();
    a.prefiltered = f.brightPrefiltered.get();
  }
  pass.run(a);
  return {gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba),
          gl::readTexture(tr.get(), kWidth, kHeight, gl::TexelData::Rgba)};
}

const char* modeName(AtmosphereShafts m) {
  switch (m) {
  case AtmosphereShafts::None:
    return "None";
  case AtmosphereShafts::Integrated:
    return "(a) Integrated";
  case AtmosphereShafts::LitLengthTable:
    return "(b) LitLengthTable";
  case AtmosphereShafts::PrefilteredVisibility:
    return "(c) PrefilteredVisibility";
  }
  return "?";
}

} // namespace

TEST_CASE("Atmosphere pass: every shafts mode agrees with the CPU atmosphereImage on the terrain scene") {
  CREP_REQUIRE_GL();
  Frame& f = frame();
  const AtmospherePlacement place = placement();
  int sky = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x)
      sky += f.s.cameraDepth.at(x, y) >= 1.0f ? 1 : 0;
  MESSAGE("sky pixels: " << sky << " of " << kWidth * kHeight);
  REQUIRE(sky > 0);
  REQUIRE(sky < kWidth * kHeight);
  for (const AtmosphereShafts mode :
       {AtmosphereShafts::None, AtmosphereShafts::Integrated, AtmosphereShafts::LitLengthTable,
        AtmosphereShafts::PrefilteredVisibility}) {
    const std::string name = modeName(mode);
    CAPTURE(name);
    AtmospherePass::CreateInfo info;
    info.shafts = mode;
    info.options.integrationSteps = 16;
    info.options.skySteps = 8;
    info.mapWidth = kMapWidth;
    info.mapHeight = kMapHeight;
    const Result gpu = gpuImage(f, info, place);
    AtmosphereRayOptions options = info.options;
    options.shafts = mode;
    const AtmosphereImage cpu = atmosphereImage(tables().cpu, place, f.s.scene.camera, f.s.scene.sun,
                                                f.s.cameraDepth, cpuShadowing(f, mode), options);
    // In-scattering: float vs double along the whole chain (look-up coordinates, the table's bilinear
    // weights, exp of optical depths; the shader keeps altitudes to millimetres, see atmosphere.comp),
    // plus, for (a) and (b), shadow tests that may flip where a map texel's depth is within float rounding
    // of the ray's depth (counted as outliers: pixels over 1% of the peak, as the march tests do).
    const ImageMetrics m = rgbMetrics(gpu.inscattering, cpu.inscattering);
    CompareOptions o;
    o.channels = 3;
    o.overThreshold = 0.01 * m.peak;
    const ImageMetrics outliers = compareImages(gpu.inscattering, cpu.inscattering, o);
    report(name + " in-scattering GPU vs CPU", m);
    MESSAGE(name << ": pixels over 1% of the peak " << outliers.fractionOver * 100.0 << "%");
    // Measured: relative RMSE 2.1e-6 to 4.8e-6, max abs 2.2e-5 of the peak, no pixel over 1% of the peak
    // (every mode; 3.7e-5 to 4.7e-5 while the shader found the ground by a float ray-sphere test, metres
    // off at the planet's scale). Bounds: 10x the RMSE; 0.02 of the peak and 1% of the pixels for flips.
    CHECK(m.nanCount == 0);
    CHECK(m.relativeRmse < 3e-5);
    CHECK(m.maxAbsError < 0.02 * m.peak);
    CHECK(outliers.fractionOver < 0.01);
    if (mode != AtmosphereShafts::None) {
      // The shafts matter far more than the GPU's error: the same mode with every ray lit (sections
      // [0, surface], visibility 1) on the CPU.
      std::vector<AtmosphereShadowing> lit(static_cast<std::size_t>(kWidth) * kHeight);
      for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x)
          lit[static_cast<std::size_t>(y) * kWidth + x] = shadowingFromSections(
              {glm::dvec2(0.0, pixelRay(f.s.scene.camera, f.s.cameraDepth, x, y).surface)});
      const AtmosphereImage unshadowed = atmosphereImage(tables().cpu, place, f.s.scene.camera, f.s.scene.sun,
                                                         f.s.cameraDepth, lit, options);
      const ImageMetrics shafts = rgbMetrics(cpu.inscattering, unshadowed.inscattering);
      MESSAGE(name << ": shadowed vs every ray lit (CPU): relative RMSE " << shafts.relativeRmse);
      CHECK(shafts.relativeRmse > 10.0 * m.relativeRmse);
      // The shadows alone: (shadowed - all lit) on the GPU against the same difference on the CPU, so the
      // bright sky does not hide an error in the walk, the sections or the visibility.
      const Result gpuLit = gpuImage(f, info, place, true);
      Image gpuShadow(kWidth, kHeight, 3), cpuShadow(kWidth, kHeight, 3);
      for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x)
          for (int c = 0; c < 3; ++c) {
            gpuShadow.at(x, y, c) = gpu.inscattering.at(x, y, c) - gpuLit.inscattering.at(x, y, c);
            cpuShadow.at(x, y, c) = cpu.inscattering.at(x, y, c) - unshadowed.inscattering.at(x, y, c);
          }
      const ImageMetrics d = compareImages(gpuShadow, cpuShadow);
      report(name + " shadow (shadowed - all lit) GPU vs CPU", d);
      // Measured relative RMSE of the shadow alone: (a) 2.2e-5, (b) 1.7e-4 (Eq. 8 of two look-ups at
      // nearby points: a float difference of close values), (c) 3.3e-5. Bound: 10x (b)'s figure. (With
      // the look-ups at float positions, 0.5 m apart at the planet's surface, (b) measured 2.3e-2.)
      CHECK(d.nanCount == 0);
      CHECK(d.peak > 0.0);
      CHECK(d.relativeRmse < 2e-3);
    }
    // Transmittance (RGB, and A of the output is its mean).
    const ImageMetrics t = rgbMetrics(gpu.transmittance, cpu.transmittance);
    report(name + " transmittance GPU vs CPU", t);
    // Measured max abs 7.9e-6 (float coordinates of the optical depth table). Bound: 13x.
    CHECK(t.maxAbsError < 1e-4);
    double meanDiff = 0.0;
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) {
        const double mean =
            (gpu.transmittance.at(x, y, 0) + gpu.transmittance.at(x, y, 1) + gpu.transmittance.at(x, y, 2)) /
            3.0;
        meanDiff = std::max(meanDiff, std::abs(mean - gpu.inscattering.at(x, y, 3)));
      }
    CHECK(meanDiff < 1e-6);
  }
}

TEST_CASE("Atmosphere pass: the view tables agree with the CPU atmosphereViewTables") {
  CREP_REQUIRE_GL();
  Frame& f = frame();
  const AtmospherePlacement place = placement();
  AtmospherePass::CreateInfo info;
  info.options.volumeSize = {16, 12, 8};
  info.options.skyViewSize = {24, 16};
  AtmospherePass pass(info);
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
  pass.run(attribs(f, place, out.get(), 0));
  REQUIRE(pass.volumeRayleighTexture() != 0);
  REQUIRE(pass.skyRayleighTexture() != 0);
  const AtmosphereViewTables cpu =
      atmosphereViewTables(tables().cpu, place, f.s.scene.camera, f.s.scene.sun, info.options);
  // Max abs difference over RGB relative to the table's peak.
  const auto compare = [](std::uint32_t texture, const std::vector<glm::vec3>& reference) {
    std::vector<float> texels(reference.size() * 4);
    glGetTextureImage(texture, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(texels.size() * sizeof(float)),
                      texels.data());
    double worst = 0.0, peak = 0.0;
    for (std::size_t i = 0; i < reference.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        peak = std::max(peak, static_cast<double>(reference[i][c]));
        worst = std::max(worst, std::abs(static_cast<double>(texels[4 * i + c] - reference[i][c])));
      }
    REQUIRE(peak > 0.0);
    return worst / peak;
  };
  const double volume = std::max(compare(pass.volumeRayleighTexture(), cpu.volumeRayleigh),
                                 compare(pass.volumeMieTexture(), cpu.volumeMie));
  const double sky = std::max(compare(pass.skyRayleighTexture(), cpu.skyRayleigh),
                              compare(pass.skyMieTexture(), cpu.skyMie));
  MESSAGE("view tables GPU vs CPU, max abs / peak: volume " << volume << ", sky view " << sky);
  CHECK(volume < 1e-5);
  CHECK(sky < 1e-4);
}

TEST_CASE("Atmosphere pass: bad attributes name the field") {
  CREP_REQUIRE_GL();
  Frame& f = frame();
  const AtmospherePlacement place = placement();
  AtmospherePass::CreateInfo info;
  info.shafts = AtmosphereShafts::Integrated;
  info.mapWidth = kMapWidth;
  info.mapHeight = kMapHeight;
  {
    AtmospherePass::CreateInfo bad = info;
    bad.options.integrationSteps = 0;
    requireNamed([&] { AtmospherePass p(bad); }, "AtmospherePass::CreateInfo.options.integrationSteps");
    bad = info;
    bad.options.skySteps = 0;
    requireNamed([&] { AtmospherePass p(bad); }, "AtmospherePass::CreateInfo.options.skySteps");
    bad = info;
    bad.options.volumeSize.z = 1;
    requireNamed([&] { AtmospherePass p(bad); }, "AtmospherePass::CreateInfo.options.volumeSize.z");
    bad = info;
    bad.options.skyViewSize.y = 7;
    requireNamed([&] { AtmospherePass p(bad); }, "AtmospherePass::CreateInfo.options.skyViewSize.y");
    bad = info;
    bad.mapWidth = 0;
    requireNamed([&] { AtmospherePass p(bad); }, "AtmospherePass::CreateInfo.mapWidth/mapHeight");
  }
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight),
                   small = gl::createTexture2D(GL_RGBA32F, kWidth / 2, kHeight),
                   r8 = gl::createTexture2D(GL_R32F, kWidth, kHeight);
  AtmospherePass pass(info);
  AtmospherePass prefilteredPass({AtmosphereShafts::PrefilteredVisibility, {}, 0, 0});
  const AtmospherePass::FrameAttribs good = attribs(f, place, out.get(), 0);
  const std::string p = "AtmospherePass::FrameAttribs.";
  const std::vector<std::pair<std::string, std::function<void(AtmospherePass::FrameAttribs&)>>> cases = {
      {"tables", [](auto& a) { a.tables = nullptr; }},
      {"placement", [](auto& a) { a.placement = nullptr; }},
      {"camera", [](auto& a) { a.camera = nullptr; }},
      {"sun", [](auto& a) { a.sun = nullptr; }},
      {"cameraDepth", [](auto& a) { a.cameraDepth = 0; }},
      {"output", [](auto& a) { a.output = 0; }},
      {"layout", [](auto& a) { a.layout = nullptr; }},
      {"rectifiedDepth", [](auto& a) { a.rectifiedDepth = 0; }},
      {"minMaxBuffer", [](auto& a) { a.minMaxBuffer = 0; }},
  };
  for (const auto& [name, spoil] : cases) {
    CAPTURE(name);
    AtmospherePass::FrameAttribs a = good;
    spoil(a);
    requireNamed([&] { pass.run(a); }, p + name);
  }
  {
    AtmospherePass::FrameAttribs a = good;
    a.output = small.get();
    requireNamed([&] { pass.run(a); }, p + "output");
    a = good;
    a.output = r8.get();
    requireNamed([&] { pass.run(a); }, p + "output");
    a = good;
    a.transmittanceOutput = small.get();
    requireNamed([&] { pass.run(a); }, p + "transmittanceOutput");
    a = good;
    AtmospherePlacement badPlace = place;
    badPlace.metersPerUnit = 0.0;
    a.placement = &badPlace;
    requireNamed([&] { pass.run(a); }, p + "placement");
  }
  {
    AtmospherePass::FrameAttribs a = good;
    a.prefiltered = 0;
    requireNamed([&] { prefilteredPass.run(a); }, p + "prefiltered");
    a = good;
    a.proxyMedium = nullptr;
    requireNamed([&] { prefilteredPass.run(a); }, p + "proxyMedium");
    // (c) and None read no map: the map's fields may be unset.
    a = good;
    a.layout = nullptr;
    a.rectifiedDepth = 0;
    a.minMaxBuffer = 0;
    prefilteredPass.run(a);
  }
}

TEST_CASE("Atmosphere pass: a camera above the atmosphere agrees with the CPU (restrained camera)") {
  CREP_REQUIRE_GL();
  Frame& f = frame();
  // 10 km per world unit: the camera (y = 12) is 120 km up, above the 80 km atmosphere; rays enter it
  // (Yusov's restrained camera position) or miss it (nothing in-scattered, everything transmitted).
  AtmospherePlacement place;
  place.metersPerUnit = 1.0e4;
  for (const AtmosphereShafts mode : {AtmosphereShafts::None, AtmosphereShafts::Integrated}) {
    const std::string name = modeName(mode);
    CAPTURE(name);
    AtmospherePass::CreateInfo info;
    info.shafts = mode;
    info.mapWidth = kMapWidth;
    info.mapHeight = kMapHeight;
    const Result gpu = gpuImage(f, info, place);
    AtmosphereRayOptions options = info.options;
    options.shafts = mode;
    const AtmosphereImage cpu = atmosphereImage(tables().cpu, place, f.s.scene.camera, f.s.scene.sun,
                                                f.s.cameraDepth, cpuShadowing(f, mode), options);
    const ImageMetrics m = rgbMetrics(gpu.inscattering, cpu.inscattering);
    const ImageMetrics t = rgbMetrics(gpu.transmittance, cpu.transmittance);
    report(name + " above the atmosphere: in-scattering GPU vs CPU", m);
    report(name + " above the atmosphere: transmittance GPU vs CPU", t);
    CHECK(m.nanCount == 0);
    CHECK(t.nanCount == 0);
    // Measured: relative RMSE None 6.0e-6, (a) 8.6e-7; transmittance max abs 1.9e-5. Bounds ~10x.
    CHECK(m.peak > 0.0);
    CHECK(m.relativeRmse < 1e-4);
    CHECK(t.maxAbsError < 2e-4);
  }
}
