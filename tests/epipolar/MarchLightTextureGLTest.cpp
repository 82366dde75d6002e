// Light textures in the rectified marches (Klehm et al. 2014, Sec. 3.2 coloured light textures; the rule in
// crep/scatter/rectified_march.h): RectifiedMarchPass::FrameAttribs::lightColors (brute force and min/max
// tree) against the CPU textured brute-force march, the CPU min/max march with a colour map against the CPU
// textured brute-force march (same map), and a constant colour map c against c times the untextured march,
// for the sun's window and a spot light's gobo on the analytic plane scenes (160x90, map 256x128).
// The first test case needs no GL context (CPU only).
#include "common/analytic_reference.h"
#include "common/analytic_scene.h"
#include "common/gl_fixture.h"
#include "common/light_texture_frames.h"
#include "common/local_light_scene.h"
#include "common/prefilter_gpu.h"

#include <crep/core/error.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/light_texture.h>
#include <crep/scatter/rectified_march.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kW = 160, kH = 90, kMapW = 256, kMapH = 128;

MarchResult cpuBrute(const LightTextureFrame& f, const Image* colors) {
  if (f.local)
    return colors ? bruteForceMarch(f.map, f.depth, f.camera, *f.local, f.medium, *colors)
                  : bruteForceMarch(f.map, f.depth, f.camera, *f.local, f.medium);
  return colors ? bruteForceMarch(f.map, f.depth, f.camera, f.sun, f.medium, *colors)
                : bruteForceMarch(f.map, f.depth, f.camera, f.sun, f.medium);
}

MarchResult cpuMinMax(const LightTextureFrame& f, const Image* colors) {
  if (f.local)
    return colors ? minMaxMarch(f.map, f.depth, f.camera, *f.local, f.medium, *colors)
                  : minMaxMarch(f.map, f.depth, f.camera, *f.local, f.medium);
  return colors ? minMaxMarch(f.map, f.depth, f.camera, f.sun, f.medium, *colors)
                : minMaxMarch(f.map, f.depth, f.camera, f.sun, f.medium);
}

/// Count of RGB values that differ bitwise.
long long bitDifferences(const Image& a, const Image& b) {
  long long n = 0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x)
      for (int c = 0; c < 3; ++c) {
        const float u = a.at(x, y, c), v = b.at(x, y, c);
        n += std::memcmp(&u, &v, sizeof u) == 0 ? 0 : 1;
      }
  return n;
}

/// `image` with its RGB channels times c.
Image scaled(const Image& image, const glm::vec3& c) {
  Image out = image;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int k = 0; k < 3; ++k)
        out.at(x, y, k) = image.at(x, y, k) * c[k];
  return out;
}

double peakRgb(const Image& image) {
  double peak = 0.0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int k = 0; k < 3; ++k)
        peak = std::max(peak, static_cast<double>(image.at(x, y, k)));
  return peak;
}

Image constantColors(const glm::vec3& c) {
  Image out(kMapW, kMapH, 3);
  for (int y = 0; y < kMapH; ++y)
    for (int x = 0; x < kMapW; ++x)
      for (int k = 0; k < 3; ++k)
        out.at(x, y, k) = c[k];
  return out;
}

/// RectifiedMarchPass on a frame's map (0 colour map: untextured).
Image gpuMarch(const LightTextureFrame& f, RectifiedMarchPass::Mode mode, std::uint32_t lightColors,
               Image* steps = nullptr) {
  const gl::Handle map = uploadR32F(f.map.depth), cameraDepth = uploadR32F(f.depth);
  MinMaxTreePass trees({kMapW, kMapH});
  trees.run(map.get());
  RectifiedMarchPass pass({kMapW, kMapH, mode});
  const gl::Handle out = createTexture2D(GL_RGBA32F, kW, kH), stepsOut = createTexture2D(GL_R32F, kW, kH);
  RectifiedMarchPass::FrameAttribs a;
  a.layout = f.layout.get();
  a.camera = &f.camera;
  a.medium = &f.medium;
  if (f.local)
    a.localLight = &*f.local;
  else
    a.light = &f.sun;
  a.cameraDepth = cameraDepth.get();
  a.rectifiedDepth = map.get();
  a.minMaxBuffer = trees.treeBuffer();
  a.output = out.get();
  a.stepsOutput = stepsOut.get();
  a.lightColors = lightColors;
  pass.run(a);
  GLint unit2 = -1;
  glActiveTexture(GL_TEXTURE2);
  glGetIntegerv(GL_TEXTURE_BINDING_2D, &unit2);
  glActiveTexture(GL_TEXTURE0);
  CHECK(unit2 == 0); // the pass leaves texture unit 2 unbound
  if (steps) *steps = gl::readTexture(stepsOut.get(), kW, kH, gl::TexelData::Red);
  return readRgbaTexture(out.get(), kW, kH);
}

} // namespace

