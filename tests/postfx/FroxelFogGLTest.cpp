// The froxel fog's GL passes (crep/postfx/gpu_froxel_fog.h; Wronski 2014) against their CPU references
// (crep/postfx/froxel_fog.h) on a small grid (32 x 18 x 16) over the analytic ground scene with a barred
// shadow map; FroxelFog end to end against the closed form of the homogeneous unshadowed medium; temporal
// convergence with a static camera; flicker under a slow pan against the world-space reference; NaN
// containment; the block's std140 offsets; bad options named.
#include "common/analytic_scene.h"
#include "common/error_checks.h"
#include "common/gl_fixture.h"
#include "common/gl_util.h"

#include <crep/core/error.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/shader_library.h>
#include <crep/pipeline/scattering.h>
#include <crep/postfx/froxel_fog.h>
#include <crep/postfx/gpu_froxel_fog.h>
#include <crep/scatter/ray.h>
#include <crep/scatter/world_march.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <glm/gtc/quaternion.hpp>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

using namespace crep;
using crep::test::requireNamed;
using crep::test::resourceProperty;
using crep::test::uploadR32F;

namespace {

constexpr int kW = 64, kH = 36;
const FroxelGrid kGrid{32, 18, 16, 0.5, 60.0};

gl::Handle uploadVolume(const FroxelVolume& v) {
  gl::Handle t = createFroxelVolume({v.width, v.height, v.depth, 0.0, 0.0}, GL_RGBA32F, "test");
  std::vector<float> data;
  data.reserve(v.cells.size() * 4);
  for (const glm::dvec4& c : v.cells)
    for (int k = 0; k < 4; ++k)
      data.push_back(static_cast<float>(c[k]));
  glTextureSubImage3D(t.get(), 0, 0, 0, 0, v.width, v.height, v.depth, GL_RGBA, GL_FLOAT, data.data());
  return t;
}

FroxelVolume readVolume(std::uint32_t texture, const FroxelGrid& g) {
  FroxelVolume v(g.width, g.height, g.depth);
  std::vector<float> data(v.cells.size() * 4);
  glGetTextureImage(texture, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(data.size() * sizeof(float)),
                    data.data());
  for (std::size_t i = 0; i < v.cells.size(); ++i)
    v.cells[i] = glm::dvec4(data[4 * i], data[4 * i + 1], data[4 * i + 2], data[4 * i + 3]);
  return v;
}

/// max |a - b| / max |b| per channel, the worst channel.
double volumeError(const FroxelVolume& a, const FroxelVolume& b) {
  glm::dvec4 diff(0.0), scale(0.0);
  for (std::size_t i = 0; i < a.cells.size(); ++i) {
    diff = glm::max(diff, glm::abs(a.cells[i] - b.cells[i]));
    scale = glm::max(scale, glm::abs(b.cells[i]));
  }
  double worst = 0.0;
  for (int c = 0; c < 4; ++c)
    worst = std::max(worst, diff[c] / std::max(scale[c], 1e-30));
  return worst;
}

double imageError(const Image& a, const Image& b) {
  double diff[4] = {0, 0, 0, 0}, scale[4] = {0, 0, 0, 0};
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x)
      for (int c = 0; c < 4; ++c) {
        diff[c] = std::max(diff[c], std::abs(double(a.at(x, y, c)) - b.at(x, y, c)));
        scale[c] = std::max(scale[c], std::abs(double(b.at(x, y, c))));
      }
  double worst = 0.0;
  for (int c = 0; c < 4; ++c)
    worst = std::max(worst, diff[c] / std::max(scale[c], 1e-30));
  return worst;
}

/// max |a - b| / b over every pixel and channel (RGBA; b > 0 everywhere).
double maxRelative(const Image& a, const Image& b) {
  double worst = 0.0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x)
      for (int c = 0; c < 4; ++c)
        worst = std::max(worst, double(std::abs(a.at(x, y, c) - b.at(x, y, c)) / b.at(x, y, c)));
  return worst;
}

/// Relative RMSE of RGB.
double relativeRmse(const Image& a, const Image& ref) {
  double e = 0.0, r = 0.0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x)
      for (int c = 0; c < 3; ++c) {
        const double d = double(a.at(x, y, c)) - ref.at(x, y, c);
        e += d * d;
        r += double(ref.at(x, y, c)) * ref.at(x, y, c);
      }
  return std::sqrt(e / r);
}

/// Mean |a - b| over RGB.
double meanAbsDiff(const Image& a, const Image& b) {
  double s = 0.0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x)
      for (int c = 0; c < 3; ++c)
        s += std::abs(double(a.at(x, y, c)) - b.at(x, y, c));
  return s / (3.0 * a.width() * a.height());
}

/// Frame-to-frame figures of a pan: mean |X_k - X_{k-1}| of the reference and of a method, and the mean
/// frame-to-frame change of the method's error image X_k - R_k (averaged over the frames).
struct PanFigures {
  double reference = 0.0, method = 0.0, errorChange = 0.0;
};

PanFigures panFigures(const std::vector<Image>& ref, const std::vector<Image>& method) {
  const auto errorImage = [](const Image& x, const Image& r) {
    Image e(x.width(), x.height(), 4);
    for (std::size_t i = 0; i < e.sampleCount(); ++i)
      e.data()[i] = x.data()[i] - r.data()[i];
    return e;
  };
  PanFigures f;
  const double n = static_cast<double>(ref.size() - 1);
  for (std::size_t k = 1; k < ref.size(); ++k) {
    f.reference += meanAbsDiff(ref[k], ref[k - 1]) / n;
    f.method += meanAbsDiff(method[k], method[k - 1]) / n;
    f.errorChange += meanAbsDiff(errorImage(method[k], ref[k]), errorImage(method[k - 1], ref[k - 1])) / n;
  }
  return f;
}

