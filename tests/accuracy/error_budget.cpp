// The error budget of the prefiltered method on the analytic scenes (a ground plane and one plane occluder,
// whose single scattering is known in closed form): each source of error removed alone, the reference marches
// beside, where along a ray the Fourier truncation's error sits (CPU), and the frame-to-frame flicker under a
// slow strafe and a slow rotation. Prints Markdown tables; docs/MEASUREMENTS.md, "Error budget", keeps the
// figures.
//
//   build/tests/accuracy/crep_error_budget [--size WxH] [--section budget|split|flicker|all] [--case NAME]
//                                          [--knob TEXT]
//
// It reuses the tests' analytic scenes (tests/common), so it is built with the tests.
#define DOCTEST_CONFIG_IMPLEMENT // the test helpers' doctest symbols; no test runs here
#include <doctest/doctest.h>

#include "common/analytic_reference.h"
#include "common/gl_fixture.h"
#include "common/local_light_scene.h"

#include <crep/core/error.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/pipeline/scattering.h>
#include <crep/prefilter/fourier.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/gpu_world_march.h>
#include <crep/scatter/rectified_march.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <epoxy/gl.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>
#include <vector>

using namespace crep;

namespace {

int gWidth = 320, gHeight = 180;
std::string gKnob;                 // --knob: only the knobs whose name contains it (and the defaults)
constexpr int kStandardMap = 2048; // the engine's standard map of the resampled input and the world march

/// One analytic case: the ground camera, a light and its plane occluder (a sun's, or the local lights' wall).
struct Case {
  std::string name;
  std::optional<DirectionalLight> sun;
  std::optional<SpotLight> spot;
  test::HalfSpace plane;
};

/// The sun cases' occluder, oriented so that its shadowed side (normal side) faces away from the light.
test::HalfSpace sunPlane(const glm::dvec3& direction) {
  test::HalfSpace p;
  if (glm::dot(p.normal, direction) < 0.0) p.normal = -p.normal;
  return p;
}

Case sunCase(std::string name, const glm::dvec3& direction) {
  return {std::move(name), DirectionalLight(direction, glm::dvec3(2.0, 1.8, 1.5)), std::nullopt,
          sunPlane(glm::normalize(direction))};
}

std::vector<Case> allCases() {
  return {sunCase("sun to the side", {1.0, -1.0, -0.3}),
          sunCase("sun in view", {0.3, -0.3, 1.0}),
          sunCase("sun oblique", {0.6, -0.5, -0.8}),
          sunCase("sun behind", {0.2, -0.4, -1.0}),
          {"spot near the view", std::nullopt, test::analyticViewSpot(), test::wall()},
          {"spot to the side", std::nullopt, test::analyticSpot(), test::wall()}};
}

/// A square of half-size `extent` in the plane through `point` with `normal`: two triangles.
void addQuad(scenes::Mesh& mesh, const glm::dvec3& point, const glm::dvec3& normal, double extent) {
  const glm::dvec3 a = glm::normalize(
      glm::cross(normal, std::abs(normal.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0)));
  const glm::dvec3 b = glm::cross(normal, a);
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  for (const auto& [s, t] : {std::pair{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}}) {
    mesh.positions.push_back(glm::vec3(point + extent * (s * a + t * b)));
    mesh.normals.push_back(glm::vec3(normal));
  }
  for (const std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u})
    mesh.indices.push_back(base + i);
}

/// The casters of a case: the ground (it shadows nothing above it, but it is in every map, as in an engine)
/// and the occluder's plane, both 4000 units wide.
scenes::Mesh casters(const Case& c) {
  scenes::Mesh mesh;
  addQuad(mesh, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 2000.0);
  addQuad(mesh, c.plane.point, c.plane.normal, 2000.0);
  return mesh;
}

/// A camera at `position` with the ground camera's orientation turned by `yaw` radians about +y.
Camera caseCamera(const glm::dvec3& position, double yaw) {
  const glm::dvec3 forward(std::sin(-yaw) * 10.0, -0.5, -std::cos(-yaw) * 10.0);
  return Camera::lookAt(position, position + forward, {0, 1, 0}, glm::radians(60.0),
                        static_cast<double>(gWidth) / gHeight, 0.1, 80.0);
}

