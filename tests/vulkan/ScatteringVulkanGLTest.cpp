// The front door on both backends: crep::Scattering with CreateInfo::backend on gpu::VulkanBackend
// (lavapipe, validation on) and on gpu::GlBackend (llvmpipe), fed the same engine inputs: the camera depth
// and the shadow maps of a built-in scene, rendered once by GL and uploaded to each backend (a Vulkan
// engine renders its own). The frames of the port's goal: forest (projective) and sunset (the sun in view:
// epipolar layout and its tree-marched epipole block) at 320x180, colonnade-night (its local lights and a
// spot added in view, from their perspective maps, no sun), and stained-glass (a light texture on the sun);
// froxel volumes filled on the sunlit ones. Bar: relative RMSE <= 1e-4 between the backends' outputs.
#include "common/frame_extras.h"
#include "common/gl_fixture.h"
#include "common/image_check.h"
#include "common/vulkan_fixture.h"

#include <crep/core/error.h>
#include <crep/gpu/gl_backend.h>
#include <crep/pipeline/scattering.h>
#include <crep/scatter/gpu_light_texture.h>
#include <crep/scenes/engine_frame.h>
#include <crep/scenes/scene.h>
#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

using namespace crep;
using crep::test::relativeRmse;

namespace {

constexpr int kWidth = 320, kHeight = 180, kSunMap = 1024, kLocalMap = 512;

/// A built-in scene and its engine maps (rendered once by GL, uploaded to each backend).
struct EngineInputs {
  scenes::Scene scene;
  scenes::EngineMaps maps;
};

EngineInputs renderInputs(const std::string& name) {
  EngineInputs in{scenes::makeScene(name, static_cast<double>(kWidth) / kHeight), {}};
  if (name == "colonnade-night") {
    // And a spot in view, 6 units ahead of the camera and 1 up, aimed down and forward: its rectification
    // falls back to its epipolar layout (Klehm et al. 2014, Sec. 4.1) with a world-marched epipole block.
    in.scene.spotLights.push_back(crep::test::spotInView(in.scene.camera));
  }
  in.maps = scenes::renderEngineMaps(in.scene, kWidth, kHeight, kSunMap, kLocalMap);
  return in;
}

struct FrameOutput {
  std::vector<float> rgba, volume; ///< the output; the froxel volume (with a grid)
  Scattering::FrameResult result;
};

/// RGBA floats of a 3- or 4-channel image (alpha 1 when it has none).
/// One frame of `in` through crep::Scattering on `b` (the engine's maps given, no drawCasters).
FrameOutput frameOn(gpu::Backend& b, const EngineInputs& in, Scattering::CreateInfo info,
                    const FroxelGrid* grid = nullptr) {
  const scenes::Scene& s = in.scene;
  const scenes::EngineFrame engine(b, s, in.maps);
  gpu::Texture output(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, kWidth, kHeight, 1, "output"});
  info.width = kWidth;
  info.height = kHeight;
  info.backend = &b;
  Scattering scattering(info);
  Scattering::FrameAttribs f = engine.attribs(output.id());
  // A froxel volume filled from the same basis (the scene's light texture comes with the engine frame).
  crep::test::FroxelVolume volume;
  if (grid != nullptr) {
    volume = crep::test::FroxelVolume(b, *grid, gpu::Format::RGBA16F);
    f.froxels = &volume.target;
  }
  FrameOutput out;
  out.result = scattering.run(f);
  out.rgba = b.readTexture(output.id());
  if (grid != nullptr) out.volume = b.readTexture(volume.texture.id());
  return out;
}

} // namespace

TEST_CASE("Vulkan backend: crep::Scattering gives GL's frame on forest, sunset (sun in view) and "
          "colonnade-night (local lights)") {
  CREP_REQUIRE_GL();
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  gpu::GlBackend gl;
  FroxelGrid grid;
  grid.width = 40;
  grid.height = 24;
  grid.depth = 32;
  for (const std::string name : {"forest", "sunset", "colonnade-night", "stained-glass"}) {
    CAPTURE(name);
    const EngineInputs in = renderInputs(name);
    for (const Scattering::Method method :
         {Scattering::Method::Prefiltered, Scattering::Method::MinMaxMarch}) {
      if (method == Scattering::Method::MinMaxMarch && !in.scene.hasSun) continue; // a method of the sun
      Scattering::CreateInfo info;
      info.mapSize = 512;
      info.method = method;
      // Froxels with the sun's prefiltered basis (a stage of the front door's Prefiltered method).
      const FroxelGrid* volume =
          in.scene.hasSun && method == Scattering::Method::Prefiltered ? &grid : nullptr;
      const FrameOutput a = frameOn(vk, in, info, volume), b = frameOn(gl, in, info, volume);
      long long nonFinite = 0;
      const double e = relativeRmse(a.rgba, b.rgba, nonFinite);
      int epipolarLights = 0;
      for (const Scattering::LightResult& l : a.result.localLights)
        epipolarLights += l.epipolar;
      MESSAGE(name << std::string(method == Scattering::Method::MinMaxMarch ? " (min/max march)" : "") << ", "
                   << std::string(in.scene.hasSun ? layoutToken(a.result.layout) : "no sun") << ", "
                   << a.result.localLights.size() << " local lights (" << epipolarLights
                   << " on their epipolar layout), " << a.result.stages.size()
                   << " stages: Vulkan vs GL relative RMSE " << e << ", " << nonFinite << " non-finite");
      CHECK(nonFinite == 0);
      CHECK(e <= 1e-4);
      CHECK(a.result.stages.size() == b.result.stages.size());
      CHECK(a.result.layout == b.result.layout);
      if (name == "colonnade-night") CHECK(epipolarLights >= 1);
      if (volume != nullptr) {
        const double v = relativeRmse(a.volume, b.volume, nonFinite);
        MESSAGE(name << ": froxel volume (RGBA16F), Vulkan vs GL relative RMSE " << v << ", " << nonFinite
                     << " non-finite");
        CHECK(nonFinite == 0);
        CHECK(v <= 1e-4);
      }
    }
  }
  crep::test::checkNoValidationMessages(vk);
}