/// The scene: the analytic ground camera, a side light, a grey-ish medium and a 128^2 shadow map over the
/// frustum with bars of occluders at light depth 0.3 (light shafts).
struct Scene {
  Camera camera = test::groundCamera(kW, kH);
  DirectionalLight light = test::sideLight();
  Medium medium = test::colouredMedium();
  glm::dmat4 lightClipFromWorld{1.0};
  Image shadow;
  explicit Scene(const Camera& cam) : camera(cam) {
    const FrustumCorners c = test::groundCamera(kW, kH).frustumCorners();
    lightClipFromWorld = orthographicLightClipFromWorld(light, c);
    shadow = Image(128, 128, 1, 1.0f);
    for (int y = 16; y < 112; ++y)
      for (int x = 0; x < 128; ++x)
        if ((x / 6) % 3 == 0) shadow.at(x, y) = 0.3f;
  }
  Scene() : Scene(test::groundCamera(kW, kH)) {}
};

Camera panned(double degrees) {
  const Camera base = test::groundCamera(kW, kH);
  const glm::dquat yaw = glm::angleAxis(glm::radians(degrees), glm::dvec3(0.0, 1.0, 0.0));
  return Camera(base.position(), yaw * base.orientation(), base.fovY(), base.aspect(), base.near(),
                base.far());
}

/// Run i of a still camera over `s` (its ESM mode: the shadow map and its matrix), the previous camera from
/// run 1 on.
FroxelFog::FrameAttribs sceneFrame(const Scene& s, std::uint32_t depth, std::uint32_t shadow,
                                   std::uint32_t output, int i) {
  FroxelFog::FrameAttribs f;
  f.camera = &s.camera;
  f.light = &s.light;
  f.medium = &s.medium;
  f.cameraDepth = depth;
  f.shadowMap = shadow;
  f.lightClipFromWorld = s.lightClipFromWorld;
  f.output = output;
  f.frameIndex = i;
  f.previousCamera = i == 0 ? nullptr : &s.camera;
  return f;
}

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

} // namespace

TEST_CASE("FroxelFog GL: CrepFroxelParams offsets match gpu::FroxelParams") {
  CREP_REQUIRE_GL();
  struct Member {
    const char* name;
    std::size_t offset;
  };
  const Member members[] = {
      {"camera.position", offsetof(gpu::FroxelParams, camera)},
      {"camera.forward", offsetof(gpu::FroxelParams, camera) + offsetof(gpu::FroxelCamera, forward)},
      {"camera.center", offsetof(gpu::FroxelParams, camera) + offsetof(gpu::FroxelCamera, center)},
      {"previous.position", offsetof(gpu::FroxelParams, previous)},
      {"previous.right", offsetof(gpu::FroxelParams, previous) + offsetof(gpu::FroxelCamera, right)},
      {"cameraDepth", offsetof(gpu::FroxelParams, cameraDepth)},
      {"range", offsetof(gpu::FroxelParams, range)},
      {"grid", offsetof(gpu::FroxelParams, grid)},
      {"jitter", offsetof(gpu::FroxelParams, jitter)},
      {"lightDirection", offsetof(gpu::FroxelParams, lightDirection)},
      {"lightIrradiance", offsetof(gpu::FroxelParams, lightIrradiance)},
      {"mieScattering", offsetof(gpu::FroxelParams, mieScattering)},
      {"rayleighScattering", offsetof(gpu::FroxelParams, rayleighScattering)},
      {"extinction", offsetof(gpu::FroxelParams, extinction)},
      {"ambient", offsetof(gpu::FroxelParams, ambient)},
      {"density", offsetof(gpu::FroxelParams, density)},
      {"noiseOffset", offsetof(gpu::FroxelParams, noiseOffset)},
      {"esm", offsetof(gpu::FroxelParams, esm)},
      {"sizes", offsetof(gpu::FroxelParams, sizes)},
      {"info", offsetof(gpu::FroxelParams, info)},
      {"lightClipFromWorld", offsetof(gpu::FroxelParams, lightClipFromWorld)},
  };
  int found = 0;
  for (const char* path : {"passes/postfx/froxel_light.comp", "passes/postfx/froxel_temporal.comp",
                           "passes/postfx/esm_downsample.comp"}) {
    const gl::Handle program = buildProgram({{ShaderStage::Compute, path, {}}});
    CHECK(resourceProperty(program.get(), GL_UNIFORM_BLOCK, "CrepFroxelBlock", GL_BUFFER_DATA_SIZE) ==
          static_cast<GLint>(sizeof(gpu::FroxelParams)));
    for (const Member& m : members) {
      const GLint offset =
          resourceProperty(program.get(), GL_UNIFORM, std::string("crep_froxel.") + m.name, GL_OFFSET);
      if (offset < 0) continue; // not active in this program
      CAPTURE(m.name);
      CHECK(static_cast<std::size_t>(offset) == m.offset);
      ++found;
    }
  }
  CHECK(found >= 20);
}