Image truthOf(const Case& c, const Camera& camera, const Image& depth, const Medium& medium) {
  if (c.sun) return test::closedForm(depth, camera, *c.sun, medium, c.plane);
  return test::closedFormLocal(depth, camera, {LocalLight::spot(*c.spot)}, medium);
}

double relativeRmse(const Image& actual, const Image& reference) {
  return test::rgbMetrics(actual, reference).relativeRmse;
}

/// How the frame gets its shadow maps.
enum class Input { Rasterized, Resampled };

/// The GL side of one case at one camera: camera depth, casters, the engine's standard map and the marches.
class CaseFrame {
public:
  CaseFrame(const Case& c, const Camera& camera)
      : case_(c), camera_(camera), medium_(test::colouredMedium()), renderer_(casters(c)) {
    depth_ = test::groundDepth(camera_, gWidth, gHeight);
    depthTexture_ =
        gl::createTexture2D(GL_R32F, gWidth, gHeight); // (test::uploadR32F asserts through doctest)
    glTextureSubImage2D(depthTexture_.get(), 0, 0, 0, gWidth, gHeight, GL_RED, GL_FLOAT,
                        depth_.data().data());
    output_ = gl::createTexture2D(GL_RGBA32F, gWidth, gHeight);
    standard_.texture = standardTexture_.get();
    standard_.bias = 1e-4;
    standard_.lightClipFromWorld = c.sun ? test::analyticLightMatrix(*c.sun) : c.spot->lightClipFromWorld();
    renderer_.renderDepth(standard_.lightClipFromWorld, standardTexture_.get(), 0, 0, 0, kStandardMap,
                          kStandardMap, {.depthClamp = true});
  }
  const Image& depth() const { return depth_; }
  const Medium& medium() const { return medium_; }

  Image run(Scattering& s, Input input, Scattering::FrameResult* result = nullptr) {
    Scattering::FrameAttribs a;
    a.camera = &camera_;
    a.medium = &medium_;
    a.cameraDepth = depthTexture_.get();
    a.output = output_.get();
    if (input == Input::Rasterized)
      a.drawCasters = [this](const glm::dmat4& clipFromWorld) { renderer_.drawDepth(clipFromWorld); };
    if (case_.sun) {
      a.light = &*case_.sun;
      if (input == Input::Resampled) a.shadowMap = &standard_;
    } else {
      a.spotLights = std::span<const SpotLight>(&*case_.spot, 1);
      if (input == Input::Resampled) a.spotShadowMaps = std::span<const Scattering::ShadowMap>(&standard_, 1);
    }
    Scattering::FrameResult r = s.run(a);
    if (result) *result = std::move(r);
    return read();
  }

  /// The world-space reference march (256 sections, 12 refinements) against the standard map.
  Image worldMarch() {
    static WorldMarchPass pass({{.steps = 256, .refinements = 12}});
    WorldMarchPass::FrameAttribs f;
    f.camera = &camera_;
    const std::optional<LocalLight> local =
        case_.spot ? std::optional<LocalLight>(LocalLight::spot(*case_.spot)) : std::nullopt;
    if (case_.sun)
      f.light = &*case_.sun;
    else
      f.localLight = &*local;
    f.medium = &medium_;
    f.cameraDepth = depthTexture_.get();
    f.shadowMap = standard_.texture;
    f.lightClipFromWorld = standard_.lightClipFromWorld;
    f.bias = standard_.bias;
    f.output = output_.get();
    pass.run(f);
    return read();
  }

  /// The brute-force march over the rectified map a sun frame used (exact visibility per texel).
  Image marchSameMap(const Scattering::FrameResult& r) {
    const Scattering::FrameResult::RectifiedMapView& m = r.rectifiedMap;
    RectifiedMarchPass pass({m.width, m.height, RectifiedMarchPass::Mode::BruteForce});
    RectifiedMarchPass::FrameAttribs a;
    a.layout = m.layout.get();
    a.camera = &camera_;
    a.light = &*case_.sun;
    a.medium = &medium_;
    a.cameraDepth = depthTexture_.get();
    a.rectifiedDepth = m.texture;
    a.output = output_.get();
    pass.run(a);
    return read();
  }

private:
  Image read() const { return gl::readTexture(output_.get(), gWidth, gHeight, gl::TexelData::Rgba); }

  const Case& case_;
  Camera camera_;
  Medium medium_;
  scenes::SceneRenderer renderer_;
  Image depth_;
  gl::Handle depthTexture_, output_,
      standardTexture_ = scenes::createDepthTexture(kStandardMap, kStandardMap);
  Scattering::ShadowMap standard_;
};

