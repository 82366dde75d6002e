// Light textures on the CPU (crep/scatter/light_texture.h; Klehm et al. 2014, Sec. 3.2 coloured light
// textures): a constant texture c gives exactly c times the untextured result in every method (prefilter
// with each evaluation mode, brute-force march over the rectified map, world march; bit for bit for c = 1),
// and a two-colour texture (left half red, right half blue) over the sun's window and over a spot light's
// cone is prefiltered within the untextured method's own error of the brute-force march over the same map
// and of the world march (relative RMSE per channel stated). Bad textures are named.
#include "common/analytic_reference.h"
#include "common/analytic_scene.h"
#include "common/light_texture_frames.h"
#include "common/local_light_scene.h"

#include <crep/core/error.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/light_texture.h>
#include <crep/scatter/rectified_march.h>
#include <crep/scatter/world_march.h>

#include <doctest/doctest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>
#include <string>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kW = 160, kH = 90, kMapW = 512, kMapH = 256, kShadow = 1024;

PrefilterOptions prefilterOptions() {
  PrefilterOptions o;
  o.regionsPerSplit = 2;
  return o;
}

bool identical(const Image& a, const Image& b) {
  return a.sameShape(b) && std::memcmp(a.data().data(), b.data().data(), a.byteSize()) == 0;
}

/// Largest |a_c - c_c b_c| / (c_c peak(b)) over the RGB samples (relative to the image's peak: near-zero
/// samples carry only absolute rounding).
double maxScaledDifference(const Image& a, const Image& b, const glm::dvec3& c) {
  double peak = 0.0, worst = 0.0;
  for (int y = 0; y < b.height(); ++y)
    for (int x = 0; x < b.width(); ++x)
      for (int k = 0; k < 3; ++k)
        peak = std::max(peak, std::abs(static_cast<double>(b.at(x, y, k))));
  for (int y = 0; y < b.height(); ++y)
    for (int x = 0; x < b.width(); ++x)
      for (int k = 0; k < 3; ++k)
        worst = std::max(worst, std::abs(a.at(x, y, k) - c[k] * b.at(x, y, k)) / (c[k] * peak));
  return worst;
}

/// Relative RMSE per channel: RMS(a_c - r_c) / RMS(r_c).
glm::dvec3 channelRelativeRmse(const Image& a, const Image& r) {
  glm::dvec3 e(0.0), ref(0.0);
  for (int y = 0; y < r.height(); ++y)
    for (int x = 0; x < r.width(); ++x)
      for (int k = 0; k < 3; ++k) {
        const double d = static_cast<double>(a.at(x, y, k)) - r.at(x, y, k);
        e[k] += d * d;
        ref[k] += static_cast<double>(r.at(x, y, k)) * r.at(x, y, k);
      }
  return glm::sqrt(e / ref);
}

std::string str(const glm::dvec3& v) {
  std::ostringstream s;
  s.precision(3);
  s << "R " << 100.0 * v.x << "%, G " << 100.0 * v.y << "%, B " << 100.0 * v.z << "%";
  return s.str();
}

double maxOf(const glm::dvec3& v) {
  return std::max(v.x, std::max(v.y, v.z));
}

/// Every texel of the textured basis's colour bases equals the untextured basis, and cbar = c.
void checkBasisEqualsUntextured(const FilteredBasis& textured, const FilteredBasis& plain,
                                const glm::dvec3& c) {
  REQUIRE(textured.textured);
  REQUIRE(textured.texels.size() == 3 * plain.texels.size());
  for (int k = 0; k < 3; ++k)
    CHECK(std::memcmp(textured.texels.data() + k * plain.texels.size(), plain.texels.data(),
                      plain.texels.size() * sizeof(float)) == 0);
  bool meanIsC = true;
  for (int y = 0; y < textured.height; ++y)
    for (int x = 0; x < textured.width; ++x)
      for (int k = 0; k < 3; ++k)
        meanIsC = meanIsC && textured.mean(x, y, k) == static_cast<float>(c[k]);
  CHECK(meanIsC);
}

/// a == b bit for bit when c = 1, else a = c b up to rounding (float output, double arithmetic).
void checkScaled(const char* what, const Image& a, const Image& b, const glm::dvec3& c) {
  CAPTURE(what);
  if (c == glm::dvec3(1.0)) {
    CHECK(identical(a, b));
  } else {
    const double d = maxScaledDifference(a, b, c);
    MESSAGE(std::string(what) << ": max |textured - c untextured| / (c peak) = " << d);
    CHECK(d < 1e-6);
  }
}

