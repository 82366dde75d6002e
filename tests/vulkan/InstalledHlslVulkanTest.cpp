// The HLSL the package installs, run (issue 44): each shipped HLSL file (share/crepuscular/shaders/hlsl/, the
// passes' defaults and the variants of glsl/portable_variants.txt), compiled by glslang's HLSL front end to
// SPIR-V at build time (hlsl_vulkan/: CrepPortableShaders.cmake, with the Vulkan attributes of
// CrepHlslForVulkan.cmake), runs whole crep::Scattering frames on gpu::VulkanBackend (lavapipe, validation
// on) through VulkanBackend::CreateInfo::shaderBinary, and the frames equal those the backend runs from the
// GLSL (shaderc) within a relative RMSE of 1e-5. Every program variant a frame runs must come from the HLSL:
// the GLSL run records each variant it compiles, and the HLSL run must have served each of them from a file.
// Engine inputs are made up on the CPU (no GL): the sun's map over the view, and the spot and point lights'
// maps. Frames: forest (sun projective: prefiltered with a froxel volume, then the min/max march), sunset
// (the sun in view: epipolar layout, prefiltered and min/max march), stained-glass (a light texture on the
// sun), colonnade-night (its three spots, one more in view on its epipolar layout, and a point light).
#include "common/frame_extras.h"
#include "common/image_check.h"
#include "common/shader_tools.h"
#include "common/synthetic_engine_maps.h"
#include "common/vulkan_fixture.h"

#include <crep/core/image.h>
#include <crep/pipeline/scattering.h>
#include <crep/scenes/engine_frame.h>
#include <crep/scenes/scene.h>
#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

using namespace crep;
using crep::test::relativeRmse;

namespace {

constexpr int kWidth = 160, kHeight = 90, kSunMap = 512, kLocalMap = 128;

std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string variantName(std::string_view program, std::span<const ShaderDefine> defines) {
  std::string name(program);
  for (const ShaderDefine& d : defines)
    name += " " + d.name + "=" + d.value;
  return name;
}

/// SPIR-V's SourceLanguage HLSL (the SPIR-V specification, 3.2 "Source Language"), which glslang's HLSL front
/// end writes in the module's OpSource.
constexpr std::uint32_t kSourceLanguageHlsl = 5;

/// The source language of a SPIR-V module's OpSource (opcode 3), ~0u without one.
std::uint32_t sourceLanguage(const std::vector<std::byte>& module) {
  std::vector<std::uint32_t> words(module.size() / 4);
  std::memcpy(words.data(), module.data(), words.size() * 4);
  for (std::size_t i = 5; i < words.size();) { // after the header's five words, one instruction at a time
    const std::uint32_t count = words[i] >> 16, opcode = words[i] & 0xffffu;
    if (opcode == 3 && count >= 2) return words[i + 1];
    if (count == 0) break;
    i += count;
  }
  return ~0u;
}

/// The program variants a backend asked its provider for. As `glsl`: returns nothing (the backend compiles
/// the GLSL) and records each. As `hlsl`: serves the SPIR-V the build compiled from the shipped HLSL file of
/// the variant (resources.json), and records a variant with no such file as a fallback to the GLSL.
struct Provider {
  enum class Source { Glsl, Hlsl };
  explicit Provider(Source s) : source(s) {}
  Source source;
  nlohmann::json resources = crep::test::portableShaderResources();
  std::set<std::string> asked, served, fellBack;
  /// Served modules whose HLSL for Vulkan is not the shipped HLSL plus the Vulkan attributes, or whose
  /// SPIR-V does not say it was compiled from HLSL.
  std::set<std::string> altered, notFromHlsl;