Scattering::CreateInfo defaultInfo() {
  Scattering::CreateInfo info;
  info.width = gWidth;
  info.height = gHeight;
  info.stageTimings = false;
  return info;
}

/// One knob: a change of the defaults that removes (or shrinks) one source of error.
struct Knob {
  std::string name;
  std::function<void(Scattering::CreateInfo&)> change;
  Input input = Input::Rasterized;
};

/// The Fourier series (Klehm et al. 2014, the former default) with a change.
Knob fourier(std::string name, std::function<void(Scattering::CreateInfo&)> change,
             Input input = Input::Rasterized) {
  return {"Fourier, " + name,
          [change](Scattering::CreateInfo& i) {
            i.prefilter.reconstruction = VisibilityReconstruction::Fourier;
            change(i);
          },
          input};
}

std::vector<Knob> knobs() {
  const auto none = [](Scattering::CreateInfo&) {};
  return {
      {"defaults: exact reconstruction, 1024^2, rasterized", none},
      {"exact, map resolution 2048^2", [](Scattering::CreateInfo& i) { i.mapSize = 2048; }},
      {"exact, resampled from a 2048^2 standard map", none, Input::Resampled},
      {"exact, table samples Z = 512",
       [](Scattering::CreateInfo& i) {
         i.evaluate.visibilityTableSamples = 512;
         i.localLightTableSamples = i.spotLightTableSamples = 512;
       }},
      {"exact, prefilter regions P = 8", [](Scattering::CreateInfo& i) { i.prefilter.regionsPerSplit = 8; }},
      fourier("M = 32, RGBA8 (the former defaults)", none),
      fourier("truncation: M = 64",
              [](Scattering::CreateInfo& i) { i.prefilter.bases = i.spotLightBases = 64; }),
      fourier("truncation: M = 128, RGBA32F",
              [](Scattering::CreateInfo& i) {
                i.prefilter.bases = i.spotLightBases = 128;
                i.prefilter.format = StorageFormat::RGBA32F;
              }),
      fourier("storage: RGBA32F",
              [](Scattering::CreateInfo& i) { i.prefilter.format = StorageFormat::RGBA32F; }),
      fourier("map resolution: 2048^2", [](Scattering::CreateInfo& i) { i.mapSize = 2048; }),
      fourier("resampling: from a 2048^2 standard map", none, Input::Resampled),
      fourier("prefilter regions: P = 1", [](Scattering::CreateInfo& i) { i.prefilter.regionsPerSplit = 1; }),
      fourier("prefilter regions: P = 8", [](Scattering::CreateInfo& i) { i.prefilter.regionsPerSplit = 8; }),
      fourier("prefix table samples: Z = 512",
              [](Scattering::CreateInfo& i) {
                i.evaluate.visibilityTableSamples = 512;
                i.localLightTableSamples = i.spotLightTableSamples = 512;
              }),
      fourier("prefix table: none (per-region sums)",
              [](Scattering::CreateInfo& i) { i.evaluate.visibilityTableSamples = 0; }),
      fourier("epipole block: none",
              [](Scattering::CreateInfo& i) { i.epipoleBlockRadius = i.localLightBlockRadius = 0; }),
      fourier("depth warp: none (linear)",
              [](Scattering::CreateInfo& i) { i.epipolarDepthWarp = i.localLightDepthWarp = 0.0; }),
      {"exact, epipole block: none",
       [](Scattering::CreateInfo& i) { i.epipoleBlockRadius = i.localLightBlockRadius = 0; }},
      {"exact, depth warp: none (linear)",
       [](Scattering::CreateInfo& i) { i.epipolarDepthWarp = i.localLightDepthWarp = 0.0; }},
  };
}

const glm::dvec3 kCameraPosition{0.0, 2.0, 0.0};