/// The texture colours the frame: some pixels 1.5x redder (R / B) than untextured, others 1.5x bluer (a
/// ray lit through the red half alone is 20x redder, through the blue half 20x bluer; through both, between).
void checkBothColours(const Image& textured, const Image& plain) {
  int red = 0, blue = 0, lit = 0;
  for (int y = 0; y < textured.height(); ++y)
    for (int x = 0; x < textured.width(); ++x) {
      if (!(plain.at(x, y, 0) > 0.0f && textured.at(x, y, 2) > 0.0f)) continue;
      ++lit;
      const double q =
          (textured.at(x, y, 0) / textured.at(x, y, 2)) / (plain.at(x, y, 0) / plain.at(x, y, 2));
      red += q > 1.5 ? 1 : 0;
      blue += q < 1.0 / 1.5 ? 1 : 0;
    }
  MESSAGE("pixels 1.5x redder " << red << ", 1.5x bluer " << blue << " of " << lit);
  CHECK(red > lit / 20);
  CHECK(blue > lit / 20);
}

std::vector<EvaluateOptions> evaluateVariants(bool nearPlane) {
  std::vector<EvaluateOptions> v(4);
  v[1].visibilityTableSamples = 0;
  v[2].scatteringPrefix = false;
  v[3].sampling = Sampling::Nearest;
  if (nearPlane) {
    v.emplace_back();
    v.back().nearPlaneCorrection = true;
  }
  return v;
}

/// The methods for the sun and for a local light, with a colour map / light texture or without.
FilteredBasis prefilterWith(const LightTextureFrame& f, const Image* colors) {
  if (f.local)
    return colors ? prefilter(f.map, f.medium, *f.local, *colors, prefilterOptions())
                  : prefilter(f.map, f.medium, *f.local, prefilterOptions());
  return colors ? prefilter(f.map, f.medium, *colors, prefilterOptions())
                : prefilter(f.map, f.medium, prefilterOptions());
}
Image evaluateWith(const LightTextureFrame& f, const FilteredBasis& basis) {
  return f.local ? evaluate(basis, f.depth, f.camera, *f.local, f.medium)
                 : evaluate(basis, f.depth, f.camera, f.sun, f.medium);
}
Image bruteWith(const LightTextureFrame& f, const Image* colors) {
  if (f.local)
    return (colors ? bruteForceMarch(f.map, f.depth, f.camera, *f.local, f.medium, *colors)
                   : bruteForceMarch(f.map, f.depth, f.camera, *f.local, f.medium))
        .scattering;
  return (colors ? bruteForceMarch(f.map, f.depth, f.camera, f.sun, f.medium, *colors)
                 : bruteForceMarch(f.map, f.depth, f.camera, f.sun, f.medium))
      .scattering;
}
Image worldWith(const LightTextureFrame& f, const Image& shadow, const LightTexture* texture) {
  const glm::dmat4& M = f.shadowClipFromWorld;
  const WorldMarchOptions o{.steps = 256, .bias = 1e-5};
  if (f.local)
    return (texture ? worldSpaceMarch(shadow, M, f.depth, f.camera, *f.local, f.medium, *texture, o)
                    : worldSpaceMarch(shadow, M, f.depth, f.camera, *f.local, f.medium, o))
        .scattering;
  return (texture ? worldSpaceMarch(shadow, M, f.depth, f.camera, f.sun, f.medium, *texture, o)
                  : worldSpaceMarch(shadow, M, f.depth, f.camera, f.sun, f.medium, o))
      .scattering;
}

/// The two-colour texture over the frame's light (`what`: "sun, two-colour window", ...): the texture
/// colours the frame, and the textured method is prefiltered within the untextured method's own error of
/// the brute-force march over the same map and of the world march (relative RMSE per channel printed).
void checkTwoColour(const LightTextureFrame& f, const std::string& what) {
  const Image tex = twoColourTexture();
  const LightTexture texture{&tex, f.textureClipFromWorld};
  const Image colors = lightColorMap(texture, *f.layout, kMapW, kMapH);
  const Image shadow = halfSpaceShadowMap(f.plane, f.shadowClipFromWorld, kShadow);

  const Image ours = evaluateWith(f, prefilterWith(f, &colors));
  const Image brute = bruteWith(f, &colors);
  const Image world = worldWith(f, shadow, &texture);
  const Image plainOurs = evaluateWith(f, prefilterWith(f, nullptr));
  const Image plainBrute = bruteWith(f, nullptr);
  const Image plainWorld = worldWith(f, shadow, nullptr);

  checkBothColours(brute, plainBrute);

  const glm::dvec3 eBrute = channelRelativeRmse(ours, brute), eWorld = channelRelativeRmse(ours, world);
  const glm::dvec3 eMaps = channelRelativeRmse(brute, world);
  const glm::dvec3 pBrute = channelRelativeRmse(plainOurs, plainBrute),
                   pWorld = channelRelativeRmse(plainOurs, plainWorld);
  MESSAGE(what << ": prefiltered vs brute force (same map) " << str(eBrute) << "; untextured "
               << str(pBrute));
  MESSAGE(what << ": prefiltered vs world march " << str(eWorld) << "; untextured " << str(pWorld));
  MESSAGE(what << ": brute force vs world march (the map's own error) " << str(eMaps));
  // Each prefilter region averages its texels' colours with the reference ray's transmittance weights, as
  // it averages their visibility; the colour edge adds to the shadow edges (goal: the untextured figure).
  CHECK(maxOf(eBrute) < 0.02);
  CHECK(eBrute.y < 1.1 * pBrute.y + 0.001);
  CHECK(maxOf(eWorld) < 0.02);
}

} // namespace

