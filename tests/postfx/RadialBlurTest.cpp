// Mitchell 2007's radial blur, CPU reference (crep/postfx/radial_blur.h): the geometric series of Eq. 4 on
// a uniform sky, the pixel's own source value times the series when the samples collapse onto the pixel,
// the visible fraction of a half-occluded screen segment, the sun's screen position and fade (zero behind
// the camera, one on screen, the smoothstep in the margin), the box-downsampled source, reversed-Z sky,
// and every option's validation naming its field. Expected values come from formulas written here.
#include <crep/core/error.h>
#include <crep/postfx/radial_blur.h>
#include <crep/scatter/ray.h>

#include <doctest/doctest.h>

#include <cmath>
#include <string>

using namespace crep;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// A dense isotropic medium: every sky ray (length >= far = 40 > 1000 / 25 mean free paths) saturates,
/// so the sky's in-scattering is E sigma_s / (4 pi sigma_t) in every direction (exp(-1000) is 0 in double).
Medium denseIsotropic() {
  return Medium({.mieScattering = glm::dvec3(20.0, 15.0, 10.0), .hgG = 0.0, .absorption = glm::dvec3(5.0)});
}
glm::dvec3 saturatedSky(const DirectionalLight& light) {
  const glm::dvec3 sigmaS(20.0, 15.0, 10.0), sigmaT(25.0, 20.0, 15.0);
  return light.irradiance() * sigmaS / (4.0 * kPi * sigmaT);
}

Camera smallCamera(int w, int h) {
  return Camera::lookAt({0.0, 1.0, 0.0}, {0.0, 1.2, -10.0}, {0.0, 1.0, 0.0}, glm::radians(60.0),
                        static_cast<double>(w) / h, 0.1, 40.0);
}

/// The sun placed at normalized device coordinates `ndc` of `camera` (light travels toward the camera).
DirectionalLight sunAt(const Camera& camera, const glm::dvec2& ndc) {
  return DirectionalLight(-camera.rayDirection(ndc.x, ndc.y), glm::dvec3(3.0, 2.0, 1.0));
}

/// Sum_{i=0}^{n} d^i / (n + 1), written from the geometric series.
double series(double decay, int n) {
  return decay == 1.0 ? 1.0 : (1.0 - std::pow(decay, n + 1)) / (1.0 - decay) / (n + 1);
}

} // namespace

TEST_CASE("RadialBlur: a uniform unoccluded sky gives the geometric series of Eq. 4 times the sky") {
  const int w = 24, h = 16;
  const Camera camera = smallCamera(w, h);
  const DirectionalLight light = sunAt(camera, {0.3, -0.4});
  const Image depth(w, h, 1, 1.0f); // all sky
  const glm::dvec3 sky = saturatedSky(light);
  for (const double decay : {1.0, 0.95, 0.5})
    for (const int n : {1, 7, 40})
      for (const int scale : {1, 3}) {
        RadialBlurOptions o;
        o.decay = decay;
        o.samples = n;
        o.exposure = 0.7;
        o.weight = 1.3;
        o.density = 0.8;
        o.sourceScale = scale;
        const Image out = radialBlur(depth, camera, light, denseIsotropic(), o);
        const glm::dvec3 expected = sky * (0.7 * 1.3 * series(decay, n));
        // Float storage of the source and output: 1e-6 relative.
        double worst = 0.0;
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
              worst = std::max(worst, std::abs(out.at(x, y, c) - expected[c]) / expected[c]);
        CAPTURE(decay);
        CAPTURE(n);
        CAPTURE(scale);
        CHECK(worst < 1e-6);
      }
}