TEST_CASE("FroxelFog GL: ESM, lighting, accumulation, apply and temporal match the CPU references") {
  CREP_REQUIRE_GL();
  const Scene s;
  EsmOptions esmOptions;
  esmOptions.blurRadius = 2;
  // 1. ESM on a map whose size is not a multiple of the factor (edge blocks)
  Image map(100, 70, 1);
  for (int y = 0; y < 70; ++y)
    for (int x = 0; x < 100; ++x)
      map.at(x, y) = static_cast<float>(0.5 + 0.45 * std::sin(0.3 * x) * std::cos(0.2 * y));
  const Image esmCpu = buildEsm(map, s.lightClipFromWorld, esmOptions);
  EsmPass esmPass({esmOptions});
  const gl::Handle mapTexture = uploadR32F(map);
  esmPass.run({mapTexture.get(), s.lightClipFromWorld});
  REQUIRE(esmPass.width() == esmCpu.width());
  REQUIRE(esmPass.height() == esmCpu.height());
  const Image esmGpu = gl::readTexture(esmPass.esm(), esmPass.width(), esmPass.height(), gl::TexelData::Red);
  double esmWorst = 0.0;
  for (int y = 0; y < esmCpu.height(); ++y)
    for (int x = 0; x < esmCpu.width(); ++x)
      esmWorst = std::max(esmWorst, double(std::abs(esmGpu.at(x, y) - esmCpu.at(x, y))));
  MESSAGE(std::string(std::string("ESM GPU vs CPU: max absolute (log-space depth) ") + fmt(esmWorst)));
  // float log-space means of depths in [0, 1]: rounding of the depths (6e-8) plus float exp / log of
  // arguments up to c (d - m) over c: 1e-5 of the depth range
  CHECK(esmWorst < 1e-5);

  // 2. lighting with the scene's barred ESM, height fog, noise, ambient and a jitter
  const Image sceneEsm = buildEsm(s.shadow, s.lightClipFromWorld, esmOptions);
  EsmPass sceneEsmPass({esmOptions});
  const gl::Handle shadowTexture = uploadR32F(s.shadow);
  sceneEsmPass.run({shadowTexture.get(), s.lightClipFromWorld});
  FroxelLightingInputs in;
  in.density.heightBase = 0.5;
  in.density.heightFalloff = 3.0;
  in.density.noiseAmplitude = 0.4;
  in.density.noiseFrequency = 0.3;
  in.ambient = glm::dvec3(0.2, 0.25, 0.3);
  in.jitter = glm::dvec3(0.3, -0.2, 0.1);
  in.noiseOffset = glm::dvec3(1.5, 0.0, -2.0);
  in.esm = &sceneEsm;
  in.lightClipFromWorld = s.lightClipFromWorld;
  in.esmOptions = esmOptions;
  const FroxelVolume litCpu = froxelLighting(kGrid, s.camera, s.light, s.medium, in);
  FroxelLightingPass lightPass({kGrid, in.density, in.ambient, esmOptions, GL_RGBA32F});
  const gl::Handle volume = createFroxelVolume(kGrid, GL_RGBA32F, "test");
  FroxelLightingPass::FrameAttribs la;
  la.camera = &s.camera;
  la.light = &s.light;
  la.medium = &s.medium;
  la.esm = sceneEsmPass.esm();
  la.lightClipFromWorld = s.lightClipFromWorld;
  la.jitter = in.jitter;
  la.noiseOffset = in.noiseOffset;
  la.output = volume.get();
  lightPass.run(la);
  const double lightError = volumeError(readVolume(volume.get(), kGrid), litCpu);
  MESSAGE(std::string(std::string("lighting GPU vs CPU: max error / channel max ") + fmt(lightError)));
  // float sample points (1e-7 relative) through the ESM test exp(c (z - d_r)) (x c), the float ESM (1e-5)
  // and the noise lattice evaluated in float: 1e-3 of the channel's maximum
  CHECK(lightError < 1e-3);

  // 3. accumulation of the CPU lighting volume
  const gl::Handle litTexture = uploadVolume(litCpu);
  FroxelAccumulatePass accPass({kGrid, GL_RGBA32F});
  accPass.run({&s.camera, &s.medium, in.jitter, litTexture.get()});
  const FroxelVolume accCpu = froxelAccumulate(litCpu, kGrid, s.camera, s.medium, in.jitter);
  const double accError = volumeError(readVolume(litTexture.get(), kGrid), accCpu);
  MESSAGE(std::string(std::string("accumulation GPU vs CPU: max error / channel max ") + fmt(accError)));
  // float sums over 2 x 16 pieces and float exp: 1e-5
  CHECK(accError < 1e-5);

  // 4. apply of the CPU integrated volume, with the jitter as the sample offset
  const Image depth = test::groundDepth(s.camera, kW, kH);
  const gl::Handle depthTexture = uploadR32F(depth);
  const gl::Handle accTexture = uploadVolume(accCpu);
  const gl::Handle output = gl::createTexture2D(GL_RGBA32F, kW, kH);
  FroxelApplyPass applyPass({kGrid});
  applyPass.run({&s.camera, depthTexture.get(), accTexture.get(), in.jitter, output.get()});
  const Image applyCpu = froxelApply(accCpu, kGrid, s.camera, depth, in.jitter);
  const Image applyGpu = gl::readTexture(output.get(), kW, kH, gl::TexelData::Rgba);
  const double applyError = imageError(applyGpu, applyCpu);
  MESSAGE(std::string(std::string("apply GPU vs CPU: max error / channel max ") + fmt(applyError) +
                      ", relative RMSE " + fmt(relativeRmse(applyGpu, applyCpu))));
  // the texture unit's trilinear weights (8 fractional bits on many GPUs and llvmpipe: a weight error of
  // 2^-9 times a neighbour difference, at most the channel's range) dominate: 3e-3 of the channel max
  CHECK(applyError < 3e-3);
  CHECK(relativeRmse(applyGpu, applyCpu) < 1e-3);

  // 5. temporal: current = this frame's integrated volume, history = another jitter's, the camera panned
  // by 1 degree since
  const Camera previous = panned(-1.0);
  FroxelLightingInputs in2 = in;
  in2.jitter = glm::dvec3(-0.25, 0.35, -0.4);
  const FroxelVolume histCpu = froxelAccumulate(froxelLighting(kGrid, previous, s.light, s.medium, in2),
                                                kGrid, previous, s.medium, in2.jitter);
  const gl::Handle histTexture = uploadVolume(histCpu);
  const gl::Handle blended = createFroxelVolume(kGrid, GL_RGBA32F, "test");
  FroxelTemporalPass temporalPass({kGrid, GL_RGBA32F});
  FroxelTemporalPass::FrameAttribs ta;
  ta.camera = &s.camera;
  ta.previousCamera = &previous;
  ta.historyWeight = 0.9;
  ta.current = accTexture.get();
  ta.history = histTexture.get();
  ta.output = blended.get();
  temporalPass.run(ta);
  const FroxelVolume temporalCpu = froxelTemporal(accCpu, &histCpu, kGrid, s.camera, previous, 0.9);
  const double temporalError = volumeError(readVolume(blended.get(), kGrid), temporalCpu);
  MESSAGE(std::string(std::string("temporal GPU vs CPU: max error / channel max ") + fmt(temporalError)));
  // the history's trilinear fetch (as the apply: 3e-3) times the weight 0.9, and cells whose reprojected
  // point lies within float rounding of the volume's border may be kept on one side and rejected on the other
  CHECK(temporalError < 3e-3);
}

