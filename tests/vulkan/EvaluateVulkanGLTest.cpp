// EvaluatePass on gpu::VulkanBackend (lavapipe, validation on) against the same pass on the GL backend
// (llvmpipe) and the CPU reference: the same CPU inputs (rectified map, camera depth, light colours)
// uploaded to both backends, prefiltered and evaluated there, the images read back. The bar is the one of
// the Vulkan port: relative RMSE <= 1e-4 between the backends. That holds for an RGBA8 basis too: both
// rasterisers filter unorm8 texels with the same 8-bit bilinear weights (the same LLVM sampler code), so the
// RGBA8 rounding, which moves either image from the CPU's by up to the GL pass's RGBA8 bound
// (tests/prefilter/PrefilterGpuGLTest.cpp: relative RMSE 2e-3), is the same on both.
#include "common/analytic_reference.h"
#include "common/gl_fixture.h"
#include "common/light_texture_frames.h"
#include "common/local_light_scene.h"
#include "common/prefilter_gpu.h"
#include "common/sample_list_util.h"
#include "common/vulkan_fixture.h"

#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/resample.h>
#include <crep/gpu/gl_backend.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/scatter/light_texture.h>
#include <crep/scenes/engine_frame.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>
#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

/// One frame's CPU inputs: uploaded as they are to each backend.
struct Inputs {
  const RectifiedLayout* layout = nullptr;
  const Image* map = nullptr;         ///< rectified depth, 1 channel
  const Image* cameraDepth = nullptr; ///< depth-buffer values, 1 channel
  const Camera* camera = nullptr;
  const Medium* medium = nullptr;
  const DirectionalLight* light = nullptr; ///< or `local`
  const LocalLight* local = nullptr;
  const Image* lightColors = nullptr; ///< the map's colour map (3 channels) or null
};

/// What a backend gives for extra targets besides the image.
struct Extras {
  const FroxelGrid* froxels = nullptr;  ///< fill a volume of this grid (RGBA32F)
  glm::dvec3 jitter{0.0};               ///< its sample offset
  std::vector<glm::ivec2> listTexels{}; ///< non-empty: also evaluate a work list of these pixels
};

struct Outputs {
  std::vector<float> image, volume, list; ///< RGBA floats of the output, the volume and the list's output
};

gpu::Texture upload(gpu::Backend& b, gpu::Format format, int w, int h, std::span<const float> texels,
                    const char* label) {
  gpu::Texture t(b, {gpu::TextureType::Texture2D, format, w, h, 1, label});
  b.writeTexture(t.id(), texels);
  return t;
}

