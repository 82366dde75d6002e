// gpu::VulkanBackend on Mesa's lavapipe with the validation layer on: transfers round-trip exactly, the
// passes written once against gpu::Backend (MinMaxTreePass, ShadowResamplePass) agree with their CPU
// references as they do on GL, bad input is named (the backend's, CreateInfo::shaderBinary's and
// EvaluatePass's), and the validation layer reports nothing.
#include "common/map_agreement.h"
#include "common/vulkan_fixture.h"

#include <crep/core/error.h>
#include <crep/core/image.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/epipolar/resample.h>
#include <crep/gpu/backend.h>
#include <crep/pipeline/scattering.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/rectify/rectify.h>
#include <crep/scenes/scene.h>
#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

using namespace crep;
using crep::test::checkResampledMap;

namespace {

std::vector<float> pattern(std::size_t n, int seed) {
  std::vector<float> v(n);
  for (std::size_t i = 0; i < n; ++i)
    v[i] = static_cast<float>((static_cast<int>(i) * 7919 + seed * 104729) % 1009) / 1008.0f - 0.25f;
  return v;
}

} // namespace

TEST_CASE("Vulkan backend: buffers and textures of every format and type round-trip exactly") {
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  MESSAGE("device: " << vk.deviceName());
  CHECK(vk.maxTextureSize() >= 4096);

  const std::vector<float> words = pattern(300, 1);
  gpu::Buffer buffer(vk, words.size() * 4, "round trip");
  const auto* bytes = reinterpret_cast<const std::byte*>(words.data());
  vk.writeBuffer(buffer.id(), 0, {bytes, words.size() * 4});
  vk.writeBuffer(buffer.id(), 8, {bytes + 100, 12}); // in order: the second write wins where they overlap
  std::vector<float> expected = words;
  std::memcpy(expected.data() + 2, words.data() + 25, 12);
  const std::vector<std::byte> back = vk.readBuffer(buffer.id(), 0, words.size() * 4);
  CHECK(std::memcmp(back.data(), expected.data(), back.size()) == 0);

  struct Case {
    gpu::TextureType type;
    gpu::Format format;
    int depth;
  };
  for (const Case c : {Case{gpu::TextureType::Texture2D, gpu::Format::R32F, 1},
                       Case{gpu::TextureType::Texture2D, gpu::Format::RG32F, 1},
                       Case{gpu::TextureType::Texture2D, gpu::Format::RGBA32F, 1},
                       Case{gpu::TextureType::Texture2D, gpu::Format::RGBA16F, 1},
                       Case{gpu::TextureType::Texture2D, gpu::Format::Depth32F, 1},
                       Case{gpu::TextureType::Texture2D, gpu::Format::RG32I, 1},
                       Case{gpu::TextureType::Texture2DArray, gpu::Format::RGBA16F, 3},
                       Case{gpu::TextureType::Texture3D, gpu::Format::RGBA32F, 4}}) {
    CAPTURE(static_cast<int>(c.type));
    CAPTURE(static_cast<int>(c.format));
    gpu::Texture t(vk, {c.type, c.format, 13, 7, c.depth, "round trip"});
    std::vector<float> texels =
        pattern(static_cast<std::size_t>(13 * 7 * c.depth * gpu::componentCount(c.format)), 2);
    if (c.format == gpu::Format::Depth32F)
      for (float& v : texels)
        v = std::clamp(v, 0.0f, 1.0f); // a depth format holds [0, 1]
    if (c.format == gpu::Format::RGBA16F)
      for (float& v : texels)
        v = std::round(v * 1024.0f) / 1024.0f; // exact in half precision
    if (c.format == gpu::Format::RG32I)
      for (float& v : texels)
        v = std::round(v * 70000.0f); // signed integers, exact in float
    vk.writeTexture(t.id(), texels);
    CHECK(vk.readTexture(t.id()) == texels);
    const gpu::TextureDesc d = vk.describe(t.id());
    CHECK((d.width == 13 && d.height == 7 && d.depth == c.depth && d.format == c.format && d.type == c.type));
  }
  crep::test::checkNoValidationMessages(vk);
}