TEST_CASE("FroxelFog GL: homogeneous unshadowed medium vs the closed form (RGBA16F)") {
  CREP_REQUIRE_GL();
  const Camera cam = test::groundCamera(kW, kH);
  const Medium medium(
      {.mieScattering = glm::dvec3(0.02, 0.025, 0.03), .hgG = 0.0, .absorption = glm::dvec3(0.01)});
  const DirectionalLight light(glm::dvec3(0.3, -0.6, -0.5), glm::dvec3(1.0, 0.9, 0.8));
  // surfaces between view depths 1 and 40 (inside the volume's samples: the ramp of FroxelFogTest)
  Image depth(kW, kH, 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      depth.at(x, y) =
          static_cast<float>(cam.depthBufferValue(1.0 + 39.0 * (x + 0.37 * y) / (kW + 0.37 * kH)));
  const gl::Handle depthTexture = uploadR32F(depth);
  const gl::Handle output = gl::createTexture2D(GL_RGBA32F, kW, kH);
  FroxelFog::CreateInfo info;
  info.grid = {32, 18, 32, 0.5, 60.0};
  info.temporal.historyWeight = 0.0;
  FroxelFog fog(info);
  FroxelFog::FrameAttribs f;
  f.camera = &cam;
  f.light = &light;
  f.medium = &medium;
  f.cameraDepth = depthTexture.get();
  f.output = output.get();
  fog.run(f);
  const Image gpu = gl::readTexture(output.get(), kW, kH, gl::TexelData::Rgba);
  const Image closed = unshadowedScattering(depth, cam, light, medium);
  const double worst = maxRelative(gpu, closed);
  MESSAGE(std::string(std::string("FroxelFog (32 slices, RGBA16F) vs closed form: max relative ") +
                      fmt(worst) + "; memory " + std::to_string(fog.memoryBytes()) + " bytes"));
  // the CPU reference's interpolation error at 32 slices (0.43%, FroxelFogTest) + RGBA16F storage (2^-11 =
  // 4.9e-4) + the trilinear weights (3e-3 of the range): 1%
  CHECK(worst < 0.01);
  CHECK(fog.memoryBytes() == std::size_t(32 * 18 * 32 * 8));
}

TEST_CASE("FroxelFog GL: static camera, the temporally accumulated jittered result converges") {
  CREP_REQUIRE_GL();
  const Scene s;
  const Image depth = test::groundDepth(s.camera, kW, kH);
  const gl::Handle depthTexture = uploadR32F(depth);
  const gl::Handle shadowTexture = uploadR32F(s.shadow);
  const gl::Handle output = gl::createTexture2D(GL_RGBA32F, kW, kH);
  FroxelFog::CreateInfo info;
  info.grid = kGrid;
  info.format = GL_RGBA32F;
  const auto frame = [&](FroxelFog& fog, int i, const Camera* previous) {
    FroxelFog::FrameAttribs f;
    f.camera = &s.camera;
    f.light = &s.light;
    f.medium = &s.medium;
    f.cameraDepth = depthTexture.get();
    f.shadowMap = shadowTexture.get();
    f.lightClipFromWorld = s.lightClipFromWorld;
    f.output = output.get();
    f.frameIndex = i;
    f.previousCamera = previous;
    fog.run(f);
    return gl::readTexture(output.get(), kW, kH, gl::TexelData::Rgba);
  };
  info.temporal.historyWeight = 0.0;
  FroxelFog still(info);
  const Image unjittered = frame(still, 0, nullptr);
  info.temporal.historyWeight = 0.9;
  FroxelFog fog(info);
  double firstError = 0.0, lastError = 0.0;
  const int frames = 40;
  for (int i = 0; i < frames; ++i) {
    const Image img = frame(fog, i, i == 0 ? nullptr : &s.camera);
    const double e = relativeRmse(img, unjittered);
    if (i == 0) firstError = e;
    lastError = e;
  }
  MESSAGE(std::string(std::string("static camera: relative RMSE vs the unjittered volume, frame 1 ") +
                      fmt(firstError) + ", frame " + std::to_string(frames) + " " + fmt(lastError)));
  // A jittered frame samples the shafts half a cell off; the blend averages the jitter positions (an
  // exponential average with 1 - 0.9 per frame, about 10 frames of Halton samples), which converges to the
  // cell-averaged fog: within 3% of the unjittered point samples, and at most half the single frame's error.
  CHECK(lastError < 0.03);
  CHECK(lastError < 0.5 * firstError);
}

TEST_CASE(
    "FroxelFog GL: slow camera pan, the frame-to-frame change of the error stays within the reference's") {
  CREP_REQUIRE_GL();
  const int frames = 16;
  const double step = 0.3; // degrees per frame
  const Scene base;
  const gl::Handle shadowTexture = uploadR32F(base.shadow);
  const gl::Handle output = gl::createTexture2D(GL_RGBA32F, kW, kH);
  FroxelFog::CreateInfo info;
  info.grid = kGrid;
  FroxelFog temporal(info);
  info.temporal.jitter = false; // reprojection and blend alone: separates the jitter's residual noise
  FroxelFog still(info);
  info.temporal.historyWeight = 0.0;
  FroxelFog plain(info);
  WorldMarchOptions march;
  march.steps = 128;
  std::vector<Image> ref, on, off, nojit;
  // 16 static frames first (the temporal history's warm-up, not measured), then the pan
  const int warmUp = 16;
  for (int j = 0; j < warmUp + frames; ++j) {
    const int i = std::max(0, j - warmUp);
    const Camera cam = panned(step * i);
    const Camera prev = panned(step * std::max(0, i - 1));
    const Image depth = test::groundDepth(cam, kW, kH);
    const gl::Handle depthTexture = uploadR32F(depth);
    if (j >= warmUp)
      ref.push_back(
          worldSpaceMarch(base.shadow, base.lightClipFromWorld, depth, cam, base.light, base.medium, march)
              .scattering);
    for (FroxelFog* fog : {&temporal, &plain, &still}) {
      FroxelFog::FrameAttribs f;
      f.camera = &cam;
      f.light = &base.light;
      f.medium = &base.medium;
      f.cameraDepth = depthTexture.get();
      f.shadowMap = shadowTexture.get();
      f.lightClipFromWorld = base.lightClipFromWorld;
      f.output = output.get();
      f.frameIndex = j;
      f.previousCamera = j == 0 ? nullptr : &prev;
      fog->run(f);
      if (j >= warmUp)
        (fog == &temporal ? on
         : fog == &plain  ? off
                          : nojit)
            .push_back(gl::readTexture(output.get(), kW, kH, gl::TexelData::Rgba));
    }
  }
  // flicker = mean |X_k - X_{k-1}|; error change = mean |(X_k - R_k) - (X_{k-1} - R_{k-1})|
  const PanFigures pOn = panFigures(ref, on), pOff = panFigures(ref, off), pNoJit = panFigures(ref, nojit);
  const double flickerRef = pOn.reference, flickerOn = pOn.method, flickerOff = pOff.method,
               changeOn = pOn.errorChange, changeOff = pOff.errorChange, flickerNoJit = pNoJit.method,
               changeNoJit = pNoJit.errorChange;
  double meanRef = 0.0;
  for (const Image& r : ref)
    meanRef += meanAbsDiff(r, Image(r.width(), r.height(), 4));
  MESSAGE(std::string(std::string("pan ") + fmt(step) + " deg/frame over " + std::to_string(frames) +
                      " frames, mean |frame-to-frame change| (mean radiance " + fmt(meanRef / frames) +
                      "): reference " + fmt(flickerRef) + ", temporal on " + fmt(flickerOn) + ", off " +
                      fmt(flickerOff) + "; change of the error vs the reference: on " + fmt(changeOn) +
                      ", off " + fmt(changeOff) + "; relative RMSE last frame: on " +
                      fmt(relativeRmse(on.back(), ref.back())) + ", off " +
                      fmt(relativeRmse(off.back(), ref.back())) + "; reprojection without jitter: change " +
                      fmt(flickerNoJit) + ", error change " + fmt(changeNoJit)));
  // The error's own change stays within the reference's change (the scene moving across the screen) plus a
  // margin of half of it: the temporal fog adds no flicker of its own beyond that.
  CHECK(changeOn <= 1.5 * flickerRef);
  CHECK(relativeRmse(on.back(), ref.back()) < 0.25);
}

TEST_CASE("FroxelFog GL: a NaN froxel in the current or history volume does not spread") {
  CREP_REQUIRE_GL();
  const Scene s;
  FroxelVolume cur =
      froxelAccumulate(froxelLighting(kGrid, s.camera, s.light, s.medium, FroxelLightingInputs{}), kGrid,
                       s.camera, s.medium, glm::dvec3(0.0));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  cur.at(10, 9, 8) = glm::dvec4(nan, 1.0, nan, 0.5);
  FroxelVolume hist = cur;
  hist.at(10, 9, 8) = cur.at(11, 9, 8);
  hist.at(20, 5, 4) = glm::dvec4(std::numeric_limits<double>::infinity(), nan, 0.0, 1.0);
  const gl::Handle current = uploadVolume(cur);
  std::vector<gl::Handle> ping;
  ping.push_back(uploadVolume(hist));
  ping.push_back(createFroxelVolume(kGrid, GL_RGBA32F, "test"));
  FroxelTemporalPass pass({kGrid, GL_RGBA32F});
  for (int i = 0; i < 6; ++i) {
    FroxelTemporalPass::FrameAttribs a;
    a.camera = &s.camera;
    a.previousCamera = &s.camera;
    a.historyWeight = 0.9;
    a.current = current.get();
    a.history = ping[static_cast<std::size_t>(i % 2)].get();
    a.output = ping[static_cast<std::size_t>(1 - i % 2)].get();
    pass.run(a);
  }
  const FroxelVolume out = readVolume(ping[0].get(), kGrid);
  int nonFinite = 0;
  for (const glm::dvec4& c : out.cells)
    for (int k = 0; k < 4; ++k)
      nonFinite += std::isfinite(c[k]) ? 0 : 1;
  MESSAGE(std::string(std::string("non-finite texels after 6 frames: ") + std::to_string(nonFinite)));
  CHECK(nonFinite == 0);
  // the NaN cell and its neighbours hold values of the current frame's neighbourhood range
  for (int dx = -1; dx <= 1; ++dx) {
    const glm::dvec4 v = out.at(10 + dx, 9, 8);
    CHECK(v.y > 0.0);
    CHECK(v.w > 0.0);
    CHECK(v.w <= 1.0);
  }
  // end to end: NaN camera depth and shadow-map texels give a finite image
  Image depth = test::groundDepth(s.camera, kW, kH);
  depth.at(5, 5) = std::nanf("");
  Image shadow = s.shadow;
  shadow.at(64, 64) = std::nanf("");
  const gl::Handle depthTexture = uploadR32F(depth), shadowTexture = uploadR32F(shadow);
  const gl::Handle output = gl::createTexture2D(GL_RGBA32F, kW, kH);
  FroxelFog::CreateInfo info;
  info.grid = kGrid;
  FroxelFog fog(info);
  FroxelFog::FrameAttribs f;
  f.camera = &s.camera;
  f.light = &s.light;
  f.medium = &s.medium;
  f.cameraDepth = depthTexture.get();
  f.shadowMap = shadowTexture.get();
  f.lightClipFromWorld = s.lightClipFromWorld;
  f.output = output.get();
  fog.run(f);
  const Image img = gl::readTexture(output.get(), kW, kH, gl::TexelData::Rgba);
  int bad = 0;
  for (float v : img.data())
    bad += std::isfinite(v) ? 0 : 1;
  CHECK(bad == 0);
}

TEST_CASE("FroxelFog GL: bad options and inputs name the field") {
  CREP_REQUIRE_GL();
  const auto create = [](const auto& change) {
    FroxelFog::CreateInfo info;
    info.grid = kGrid;
    change(info);
    FroxelFog fog(info);
  };
  using CI = FroxelFog::CreateInfo;
  requireNamed([&] { create([](CI& i) { i.grid.width = 0; }); }, "FroxelFog::CreateInfo.grid.width");
  GLint max3d = 0;
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3d);
  requireNamed([&] { create([&](CI& i) { i.grid.depth = max3d + 1; }); }, "FroxelFog::CreateInfo.grid.depth");
  requireNamed([&] { create([](CI& i) { i.grid.farDepth = std::nan(""); }); },
               "FroxelFog::CreateInfo.grid.farDepth");
  requireNamed([&] { create([](CI& i) { i.format = GL_RGBA8; }); }, "FroxelFog::CreateInfo.format");
  requireNamed([&] { create([](CI& i) { i.temporal.historyWeight = 1.0; }); },
               "FroxelFog::CreateInfo.temporal.historyWeight");
  requireNamed([&] { create([](CI& i) { i.esm.exponent = 0.0; }); }, "FroxelFog::CreateInfo.esm.exponent");
  requireNamed([&] { create([](CI& i) { i.esm.downsample = 0; }); }, "FroxelFog::CreateInfo.esm.downsample");
  requireNamed([&] { create([](CI& i) { i.density.noiseAmplitude = -1.0; }); },
               "FroxelFog::CreateInfo.density.noiseAmplitude");
  requireNamed([&] { create([](CI& i) { i.ambient.y = std::nan(""); }); }, "FroxelFog::CreateInfo.ambient");

  const Scene s;
  FroxelFog::CreateInfo info;
  info.grid = kGrid;
  FroxelFog fog(info);
  const gl::Handle depth = uploadR32F(test::groundDepth(s.camera, kW, kH));
  const gl::Handle wrongFormat = gl::createTexture2D(GL_RGBA16F, kW, kH);
  const gl::Handle wrongSize = gl::createTexture2D(GL_RGBA32F, kW + 1, kH);
  const auto run = [&](const auto& change) {
    FroxelFog::FrameAttribs f;
    f.camera = &s.camera;
    f.light = &s.light;
    f.medium = &s.medium;
    f.cameraDepth = depth.get();
    change(f);
    fog.run(f);
  };
  using FA = FroxelFog::FrameAttribs;
  requireNamed([&] { run([](FA& f) { f.camera = nullptr; }); }, "FroxelFog::FrameAttribs.camera");
  requireNamed([&] { run([](FA& f) { f.light = nullptr; }); }, "FroxelFog::FrameAttribs.light/medium");
  requireNamed([&] { run([&](FA& f) { f.output = wrongFormat.get(); }); }, "FroxelFog::FrameAttribs.output");
  requireNamed([&] { run([&](FA& f) { f.output = wrongSize.get(); }); }, "FroxelFog::FrameAttribs.output");
  requireNamed([&] { run([&](FA& f) { f.shadowMap = 987654; }); }, "FroxelFog::FrameAttribs.shadowMap");
  requireNamed(
      [&] {
        run([&](FA& f) {
          f.shadowMap = depth.get();
          f.lightClipFromWorld[1][2] = std::nan("");
        });
      },
      "FroxelFog::FrameAttribs.lightClipFromWorld");
  requireNamed([&] { run([&](FA& f) { f.noiseOffset.x = INFINITY; }); },
               "FroxelFog::FrameAttribs.noiseOffset");
}

