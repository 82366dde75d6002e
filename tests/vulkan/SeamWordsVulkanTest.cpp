// The seam in its own words: on a non-GL backend every error a pass throws for bad input or a device limit
// is an InvalidArgument naming the field, in the seam's terms (2D texture, RGBA32F, array layers), never a
// GlError or a GL enum; the backend reports its kind as a type, not a name to compare.
#include "common/vulkan_fixture.h"

#include <crep/core/error.h>
#include <crep/gpu/backend.h>
#include <crep/gpu/checks.h>
#include <crep/postfx/gpu_tone_mapping.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/vulkan/vulkan_backend.h>

#include <doctest/doctest.h>

#include <functional>
#include <string>

using namespace crep;

namespace {

/// The message of the InvalidArgument `f` throws ("" and a failed check if it throws anything else).
std::string invalidArgumentMessage(const std::function<void()>& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.what();
  } catch (const std::exception& e) {
    FAIL_CHECK("not an InvalidArgument: " << e.what());
    return "";
  }
  FAIL_CHECK("nothing thrown");
  return "";
}

/// `f` throws an InvalidArgument naming `field`, with no GL word in its message.
void namedWithoutGl(const std::function<void()>& f, const std::string& field) {
  const std::string message = invalidArgumentMessage(f);
  CAPTURE(message);
  CHECK(message.find(field) != std::string::npos);
  CHECK(message.find("GL_") == std::string::npos);
}

} // namespace

TEST_CASE("Vulkan backend: the seam's kind is typed, its checks and limits speak its own words") {
  gpu::VulkanBackend vk(crep::test::validatedVulkan());
  CHECK(vk.kind() == gpu::BackendKind::Vulkan);

  // Device limits: PrefilterPass's map size, array layers and work groups.
  const auto prefilter = [&](auto edit) {
    return [&vk, edit] {
      PrefilterPass::CreateInfo info;
      info.mapWidth = 64;
      info.mapHeight = 16;
      info.backend = &vk;
      edit(info);
      PrefilterPass pass(info);
    };
  };
  namedWithoutGl(prefilter([&](PrefilterPass::CreateInfo& i) { i.mapWidth = vk.maxTextureSize() * 2; }),
                 "PrefilterPass::CreateInfo.mapWidth");
  namedWithoutGl(prefilter([&](PrefilterPass::CreateInfo& i) { i.workgroupRows = 1 << 20; }),
                 "PrefilterPass::CreateInfo.workgroupRows");
  // The limit helper itself (PrefilterPass's array-layer limit is beyond its largest bases on a device).
  const std::string layers = invalidArgumentMessage([&] {
    gpu::throwBeyondLimit(vk, "probe.layers", "9", "GL_MAX_ARRAY_TEXTURE_LAYERS", "array layers", 8);
  });
  CHECK(layers.find("probe.layers") != std::string::npos);
  CHECK(layers.find("array layers (8)") != std::string::npos);
  CHECK(layers.find("GL_") == std::string::npos);

  // Textures of the wrong kind or format, named in gpu::Format's words.
  gpu::Texture r32(vk, {gpu::TextureType::Texture2D, gpu::Format::R32F, 8, 8, 1, "r32"});
  gpu::Texture rgba(vk, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, 8, 8, 1, "rgba"});
  gpu::Texture volume(vk, {gpu::TextureType::Texture3D, gpu::Format::RGBA16F, 8, 8, 4, "volume"});
  namedWithoutGl([&] { gpu::requireTexture2DOf(vk, "probe.texture", r32.id(), 8, 8, gpu::Format::RGBA32F); },
                 "probe.texture");
  namedWithoutGl([&] { gpu::requireTexture2DOf(vk, "probe.volume", volume.id()); }, "probe.volume");
  namedWithoutGl([&] { gpu::requireDepthFormatOf(vk, "probe.depth", rgba.id()); }, "probe.depth");
  namedWithoutGl([&] { gpu::textureLevelOf(vk, "probe.unknown", 9999); }, "probe.unknown");
  const gpu::TextureLevel level = gpu::textureLevelOf(vk, "probe.volume", volume.id());
  CHECK(level.type == gpu::TextureType::Texture3D);
  CHECK(level.depth == 4);
  REQUIRE(level.format.has_value());
  CHECK(*level.format == gpu::Format::RGBA16F);
  CHECK_FALSE(level.isDepth);

  ToneMapPass::CreateInfo toneInfo;
  toneInfo.backend = &vk;
  ToneMapPass tone(toneInfo);
  ToneMapPass::FrameAttribs frame;
  frame.input = r32.id(); // R32F: not a colour image the pass reads
  frame.output = rgba.id();
  namedWithoutGl([&] { tone.run(frame); }, "ToneMapPass::FrameAttribs.input");
  crep::test::checkNoValidationMessages(vk);
}
