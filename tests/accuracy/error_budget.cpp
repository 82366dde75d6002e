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

#include "common/analytic_frames.h"
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
using namespace crep::test;

namespace {

int gWidth = 320, gHeight = 180;
std::string gKnob; // --knob: only the knobs whose name contains it (and the defaults)
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
      {"exact, spot table samples Z = 64 (as the point lights')",
       [](Scattering::CreateInfo& i) { i.spotLightTableSamples = 64; }},
      {"exact, spot table samples Z = 128", [](Scattering::CreateInfo& i) { i.spotLightTableSamples = 128; }},
      {"exact, prefilter regions P = 4", [](Scattering::CreateInfo& i) { i.prefilter.regionsPerSplit = 4; }},
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
    frames.push_back(std::make_unique<CaseFrame>(
        c, caseCamera(kCameraPosition, 0.0, double(gWidth) / gHeight), gWidth, gHeight));
    truths.push_back(truthOf(c, caseCamera(kCameraPosition, 0.0, double(gWidth) / gHeight),
                             frames.back()->depth(), frames.back()->medium()));
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
      std::printf(" %.2f%% |", 100.0 * rgbRelativeRmse(img, truths[i]));
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
    std::printf(" %.2f%% |", 100.0 * rgbRelativeRmse(frames[i]->worldMarch(), truths[i]));
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
      std::printf(" %.2f%% |", 100.0 * rgbRelativeRmse(frames[i]->marchSameMap(r), truths[i]));
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
  const Camera camera = caseCamera(kCameraPosition, 0.0, double(gWidth) / gHeight);
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
                100.0 * rgbRelativeRmse(texelSum(map, camera, depth, *c.sun, medium, v), truth));
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
    row(tag + "exact in the last split, series before", [&](int i, int last, int n, double zt, double zr) {
      return i >= last / n * n ? exact(zt, zr) : f(zt, zr);
    });
    row(tag + "exact in the splits crossed whole, series in the last",
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
            " ray depths in whole splits, exact in the last",
        [&](int i, int last, int n, double zt, double zr) {
          return i < last / n * n ? t(zt, zr) : exact(zt, zr);
        });
  }
}

void flicker(const std::vector<Case>& cases) {
  constexpr int kFrames = 5;
  const std::vector<CameraMotion> motions = slowMotions();
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
    for (const CameraMotion& mo : motions) {
      FlickerTrack reference, ours, series, same;
      for (int f = 0; f < kFrames; ++f) {
        const Camera camera =
            caseCamera(kCameraPosition + double(f) * mo.step, double(f) * mo.yaw, double(gWidth) / gHeight);
        CaseFrame frame(c, camera, gWidth, gHeight);
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