/// PrefilterPass and EvaluatePass on `b` over `in`; the evaluation's targets read back.
Outputs runOn(gpu::Backend& b, const Inputs& in, PrefilterPass::CreateInfo p, EvaluatePass::CreateInfo e,
              const Extras& x = {}) {
  const int W = in.map->width(), H = in.map->height(), w = in.cameraDepth->width(),
            h = in.cameraDepth->height();
  const gpu::Texture map = upload(b, gpu::Format::R32F, W, H, in.map->data(), "map");
  const gpu::Texture depth = upload(b, gpu::Format::R32F, w, h, in.cameraDepth->data(), "camera depth");
  gpu::Texture colors;
  if (in.lightColors != nullptr)
    colors = upload(b, gpu::Format::RGBA32F, W, H, scenes::rgbaTexels(*in.lightColors), "light colours");
  p.mapWidth = W;
  p.mapHeight = H;
  p.backend = &b;
  PrefilterPass prefilterPass(p);
  PrefilterPass::FrameAttribs pf;
  pf.rectifiedDepth = map.id();
  pf.layout = in.layout;
  pf.medium = in.medium;
  pf.localLight = in.local;
  pf.lightColors = colors.id();
  prefilterPass.run(pf);

  e.bases = p.options.bases;
  e.backend = &b;
  EvaluatePass pass(e);
  const gpu::Format outFormat =
      e.outputFormat == StorageFormat::RGBA16F ? gpu::Format::RGBA16F : gpu::Format::RGBA32F;
  gpu::Texture out(b, {gpu::TextureType::Texture2D, outFormat, w, h, 1, "output"});
  gpu::Texture volume;
  if (x.froxels != nullptr)
    volume = gpu::Texture(b, {gpu::TextureType::Texture3D, gpu::Format::RGBA32F, x.froxels->width,
                              x.froxels->height, x.froxels->depth, "froxels"});
  EvaluatePass::FrameAttribs f;
  f.cameraDepth = depth.id();
  f.output = out.id();
  f.camera = in.camera;
  f.light = in.light;
  f.localLight = in.local;
  f.medium = in.medium;
  f.layout = in.layout;
  f.basis = prefilterPass.filteredBasis();
  if (x.froxels != nullptr) f.froxels = {volume.id(), *x.froxels, x.jitter};
  pass.run(f);
  Outputs o;
  o.image = b.readTexture(out.id());
  if (x.froxels != nullptr) o.volume = b.readTexture(volume.id());
  if (!x.listTexels.empty()) {
    // A work list written from the CPU (the producers are GL passes): header, entries x | y << 16, the
    // pixel centres' coordinates; its output starts as NaN, so an entry left unwritten shows.
    const std::vector<float> coordinates = pixelCoordinates(*in.cameraDepth);
    const gpu::Texture coords = upload(b, gpu::Format::RGBA32F, w, h, coordinates, "list coordinates");
    const std::vector<float> nan(coordinates.size(), std::numeric_limits<float>::quiet_NaN());
    const gpu::Texture listOut = upload(b, gpu::Format::RGBA32F, w, h, nan, "list output");
    const auto count = static_cast<std::uint32_t>(x.listTexels.size());
    std::vector<std::uint32_t> words{(count + 63) / 64, 1, 1, count};
    for (const glm::ivec2& t : x.listTexels)
      words.push_back(static_cast<std::uint32_t>(t.x) | (static_cast<std::uint32_t>(t.y) << 16));
    gpu::Buffer buffer(b, static_cast<std::size_t>(gpu::kSampleListHeaderBytes) + 4u * w * h, "list");
    b.writeBuffer(buffer.id(), 0, std::as_bytes(std::span(words)));
    const gpu::SampleList list{buffer.id(), coords.id(), listOut.id(), w, h, w * h};
    f.list = &list;
    f.output = 0;
    f.froxels = {};
    f.reuseTable = usesVisibilityTable(e.options); // the table of the run above
    pass.run(f);
    o.list = b.readTexture(listOut.id());
  }
  return o;
}

/// Relative RMSE of `a` against `b` over the RGB of RGBA floats, and the count of non-finite values in `a`.
struct Agreement {
  double relativeRmse = 0.0, maxAbs = 0.0, peak = 0.0;
  long long nonFinite = 0;
};

Agreement agreement(const std::vector<float>& a, const std::vector<float>& b) {
  REQUIRE(a.size() == b.size());
  Agreement g;
  double squared = 0.0, reference = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (i % 4 == 3) continue;
    if (!std::isfinite(a[i]) || !std::isfinite(b[i])) {
      g.nonFinite += !std::isfinite(a[i]);
      continue;
    }
    const double d = static_cast<double>(a[i]) - b[i];
    squared += d * d;
    reference += static_cast<double>(b[i]) * b[i];
    g.maxAbs = std::max(g.maxAbs, std::abs(d));
    g.peak = std::max(g.peak, std::abs(static_cast<double>(b[i])));
  }
  g.relativeRmse = reference > 0.0 ? std::sqrt(squared / reference) : std::sqrt(squared);
  return g;
}

void report(const std::string& what, const Agreement& g) {
  MESSAGE(what << ": relative RMSE " << g.relativeRmse << ", max abs " << g.maxAbs << " (peak " << g.peak
               << "), " << g.nonFinite << " non-finite");
}

/// Vulkan against GL (and both against `cpu`, RGBA floats, when given) for one configuration.
void checkBackendsAgree(const std::string& name, const Outputs& vk, const Outputs& gl,
                        const std::vector<float>* cpu = nullptr, double cpuRelativeRmse = 0.0) {
  CAPTURE(name);
  const Agreement g = agreement(vk.image, gl.image);
  report(name + ", Vulkan vs GL", g);
  CHECK(g.nonFinite == 0);
  CHECK(g.relativeRmse <= 1e-4);
  if (cpu != nullptr) {
    const Agreement c = agreement(vk.image, *cpu);
    report(name + ", Vulkan vs CPU", c);
    CHECK(c.relativeRmse <= cpuRelativeRmse);
  }
}