  gpu::VulkanBackend::ShaderBinaryProvider function() {
    return [this](std::string_view program, std::span<const ShaderDefine> defines) {
      const std::string name = variantName(program, defines);
      asked.insert(name);
      if (source == Source::Glsl) return std::vector<std::byte>{};
      const nlohmann::json* entry = crep::test::shippedVariant(resources, program, defines);
      if (entry == nullptr) {
        fellBack.insert(name);
        return std::vector<std::byte>{};
      }
      const std::string hlsl = entry->at("hlsl"); // hlsl/<module>/<file>.hlsl
      const std::filesystem::path dir = crep::test::portableShaderDir();
      std::filesystem::path run = dir / "hlsl_vulkan" / hlsl.substr(std::string_view("hlsl/").size());
      // The file glslang compiled is the installed one with only the Vulkan attributes added.
      const std::regex attributes(R"(\[\[(vk::push_constant|spv::format_[a-z0-9]+)\]\] )");
      if (std::regex_replace(readFile(run), attributes, "") != readFile(dir / hlsl)) altered.insert(name);
      run.replace_extension(".spv");
      const std::string bytes = readFile(run);
      if (bytes.empty()) {
        fellBack.insert(name + " (no " + run.string() + ")");
        return std::vector<std::byte>{};
      }
      std::vector<std::byte> out(bytes.size());
      std::memcpy(out.data(), bytes.data(), bytes.size());
      if (sourceLanguage(out) != kSourceLanguageHlsl) notFromHlsl.insert(name);
      served.insert(name);
      return out;
    };
  }
};

/// A made-up depth map of a local light's (spot, or a point light's cube face), `seed` varying it.
Image localMap(int seed) {
  Image m(kLocalMap, kLocalMap, 1);
  for (int j = 0; j < kLocalMap; ++j)
    for (int i = 0; i < kLocalMap; ++i) {
      const bool pillar = (i / 16 + j / 24 + seed) % 3 == 0;
      m.at(i, j) = static_cast<float>(0.97 + 0.02 * std::sin(0.2 * i + seed) * std::cos(0.15 * j) -
                                      (pillar ? 0.05 : 0.0));
    }
  return m;
}

struct Frame {
  const char* scene;
  Scattering::Method method;
  bool froxels;
  const char* what;
};

struct Output {
  std::vector<float> rgba, volume;
  Scattering::FrameResult result;
};

/// One frame of `frame` through crep::Scattering on `b`.
Output run(gpu::Backend& b, const scenes::Scene& scene, const scenes::EngineMaps& maps, const Frame& frame) {
  const scenes::EngineFrame engine(b, scene, maps);
  gpu::Texture output(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, kWidth, kHeight, 1, "output"});
  Scattering::CreateInfo info;
  info.width = kWidth;
  info.height = kHeight;
  info.mapSize = 256;
  info.method = frame.method;
  info.backend = &b;
  Scattering scattering(info);
  Scattering::FrameAttribs f = engine.attribs(output.id());
  const FroxelGrid grid{.width = 20, .height = 12, .depth = 16};
  crep::test::FroxelVolume volume;
  if (frame.froxels) {
    volume = crep::test::FroxelVolume(b, grid, gpu::Format::RGBA16F);
    f.froxels = &volume.target;
  }
  Output out;
  out.result = scattering.run(f);
  out.rgba = b.readTexture(output.id());
  if (frame.froxels) out.volume = b.readTexture(volume.texture.id());
  return out;
}

std::string joined(const std::set<std::string>& names) {
  std::string all;
  for (const std::string& n : names)
    all += "\n  " + n;
  return all;
}

} // namespace