TEST_CASE("FroxelFog GL: Mode::Prefiltered applies crep::Scattering's fill (empty map vs the closed form)") {
  CREP_REQUIRE_GL();
  const Camera cam = test::groundCamera(kW, kH);
  const Medium medium(
      {.mieScattering = glm::dvec3(0.02, 0.025, 0.03), .hgG = 0.0, .absorption = glm::dvec3(0.01)});
  const DirectionalLight light = test::sideLight();
  Image depth(kW, kH, 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      depth.at(x, y) =
          static_cast<float>(cam.depthBufferValue(1.0 + 39.0 * (x + 0.37 * y) / (kW + 0.37 * kH)));
  const gl::Handle depthTexture = uploadR32F(depth);
  const gl::Handle empty = uploadR32F(Image(64, 64, 1, 1.0f)); // nothing casts: every point lit
  const Scattering::ShadowMap shadow{empty.get(), orthographicLightClipFromWorld(light, cam.frustumCorners()),
                                     0.0};
  FroxelFog::CreateInfo info;
  info.grid = {32, 18, 32, 0.5, 60.0};
  info.temporal.historyWeight = 0.0;
  FroxelFog fog(info);
  Scattering::CreateInfo si;
  si.width = kW;
  si.height = kH;
  si.mapSize = 256;
  Scattering scattering(si);
  const Scattering::FroxelTarget target{fog.currentVolume(), info.grid, fog.jitter(0)};
  Scattering::FrameAttribs a;
  a.camera = &cam;
  a.light = &light;
  a.medium = &medium;
  a.cameraDepth = depthTexture.get();
  a.shadowMap = &shadow;
  a.froxels = &target;
  scattering.run(a);
  const gl::Handle output = gl::createTexture2D(GL_RGBA32F, kW, kH);
  FroxelFog::FrameAttribs f;
  f.mode = FroxelFog::Mode::Prefiltered;
  f.camera = &cam;
  f.cameraDepth = depthTexture.get();
  f.output = output.get();
  fog.run(f);
  const Image gpu = gl::readTexture(output.get(), kW, kH, gl::TexelData::Rgba);
  const Image closed = unshadowedScattering(depth, cam, light, medium);
  const double worst = maxRelative(gpu, closed);
  double peak = 0.0, maxAbs = 0.0, alpha = 0.0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      for (int c = 0; c < 3; ++c) {
        peak = std::max(peak, double(closed.at(x, y, c)));
        maxAbs = std::max(maxAbs, double(std::abs(gpu.at(x, y, c) - closed.at(x, y, c))));
      }
      alpha = std::max(alpha, double(std::abs(gpu.at(x, y, 3) - closed.at(x, y, 3))));
    }
  const double rmse = relativeRmse(gpu, closed);
  MESSAGE(
      std::string(std::string("FroxelFog Mode::Prefiltered (32 slices, RGBA16F, empty map) vs closed form: "
                              "max relative ") +
                  fmt(worst) + ", max |d| / peak " + fmt(maxAbs / peak) + ", relative RMSE " + fmt(rmse) +
                  ", transmittance max |d| " + fmt(alpha)));
  // The prefiltered fill's own error on an empty map (the truncated Fourier series' ringing near the map's
  // far end; PrefilterFroxelGLTest: max |d| <= 5% of the peak, relative RMSE <= 1.5e-2) plus the froxel
  // interpolation at 32 slices (0.43%, FroxelFogTest) and RGBA16F (4.9e-4): max |d| <= 5.5% of the peak,
  // relative RMSE <= 2e-2; the transmittance has no prefilter error: interpolation and RGBA16F, 1%.
  CHECK(maxAbs <= 0.055 * peak);
  CHECK(rmse <= 2e-2);
  CHECK(alpha <= 1e-2);
}