TEST_CASE("RadialBlur: samples collapsed onto the pixel give its own source value times the series") {
  // density 1e-9: every sample lies within 1e-7 pixels of the pixel's centre, where the bilinear read is
  // the pixel's own source value: the sky's unshadowed in-scattering, geometry 0.
  const int w = 20, h = 12;
  const Camera camera = smallCamera(w, h);
  const DirectionalLight light = sunAt(camera, {-0.2, 0.5});
  const Medium medium({.mieScattering = glm::dvec3(0.03, 0.04, 0.05),
                       .hgG = 0.6,
                       .rayleighScattering = glm::dvec3(0.005, 0.01, 0.02),
                       .absorption = glm::dvec3(0.01)});
  Image depth(w, h, 1, 1.0f);
  for (int y = 0; y < h / 2; ++y) // the lower half is geometry at view depth 5
    for (int x = 0; x < w; ++x)
      depth.at(x, y) = static_cast<float>(camera.depthBufferValue(5.0));
  RadialBlurOptions o;
  o.density = 1e-9;
  o.decay = 0.9;
  o.samples = 16;
  const Image out = radialBlur(depth, camera, light, medium, o);
  const double sbar = (0.03 + 0.04 + 0.05 + 0.005 + 0.01 + 0.02 + 0.03) / 3.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::dvec3 v = camera.rayDirection(2.0 * (x + 0.5) / w - 1.0, 2.0 * (y + 0.5) / h - 1.0);
      const double cosForward = glm::dot(v, camera.forward());
      const bool sky = y >= h / 2;
      // The closed form written here: C (1 - exp(-sigma s)) / sigma with C = E (sigma_mie HG + sigma_R R).
      const double s = (sky ? camera.far() : 5.0) / cosForward;
      const double cosTheta = glm::dot(light.direction(), -v);
      const double g = 0.6;
      const double hg = (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g - 2.0 * g * cosTheta, 1.5));
      const double rayleigh = 3.0 / (16.0 * kPi) * (1.0 + cosTheta * cosTheta);
      const glm::dvec3 mie(0.03, 0.04, 0.05), ray(0.005, 0.01, 0.02), sigma = mie + ray + 0.01;
      for (int c = 0; c < 3; ++c) {
        const double L = sky ? light.irradiance()[c] * (mie[c] * hg + ray[c] * rayleigh) *
                                   (1.0 - std::exp(-sigma[c] * s)) / sigma[c] * series(0.9, 16)
                             : 0.0;
        // Float storage and the < 1e-7 pixel offset of the samples: 1e-5 relative on the sky; a geometry
        // pixel next to the sky reads < 1e-7 of its neighbour (sky values < 0.1): below 1e-8.
        if (sky)
          CHECK(out.at(x, y, c) == doctest::Approx(L).epsilon(1e-5));
        else
          CHECK(std::abs(out.at(x, y, c)) < 1e-8);
      }
      // A = exp(-sbar s): the depth buffer holds a float depth, so the geometry's s is good to ~1e-5.
      CHECK(out.at(x, y, 3) == doctest::Approx(std::exp(-sbar * s)).epsilon(1e-4));
    }
}

TEST_CASE("RadialBlur: a half-occluded segment gives the visible fraction of its samples") {
  // 64 x 8 image, left half geometry, right half sky (a uniform saturated sky); the sun on the centre of
  // pixel (16, 4), the pixel (48, 4): 32 samples one pixel apart land on pixel centres 48, 47, ..., 16,
  // 17 of the 33 on sky pixels (32..48).
  const int w = 64, h = 8;
  const Camera camera = smallCamera(w, h);
  const DirectionalLight light = sunAt(camera, {2.0 * 16.5 / w - 1.0, 2.0 * 4.5 / h - 1.0});
  Image depth(w, h, 1, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w / 2; ++x)
      depth.at(x, y) = 0.5f;
  const glm::dvec3 sky = saturatedSky(light);
  for (const double decay : {1.0, 0.9}) {
    RadialBlurOptions o;
    o.samples = 32;
    o.decay = decay;
    const Image out = radialBlur(depth, camera, light, denseIsotropic(), o);
    double sum = 0.0; // the decay weights of the 17 visible samples i = 0 .. 16
    for (int i = 0; i <= 16; ++i)
      sum += std::pow(decay, i);
    for (int c = 0; c < 3; ++c)
      CHECK(out.at(48, 4, c) == doctest::Approx(sky[c] * sum / 33.0).epsilon(1e-6));
    // A pixel on the sun itself: every sample is the sun's pixel, geometry: nothing.
    for (int c = 0; c < 3; ++c)
      CHECK(out.at(16, 4, c) == doctest::Approx(0.0).scale(1e-12));
  }
}