/// The RGBA texels of an evaluation image (4 channels), as a backend's RGBA32F read-back lays them out.
std::vector<float> rgbaImage(const Image& image) {
  REQUIRE(image.channels() == 4);
  return {image.data().begin(), image.data().end()};
}

struct Backends {
  gpu::VulkanBackend vk{validatedVulkan()};
  gpu::GlBackend gl;
  ~Backends() { checkNoValidationMessages(vk); }
};

} // namespace

TEST_CASE(
    "Vulkan backend: EvaluatePass gives GL's image for every evaluation option and basis format (boxes, "
    "projective)") {
  CREP_REQUIRE_GL();
  const GpuScene s = renderGpuScene("boxes", 250, 37, 2, 161, 93);
  const Inputs in{s.layout.get(),  &s.map.depth,    &s.cameraDepth,
                  &s.scene.camera, &s.scene.medium, &s.scene.sun};
  Backends b;
  for (const StorageFormat format : {StorageFormat::RGBA32F, StorageFormat::RGBA8}) {
    PrefilterPass::CreateInfo p;
    p.options.format = format;
    p.options.regionsPerSplit = 5;
    const FilteredBasis cpuBasis = prefilter(s.map, s.scene.medium, p.options);
    for (const Sampling sampling : {Sampling::Bilinear, Sampling::Nearest})
      for (const int option : {0, 1, 2, 3, 4}) {
        // 0: defaults (scattering prefix), 1: near-plane correction, 2: Lanczos and RGBA16F output, 3: the
        // per-region loop over the visibility table, 4: no table.
        EvaluatePass::CreateInfo e;
        e.options.sampling = sampling;
        e.options.nearPlaneCorrection = option == 1;
        e.options.ringing = option == 2 ? RingingFilter::Lanczos : RingingFilter::None;
        e.options.scatteringPrefix = option != 3;
        if (option == 4) e.options.visibilityTableSamples = 0;
        e.outputFormat = option == 2 ? StorageFormat::RGBA16F : StorageFormat::RGBA32F;
        const std::string name = std::string(storageFormatToken(format)) +
                                 (sampling == Sampling::Nearest ? " nearest" : " bilinear") + ", option " +
                                 std::to_string(option);
        const Outputs vk = runOn(b.vk, in, p, e), gl = runOn(b.gl, in, p, e);
        // Against the CPU evaluation of the CPU basis: the GL pass's bounds (PrefilterGpuGLTest.cpp), for
        // the float basis bilinear 2e-6 relative RMSE, RGBA8 2e-3 (plus its basis' own steps: 2e-3),
        // nearest 1e-3; RGBA16F output adds 5e-4.
        const std::vector<float> cpu = rgbaImage(
            evaluate(cpuBasis, s.cameraDepth, s.scene.camera, s.scene.sun, s.scene.medium, e.options));
        double bound = format == StorageFormat::RGBA8 ? 4e-3 : sampling == Sampling::Nearest ? 1e-3 : 2e-6;
        if (e.outputFormat == StorageFormat::RGBA16F) bound = std::max(bound, 5e-4);
        checkBackendsAgree(name, vk, gl, &cpu, bound);
      }
  }
}