TEST_CASE("FroxelFog GL: the default grid's memory and per-stage GPU timings") {
  CREP_REQUIRE_GL();
  const Scene s;
  const Image depth = test::groundDepth(s.camera, kW, kH);
  const gl::Handle depthTexture = uploadR32F(depth), shadowTexture = uploadR32F(s.shadow);
  const gl::Handle output = gl::createTexture2D(GL_RGBA32F, kW, kH);
  FroxelFog::CreateInfo info; // 160 x 90 x 64, RGBA16F, temporal on
  info.timings = true;
  info.blockingTimings = true; // the last run's times, waited for
  FroxelFog fog(info);
  CHECK_FALSE(fog.timings().has_value());
  for (int i = 0; i < 2; ++i) {
    fog.run(sceneFrame(s, depthTexture.get(), shadowTexture.get(), output.get(), i));
  }
  REQUIRE(fog.timings().has_value());
  const FroxelFog::Timings t = *fog.timings();
  CHECK(t.run == 1);
  CHECK(fog.runCount() == 2);
  // three 160 x 90 x 64 RGBA16F volumes (current + two history) and two R32F ESM textures of (128 / 4)^2
  const std::size_t volume = std::size_t(160) * 90 * 64 * 8;
  MESSAGE(std::string(std::string("default grid: ") + std::to_string(fog.memoryBytes()) +
                      " bytes (one volume " + std::to_string(volume) + "); GPU ms: ESM " + fmt(t.esm) +
                      ", lighting " + fmt(t.lighting) + ", accumulation " + fmt(t.accumulate) +
                      ", temporal " + fmt(t.temporal) + ", apply " + fmt(t.apply) +
                      " (llvmpipe reports about 1e-6 ms for every GL_TIME_ELAPSED query)"));
  CHECK(fog.memoryBytes() == 3 * volume + 2 * 32 * 32 * 4);
  CHECK(t.esm > 0.0);
  CHECK(t.lighting > 0.0);
  CHECK(t.accumulate > 0.0);
  CHECK(t.temporal > 0.0);
  CHECK(t.apply > 0.0);
  const Image img = gl::readTexture(output.get(), kW, kH, gl::TexelData::Rgba);
  int bad = 0;
  for (float v : img.data())
    bad += std::isfinite(v) ? 0 : 1;
  CHECK(bad == 0);
}