TEST_CASE("march light texture: the CPU min/max march with a colour map equals the textured brute force") {
  const Image tex = twoColourTexture();
  for (const bool spot : {false, true}) {
    const std::string name = spot ? "spot gobo" : "sun window";
    CAPTURE(name);
    const LightTextureFrame f = lightTextureFrame(spot, kW, kH, kMapW, kMapH);
    const Image colors = lightColorMap({&tex, f.textureClipFromWorld}, *f.layout, kMapW, kMapH);
    const MarchResult brute = cpuBrute(f, &colors), tree = cpuMinMax(f, &colors);
    // The tree's lit nodes are split at the same texel boundaries into the same parts, added in the same
    // order: the same sums, bit for bit.
    const long long differ = bitDifferences(tree.scattering, brute.scattering);
    MESSAGE(name << ": min/max vs brute force (textured): " << differ << " values differ bitwise; mean steps "
                 << tree.meanSteps() << " vs " << brute.meanSteps());
    CHECK(differ == 0);
    CHECK(tree.meanSteps() < brute.meanSteps());
    // The texture matters: the textured march is not a constant multiple of the untextured one.
    const MarchResult plain = cpuBrute(f, nullptr);
    CHECK(maxRelativeDifference(brute.scattering, plain.scattering, 1e-6) > 0.1);

    // A constant colour map c (powers of two: exact scaling) gives c times the untextured march, bit for
    // bit, in both marches.
    const glm::vec3 c(0.5f, 0.25f, 2.0f);
    const Image constant = constantColors(c);
    const Image expected = scaled(plain.scattering, c);
    CHECK(bitDifferences(cpuBrute(f, &constant).scattering, expected) == 0);
    CHECK(bitDifferences(cpuMinMax(f, &constant).scattering, expected) == 0);
    // Any constant: c times the untextured march up to the rounding of the sums (one float ulp).
    const glm::vec3 d(0.8f, 0.3f, 1.7f);
    const Image constantD = constantColors(d);
    CHECK(maxRelativeDifference(cpuMinMax(f, &constantD).scattering, scaled(plain.scattering, d), 1e-6) <
          1e-6);

    // A colour map of the wrong size is named.
    const Image wrong(kMapW / 2, kMapH, 3, 1.0f);
    CHECK_THROWS_WITH_AS(cpuMinMax(f, &wrong), doctest::Contains("lightColors"), InvalidArgument);
  }
}

TEST_CASE("march light texture GL: RectifiedMarchPass with lightColors equals the CPU textured march") {
  CREP_REQUIRE_GL();
  const Image tex = twoColourTexture();
  for (const bool spot : {false, true}) {
    const LightTextureFrame f = lightTextureFrame(spot, kW, kH, kMapW, kMapH);
    const Image colors = lightColorMap({&tex, f.textureClipFromWorld}, *f.layout, kMapW, kMapH);
    const gl::Handle colorTexture = uploadRgb(colors);
    const MarchResult cpu = cpuBrute(f, &colors);
    for (const auto mode : {RectifiedMarchPass::Mode::BruteForce, RectifiedMarchPass::Mode::MinMaxTree}) {
      const bool tree = mode == RectifiedMarchPass::Mode::MinMaxTree;
      const std::string name =
          std::string(spot ? "spot gobo" : "sun window") + (tree ? ", min/max tree" : ", brute force");
      CAPTURE(name);
      Image steps;
      const Image gpu = gpuMarch(f, mode, colorTexture.get(), &steps);
      const ImageMetrics m = rgbMetrics(gpu, cpu.scattering);
      report(name + ": GPU textured march vs CPU textured brute-force march", m);
      CHECK(m.nanCount == 0);
      // Float section distances and integrals against double (the shader's direct-dispatch bound).
      CHECK(m.relativeRmse < 1e-4);
      double gpuSteps = 0.0;
      for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
          gpuSteps += steps.at(x, y);
      gpuSteps /= kW * kH;
      MESSAGE(name << ": mean steps per pixel " << gpuSteps << " (CPU brute force " << cpu.meanSteps()
                   << ")");
      if (tree) CHECK(gpuSteps < cpu.meanSteps());

      // A constant colour map c: c times the untextured pass. Brute force: the same sections, each scaled
      // by a power of two, bit for bit. Tree: the textured walk splits lit nodes per texel, so the sums
      // are grouped differently and a local light's sections (crep_localSegment, a quadrature per
      // section) are integrated piecewise: float rounding, measured 9.3e-7 (sun) and 1.5e-5 (spot)
      // relative to the value, floored at 1e-3 of the peak.
      const glm::vec3 c(0.5f, 0.25f, 2.0f);
      const gl::Handle constant = uploadRgb(constantColors(c));
      const Image textured = gpuMarch(f, mode, constant.get());
      const Image expected = scaled(gpuMarch(f, mode, 0), c);
      if (tree) {
        const double rel = maxRelativeDifference(textured, expected, 1e-3 * peakRgb(expected));
        MESSAGE(name << ": constant colour map vs c x untextured, max relative difference " << rel);
        CHECK(rel < (spot ? 1e-4 : 1e-5));
      } else {
        CHECK(bitDifferences(textured, expected) == 0);
      }
    }
  }

  // Bad input: a colour map that is not the map's size is named.
  const LightTextureFrame f = sunTextureFrame(kW, kH, kMapW, kMapH);
  const gl::Handle wrong = uploadRgb(Image(kMapW / 2, kMapH, 3, 1.0f));
  CHECK_THROWS_WITH_AS(gpuMarch(f, RectifiedMarchPass::Mode::BruteForce, wrong.get()),
                       doctest::Contains("RectifiedMarchPass::FrameAttribs.lightColors"), InvalidArgument);
}