TEST_CASE("Vulkan backend: EvaluatePass on the epipolar layout (sun in view), froxels, a work list and a "
          "reused table give GL's results") {
  CREP_REQUIRE_GL();
  constexpr int w = 160, h = 90, shadowSize = 512;
  scenes::Scene scene = scenes::makeScene("forest", static_cast<double>(w) / h);
  const Camera& cam = scene.camera;
  scene.sun = DirectionalLight(-glm::normalize(cam.forward() + 0.25 * cam.right() + 0.2 * cam.up()),
                               scene.sun.irradiance());
  scenes::SceneRenderer renderer(scene.mesh);
  const gl::Handle depthTexture = scenes::createDepthTexture(w, h);
  renderer.renderDepth(cam.clipFromWorld(), depthTexture.get(), 0, 0, 0, w, h);
  const Image cameraDepth = scenes::readDepthTexture(depthTexture.get(), w, h);
  const glm::dmat4 lightMatrix =
      scenes::standardLightClipFromWorld(scene.sun, scene.boundsMin, scene.boundsMax);
  const gl::Handle shadow = scenes::createDepthTexture(shadowSize, shadowSize);
  renderer.renderDepth(lightMatrix, shadow.get(), 0, 0, 0, shadowSize, shadowSize, {.depthClamp = true});
  const auto layout = std::make_shared<const EpipolarLayout>(cam, scene.sun, w, h);
  REQUIRE(layout->epipoleOnScreen());
  const RectifiedMap map =
      resampleShadowMap(layout, 256, layout->sliceCount(),
                        scenes::readDepthTexture(shadow.get(), shadowSize, shadowSize), lightMatrix);
  Backends b;
  PrefilterPass::CreateInfo p;
  p.options.format = StorageFormat::RGBA32F;
  const Inputs epipolar{layout.get(), &map.depth, &cameraDepth, &cam, &scene.medium, &scene.sun};
  // The epipolar layout's block (CREP_EVAL_LAYOUT), with the default prefix table and without a table.
  for (const int samples : {-1, 0}) {
    EvaluatePass::CreateInfo e;
    if (samples == 0) e.options.visibilityTableSamples = 0;
    const std::vector<float> cpu = rgbaImage(evaluate(prefilter(map, scene.medium, p.options), cameraDepth,
                                                      cam, scene.sun, scene.medium, e.options));
    // The GL pass's epipolar bound against the CPU (PrefilterEpipolarGLTest.cpp): 5e-5.
    checkBackendsAgree(samples == 0 ? "epipolar, no table" : "epipolar, prefix table",
                       runOn(b.vk, epipolar, p, e), runOn(b.gl, epipolar, p, e), &cpu, 5e-5);
  }

  // Froxels and a work list of every third pixel on the boxes scene's projective frame, with the image.
  const GpuScene s = renderGpuScene("boxes", 250, 37, 2, 161, 93);
  const Inputs boxes{s.layout.get(),  &s.map.depth,    &s.cameraDepth,
                     &s.scene.camera, &s.scene.medium, &s.scene.sun};
  FroxelGrid grid;
  grid.width = 20;
  grid.height = 12;
  grid.depth = 16;
  Extras x{&grid, glm::dvec3(0.25, -0.125, 0.5),
           texelsWhere(161, 93, [](int px, int py) { return (px + 2 * py) % 3 == 0; })};
  for (const bool table : {true, false}) {
    EvaluatePass::CreateInfo e;
    e.options.scatteringPrefix = table;
    const Outputs vk = runOn(b.vk, boxes, p, e, x), gl = runOn(b.gl, boxes, p, e, x);
    const std::string name = table ? "boxes, prefix table" : "boxes, per-region table";
    checkBackendsAgree(name, vk, gl);
    const Agreement volume = agreement(vk.volume, gl.volume);
    report(name + ", froxel volume, Vulkan vs GL", volume);
    CHECK(volume.nonFinite == 0);
    CHECK(volume.relativeRmse <= 1e-4);
    // The list's entries equal the per-pixel image on the same backend (GL: bit for bit,
    // EvaluateListGLTest), and only they are written.
    long long entries = 0, mismatched = 0, strays = 0;
    for (int py = 0; py < 93; ++py)
      for (int px = 0; px < 161; ++px) {
        const std::size_t i = (static_cast<std::size_t>(py) * 161 + static_cast<std::size_t>(px)) * 4;
        const bool entry = (px + 2 * py) % 3 == 0;
        entries += entry;
        for (int c = 0; c < 4; ++c) {
          if (entry && !sameBits(vk.list[i + c], vk.image[i + c])) ++mismatched;
          if (!entry && !std::isnan(vk.list[i + c])) ++strays;
        }
      }
    MESSAGE(name << ": Vulkan work list of " << entries << " entries, " << mismatched
                 << " values differ from the per-pixel image, " << strays << " values written outside it");
    CHECK(entries == static_cast<long long>(x.listTexels.size()));
    CHECK(mismatched == 0);
    CHECK(strays == 0);
  }
}