TEST_CASE("Vulkan backend: crep::Scattering at a reduced evaluation scale gives GL's frame") {
  CREP_REQUIRE_GL();
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  gpu::GlBackend gl;
  for (const std::string name : {"forest", "sunset"}) {
    const EngineInputs in = renderInputs(name);
    for (const double scale : {0.5, 0.25}) {
      CAPTURE(name);
      CAPTURE(scale);
      Scattering::CreateInfo info;
      info.mapSize = 512;
      info.evaluationScale = scale;
      info.blockingTimings = true; // the stages' GPU times in the frame
      const FrameOutput a = frameOn(vk, in, info), b = frameOn(gl, in, info);
      long long nonFinite = 0;
      const double e = relativeRmse(a.rgba, b.rgba, nonFinite);
      bool upsampled = false;
      double gpu = 0.0, wall = 0.0;
      for (const Scattering::Stage& st : a.result.stages) {
        upsampled = upsampled || st.name == "upsample";
        gpu += st.gpuMilliseconds;
        wall += st.wallMilliseconds;
        CHECK(st.gpuMilliseconds >= 0.0);
        CHECK(st.gpuMilliseconds <= st.wallMilliseconds + 0.5); // the GPU's span lies within the stage's
      }
      MESSAGE("stages on Vulkan: GPU (timestamps) " << gpu << " ms, wall clock " << wall << " ms");
      CHECK(gpu > 0.0); // lavapipe's compute queue has timestamps
      MESSAGE(name << ", evaluationScale " << scale << ", " << std::string(layoutToken(a.result.layout))
                   << ": Vulkan vs GL relative RMSE " << e << ", " << nonFinite << " non-finite");
      CHECK(upsampled);
      CHECK(nonFinite == 0);
      CHECK(e <= 1e-4);
      CHECK(a.result.stages.size() == b.result.stages.size());
    }
  }
  crep::test::checkNoValidationMessages(vk);
}

TEST_CASE("Vulkan backend: crep::Scattering with Yusov's epipolar sampling gives GL's frame") {
  CREP_REQUIRE_GL();
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  gpu::GlBackend gl;
  for (const std::string name : {"forest", "sunset"}) {
    const EngineInputs in = renderInputs(name);
    for (const Scattering::Method method : {Scattering::Method::MinMaxMarch, Scattering::Method::Prefiltered})
      for (const int downscale : {1, 2}) {
        CAPTURE(name);
        CAPTURE(downscale);
        Scattering::CreateInfo info;
        info.mapSize = 512;
        info.method = method;
        info.sampling = Scattering::Sampling::Epipolar;
        // 256 lines on the sunset's 512-row epipolar map: without the front door's line offset each line
        // would lie on a boundary between two rows, where float rounding picks either row (2.3e-4 to 7e-3
        // between the backends); with it, the lines are on the rows' centres.
        info.epipolarSampling.slices = 256;
        info.epipolarSampling.samples = 128;
        info.epipolarSampling.downscale = downscale;
        info.blockingTimings = true; // FrameResult::sampling's counts are read back in the frame
        const FrameOutput a = frameOn(vk, in, info), b = frameOn(gl, in, info);
        long long nonFinite = 0;
        const double e = relativeRmse(a.rgba, b.rgba, nonFinite);
        const Scattering::FrameResult::SamplingStatistics &sa = a.result.sampling, &sb = b.result.sampling;
        MESSAGE(name << (method == Scattering::Method::MinMaxMarch ? " (min/max march)" : " (prefiltered)")
                     << ", downscale " << downscale << ": Vulkan vs GL relative RMSE " << e << ", "
                     << nonFinite << " non-finite; samples marched " << sa.marchedSamples << " (GL "
                     << sb.marchedSamples << "), pixels corrected " << sa.correctedPixels << " (GL "
                     << sb.correctedPixels << "), full-resolution corrections " << sa.correctedFullPixels
                     << " (GL " << sb.correctedFullPixels << ")");
        CHECK(nonFinite == 0);
        CHECK(e <= 1e-4);
        CHECK(sa.validSamples == sb.validSamples);
        CHECK(sa.marchedSamples > 0);
        CHECK(a.result.stages.size() == b.result.stages.size());
      }
  }
  crep::test::checkNoValidationMessages(vk);
}