void budget(const std::vector<Case>& cases) {
  std::printf("\n## Error budget: relative RMSE of the in-scattering against the closed form, %dx%d\n\n",
              gWidth, gHeight);
  std::printf("| knob |");
  for (const Case& c : cases)
    std::printf(" %s |", c.name.c_str());
  std::printf("\n|---|");
  for (std::size_t i = 0; i < cases.size(); ++i)
    std::printf("---|");
  std::printf("\n");
  std::vector<std::unique_ptr<CaseFrame>> frames;
  std::vector<Image> truths;
  for (const Case& c : cases) {
    frames.push_back(std::make_unique<CaseFrame>(c, caseCamera(kCameraPosition, 0.0)));
    truths.push_back(
        truthOf(c, caseCamera(kCameraPosition, 0.0), frames.back()->depth(), frames.back()->medium()));
  }
  std::vector<std::string> layouts(cases.size());
  for (const Knob& k : knobs()) {
    if (!gKnob.empty() && k.name.find(gKnob) == std::string::npos && k.name.find("defaults") != 0) continue;
    Scattering::CreateInfo info = defaultInfo();
    k.change(info);
    Scattering s(info);
    std::printf("| %s |", k.name.c_str());
    for (std::size_t i = 0; i < cases.size(); ++i) {
      Scattering::FrameResult r;
      const Image img = frames[i]->run(s, k.input, &r);
      std::printf(" %.2f%% |", 100.0 * relativeRmse(img, truths[i]));
      if (layouts[i].empty())
        layouts[i] = cases[i].sun ? layoutToken(r.layout)
                                  : (r.localLights.empty()       ? "-"
                                     : r.localLights[0].epipolar ? "epipolar"
                                                                 : "projective");
    }
    std::printf("\n");
    std::fflush(stdout);
  }
  std::printf("| reference: world march, 2048^2 standard map |");
  for (std::size_t i = 0; i < cases.size(); ++i)
    std::printf(" %.2f%% |", 100.0 * relativeRmse(frames[i]->worldMarch(), truths[i]));
  std::printf("\n| reference: brute-force march over the frame's rectified map |");
  {
    Scattering s(defaultInfo());
    for (std::size_t i = 0; i < cases.size(); ++i) {
      if (!cases[i].sun) {
        std::printf(" - |");
        continue;
      }
      Scattering::FrameResult r;
      frames[i]->run(s, Input::Rasterized, &r);
      std::printf(" %.2f%% |", 100.0 * relativeRmse(frames[i]->marchSameMap(r), truths[i]));
    }
  }
  std::printf("\n| layout |");
  for (const std::string& l : layouts)
    std::printf(" %s |", l.c_str());
  std::printf("\n");
}

/// Where along a ray the truncation's error sits (CPU, double): the prefiltered sum of Klehm et al. 2014 is
/// sum_i w_i V(z_i), V the truncated series of Eq. 9; here each texel's V is evaluated alone with the ray's
/// own exact weights (no reference ray, no storage, no clamp), and chosen per texel from `visibility`.
using TexelVisibility =
    std::function<double(int texel, int last, int regionWidth, double zTexel, double zRay)>;
Image texelSum(const RectifiedMap& map, const Camera& camera, const Image& depth,
               const DirectionalLight& light, const Medium& medium, const TexelVisibility& visibility) {
  const RectifiedLayout& layout = *map.layout;
  const int W = map.width(), H = map.height(), n = W / layout.regionCount();
  const glm::dvec3 sigma = medium.extinction();
  Image out(depth.width(), depth.height(), 4);
  for (int y = 0; y < depth.height(); ++y)
    for (int x = 0; x < depth.width(); ++x) {
      const PixelRay ray = pixelRay(camera, depth, x, y, false);
      RowRay r;
      glm::dvec3 L(0.0);
      if (!mapRowRay(layout, camera.position(), ray, W, H, r)) {
        L = transmittanceIntegral(sigma, ray.start, ray.surface);
      } else {
        const RowDistances T(layout, r, W, ray.surface);
        for (int i = 0; i <= r.last; ++i)
          L += visibility(i, r.last, n, map.depth.at(i, r.texelRow), r.depth) *
               transmittanceIntegral(sigma, T.at(i), T.at(i + 1));
      }
      storeScattering(out, x, y, scatteringConstant(light, medium, ray.direction) * L, 1.0f);
    }
  return out;
}