TEST_CASE("Vulkan backend: MinMaxTreePass, written once for every backend, gives the CPU trees bit for bit") {
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  // A width that is not a power of two, and rows of 10 levels (the build's two phases).
  for (const auto& [W, H] : {std::pair{200, 5}, std::pair{1024, 3}, std::pair{1000, 3}}) {
    CAPTURE(W);
    Image depth(W, H, 1);
    for (int j = 0; j < H; ++j)
      for (int i = 0; i < W; ++i)
        depth.at(i, j) = static_cast<float>(((i * 7919 + j * 104729) % 1009) / 1008.0);
    for (const gpu::Format format : {gpu::Format::R32F, gpu::Format::Depth32F}) {
      gpu::Texture map(vk, {gpu::TextureType::Texture2D, format, W, H, 1, "rectified depth"});
      vk.writeTexture(map.id(), depth.data());
      MinMaxTreePass pass({.mapWidth = W, .mapHeight = H, .backend = &vk});
      pass.run(map.id());
      const std::vector<float> nodes = pass.readNodes();
      const MinMaxTrees cpu(depth);
      REQUIRE(nodes.size() == cpu.data().size());
      CHECK(std::equal(nodes.begin(), nodes.end(), cpu.data().begin()));
      // The split build: low levels by run(), the upper ones again from them.
      if (MinMaxTreePass::lowLevels(W) >= 1) {
        pass.completeUpperLevels();
        const std::vector<float> again = pass.readNodes();
        CHECK(std::equal(again.begin(), again.end(), cpu.data().begin()));
      }
    }
  }
  crep::test::checkNoValidationMessages(vk);
}

TEST_CASE("Vulkan backend: bad input is named") {
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  CHECK_THROWS_WITH_AS(vk.createTexture({gpu::TextureType::Texture2D, gpu::Format::R32F, 0, 4, 1, ""}),
                       doctest::Contains("gpu::TextureDesc.width/height"), InvalidArgument);
  CHECK_THROWS_WITH_AS(vk.createTexture({gpu::TextureType::Texture2D, gpu::Format::R32F, 1 << 20, 4, 1, ""}),
                       doctest::Contains("maximum texture size"), InvalidArgument);
  CHECK_THROWS_WITH_AS(vk.createTexture({gpu::TextureType::Texture2D, gpu::Format::R32F, 4, 4, 2, ""}),
                       doctest::Contains("gpu::TextureDesc.depth"), InvalidArgument);
  CHECK_THROWS_WITH_AS(vk.createBuffer(0, ""), doctest::Contains("bytes"), InvalidArgument);
  gpu::Texture t(vk, {gpu::TextureType::Texture2D, gpu::Format::R32F, 4, 4, 1, ""});
  CHECK_THROWS_WITH_AS(vk.writeTexture(t.id(), std::vector<float>(15)), doctest::Contains("16 floats"),
                       InvalidArgument);
  CHECK_THROWS_WITH_AS(vk.readTexture(9999), doctest::Contains("texture"), InvalidArgument);
  gpu::Buffer b(vk, 16, "");
  CHECK_THROWS_WITH_AS(vk.writeBuffer(b.id(), 8, std::vector<std::byte>(12)), doctest::Contains("16 bytes"),
                       InvalidArgument);
  MinMaxTreePass pass({.mapWidth = 8, .mapHeight = 4, .backend = &vk});
  CHECK_THROWS_WITH_AS(pass.run(t.id()), doctest::Contains("MinMaxTreePass::run.rectifiedDepth"),
                       InvalidArgument);
  CHECK_THROWS_WITH_AS(MinMaxTreePass({.mapWidth = -1, .mapHeight = 4, .backend = &vk}),
                       doctest::Contains("MinMaxTreePass::CreateInfo.mapWidth/mapHeight"), InvalidArgument);
  CHECK_THROWS_AS(vk.prepareProgram("passes/does/not_exist.comp", {}), ShaderError);
  crep::test::checkNoValidationMessages(vk);
}

