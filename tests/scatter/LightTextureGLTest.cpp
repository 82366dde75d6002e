// Light textures on the GPU against their CPU references (crep/scatter/light_texture.h; Klehm et al. 2014,
// Sec. 3.2 coloured light textures): the colour map pass (LightColorMapPass vs crep::lightColorMap), the
// textured prefilter (PrefilterPass::FrameAttribs::lightColors vs crep::prefilter with lightColors: the three
// bases and the mean colour), the textured evaluation (EvaluatePass on a textured basis vs crep::evaluate,
// with the scattering prefix table and without a table) and the textured world march (WorldMarchPass::
// FrameAttribs::lightTexture vs crep::worldSpaceMarch), for the sun's window and a spot light's gobo; the
// modes without a textured variant reject it by name.
#include "common/analytic_reference.h"
#include "common/analytic_scene.h"
#include "common/gl_fixture.h"
#include "common/light_texture_frames.h"
#include "common/local_light_scene.h"
#include "common/prefilter_gpu.h"

#include <crep/core/error.h>
#include <crep/gpu/shader_library.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/gpu_layout_buffers.h>
#include <crep/scatter/gpu_light_texture.h>
#include <crep/scatter/gpu_world_march.h>
#include <crep/scatter/light_texture.h>
#include <crep/scatter/rectified_march.h>
#include <crep/scatter/world_march.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kW = 160, kH = 90, kMapW = 256, kMapH = 128;

PrefilterOptions prefilterOptions(StorageFormat format) {
  PrefilterOptions o;
  o.regionsPerSplit = 2;
  o.format = format;
  return o;
}

double maxAbsDifference(const Image& a, const Image& b, int channels) {
  double worst = 0.0;
  for (int j = 0; j < b.height(); ++j)
    for (int i = 0; i < b.width(); ++i)
      for (int k = 0; k < channels; ++k) {
        const double d = std::abs(static_cast<double>(a.at(i, j, k)) - b.at(i, j, k));
        worst = std::max(worst, d == d ? d : 1e30);
      }
  return worst;
}

} // namespace

TEST_CASE("light texture GL: the colour map pass equals lightColorMap (sun window, spot gobo)") {
  CREP_REQUIRE_GL();
  const Image tex = twoColourTexture();
  const gl::Handle texture = uploadRgb(tex);
  LightColorMapPass pass({.mapWidth = kMapW, .mapHeight = kMapH});
  for (const bool spot : {false, true}) {
    CAPTURE(spot);
    const LightTextureFrame f = lightTextureFrame(spot, kW, kH, kMapW, kMapH);
    const Image cpu = lightColorMap({&tex, f.textureClipFromWorld}, *f.layout, kMapW, kMapH);
    LightColorMapPass::FrameAttribs a{.layout = f.layout.get(),
                                      .lightTexture = {texture.get(), f.textureClipFromWorld}};
    if (spot)
      a.localLight = &*f.local;
    else
      a.light = &f.sun;
    pass.run(a);
    const Image gpu = readRgbaTexture(pass.colorMapTexture(), kMapW, kMapH);
    // Float light rays and projection against double: the colour edge (one texel of the 64-texel texture
    // wide, 0.95 of contrast) turns a position error of ~1e-6 NDC into ~3e-5 of colour; elsewhere exact.
    const double d = maxAbsDifference(gpu, cpu, 3);
    MESSAGE(std::string(spot ? "spot gobo" : "sun window") << ": colour map, max |gpu - cpu| = " << d);
    CHECK(d < 1e-3);
  }
}