TEST_CASE("RadialBlur: OcclusionFraction is the visible fraction times the pixel's own in-scattering") {
  // The layout of the previous case with the sun on the centre of sky pixel (48, 4) and the geometry
  // pixel (16, 4): 17 of its 33 samples (pixels 32..48) see the sky; its own ray ends at depth 0.5.
  const int w = 64, h = 8;
  const Camera camera = smallCamera(w, h);
  const DirectionalLight light = sunAt(camera, {2.0 * 48.5 / w - 1.0, 2.0 * 4.5 / h - 1.0});
  Image depth(w, h, 1, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w / 2; ++x)
      depth.at(x, y) = 0.5f;
  RadialBlurOptions o;
  o.samples = 32;
  o.mode = RadialBlurMode::OcclusionFraction;
  const Image out = radialBlur(depth, camera, light, denseIsotropic(), o);
  // U = C (1 - exp(-sigma_t s)) / sigma_t, C = E sigma_s / (4 pi) (isotropic), s = Z / cos, Z the view
  // depth of the GL depth value 0.5: n f / (f - 0.5 (f - n)).
  const double n = camera.near(), f = camera.far();
  const double Z = n * f / (f - 0.5 * (f - n));
  const glm::dvec3 v = camera.rayDirection(2.0 * 16.5 / w - 1.0, 2.0 * 4.5 / h - 1.0);
  const double s = Z / glm::dot(v, camera.forward());
  const glm::dvec3 sigmaS(20.0, 15.0, 10.0), sigmaT(25.0, 20.0, 15.0);
  for (int c = 0; c < 3; ++c) {
    const double U =
        light.irradiance()[c] * sigmaS[c] / (4.0 * kPi) * (1.0 - std::exp(-sigmaT[c] * s)) / sigmaT[c];
    CHECK(out.at(16, 4, c) == doctest::Approx(17.0 / 33.0 * U).epsilon(1e-6));
  }
  // The default mode gives the sky's radiance instead (saturated: E sigma_s / (4 pi sigma_t)), larger.
  o.mode = RadialBlurMode::SourceRadiance;
  const Image sky = radialBlur(depth, camera, light, denseIsotropic(), o);
  for (int c = 0; c < 3; ++c)
    CHECK(sky.at(16, 4, c) == doctest::Approx(17.0 / 33.0 * saturatedSky(light)[c]).epsilon(1e-6));
}