TEST_CASE("Vulkan backend: ShadowResamplePass matches the CPU resampling, and its fused tree levels "
          "MinMaxTreePass") {
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  const scenes::Scene scene = scenes::makeScene("colonnade", 16.0 / 9.0);
  const glm::dmat4 lightMatrix =
      scenes::standardLightClipFromWorld(scene.sun, scene.boundsMin, scene.boundsMax);
  // A standard shadow map with smooth slopes and steps (silhouettes), in [0, 1].
  const int S = 512;
  Image shadow(S, S, 1);
  for (int j = 0; j < S; ++j)
    for (int i = 0; i < S; ++i) {
      const double u = (i + 0.5) / S, v = (j + 0.5) / S;
      const bool box = (i / 64 + j / 48) % 3 == 0;
      shadow.at(i, j) =
          static_cast<float>(0.55 + 0.25 * std::sin(6.0 * u) * std::cos(4.0 * v) - (box ? 0.2 : 0.0));
    }
  gpu::Texture shadowTexture(vk, {gpu::TextureType::Texture2D, gpu::Format::Depth32F, S, S, 1, "shadow map"});
  vk.writeTexture(shadowTexture.id(), shadow.data());

  const auto epipolar = std::make_shared<const EpipolarLayout>(scene.camera, scene.sun, 160, 90);
  RectifyOptions ro;
  ro.splits = 4;
  const auto projective = std::make_shared<const ProjectiveLayout>(rectify(scene.camera, scene.sun, ro));
  for (const auto& [name, layout, H] : {std::tuple<std::string, std::shared_ptr<const RectifiedLayout>, int>{
                                            "epipolar", epipolar, epipolar->sliceCount()},
                                        {"projective", projective, 128}}) {
    CAPTURE(name);
    const int W = 256;
    const RectifiedMap cpu = resampleShadowMap(layout, W, H, shadow, lightMatrix);
    gpu::Texture map(vk, {gpu::TextureType::Texture2D, gpu::Format::R32F, W, H, 1, "rectified map"});
    ShadowResamplePass pass({.mapWidth = W, .mapHeight = H, .backend = &vk});
    ShadowResamplePass::FrameAttribs f;
    f.layout = layout.get();
    f.shadowMap = shadowTexture.id();
    f.lightClipFromWorld = lightMatrix;
    f.output = map.id();
    pass.run(f);
    const std::vector<float> gpu = vk.readTexture(map.id());
    checkResampledMap(name, gpu, cpu.depth); // the GL pass's bounds
    // With a tree buffer: the same map bit for bit, and after completeUpperLevels() the trees of the map.
    MinMaxTreePass fromMap({.mapWidth = W, .mapHeight = H, .backend = &vk}),
        fused({.mapWidth = W, .mapHeight = H, .backend = &vk});
    fromMap.run(map.id());
    gpu::Texture fusedMap(vk, {gpu::TextureType::Texture2D, gpu::Format::R32F, W, H, 1, "rectified map"});
    f.output = fusedMap.id();
    f.minMaxBuffer = fused.treeBuffer();
    pass.run(f);
    CHECK(vk.readTexture(fusedMap.id()) == gpu);
    fused.completeUpperLevels();
    CHECK(fused.readNodes() == fromMap.readNodes());
  }
  ShadowResamplePass pass({.mapWidth = 64, .mapHeight = 32, .backend = &vk});
  ShadowResamplePass::FrameAttribs bad;
  bad.layout = projective.get();
  bad.shadowMap = shadowTexture.id();
  bad.lightClipFromWorld = lightMatrix;
  bad.output = shadowTexture.id(); // a depth texture of another size
  CHECK_THROWS_WITH_AS(pass.run(bad), doctest::Contains("ShadowResamplePass::FrameAttribs.output"),
                       InvalidArgument);
  crep::test::checkNoValidationMessages(vk);
}

TEST_CASE("Vulkan backend: EvaluatePass names the field of a texture or buffer it cannot use") {
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  const scenes::Scene scene = scenes::makeScene("boxes", 16.0 / 9.0);
  RectifyOptions ro;
  ro.splits = 2;
  Rectification r = rectify(scene.camera, scene.sun, ro);
  REQUIRE(r.projective());
  const ProjectiveLayout layout(std::move(r));
  constexpr int W = 64, H = 16, w = 16, h = 9;
  gpu::Texture map(vk, {gpu::TextureType::Texture2D, gpu::Format::R32F, W, H, 1, "map"});
  vk.writeTexture(map.id(), std::vector<float>(W * H, 0.5f));
  PrefilterPass::CreateInfo prefilterInfo;
  prefilterInfo.mapWidth = W;
  prefilterInfo.mapHeight = H;
  prefilterInfo.backend = &vk;
  PrefilterPass prefilterPass(prefilterInfo);
  prefilterPass.run({.rectifiedDepth = map.id(), .layout = &layout, .medium = &scene.medium});
  EvaluatePass::CreateInfo evaluateInfo;
  evaluateInfo.backend = &vk;
  EvaluatePass pass(evaluateInfo);
  gpu::Texture depth(vk, {gpu::TextureType::Texture2D, gpu::Format::R32F, w, h, 1, "depth"});
  gpu::Texture out(vk, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, w, h, 1, "out"});
  gpu::Texture wrongFormat(vk, {gpu::TextureType::Texture2D, gpu::Format::R32F, w, h, 1, "R32F"});
  gpu::Texture wrongSize(vk, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, w + 1, h, 1, "size"});
  gpu::Texture colour(vk, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, w, h, 1, "colour"});
  EvaluatePass::FrameAttribs f;
  f.cameraDepth = depth.id();
  f.output = out.id();
  f.camera = &scene.camera;
  f.light = &scene.sun;
  f.medium = &scene.medium;
  f.layout = &layout;
  f.basis = prefilterPass.filteredBasis();
  pass.run(f); // the frame as given works
  const auto rejects = [&](EvaluatePass::FrameAttribs bad, const char* field) {
    CAPTURE(std::string(field));
    CHECK_THROWS_WITH_AS(pass.run(bad), doctest::Contains(field), InvalidArgument);
  };
  EvaluatePass::FrameAttribs bad = f;
  bad.output = wrongFormat.id();
  rejects(bad, "EvaluatePass::FrameAttribs.output");
  bad.output = wrongSize.id();
  rejects(bad, "EvaluatePass::FrameAttribs.output");
  bad = f;
  bad.cameraDepth = colour.id(); // a colour texture is no depth
  rejects(bad, "EvaluatePass::FrameAttribs.cameraDepth");
  bad.cameraDepth = 9999; // no texture of this backend (a GL name, say)
  rejects(bad, "EvaluatePass::FrameAttribs.cameraDepth");
  bad = f;
  bad.basis.texture = map.id(); // a 2D texture, not the basis array
  rejects(bad, "EvaluatePass::FrameAttribs.basis.texture");
  bad = f;
  bad.froxels.volume = out.id(); // 2D, not a volume
  rejects(bad, "EvaluatePass::FrameAttribs.froxels.volume");
  gpu::Buffer small(vk, 16, "list");
  const gpu::SampleList list{small.id(), colour.id(), out.id(), w, h, w * h};
  bad = f;
  bad.list = &list;
  rejects(bad, "EvaluatePass::FrameAttribs.list.buffer");
  EvaluatePass moved = std::move(pass);
  CHECK_THROWS_WITH_AS(pass.run(f), doctest::Contains("EvaluatePass"), InvalidArgument);
  moved.run(f);
  crep::test::checkNoValidationMessages(vk);
}

