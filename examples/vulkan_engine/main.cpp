// crep-vulkan-engine: a Vulkan engine with crepuscular recorded into its frames. Each frame the engine
// (engine.h) records its depth pre-pass and its shadow maps with its own graphics pipeline, crepuscular
// (volumetrics.h) records its compute passes into the same command buffer, and the engine submits it once;
// three frames in flight, a camera strafing sideways. The last frame's volumetrics (RGB in-scattering, A
// transmittance) go to an EXR and a PNG.
//
//   crep-vulkan-engine [--frames 10] [--width 640] [--height 360] [--out DIR] [--validation]
//                      [--scene NAME]  (a built-in scene of crep_scenes, in the source tree's build)
// Exit 0 on success; 1 on an error, a non-finite or out-of-range output, or (with --validation) any message
// of the validation layer with synchronization validation on.
#include "app.h"

#include <crep/core/image.h>
#include <crep/support/exr.h>
#include <crep/support/png.h>

#if CREP_VULKAN_ENGINE_SCENES
#include "scene_world.h"
#endif

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>

namespace {

using vkengine::World;

void addBox(vkengine::Mesh& m, glm::vec3 lo, glm::vec3 hi) {
  const auto base = static_cast<std::uint32_t>(m.positions.size());
  for (int k = 0; k < 8; ++k)
    m.positions.emplace_back(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
  const std::uint32_t faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                     {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (const auto& f : faces)
    for (const std::uint32_t k : {f[0], f[1], f[2], f[0], f[2], f[3]})
      m.indices.push_back(base + k);
}

/// The example's own hall: a ground, two rows of pillars under a slatted roof, the sun low from the side
/// shining between them (a projective frame).
World hall() {
  World w;
  addBox(w.mesh, {-30.0f, -1.0f, -40.0f}, {30.0f, 0.0f, 20.0f});
  for (int i = 0; i < 8; ++i)
    for (const float x : {-6.0f, 6.0f}) {
      const float z = 10.0f - 5.0f * static_cast<float>(i);
      addBox(w.mesh, {x - 0.6f, 0.0f, z - 0.6f}, {x + 0.6f, 9.0f, z + 0.6f});
    }
  for (int i = 0; i < 18; ++i) {
    const float z = 12.0f - 2.0f * static_cast<float>(i);
    addBox(w.mesh, {-7.0f, 9.0f, z - 0.5f}, {7.0f, 9.6f, z + 0.5f});
  }
  w.eye = {-1.0, 2.0, 16.0};
  w.target = {1.0, 4.0, -20.0};
  w.sun = crep::DirectionalLight(glm::dvec3(-0.75, -0.55, 0.3), glm::dvec3(5.0, 4.6, 4.0));
  return w;
}

} // namespace

int main(int argc, char** argv) {
  int frames = 10, width = 640, height = 360;
  std::filesystem::path out = ".";
  bool validation = false;
  std::string scene;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool hasValue = i + 1 < argc;
    if (a == "--frames" && hasValue)
      frames = std::atoi(argv[++i]);
    else if (a == "--width" && hasValue)
      width = std::atoi(argv[++i]);
    else if (a == "--height" && hasValue)
      height = std::atoi(argv[++i]);
    else if (a == "--out" && hasValue)
      out = argv[++i];
    else if (a == "--scene" && hasValue)
      scene = argv[++i];
    else if (a == "--validation")
      validation = true;
    else {
      std::fprintf(stderr, "crep-vulkan-engine: unknown argument %s (see the comment of main.cpp)\n",
                   a.c_str());
      return 1;
    }
  }
  try {
    if (frames < 1 || width < 1 || height < 1)
      throw std::invalid_argument("--frames, --width, --height must be >= 1");
    [[maybe_unused]] const double aspect = double(width) / height;
#if CREP_VULKAN_ENGINE_SCENES
    const World world = scene.empty() ? hall() : vkengine::worldOf(crep::scenes::makeScene(scene, aspect));
#else
    if (!scene.empty())
      throw std::invalid_argument("--scene needs the build of the source tree (crep_scenes)");
    const World world = hall();
#endif

    // The engine, crepuscular on its device, and the frames.
    vkengine::App app(world, {.width = static_cast<std::uint32_t>(width),
                              .height = static_cast<std::uint32_t>(height),
                              .engine = {.framesInFlight = 3, .validation = validation}});
    for (int i = 0; i < frames; ++i) {
      const crep::Scattering::FrameResult r = app.frame(i);
      std::printf("frame %d: %s", i + 1, world.hasSun ? crep::layoutToken(r.layout) : "no sun");
      if (r.gpuTimes)
        std::printf(", GPU %.2f ms (frame %llu's)", r.gpuTimes->totalMilliseconds(),
                    static_cast<unsigned long long>(r.gpuTimes->frame + 1));
      std::printf("\n");
    }
    app.finish();
    vkengine::Engine& engine = app.engine();

    const std::vector<float> rgba = engine.download(*app.images().output);
    crep::Image image(width, height, 4);
    std::copy(rgba.begin(), rgba.end(), image.data().begin());
    int bad = 0;
    for (std::size_t p = 0; p < rgba.size(); p += 4)
      bad += !(std::isfinite(rgba[p]) && rgba[p] >= 0.0f && rgba[p + 3] > 0.0f && rgba[p + 3] <= 1.0f);
    std::filesystem::create_directories(out);
    crep::writeExr(out / "vulkan-engine.exr", image);
    crep::writePng(out / "vulkan-engine.png", image);
    const std::vector<std::string> messages = engine.validationMessages();
    for (const std::string& m : messages)
      std::printf("validation: %s\n", m.c_str());
    std::printf(
        "crep-vulkan-engine on %s: %d frames of %dx%d, 3 in flight, 1 submission each; %d pixels out of "
        "range; %s; wrote %s\n",
        engine.deviceName().c_str(), frames, width, height, bad,
        validation ? (std::to_string(messages.size()) + " validation messages").c_str() : "validation off",
        (out / "vulkan-engine.exr").string().c_str());
    return bad == 0 && messages.empty() ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crep-vulkan-engine: %s\n", e.what());
    return 1;
  }
}