TEST_CASE("light texture: a constant texture is c times the untextured result in every method (sun)") {
  const LightTextureFrame f = sunTextureFrame(kW, kH, kMapW, kMapH);
  const Camera& camera = f.camera;
  const Image& depth = f.depth;
  const Medium& medium = f.medium;
  const DirectionalLight& light = f.sun;
  const RectifiedMap& map = f.map;
  const glm::dmat4& M = f.shadowClipFromWorld;
  const Image shadow = halfSpaceShadowMap(f.plane, M, 256);
  const FilteredBasis plain = prefilter(map, medium, prefilterOptions());
  const MarchResult brute = bruteForceMarch(map, depth, camera, light, medium);
  const MarchResult world = worldSpaceMarch(shadow, M, depth, camera, light, medium, {.steps = 32});
  for (const glm::dvec3 c : {glm::dvec3(1.0), glm::dvec3(0.75, 0.5, 0.25)}) {
    CAPTURE(c.y);
    const Image tex = constantTexture(c);
    const LightTexture texture{&tex, M};
    const Image colors = lightColorMap(texture, *f.layout, kMapW, kMapH);
    bool colorsAreC = true;
    for (int j = 0; j < kMapH; ++j)
      for (int i = 0; i < kMapW; ++i)
        for (int k = 0; k < 3; ++k)
          colorsAreC = colorsAreC && colors.at(i, j, k) == static_cast<float>(c[k]);
    CHECK(colorsAreC);
    const FilteredBasis textured = prefilter(map, medium, colors, prefilterOptions());
    checkBasisEqualsUntextured(textured, plain, c);
    for (const EvaluateOptions& o : evaluateVariants(true)) {
      CAPTURE(o.visibilityTableSamples);
      CAPTURE(o.scatteringPrefix);
      CAPTURE(o.nearPlaneCorrection);
      CAPTURE(static_cast<int>(o.sampling));
      checkScaled("prefiltered", evaluate(textured, depth, camera, light, medium, o),
                  evaluate(plain, depth, camera, light, medium, o), c);
    }
    checkScaled("brute force", bruteForceMarch(map, depth, camera, light, medium, colors).scattering,
                brute.scattering, c);
    checkScaled("world march",
                worldSpaceMarch(shadow, M, depth, camera, light, medium, texture, {.steps = 32}).scattering,
                world.scattering, c);
  }
}

TEST_CASE("light texture: a constant texture is c times the untextured result in every method (spot)") {
  const LightTextureFrame f = spotTextureFrame(kW, kH, kMapW, kMapH);
  const Camera& camera = f.camera;
  const Image& depth = f.depth;
  const Medium& medium = f.medium;
  const LocalLight& light = *f.local;
  const RectifiedMap& map = f.map;
  const glm::dmat4& M = f.shadowClipFromWorld;
  const Image shadow = halfSpaceShadowMap(f.plane, M, 256);
  const FilteredBasis plain = prefilter(map, medium, light, prefilterOptions());
  const MarchResult brute = bruteForceMarch(map, depth, camera, light, medium);
  const MarchResult world = worldSpaceMarch(shadow, M, depth, camera, light, medium, {.steps = 32});
  for (const glm::dvec3 c : {glm::dvec3(1.0), glm::dvec3(0.75, 0.5, 0.25)}) {
    CAPTURE(c.y);
    const Image tex = constantTexture(c);
    const LightTexture texture{&tex, M};
    const Image colors = lightColorMap(texture, *f.layout, kMapW, kMapH);
    const FilteredBasis textured = prefilter(map, medium, light, colors, prefilterOptions());
    CHECK(textured.localLight);
    // Texels whose light ray points behind the spot (colour 0) carry no light untextured either; the
    // bases agree wherever the colour is c.
    int behind = 0;
    for (int j = 0; j < kMapH; ++j)
      for (int i = 0; i < kMapW; ++i)
        behind += colors.at(i, j, 0) == static_cast<float>(c.x) ? 0 : 1;
    MESSAGE("map texels behind the spot (colour 0): " << behind);
    if (behind == 0) checkBasisEqualsUntextured(textured, plain, c);
    for (const EvaluateOptions& o : evaluateVariants(false)) {
      CAPTURE(o.visibilityTableSamples);
      CAPTURE(o.scatteringPrefix);
      CAPTURE(static_cast<int>(o.sampling));
      checkScaled("prefiltered (spot)", evaluate(textured, depth, camera, light, medium, o),
                  evaluate(plain, depth, camera, light, medium, o), c);
    }
    checkScaled("brute force (spot)", bruteForceMarch(map, depth, camera, light, medium, colors).scattering,
                brute.scattering, c);
    checkScaled("world march (spot)",
                worldSpaceMarch(shadow, M, depth, camera, light, medium, texture, {.steps = 32}).scattering,
                world.scattering, c);
  }
}