TEST_CASE("RadialBlur: the sun's screen position and fade") {
  const Camera camera = smallCamera(32, 18);
  const double margin = 0.5;
  SUBCASE("on screen: the projected position, fade 1") {
    for (const glm::dvec2 ndc : {glm::dvec2(0.0), glm::dvec2(0.3, -0.7), glm::dvec2(-0.99, 0.99)}) {
      const RadialLight r = radialLight(camera, sunAt(camera, ndc), margin);
      CHECK(r.inFront);
      CHECK(r.fade == 1.0);
      CHECK(r.uv.x == doctest::Approx(0.5 * ndc.x + 0.5).epsilon(1e-12));
      CHECK(r.uv.y == doctest::Approx(0.5 * ndc.y + 0.5).epsilon(1e-12));
    }
  }
  SUBCASE("in the margin: the smoothstep of the distance outside the screen") {
    // e = margin / 2 -> t = 1/2 -> fade 1/2; e = margin / 4 -> 1 - (1/16)(3 - 1/2) = 0.84375.
    CHECK(radialLight(camera, sunAt(camera, {1.0 + margin / 2, 0.2}), margin).fade ==
          doctest::Approx(0.5).epsilon(1e-9));
    CHECK(radialLight(camera, sunAt(camera, {0.1, -1.0 - margin / 4}), margin).fade ==
          doctest::Approx(0.84375).epsilon(1e-9));
    // The larger of the two excesses counts.
    CHECK(radialLight(camera, sunAt(camera, {1.0 + margin / 4, -1.0 - margin / 2}), margin).fade ==
          doctest::Approx(0.5).epsilon(1e-9));
    CHECK(radialLight(camera, sunAt(camera, {1.0 + margin * 1.01, 0.0}), margin).fade == 0.0);
  }
  SUBCASE("behind the camera or perpendicular: exactly zero, and nothing is added") {
    const DirectionalLight behind(camera.forward(), glm::dvec3(1.0)); // travels along the view: sun behind
    const DirectionalLight side(camera.right(), glm::dvec3(1.0));     // perpendicular to the view
    const DirectionalLight behindOff(camera.forward() + 0.3 * camera.up() - 0.2 * camera.right());
    for (const DirectionalLight& l : {behind, side, behindOff}) {
      const RadialLight r = radialLight(camera, l, margin);
      CHECK(r.fade == 0.0);
      const Image out = radialBlur(Image(32, 18, 1, 1.0f), camera, l, denseIsotropic());
      for (int y = 0; y < 18; ++y)
        for (int x = 0; x < 32; ++x)
          for (int c = 0; c < 3; ++c)
            REQUIRE(out.at(x, y, c) == 0.0f);
    }
    CHECK_FALSE(radialLight(camera, behind, margin).inFront);
  }
  SUBCASE("the fade scales the result") {
    const DirectionalLight l = sunAt(camera, {1.0 + margin / 2, 0.0}); // fade 1/2
    const Image out = radialBlur(Image(32, 18, 1, 1.0f), camera, l, denseIsotropic());
    CHECK(out.at(5, 7, 1) == doctest::Approx(0.5 * saturatedSky(l).y).epsilon(1e-6));
  }
}