TEST_CASE("light texture GL: the textured prefilter equals the CPU reference (3 bases, mean colour)") {
  CREP_REQUIRE_GL();
  const Image tex = twoColourTexture();
  const PrefilterOptions o = prefilterOptions(StorageFormat::RGBA32F);
  PrefilterPass pass({.mapWidth = kMapW, .mapHeight = kMapH, .options = o});
  for (const bool spot : {false, true}) {
    CAPTURE(spot);
    const LightTextureFrame f = lightTextureFrame(spot, kW, kH, kMapW, kMapH);
    const Image colors = lightColorMap({&tex, f.textureClipFromWorld}, *f.layout, kMapW, kMapH);
    const FilteredBasis cpu =
        spot ? prefilter(f.map, f.medium, *f.local, colors, o) : prefilter(f.map, f.medium, colors, o);
    const gl::Handle depth = uploadR32F(f.map.depth);
    const gl::Handle colorTexture = uploadRgb(colors);
    PrefilterPass::FrameAttribs a{
        .rectifiedDepth = depth.get(), .layout = f.layout.get(), .medium = &f.medium};
    a.localLight = spot ? &*f.local : nullptr;
    a.lightColors = colorTexture.get();
    pass.run(a);
    const FilteredBasisView view = pass.filteredBasis();
    CHECK(view.textured);
    const std::vector<float> gpu = readTextureArray(view.texture, kMapW, kMapH, 3 * pass.layers());
    // The directional and local prefilters' RGBA32F tolerance (4e-6; float weights against double).
    const BasisDifference d = compareBasis(gpu, cpu, FormatTolerance{StorageFormat::RGBA32F});
    MESSAGE(std::string(spot ? "spot" : "sun") << ": textured basis, " << describe(d));
    CHECK(d.over == 0);
    // cbar: rounded to binary16 on both sides from float / double prefixes: at most one half ulp apart.
    const Image mean = readRgbaTexture(view.meanColor, kMapW, kMapH);
    long long over = 0;
    double worst = 0.0;
    for (int j = 0; j < kMapH; ++j)
      for (int i = 0; i < kMapW; ++i)
        for (int k = 0; k < 3; ++k) {
          const double c = cpu.mean(i, j, k), e = std::abs(mean.at(i, j, k) - c);
          worst = std::max(worst, e);
          over += e <= ulpHalf(c) + 1e-7 ? 0 : 1;
        }
    MESSAGE("mean colour: max |gpu - cpu| " << worst << ", " << over << " beyond one half ulp");
    CHECK(over == 0);
  }

  // c = 1 everywhere: the textured bases are the untextured one, bit for bit, on the GPU too.
  const LightTextureFrame f = sunTextureFrame(kW, kH, kMapW, kMapH);
  const gl::Handle depth = uploadR32F(f.map.depth);
  const gl::Handle ones = uploadRgb(Image(kMapW, kMapH, 3, 1.0f));
  pass.run({.rectifiedDepth = depth.get(), .layout = f.layout.get(), .medium = &f.medium});
  CHECK_FALSE(pass.filteredBasis().textured);
  const std::vector<float> plain = readTextureArray(pass.filteredBasisTexture(), kMapW, kMapH, pass.layers());
  pass.run({.rectifiedDepth = depth.get(),
            .layout = f.layout.get(),
            .medium = &f.medium,
            .lightColors = ones.get()});
  const std::vector<float> textured =
      readTextureArray(pass.filteredBasisTexture(), kMapW, kMapH, 3 * pass.layers());
  for (int c = 0; c < 3; ++c)
    CHECK(std::memcmp(textured.data() + c * plain.size(), plain.data(), plain.size() * sizeof(float)) == 0);

  gl::Handle wrong = uploadRgb(Image(kMapW / 2, kMapH, 3, 1.0f));
  CHECK_THROWS_WITH_AS(pass.run({.rectifiedDepth = depth.get(),
                                 .layout = f.layout.get(),
                                 .medium = &f.medium,
                                 .lightColors = wrong.get()}),
                       doctest::Contains("PrefilterPass::FrameAttribs.lightColors"), InvalidArgument);
}