void split(const Case& c) {
  if (!c.sun) return;
  const Camera camera = caseCamera(kCameraPosition, 0.0);
  Rectification rect = rectify(camera, *c.sun, defaultInfo().rectify);
  if (!rect.projective()) {
    std::printf("\n(%s: not projective; the split needs the projective layout)\n", c.name.c_str());
    return;
  }
  const Scattering::CreateInfo info = defaultInfo();
  const auto layout = std::make_shared<const ProjectiveLayout>(std::move(rect));
  // The casters of casters(c), as planes: the first hit along the light ray (casters before the ray's
  // origin count, as with depth clamping).
  const RectifiedMap map = castRectifiedMap(layout, info.mapSize, info.mapSize, [&](const LightRay& ray) {
    double t = 1e300;
    if (const double dn = glm::dot(c.plane.normal, ray.direction); dn > 0.0)
      t = glm::dot(c.plane.normal, c.plane.point - ray.origin) / dn;
    if (ray.direction.y < 0.0) t = std::min(t, -ray.origin.y / ray.direction.y);
    return t == 1e300 ? std::nullopt : std::optional<glm::dvec3>(ray.origin + t * ray.direction);
  });
  const Medium medium = test::colouredMedium();
  const Image depth = test::groundDepth(camera, gWidth, gHeight);
  const Image truth = truthOf(c, camera, depth, medium);
  const double m = info.prefilter.depthMargin;
  const auto exact = [](double zt, double zr) { return zt >= zr ? 1.0 : 0.0; };
  const auto fourier = [m](int bases) {
    return [m, bases](double zt, double zr) {
      return fourierVisibility(rayBasisDepth(zr, m), texelBasisDepth(zt, m), bases); // Eq. 9, with its 0.5
    };
  };
  // The visibility a table of Z exact samples of the region's visibility, interpolated linearly in z_r,
  // gives.
  const auto sampled = [](int Z) {
    return [Z](double zt, double zr) {
      const double xs = std::clamp(zr, 0.0, 1.0) * (Z - 1);
      const int s0 = std::min(static_cast<int>(xs), Z - 2);
      const double f = xs - s0;
      return (1.0 - f) * (zt >= double(s0) / (Z - 1) ? 1.0 : 0.0) +
             f * (zt >= double(s0 + 1) / (Z - 1) ? 1.0 : 0.0);
    };
  };
  const auto row = [&](const std::string& what, const TexelVisibility& v) {
    std::printf("| %s | %.2f%% |\n", what.c_str(),
                100.0 * relativeRmse(texelSum(map, camera, depth, *c.sun, medium, v), truth));
    std::fflush(stdout);
  };
  std::printf(
      "\n## Where the truncation error sits (%s, CPU, texel by texel with each ray's own weights)\n\n",
      c.name.c_str());
  std::printf("| visibility per texel | relative RMSE |\n|---|---|\n");
  row("exact everywhere (the map's own floor)",
      [&](int, int, int, double zt, double zr) { return exact(zt, zr); });
  for (const int M : {32, 64}) {
    const auto f = fourier(M);
    const std::string tag = "M = " + std::to_string(M) + ": ";
    row(tag + "truncated series everywhere", [&](int, int, int, double zt, double zr) { return f(zt, zr); });
    row(tag + "exact in the last (partial) region, series before",
        [&](int i, int last, int n, double zt, double zr) {
          return i >= last / n * n ? exact(zt, zr) : f(zt, zr);
        });
    row(tag + "exact in the regions crossed whole, series in the last",
        [&](int i, int last, int n, double zt, double zr) {
          return i < last / n * n ? exact(zt, zr) : f(zt, zr);
        });
    row(tag + "exact in the last 16 texels, series before", [&](int i, int last, int, double zt, double zr) {
      return i > last - 16 ? exact(zt, zr) : f(zt, zr);
    });
  }
  for (const int Z : {128, 256}) {
    const auto t = sampled(Z);
    row("exact visibility sampled at Z = " + std::to_string(Z) +
            " ray depths in whole regions, exact in the last",
        [&](int i, int last, int n, double zt, double zr) {
          return i < last / n * n ? t(zt, zr) : exact(zt, zr);
        });
  }
}