TEST_CASE("Vulkan backend: EvaluatePass with local lights (spot, point face, closed form) and light textures "
          "gives GL's image") {
  CREP_REQUIRE_GL();
  constexpr int W = 256, H = 128, w = 160, h = 90;
  const auto [camera, depth, medium, ro] = localLightView(w, h);
  Backends b;
  PrefilterPass::CreateInfo p;
  p.options.regionsPerSplit = 2;
  p.options.format = StorageFormat::RGBA32F;
  const SpotLight spot = analyticSpot();
  const PointLight point = analyticPoint();
  const struct {
    const char* name;
    Rectification rect;
    LocalLight light;
  } lights[] = {{"spot", rectify(camera, spot, ro), LocalLight::spot(spot)},
                {"point face +X", rectifyPointLight(camera, point, ro)[0], LocalLight::pointFace(point, 0)}};
  for (const auto& k : lights) {
    REQUIRE(k.rect.projective());
    const auto layout = std::make_shared<const ProjectiveLayout>(k.rect);
    const RectifiedMap map = castRectifiedMap(layout, W, H, wallHitFromLight);
    const Inputs in{layout.get(), &map.depth, &depth, &camera, &medium, nullptr, &k.light};
    for (const int variant : {0, 1, 2}) {
      // Prefix table (with the local section table) or per-region loop; the sections by the quadrature or
      // in closed form (the airlight table).
      EvaluatePass::CreateInfo e;
      e.options.scatteringPrefix = variant != 1;
      e.localClosedForm = variant == 2;
      const std::string name = std::string(k.name) +
                               (variant == 1 ? ", per-region table" : ", prefix table") +
                               (variant == 2 ? ", closed form" : "");
      checkBackendsAgree(name, runOn(b.vk, in, p, e), runOn(b.gl, in, p, e));
    }
  }
  // In view: a spot and a point-light face on their epipolar layouts (Sec. 4.1 around the light's image).
  for (const LocalLight& light :
       {LocalLight::spot(analyticViewSpot()), LocalLight::pointFace(analyticViewPoint(), 5)}) {
    EpipolarOptions eo;
    eo.slices = H;
    eo.depthWarp = 0.03; // Scattering::CreateInfo::localLightDepthWarp
    const auto layout = std::make_shared<const EpipolarLayout>(camera, light.position, w, h, eo);
    REQUIRE(layout->epipoleOnScreen());
    const RectifiedMap map = castRectifiedMap(layout, W, H, wallHitFromLight);
    const Inputs in{layout.get(), &map.depth, &depth, &camera, &medium, nullptr, &light};
    for (const int variant : {0, 1}) {
      EvaluatePass::CreateInfo e;
      e.options.scatteringPrefix = variant == 0;
      checkBackendsAgree(std::string(light.cone ? "spot in view" : "point face -Z in view") +
                             ", epipolar layout" + (variant == 0 ? ", prefix table" : ", per-region table"),
                         runOn(b.vk, in, p, e), runOn(b.gl, in, p, e));
    }
  }
  // Light textures: the sun's window and a spot's gobo, their colour maps from the CPU.
  const Image texture = twoColourTexture();
  for (const bool isSpot : {false, true}) {
    const LightTextureFrame f = lightTextureFrame(isSpot, w, h, W, H);
    const Image colors =
        lightColorMap({&texture, f.textureClipFromWorld}, *f.layout, f.map.width(), f.map.height());
    const Inputs in{f.layout.get(),
                    &f.map.depth,
                    &f.depth,
                    &f.camera,
                    &f.medium,
                    f.local ? nullptr : &f.sun,
                    f.local ? &*f.local : nullptr,
                    &colors};
    for (const int samples : {-1, 0}) {
      EvaluatePass::CreateInfo e;
      if (samples == 0) e.options.visibilityTableSamples = 0;
      checkBackendsAgree(std::string(isSpot ? "spot gobo" : "sun window") +
                             (samples == 0 ? ", textured, no table" : ", textured, prefix table"),
                         runOn(b.vk, in, p, e), runOn(b.gl, in, p, e));
    }
  }
}