TEST_CASE("light texture GL: the textured evaluation equals the CPU evaluation (prefix table, no table)") {
  CREP_REQUIRE_GL();
  const Image tex = twoColourTexture();
  const PrefilterOptions o = prefilterOptions(StorageFormat::RGBA8);
  PrefilterPass prefilterPass({.mapWidth = kMapW, .mapHeight = kMapH, .options = o});
  for (const bool spot : {false, true}) {
    const LightTextureFrame f = lightTextureFrame(spot, kW, kH, kMapW, kMapH);
    const Image colors = lightColorMap({&tex, f.textureClipFromWorld}, *f.layout, kMapW, kMapH);
    const FilteredBasis basis =
        spot ? prefilter(f.map, f.medium, *f.local, colors, o) : prefilter(f.map, f.medium, colors, o);
    const gl::Handle depth = uploadR32F(f.map.depth), cameraDepth = uploadR32F(f.depth);
    const gl::Handle colorTexture = uploadRgb(colors);
    PrefilterPass::FrameAttribs pa{
        .rectifiedDepth = depth.get(), .layout = f.layout.get(), .medium = &f.medium};
    pa.localLight = spot ? &*f.local : nullptr;
    pa.lightColors = colorTexture.get();
    prefilterPass.run(pa);
    for (const int samples : {128, 0}) {
      const std::string name = std::string(spot ? "spot gobo" : "sun window") +
                               (samples > 0 ? ", scattering prefix table" : ", no table");
      CAPTURE(name);
      EvaluateOptions eo;
      eo.visibilityTableSamples = samples;
      EvaluatePass evaluatePass({.options = eo});
      const gl::Handle out = createTexture2D(GL_RGBA32F, kW, kH);
      EvaluatePass::FrameAttribs ea{.cameraDepth = cameraDepth.get(),
                                    .output = out.get(),
                                    .camera = &f.camera,
                                    .medium = &f.medium,
                                    .layout = f.layout.get(),
                                    .basis = prefilterPass.filteredBasis()};
      if (spot)
        ea.localLight = &*f.local;
      else
        ea.light = &f.sun;
      evaluatePass.run(ea);
      const Image gpu = readRgbaTexture(out.get(), kW, kH);
      const Image cpu = spot ? evaluate(basis, f.depth, f.camera, *f.local, f.medium, eo)
                             : evaluate(basis, f.depth, f.camera, f.sun, f.medium, eo);
      const ImageMetrics m = rgbMetrics(gpu, cpu);
      report(name + ": GPU vs CPU textured evaluation", m);
      CHECK(m.nanCount == 0);
      CHECK(m.relativeRmse < 1e-3); // the untextured tolerance: RGBA8 basis through GL_LINEAR's 8-bit weights
    }
  }

  // Modes without a textured variant reject the basis by name.
  const LightTextureFrame f = sunTextureFrame(kW, kH, kMapW, kMapH);
  const gl::Handle depth = uploadR32F(f.map.depth), cameraDepth = uploadR32F(f.depth);
  const gl::Handle ones = uploadRgb(Image(kMapW, kMapH, 3, 1.0f));
  prefilterPass.run({.rectifiedDepth = depth.get(),
                     .layout = f.layout.get(),
                     .medium = &f.medium,
                     .lightColors = ones.get()});
  const gl::Handle out = createTexture2D(GL_RGBA32F, kW, kH);
  EvaluateOptions nearPlane, tableAlone;
  nearPlane.nearPlaneCorrection = true;
  tableAlone.scatteringPrefix = false;
  for (const EvaluateOptions& eo : {nearPlane, tableAlone}) {
    EvaluatePass evaluatePass({.options = eo});
    CHECK_THROWS_WITH_AS(evaluatePass.run({.cameraDepth = cameraDepth.get(),
                                           .output = out.get(),
                                           .camera = &f.camera,
                                           .light = &f.sun,
                                           .medium = &f.medium,
                                           .layout = f.layout.get(),
                                           .basis = prefilterPass.filteredBasis()}),
                         doctest::Contains("EvaluatePass::FrameAttribs.basis.textured"), InvalidArgument);
  }
}

TEST_CASE("light texture GL: the textured world march equals the CPU world march (sun window, spot gobo)") {
  CREP_REQUIRE_GL();
  const Image tex = twoColourTexture();
  const gl::Handle texture = uploadRgb(tex);
  WorldMarchPass pass({.options = {.steps = 64, .refinements = 12}});
  for (const bool spot : {false, true}) {
    CAPTURE(spot);
    const LightTextureFrame f = lightTextureFrame(spot, kW, kH, kMapW, kMapH);
    const Image shadow = halfSpaceShadowMap(f.plane, f.shadowClipFromWorld, 512);
    const gl::Handle shadowTexture = uploadR32F(shadow), cameraDepth = uploadR32F(f.depth);
    const gl::Handle out = createTexture2D(GL_RGBA32F, kW, kH);
    WorldMarchPass::FrameAttribs a;
    a.camera = &f.camera;
    a.medium = &f.medium;
    a.cameraDepth = cameraDepth.get();
    a.shadowMap = shadowTexture.get();
    a.lightClipFromWorld = f.shadowClipFromWorld;
    a.bias = 1e-5;
    a.output = out.get();
    a.lightTexture = {texture.get(), f.textureClipFromWorld};
    if (spot)
      a.localLight = &*f.local;
    else
      a.light = &f.sun;
    pass.run(a);
    const WorldMarchOptions wo{.steps = 64, .refinements = 12, .bias = 1e-5};
    const LightTexture lt{&tex, f.textureClipFromWorld};
    const Image cpu =
        (spot ? worldSpaceMarch(shadow, f.shadowClipFromWorld, f.depth, f.camera, *f.local, f.medium, lt, wo)
              : worldSpaceMarch(shadow, f.shadowClipFromWorld, f.depth, f.camera, f.sun, f.medium, lt, wo))
            .scattering;
    const ImageMetrics m = rgbMetrics(readRgbaTexture(out.get(), kW, kH), cpu);
    report(std::string(spot ? "spot gobo" : "sun window") + ": GPU vs CPU textured world march", m);
    CHECK(m.nanCount == 0);
    // The untextured local-light world march's bound (WorldMarchLocalGLTest: 2e-3; float ray positions
    // may put a visibility change in a neighbouring section).
    CHECK(m.relativeRmse < 2e-3);

    // A projection that does not follow the light's rays is named.
    a.lightTexture.textureClipFromWorld = lightTextureFrame(!spot, kW, kH, kMapW, kMapH).textureClipFromWorld;
    CHECK_THROWS_WITH_AS(pass.run(a),
                         doctest::Contains("WorldMarchPass::FrameAttribs.lightTexture.textureClipFromWorld"),
                         InvalidArgument);
  }
}