TEST_CASE("RadialBlur: the source image is the occlusion pre-pass, box-downsampled by sourceScale") {
  const int w = 11, h = 7; // odd sizes: the last row and column of blocks are partial
  const Camera camera = smallCamera(w, h);
  const DirectionalLight light = sunAt(camera, {0.1, 0.1});
  const Medium medium({.mieScattering = glm::dvec3(0.05), .hgG = 0.3, .absorption = glm::dvec3(0.02)});
  Image depth(w, h, 1, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if ((x * 7 + y * 3) % 5 == 0) depth.at(x, y) = 0.9f;
  const Image unshadowed = unshadowedScattering(depth, camera, light, medium);
  RadialBlurOptions o;
  o.sourceScale = 3;
  const Image source = radialBlurSource(depth, camera, light, medium, o);
  REQUIRE(source.width() == 4);
  REQUIRE(source.height() == 3);
  for (int sy = 0; sy < 3; ++sy)
    for (int sx = 0; sx < 4; ++sx) {
      glm::dvec4 sum(0.0);
      int count = 0;
      for (int y = 3 * sy; y < std::min(h, 3 * sy + 3); ++y)
        for (int x = 3 * sx; x < std::min(w, 3 * sx + 3); ++x, ++count)
          if (depth.at(x, y) == 1.0f)
            sum += glm::dvec4(unshadowed.at(x, y, 0), unshadowed.at(x, y, 1), unshadowed.at(x, y, 2), 1.0);
      for (int c = 0; c < 4; ++c) // float storage: 1e-6 relative
        CHECK(source.at(sx, sy, c) == doctest::Approx(sum[c] / count).epsilon(1e-6).scale(1e-12));
    }
}

TEST_CASE("RadialBlur: the sky of a reversed-Z camera is its cleared value 0") {
  const int w = 16, h = 10;
  const Camera standard = smallCamera(w, h);
  glm::dmat4 proj(0.0); // reversed-Z, [0, 1] clip depth, infinite far: depth = near / Z
  const double ty = std::tan(0.5 * standard.fovY());
  proj[0][0] = 1.0 / (ty * standard.aspect());
  proj[1][1] = 1.0 / ty;
  proj[2][3] = -1.0;
  proj[3][2] = standard.near();
  const Camera reversed = Camera::fromMatrices(standard.viewFromWorld(), proj, ClipDepth::ZeroToOne, 40.0);
  const DirectionalLight light = sunAt(standard, {0.2, 0.3});
  const Image a = radialBlur(Image(w, h, 1, 1.0f), standard, light, denseIsotropic());
  const Image b = radialBlur(Image(w, h, 1, 0.0f), reversed, light, denseIsotropic());
  const glm::dvec3 sky = saturatedSky(light);
  for (int c = 0; c < 3; ++c) {
    CHECK(a.at(3, 4, c) == doctest::Approx(sky[c]).epsilon(1e-6));
    CHECK(b.at(3, 4, c) == doctest::Approx(sky[c]).epsilon(1e-6)); // same rays: the same sky
  }
  // Reversed depth 1 is the near plane: geometry, so the blur of an all-geometry image is 0.
  const Image g = radialBlur(Image(w, h, 1, 1.0f), reversed, light, denseIsotropic());
  CHECK(g.at(3, 4, 0) == 0.0f);
}

TEST_CASE("RadialBlur: bad options and inputs name the field") {
  const auto expectField = [](RadialBlurOptions o, const std::string& name) {
    try {
      validate(o, "RadialBlurPass::CreateInfo.options");
      FAIL("no exception for " << name);
    } catch (const InvalidArgument& e) {
      CHECK(e.parameter() == "RadialBlurPass::CreateInfo.options." + name);
    }
  };
  const double nan = std::nan(""), inf = INFINITY;
  for (const double v : {0.0, -0.1, 1.0001, nan, inf}) {
    RadialBlurOptions o;
    o.decay = v;
    expectField(o, "decay");
  }
  for (const double v : {0.0, -1.0, nan, inf}) {
    RadialBlurOptions o;
    o.density = v;
    expectField(o, "density");
    o = {};
    o.fadeMargin = v;
    expectField(o, "fadeMargin");
  }
  for (const double v : {-1.0, nan, inf}) {
    RadialBlurOptions o;
    o.exposure = v;
    expectField(o, "exposure");
    o = {};
    o.weight = v;
    expectField(o, "weight");
  }
  for (const int v : {0, -3, 1025}) {
    RadialBlurOptions o;
    o.samples = v;
    expectField(o, "samples");
  }
  for (const int v : {0, 17}) {
    RadialBlurOptions o;
    o.sourceScale = v;
    expectField(o, "sourceScale");
  }
  {
    RadialBlurOptions o;
    o.threads = -1;
    expectField(o, "threads");
    o = {};
    o.mode = static_cast<RadialBlurMode>(7);
    expectField(o, "mode");
  }
  // The edges are accepted.
  RadialBlurOptions ok;
  ok.decay = 1.0;
  ok.samples = 1024;
  ok.sourceScale = 16;
  ok.exposure = 0.0;
  CHECK_NOTHROW(validate(ok, "x"));
  // A bad camera depth (NaN, outside [0, 1]) names "cameraDepth".
  const Camera camera = smallCamera(8, 8);
  Image depth(8, 8, 1, 1.0f);
  depth.at(2, 3) = std::nanf("");
  try {
    (void)radialBlur(depth, camera, sunAt(camera, {0.0, 0.0}), denseIsotropic());
    FAIL("no exception for a NaN depth");
  } catch (const InvalidArgument& e) {
    CHECK(e.parameter() == "cameraDepth");
  }
  depth.at(2, 3) = 1.5f;
  CHECK_THROWS_AS(radialBlur(depth, camera, sunAt(camera, {0.0, 0.0}), denseIsotropic()), InvalidArgument);
  CHECK_THROWS_AS(radialLight(camera, sunAt(camera, {0.0, 0.0}), 0.0), InvalidArgument);
}