TEST_CASE("Vulkan backend: crep::Scattering frames run from the installed HLSL (glslang) equal the GLSL's") {
  Provider glsl(Provider::Source::Glsl), hlsl(Provider::Source::Hlsl);
  gpu::VulkanBackend::CreateInfo glslInfo = crep::test::validatedVulkan(), hlslInfo = glslInfo;
  glslInfo.shaderBinary = glsl.function();
  hlslInfo.shaderBinary = hlsl.function();
  gpu::VulkanBackend fromGlsl(glslInfo), fromHlsl(hlslInfo);

  const Frame frames[] = {
      {"forest", Scattering::Method::Prefiltered, true, "sun projective, prefiltered, froxels"},
      {"forest", Scattering::Method::MinMaxMarch, false, "sun projective, min/max march"},
      {"sunset", Scattering::Method::Prefiltered, false, "sun in view (epipolar), prefiltered"},
      {"sunset", Scattering::Method::MinMaxMarch, false, "sun in view (epipolar), min/max march"},
      {"stained-glass", Scattering::Method::Prefiltered, false, "sun with a light texture"},
      {"colonnade-night", Scattering::Method::Prefiltered, false, "spot lights (one in view) and a point"},
  };
  for (const Frame& frame : frames) {
    const std::string label = std::string(frame.scene) + ", " + frame.what;
    CAPTURE(label);
    scenes::Scene scene = scenes::makeScene(frame.scene, static_cast<double>(kWidth) / kHeight);
    if (!scene.hasSun) {
      // A spot in view, 6 units ahead of the camera and 1 up, aimed down and forward (its epipolar layout,
      // Klehm et al. 2014, Sec. 4.1), and a point light behind the camera to the left.
      const Camera& c = scene.camera;
      scene.spotLights.push_back(crep::test::spotInView(c));
      scene.pointLights.push_back(crep::test::pointBehindLeft(c));
    }
    scenes::EngineMaps maps = crep::test::syntheticMaps(scene, kWidth, kHeight, kSunMap);
    for (std::size_t i = 0; i < scene.spotLights.size(); ++i)
      maps.spotMaps.push_back(localMap(static_cast<int>(i)));
    for (std::size_t i = 0; i < 6 * scene.pointLights.size(); ++i)
      maps.pointMaps.push_back(localMap(static_cast<int>(i) + 7));

    const Output a = run(fromHlsl, scene, maps, frame), b = run(fromGlsl, scene, maps, frame);
    long long nonFinite = 0;
    const double e = relativeRmse(a.rgba, b.rgba, nonFinite);
    int epipolarLights = 0;
    for (const Scattering::LightResult& l : a.result.localLights)
      epipolarLights += l.epipolar;
    MESSAGE(label << " (" << std::string(scene.hasSun ? layoutToken(a.result.layout) : "no sun") << ", "
                  << a.result.localLights.size() << " local lights, " << epipolarLights
                  << " on their epipolar layout): from the HLSL vs from the GLSL, relative RMSE " << e << ", "
                  << nonFinite << " non-finite");
    CHECK(nonFinite == 0);
    CHECK(e <= 1e-5);
    CHECK(a.result.stages.size() == b.result.stages.size());
    if (!scene.hasSun) CHECK(epipolarLights >= 1);
    if (std::string(frame.scene) == "sunset") CHECK(a.result.layout == b.result.layout);
    if (frame.froxels) {
      const double v = relativeRmse(a.volume, b.volume, nonFinite);
      MESSAGE(label << ": froxel volume (RGBA16F), from the HLSL vs from the GLSL, relative RMSE " << v);
      CHECK(nonFinite == 0);
      CHECK(v <= 1e-5);
    }
  }

  // Every program variant the frames ran came from the HLSL: the GLSL run compiled exactly those the HLSL run
  // served, none fell back (a variant not shipped names the line glsl/portable_variants.txt needs).
  MESSAGE(hlsl.served.size() << " program variants run from the installed HLSL, " << glsl.asked.size()
                             << " compiled from the GLSL");
  CHECK_MESSAGE(hlsl.fellBack.empty(), "run from the GLSL, not the HLSL:" << joined(hlsl.fellBack));
  CHECK_MESSAGE(hlsl.altered.empty(), "HLSL for Vulkan is not the installed HLSL:" << joined(hlsl.altered));
  CHECK_MESSAGE(hlsl.notFromHlsl.empty(), "SPIR-V without OpSource HLSL:" << joined(hlsl.notFromHlsl));
  CHECK(hlsl.served == glsl.asked);
  CHECK(hlsl.asked == glsl.asked);
  CHECK(hlsl.served.size() >= 20);
  crep::test::checkNoValidationMessages(fromHlsl);
  crep::test::checkNoValidationMessages(fromGlsl);
}