TEST_CASE("light texture: a two-colour window over the sun, prefiltered vs brute force and world march") {
  checkTwoColour(sunTextureFrame(kW, kH, kMapW, kMapH), "sun, two-colour window");
}

TEST_CASE(
    "light texture: a two-colour gobo over a spot light's cone, prefiltered vs brute force and world march") {
  checkTwoColour(spotTextureFrame(kW, kH, kMapW, kMapH), "spot, two-colour gobo");
}

TEST_CASE("light texture: missing, empty or bad textures and colour maps are named") {
  const DirectionalLight light = sideLight();
  const glm::dmat4 M = analyticLightMatrix(light);
  const auto parameterOf = [](const auto& call) {
    try {
      call();
    } catch (const InvalidArgument& e) {
      MESSAGE(std::string(e.what()));
      return e.parameter();
    }
    return std::string("(no throw)");
  };
  CHECK(parameterOf([&] { validate(LightTexture{nullptr, M}); }) == "LightTexture.rgb");
  const Image empty;
  CHECK(parameterOf([&] { validate(LightTexture{&empty, M}); }) == "LightTexture.rgb");
  Image bad = constantTexture(glm::dvec3(1.0));
  bad.at(1, 2, 1) = std::numeric_limits<float>::quiet_NaN();
  try {
    validate(LightTexture{&bad, M});
    FAIL("a NaN texel must throw");
  } catch (const InvalidArgument& e) {
    CHECK(e.parameter() == "LightTexture.rgb");
    CHECK(std::string(e.what()).find("texel (1, 2)") != std::string::npos);
  }
  bad.at(1, 2, 1) = -1.0f;
  CHECK(parameterOf([&] { validate(LightTexture{&bad, M}); }) == "LightTexture.rgb");
  const Image good = constantTexture(glm::dvec3(1.0));
  glm::dmat4 infinite = M;
  infinite[3][0] = std::numeric_limits<double>::infinity();
  CHECK(parameterOf([&] { validate(LightTexture{&good, infinite}); }) == "LightTexture.textureClipFromWorld");
  // A perspective projection does not follow the sun's parallel rays; the sun's ortho matrix is not centred
  // on a spot light.
  CHECK(parameterOf([&] {
          validateLightTexture(LightTexture{&good, analyticSpot().lightClipFromWorld()}, light);
        }) == "LightTexture.textureClipFromWorld");
  CHECK(parameterOf([&] {
          validateLightTexture(LightTexture{&good, M}, LocalLight::spot(analyticSpot()));
        }) == "LightTexture.textureClipFromWorld");
  CHECK_NOTHROW(validateLightTexture(LightTexture{&good, M}, light));
  CHECK_NOTHROW(validateLightTexture(LightTexture{&good, analyticSpot().lightClipFromWorld()},
                                     LocalLight::spot(analyticSpot())));

  // The methods name their inputs.
  const Camera camera = groundCamera(16, 9);
  const Image depth = groundDepth(camera, 16, 9);
  const Medium medium = colouredMedium();
  const auto layout = projectiveLayout(camera, light, 2);
  const RectifiedMap map = castRectifiedMap(layout, 32, 8, [](const LightRay&) { return std::nullopt; });
  Image colors(32, 8, 3, 1.0f);
  colors.at(3, 4, 2) = std::numeric_limits<float>::quiet_NaN();
  CHECK(parameterOf([&] { prefilter(map, medium, colors); }) == "lightColors");
  CHECK(parameterOf([&] { bruteForceMarch(map, depth, camera, light, medium, colors); }) == "lightColors");
  CHECK(parameterOf([&] { prefilter(map, medium, Image(16, 8, 3, 1.0f)); }) == "lightColors");
  CHECK(parameterOf([&] {
          worldSpaceMarch(Image(8, 8, 1, 1.0f), M, depth, camera, light, medium, LightTexture{nullptr, M});
        }) == "lightTexture.rgb");
  CHECK(parameterOf([&] { lightColorMap(LightTexture{&empty, M}, *layout, 32, 8); }) == "LightTexture.rgb");
}