/// The flicker of a method: the mean over consecutive frames of the RMS of the change of its error, relative
/// to the RMS of the truth (Sec. "Flicker" of docs/MEASUREMENTS.md).
struct FlickerTrack {
  std::vector<Image> errors;
  double rmsTruth = 0.0;
  void add(const Image& image, const Image& truth) {
    Image e(image.width(), image.height(), 3);
    double t2 = 0.0;
    for (int y = 0; y < image.height(); ++y)
      for (int x = 0; x < image.width(); ++x)
        for (int ch = 0; ch < 3; ++ch) {
          e.at(x, y, ch) = image.at(x, y, ch) - truth.at(x, y, ch);
          t2 += double(truth.at(x, y, ch)) * truth.at(x, y, ch);
        }
    rmsTruth += std::sqrt(t2 / (3.0 * image.width() * image.height()));
    errors.push_back(std::move(e));
  }
  double flicker() const {
    double sum = 0.0;
    for (std::size_t f = 1; f < errors.size(); ++f) {
      double d2 = 0.0;
      const Image &a = errors[f - 1], &b = errors[f];
      for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x)
          for (int ch = 0; ch < 3; ++ch) {
            const double d = double(b.at(x, y, ch)) - a.at(x, y, ch);
            d2 += d * d;
          }
      sum += std::sqrt(d2 / (3.0 * a.width() * a.height()));
    }
    return sum / double(errors.size() - 1) / (rmsTruth / double(errors.size()));
  }
};

void flicker(const std::vector<Case>& cases) {
  constexpr int kFrames = 5;
  struct Motion {
    const char* name;
    glm::dvec3 step;
    double yaw;
  };
  const Motion motions[] = {{"strafe 0.05 / frame", {0.05, 0.0, 0.0}, 0.0},
                            {"rotation 0.25 deg / frame", {0.0, 0.0, 0.0}, glm::radians(0.25)}};
  std::printf("\n## Flicker: frame-to-frame change of the error (%d frames), relative to the truth's RMS\n\n",
              kFrames);
  std::printf(
      "| case | motion | world march (reference) | exact (default) | ratio | Fourier M = 32 | ratio | "
      "brute force, same map | ratio |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  Scattering s(defaultInfo());
  Scattering::CreateInfo fourierInfo = defaultInfo();
  fourierInfo.prefilter.reconstruction = VisibilityReconstruction::Fourier;
  Scattering fourier(fourierInfo);
  for (const Case& c : cases)
    for (const Motion& mo : motions) {
      FlickerTrack reference, ours, series, same;
      for (int f = 0; f < kFrames; ++f) {
        const Camera camera = caseCamera(kCameraPosition + double(f) * mo.step, double(f) * mo.yaw);
        CaseFrame frame(c, camera);
        const Image truth = truthOf(c, camera, frame.depth(), frame.medium());
        Scattering::FrameResult r;
        series.add(frame.run(fourier, Input::Rasterized), truth);
        ours.add(frame.run(s, Input::Rasterized, &r), truth);
        if (c.sun) same.add(frame.marchSameMap(r), truth);
        reference.add(frame.worldMarch(), truth);
      }
      const double ref = reference.flicker(), f = ours.flicker(), g = series.flicker();
      std::printf("| %s | %s | %.3f%% | %.3f%% | %.2fx | %.3f%% | %.2fx |", c.name.c_str(), mo.name,
                  100 * ref, 100 * f, f / ref, 100 * g, g / ref);
      if (c.sun)
        std::printf(" %.3f%% | %.2fx |\n", 100 * same.flicker(), same.flicker() / ref);
      else
        std::printf(" - | - |\n");
      std::fflush(stdout);
    }
}

} // namespace

int main(int argc, char** argv) {
  std::string section = "all", only;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--size" && i + 1 < argc) {
      if (std::sscanf(argv[++i], "%dx%d", &gWidth, &gHeight) != 2 || gWidth <= 0 || gHeight <= 0) {
        std::fprintf(stderr, "--size: expected WxH with positive W and H\n");
        return 2;
      }
    } else if (a == "--section" && i + 1 < argc) {
      section = argv[++i];
    } else if (a == "--knob" && i + 1 < argc) {
      gKnob = argv[++i];
    } else if (a == "--case" && i + 1 < argc) {
      only = argv[++i];
    } else {
      std::fprintf(stderr, "usage: crep_error_budget [--size WxH] [--section budget|split|flicker|all] "
                           "[--case NAME] [--knob TEXT]\n");
      return 2;
    }
  }
  try {
    test::requireGl();
    std::vector<Case> cases;
    for (const Case& c : allCases())
      if (only.empty() || c.name == only) cases.push_back(c);
    if (cases.empty()) {
      std::fprintf(stderr, "--case: no case named '%s'\n", only.c_str());
      return 2;
    }
    if (section == "budget" || section == "all") budget(cases);
    if (section == "split" || section == "all") split(cases.front());
    if (section == "flicker" || section == "all") flicker(cases);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