TEST_CASE("FroxelFog GL: timings without blockingTimings never wait and arrive with a later run") {
  CREP_REQUIRE_GL();
  const Scene s;
  const Image depth = test::groundDepth(s.camera, kW, kH);
  const gl::Handle depthTexture = uploadR32F(depth), shadowTexture = uploadR32F(s.shadow);
  const gl::Handle output = gl::createTexture2D(GL_RGBA32F, kW, kH);
  gpu::GlBackend backend;
  FroxelFog::CreateInfo info;
  info.grid.depth = 32;
  info.timings = true; // blockingTimings false: the default
  info.backend = &backend;
  FroxelFog fog(info);
  const auto run = [&](int i) {
    fog.run(sceneFrame(s, depthTexture.get(), shadowTexture.get(), output.get(), i));
  };
  run(0);
  // Nothing read in the run: its five spans (ESM, lighting, accumulation, temporal, apply) wait.
  CHECK_FALSE(fog.timings().has_value());
  CHECK(backend.pendingTimers() == 5);
  GLint active = -1;
  glGetQueryiv(GL_TIME_ELAPSED, GL_CURRENT_QUERY, &active);
  CHECK(active == 0);
  glFinish(); // the test waits, so that run 0's times are there for run 1
  run(1);
  REQUIRE(fog.timings().has_value());
  const FroxelFog::Timings t = *fog.timings();
  CHECK(t.run == 0);
  CHECK(fog.runCount() == 2);
  for (const double ms : {t.esm, t.lighting, t.accumulate, t.temporal, t.apply}) {
    CHECK(std::isfinite(ms));
    CHECK(ms >= 0.0);
  }
  CHECK(backend.pendingTimers() == 5); // run 1's
  glFinish();
  run(2);
  REQUIRE(fog.timings().has_value());
  CHECK(fog.timings()->run == 1);
}