TEST_CASE("Vulkan backend: crep::Scattering names what needs the OpenGL backend") {
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  Scattering::CreateInfo info;
  info.width = 64;
  info.height = 32;
  info.mapSize = 256;
  info.backend = &vk;
  Scattering scattering(info);
  const scenes::Scene scene = scenes::makeScene("forest", 2.0);
  gpu::Texture depth(vk, {gpu::TextureType::Texture2D, gpu::Format::Depth32F, 64, 32, 1, "depth"});
  gpu::Texture output(vk, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, 64, 32, 1, "output"});
  Scattering::FrameAttribs f;
  f.camera = &scene.camera;
  f.light = &scene.sun;
  f.medium = &scene.medium;
  f.cameraDepth = depth.id();
  f.output = output.id();
  f.drawCasters = [](const glm::dmat4&) {};
  CHECK_THROWS_WITH_AS(scattering.run(f), doctest::Contains("Scattering::FrameAttribs.drawCasters"),
                       InvalidArgument);
  f.drawCasters = nullptr;
  gpu::Texture colour(vk, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, 64, 64, 1, "colour"});
  const Scattering::ShadowMap notDepth{colour.id(), glm::dmat4(1.0), 0.0};
  f.shadowMap = &notDepth;
  CHECK_THROWS_WITH_AS(scattering.run(f), doctest::Contains("Scattering::FrameAttribs.shadowMap.texture"),
                       InvalidArgument);
  f.shadowMap = nullptr;
  f.output = 12345; // no texture of this backend (say, a GL name)
  CHECK_THROWS_WITH_AS(scattering.run(f), doctest::Contains("Scattering::FrameAttribs.output"),
                       InvalidArgument);
  crep::test::checkNoValidationMessages(vk);
}

TEST_CASE("Vulkan backend: CreateInfo::shaderBinary is refused when it is not SPIR-V, naming the program") {
  std::vector<std::byte> binary;
  gpu::VulkanBackend::CreateInfo info;
  info.shaderBinary = [&](std::string_view, std::span<const ShaderDefine>) { return binary; };
  gpu::VulkanBackend vk(info);
  const std::string program = "passes/pipeline/accumulate.comp";
  // Not a whole number of 4-byte words.
  binary.assign(10, std::byte{0});
  CHECK_THROWS_WITH_AS(vk.prepareProgram(program, {}),
                       doctest::Contains("CreateInfo.shaderBinary(\"passes/pipeline/accumulate.comp\")"),
                       InvalidArgument);
  CHECK_THROWS_WITH_AS(vk.prepareProgram(program, {}), doctest::Contains("10 bytes"), InvalidArgument);
  // Words, but not SPIR-V's magic number first (here the number byte-swapped, as a big-endian file has it).
  const std::uint32_t swapped[] = {0x03022307u, 0x00010300u, 0u, 8u, 0u};
  binary.resize(sizeof swapped);
  std::memcpy(binary.data(), swapped, sizeof swapped);
  CHECK_THROWS_WITH_AS(vk.prepareProgram(program, {}), doctest::Contains("0x03022307"), InvalidArgument);
  CHECK_THROWS_WITH_AS(vk.prepareProgram(program, {}), doctest::Contains("accumulate.comp"), InvalidArgument);
  // Nothing: the GLSL is compiled as without a provider; the module is then kept (the provider is not asked
  // again for that variant).
  binary.clear();
  vk.prepareProgram(program, {});
  binary.assign(10, std::byte{0});
  CHECK_NOTHROW(vk.prepareProgram(program, {}));
}