TEST_CASE("light texture GL: march_rectified.comp's textured brute force equals the CPU brute-force march") {
  // RectifiedMarchPass (epipolar/) does not bind a colour map yet: the shader's CREP_LIGHT_TEXTURE variant
  // is dispatched here with the march passes' own resource helpers (gpu::bindMarchResources) and the
  // colour map at texture unit 2.
  CREP_REQUIRE_GL();
  const Image tex = twoColourTexture();
  const gl::Handle program =
      buildProgram({{ShaderStage::Compute,
                     "passes/epipolar/march_rectified.comp",
                     {{"CREP_MARCH_TREE", "0"}, {"CREP_LAYOUT", "0"}, {"CREP_LIGHT_TEXTURE", "1"}}}});
  const gl::Handle sampler = gl::createClampSampler(GL_NEAREST);
  for (const bool spot : {false, true}) {
    CAPTURE(spot);
    const LightTextureFrame f = lightTextureFrame(spot, kW, kH, kMapW, kMapH);
    const Image colors = lightColorMap({&tex, f.textureClipFromWorld}, *f.layout, kMapW, kMapH);
    const gl::Handle map = uploadR32F(f.map.depth), cameraDepth = uploadR32F(f.depth),
                     colorTexture = uploadRgb(colors);
    const gl::Handle out = createTexture2D(GL_RGBA32F, kW, kH), steps = createTexture2D(GL_R32F, kW, kH);
    const gpu::MarchParams params =
        spot ? gpu::makeMarchParams(f.camera, *f.local, f.medium, kW, kH, kMapW, kMapH)
             : gpu::makeMarchParams(f.camera, f.sun, f.medium, kW, kH, kMapW, kMapH);
    const gl::Handle paramsBuffer = gl::createDynamicBuffer(sizeof params);
    glNamedBufferSubData(paramsBuffer.get(), 0, sizeof params, &params);
    gpu::LayoutBuffers layoutBuffers;
    layoutBuffers.upload(*f.layout, kMapH);
    gpu::bindMarchResources(program.get(), paramsBuffer.get(), cameraDepth.get(), map.get(), sampler.get(),
                            out.get(), steps.get());
    layoutBuffers.bind(1, 1);
    glBindTextureUnit(2, colorTexture.get());
    glBindSampler(2, sampler.get());
    gpu::dispatchMarch(kW, kH, "march_rectified.comp (CREP_LIGHT_TEXTURE)");
    glBindSampler(2, 0);
    glBindTextureUnit(2, 0);
    const Image cpu = (spot ? bruteForceMarch(f.map, f.depth, f.camera, *f.local, f.medium, colors)
                            : bruteForceMarch(f.map, f.depth, f.camera, f.sun, f.medium, colors))
                          .scattering;
    const ImageMetrics m = rgbMetrics(readRgbaTexture(out.get(), kW, kH), cpu);
    report(std::string(spot ? "spot gobo" : "sun window") + ": GPU vs CPU textured brute-force march", m);
    CHECK(m.nanCount == 0);
    CHECK(m.relativeRmse < 1e-4); // float section distances and integrals against double
  }
}