TEST_CASE("FroxelFog GL: Mode::Prefiltered with temporal reprojection converges and does not flicker") {
  // The prefiltered path's temporal pass (the fill by crep::Scattering at jitter(i), then FroxelFog's
  // reprojection and blend) on the barred scene: with a static camera the blended result converges to the
  // unjittered fill's; under the slow pan of the ESM test the frame-to-frame change of its error against the
  // world-space reference stays within the reference's own change plus half of it.
  CREP_REQUIRE_GL();
  const Scene base;
  const gl::Handle shadowTexture = uploadR32F(base.shadow);
  const Scattering::ShadowMap shadow{shadowTexture.get(), base.lightClipFromWorld, 0.0};
  const gl::Handle output = gl::createTexture2D(GL_RGBA32F, kW, kH);
  Scattering::CreateInfo si;
  si.width = kW;
  si.height = kH;
  si.mapSize = 256;
  Scattering scattering(si);
  FroxelFog::CreateInfo info;
  info.grid = kGrid;
  info.format = GL_RGBA32F;
  FroxelFog temporal(info);
  info.temporal.historyWeight = 0.0;
  FroxelFog plain(info);
  const auto frame = [&](FroxelFog& fog, const Camera& cam, const Camera* previous, int i,
                         std::uint32_t depthTexture) {
    const Scattering::FroxelTarget target{fog.currentVolume(), info.grid, fog.jitter(i)};
    Scattering::FrameAttribs a;
    a.camera = &cam;
    a.light = &base.light;
    a.medium = &base.medium;
    a.shadowMap = &shadow;
    a.froxels = &target; // output = 0: the volume only
    scattering.run(a);
    FroxelFog::FrameAttribs f;
    f.mode = FroxelFog::Mode::Prefiltered;
    f.camera = &cam;
    f.cameraDepth = depthTexture;
    f.output = output.get();
    f.frameIndex = i;
    f.previousCamera = previous;
    fog.run(f);
    return gl::readTexture(output.get(), kW, kH, gl::TexelData::Rgba);
  };
  // Static camera.
  {
    const Image depth = test::groundDepth(base.camera, kW, kH);
    const gl::Handle depthTexture = uploadR32F(depth);
    const Image unjittered = frame(plain, base.camera, nullptr, 0, depthTexture.get());
    double firstError = 0.0, lastError = 0.0;
    const int frames = 30;
    for (int i = 0; i < frames; ++i) {
      const Image img = frame(temporal, base.camera, i == 0 ? nullptr : &base.camera, i, depthTexture.get());
      const double e = relativeRmse(img, unjittered);
      if (i == 0) firstError = e;
      lastError = e;
    }
    MESSAGE(std::string(std::string("prefiltered fill, static camera: relative RMSE vs the unjittered fill, "
                                    "frame 1 ") +
                        fmt(firstError) + ", frame " + std::to_string(frames) + " " + fmt(lastError)));
    // The blend averages the jitter positions across the cells (x, y only here: the fill's integrals end on
    // the slice centres), which converges to the cell-averaged fog rather than the centre rays' (measured:
    // 0.87% after one frame, 0.63% after 30: what remains is mostly that average, the bars being a few
    // cells wide); stated bound 1%, and below the single frame's error.
    CHECK(lastError < 0.01);
    CHECK(lastError < firstError);
  }
  // Slow pan, after a warm-up of static frames (not measured).
  const int frames = 16, warmUp = 16;
  const double step = 0.3;
  WorldMarchOptions march;
  march.steps = 128;
  std::vector<Image> ref, on, off;
  for (int j = 0; j < warmUp + frames; ++j) {
    const int i = std::max(0, j - warmUp);
    const Camera cam = panned(step * i);
    const Camera prev = panned(step * std::max(0, i - 1));
    const Image depth = test::groundDepth(cam, kW, kH);
    const gl::Handle depthTexture = uploadR32F(depth);
    const Image t = frame(temporal, cam, &prev, 100 + j, depthTexture.get());
    const Image p = frame(plain, cam, &prev, 100 + j, depthTexture.get());
    if (j < warmUp) continue;
    on.push_back(t);
    off.push_back(p);
    ref.push_back(
        worldSpaceMarch(base.shadow, base.lightClipFromWorld, depth, cam, base.light, base.medium, march)
            .scattering);
  }
  const PanFigures pOn = panFigures(ref, on), pOff = panFigures(ref, off);
  const double flickerRef = pOn.reference, flickerOn = pOn.method, flickerOff = pOff.method,
               changeOn = pOn.errorChange, changeOff = pOff.errorChange;
  MESSAGE(std::string(
      std::string("prefiltered fill, pan ") + fmt(step) +
      " deg/frame, mean |frame-to-frame change|: reference " + fmt(flickerRef) + ", temporal on " +
      fmt(flickerOn) + ", off " + fmt(flickerOff) + "; change of the error vs the reference: on " +
      fmt(changeOn) + ", off " + fmt(changeOff) + "; relative RMSE last frame: on " +
      fmt(relativeRmse(on.back(), ref.back())) + ", off " + fmt(relativeRmse(off.back(), ref.back()))));
  CHECK(changeOn <= 1.5 * flickerRef);
  // Measured 4.9% with temporal (the history lags the pan by the blend's ~10 frames and averages the cells),
  // 3.4% without (the 16 slices' interpolation): bound 8% with temporal, 5% without. The ESM path is at 24%
  // on the same frames (its filtered shadow map leaks through the bars).
  CHECK(relativeRmse(on.back(), ref.back()) < 0.08);
  CHECK(relativeRmse(off.back(), ref.back()) < 0.05);
}
