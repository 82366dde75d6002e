// GPU passes of the marches (crep/epipolar/gpu_march.h) and the shared blocks (gpu_layout.h): min/max
// trees (Yusov 2012 Sec. 6.3) and the tree / brute-force march along rectified rows (Algorithm 2). The
// world-space reference march is WorldMarchPass in scatter/ (crep/scatter/gpu_world_march.h). Shaders:
// passes/epipolar/minmax_build.comp, passes/epipolar/march_rectified.comp, crep/layout.glsl.
#include <crep/core/error.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/shader_library.h>

#include <crep/scatter/gpu_layout_buffers.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace crep {

namespace gpu {

LayoutKind layoutKind(const RectifiedLayout& layout) {
  return requireGpuLayout(layout).kind;
}

} // namespace gpu

// ---------------------------------------------------------------------------------------------------
// MinMaxTreePass

void requireTreeLevels(const char* parameter, int mapWidth) {
  if (MinMaxTrees::levelCount(mapWidth) > 16)
    throw InvalidArgument(parameter, std::to_string(mapWidth), "must need at most 16 tree levels");
}

namespace {
/// InvalidArgument naming `parameter` unless `bytes` hold the trees of a mapWidth x mapHeight map.
void requireTreeBytes(const char* parameter, std::size_t bytes, int mapWidth, int mapHeight) {
  const std::size_t needed =
      static_cast<std::size_t>(MinMaxTrees::rowStrideFor(mapWidth)) * static_cast<std::size_t>(mapHeight) * 8;
  if (bytes < needed)
    invalid(parameter, std::to_string(bytes) + " bytes",
            "must be a MinMaxTreePass::treeBuffer() of a " + std::to_string(mapWidth) + " x " +
                std::to_string(mapHeight) + " map (" + std::to_string(needed) + " bytes)");
}

std::string treeBufferRequirement(const std::string& use) {
  return "must be the MinMaxTreePass::treeBuffer() of the map (" + use + ")";
}
} // namespace

void requireMinMaxBuffer(const char* parameter, std::uint32_t buffer, int mapWidth, int mapHeight,
                         const std::string& use) {
  const long long size = gl::requireBuffer(parameter, buffer, treeBufferRequirement(use));
  requireTreeBytes(parameter, static_cast<std::size_t>(size), mapWidth, mapHeight);
}

void requireMinMaxBuffer(const gpu::Backend& backend, const char* parameter, std::uint32_t buffer,
                         int mapWidth, int mapHeight, const std::string& use) {
  const std::size_t size = gpu::requireBufferOf(backend, parameter, buffer, treeBufferRequirement(use));
  requireTreeBytes(parameter, size, mapWidth, mapHeight);
}

MinMaxTreePass::MinMaxTreePass(const CreateInfo& info) : info_(info) {
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  gpu::checkTextureSize(*backend_, "MinMaxTreePass::CreateInfo.mapWidth/mapHeight", info.mapWidth,
                        info.mapHeight);
  requireTreeLevels("MinMaxTreePass::CreateInfo.mapWidth", info.mapWidth);
  levels_ = MinMaxTrees::levelCount(info.mapWidth);
  rowStride_ = MinMaxTrees::rowStrideFor(info.mapWidth);
  backend_->prepareProgram("passes/epipolar/minmax_build.comp", {});
  const std::size_t bytes =
      static_cast<std::size_t>(std::max(rowStride_, 1)) * static_cast<std::size_t>(info.mapHeight) * 8;
  buffer_ = gpu::Buffer(*backend_, bytes, "MinMaxTreePass: trees");
}

/// One workgroup per row (passes/epipolar/minmax_build.comp); the upper-only variant reads no texture.
gpu::Dispatch MinMaxTreePass::dispatch(bool upperOnly, std::uint32_t rectifiedDepth) const {
  gpu::Dispatch d;
  d.label = upperOnly ? "MinMaxTreePass::completeUpperLevels" : "MinMaxTreePass::run";
  d.program = "passes/epipolar/minmax_build.comp";
  if (upperOnly)
    d.defines = {{"CREP_TREE_UPPER_ONLY", "1"}};
  else
    d.resources.push_back(gpu::Resource::sampled(CREP_MIN_MAX_TREE_RECTIFIED_DEPTH_UNIT, rectifiedDepth));
  d.resources.push_back(gpu::Resource::storage(CREP_MIN_MAX_TREE_MIN_MAX_BINDING, buffer_.id()));
  d.push = {gpu::PushValue::of(0, glm::ivec4(info_.mapWidth, info_.mapHeight, levels_, rowStride_))};
  d.groups = glm::uvec3(levels_ > 0 ? static_cast<unsigned>(info_.mapHeight) : 0u, 1u, 1u);
  return d;
}

void MinMaxTreePass::run(std::uint32_t rectifiedDepth) {
  gpu::requireTexture2DOf(*backend_, "MinMaxTreePass::run.rectifiedDepth", rectifiedDepth, info_.mapWidth,
                          info_.mapHeight);
  gpu::requireDepthFormatOf(*backend_, "MinMaxTreePass::run.rectifiedDepth", rectifiedDepth);
  backend_->dispatch(dispatch(false, rectifiedDepth));
}

int MinMaxTreePass::lowLevels(int mapWidth) {
  return std::max(0, MinMaxTrees::levelCount(mapWidth) - 6);
}

void MinMaxTreePass::completeUpperLevels() {
  if (lowLevels(info_.mapWidth) < 1)
    throw InvalidArgument("MinMaxTreePass::CreateInfo.mapWidth", std::to_string(info_.mapWidth),
                          "must exceed 64 texels for completeUpperLevels (no low levels to start from)");
  backend_->dispatch(dispatch(true, 0));
}

std::vector<float> MinMaxTreePass::readNodes() const {
  std::vector<float> out(static_cast<std::size_t>(rowStride_) * static_cast<std::size_t>(info_.mapHeight) *
                         2);
  if (out.empty()) return out;
  const std::vector<std::byte> bytes = backend_->readBuffer(buffer_.id(), 0, out.size() * sizeof(float));
  std::memcpy(out.data(), bytes.data(), bytes.size());
  return out;
}

// ---------------------------------------------------------------------------------------------------
// RectifiedMarchPass

RectifiedMarchPass::RectifiedMarchPass(const CreateInfo& info) : info_(info) {
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  gpu::checkTextureSize(*backend_, "RectifiedMarchPass::CreateInfo.mapWidth/mapHeight", info.mapWidth,
                        info.mapHeight);
  requireTreeLevels("RectifiedMarchPass::CreateInfo.mapWidth", info.mapWidth);
  layoutBuffers_ = gpu::LayoutBuffers(backend_);
  params_ = gpu::Buffer(*backend_, sizeof(gpu::MarchParams), "RectifiedMarchPass: parameters");
}

ShaderStageSource RectifiedMarchPass::program(gpu::LayoutKind kind, bool textured, bool list) const {
  const int k = static_cast<int>(kind);
  if (k < 0 || k > 1)
    throw InvalidArgument("RectifiedMarchPass layout kind", std::to_string(k),
                          "must be projective or epipolar");
  return {ShaderStage::Compute,
          "passes/epipolar/march_rectified.comp",
          {{"CREP_MARCH_TREE", info_.mode == Mode::MinMaxTree ? "1" : "0"},
           {"CREP_LAYOUT", std::to_string(k)},
           {"CREP_LIGHT_TEXTURE", textured ? "1" : "0"},
           {"CREP_SAMPLE_LIST", list ? "1" : "0"}}}; // at CREP_SAMPLE_LIST_DEFAULT_BINDING
}

void RectifiedMarchPass::prepare(gpu::LayoutKind kind, bool textured, bool list) {
  const ShaderStageSource stage = program(kind, textured, list);
  backend_->prepareProgram(stage.path, stage.defines);
}

/// A validated frame of the march (RectifiedMarchPass::validate) and what run() derives from it.
struct RectifiedMarchPass::Plan {
  GpuLayoutData layoutData;        ///< the map's layout block, serialized once per run
  int width = 0, height = 0;       ///< the camera image
  int outWidth = 0, outHeight = 0; ///< the textures written: the image's, or the list's
};

void RectifiedMarchPass::validate(const FrameAttribs& frame, std::string_view owner) const {
  plan(frame, owner);
}

RectifiedMarchPass::Plan RectifiedMarchPass::plan(const FrameAttribs& f, std::string_view owner) const {
  const std::string p = std::string(owner) + ".";
  if (!f.layout) invalid(p + "layout", "null", "must be set");
  if (!f.camera || !f.medium) invalid(p + "camera/medium", "null", "must be set");
  if ((f.light == nullptr) == (f.localLight == nullptr))
    invalid(p + "light/localLight", f.light ? "both set" : "both null", "exactly one must be set");
  Plan plan;
  plan.layoutData = gpu::requireGpuLayout(*f.layout);
  const int W = info_.mapWidth, H = info_.mapHeight;
  gpu::requireMapSize(*f.layout, W, H, "RectifiedMarchPass::CreateInfo.mapWidth/mapHeight");
  // The image size is the camera depth texture's own; with a work list, imageWidth x imageHeight when
  // given, and the outputs are the list's.
  const gpu::Backend& b = *backend_;
  const gpu::SampleList* list = f.list;
  gpu::TextureLevel image;
  if (list) {
    image = gpu::listImageSize(b, f.imageWidth, f.imageHeight, f.cameraDepth, std::string(owner));
  } else {
    image = gpu::requireTexture2DOf(b, (p + "cameraDepth").c_str(), f.cameraDepth);
  }
  plan.width = plan.outWidth = image.width;
  plan.height = plan.outHeight = image.height;
  gpu::requireTexture2DOf(b, (p + "rectifiedDepth").c_str(), f.rectifiedDepth, W, H);
  gpu::requireDepthFormatOf(b, (p + "rectifiedDepth").c_str(), f.rectifiedDepth);
  if (!list) gpu::requireDepthFormatOf(b, (p + "cameraDepth").c_str(), f.cameraDepth);
  if (list) {
    gpu::validateSampleList(b, *list, p + "list");
    plan.outWidth = list->width;
    plan.outHeight = list->height;
  } else {
    gpu::requireTexture2DOf(b, (p + "output").c_str(), f.output, plan.width, plan.height,
                            gpu::Format::RGBA32F);
  }
  if (f.stepsOutput != 0)
    gpu::requireTexture2DOf(b, (p + "stepsOutput").c_str(), f.stepsOutput, plan.outWidth, plan.outHeight,
                            gpu::Format::R32F);
  if (f.lightColors != 0) gpu::requireTexture2DOf(b, (p + "lightColors").c_str(), f.lightColors, W, H);
  if (info_.mode == Mode::MinMaxTree)
    requireMinMaxBuffer(b, (p + "minMaxBuffer").c_str(), f.minMaxBuffer, W, H, "MinMaxTree mode");
  if (list && f.blockRadius >= 0.0)
    invalid(p + "blockRadius", detail::formatValue(f.blockRadius),
            "must be -1 with a work list (the list says which texels to march)");
  if (!std::isfinite(f.blockRadius) || !std::isfinite(f.blockCenter.x) || !std::isfinite(f.blockCenter.y))
    invalid(p + "blockCenter/blockRadius", detail::formatValue(f.blockRadius), "must be finite");
  gpu::LayoutBuffers::requireUploadable(plan.layoutData, H);
  return plan;
}

void RectifiedMarchPass::run(const FrameAttribs& f) {
  const Plan p = plan(f, "RectifiedMarchPass::FrameAttribs");
  gpu::Backend& b = *backend_;
  const int W = info_.mapWidth, H = info_.mapHeight;
  const gpu::SampleList* list = f.list;
  const bool textured = f.lightColors != 0;
  gpu::MarchParams params =
      f.localLight ? gpu::makeMarchParams(*f.camera, *f.localLight, *f.medium, p.width, p.height, W, H)
                   : gpu::makeMarchParams(*f.camera, *f.light, *f.medium, p.width, p.height, W, H);
  params.info = glm::ivec4(MinMaxTrees::levelCount(W), MinMaxTrees::rowStrideFor(W), 0, 0);
  if (!gpu::setMarchRegion(params, p.width, p.height, f.blockCenter, list ? -1.0 : f.blockRadius,
                           "RectifiedMarchPass::FrameAttribs"))
    return; // the block misses the image
  b.writeBuffer(params_.id(), 0, std::as_bytes(std::span(&params, 1)));
  layoutBuffers_.upload(p.layoutData, H);
  std::uint32_t steps = f.stepsOutput;
  if (steps == 0) { // the program always writes its step counts: a scratch target of the output's size
    if (!dummySteps_ || dummyWidth_ != p.outWidth || dummyHeight_ != p.outHeight) {
      dummySteps_ = gpu::Texture(b, {gpu::TextureType::Texture2D, gpu::Format::R32F, p.outWidth, p.outHeight,
                                     1, "RectifiedMarchPass: step counts (unused)"});
      dummyWidth_ = p.outWidth;
      dummyHeight_ = p.outHeight;
    }
    steps = dummySteps_.id();
  }
  const ShaderStageSource stage = program(p.layoutData.kind, textured, list != nullptr);
  gpu::Dispatch d;
  d.label = list ? "RectifiedMarchPass::run (list)" : "RectifiedMarchPass::run";
  d.program = stage.path;
  d.defines = stage.defines;
  // A work list reads its coordinates at the camera depth's unit and writes its own output.
  d.resources = {
      gpu::Resource::uniform(CREP_MARCH_PARAMS_BINDING, params_.id()),
      gpu::Resource::sampled(CREP_MARCH_CAMERA_DEPTH_UNIT, list ? list->coordinates : f.cameraDepth),
      gpu::Resource::sampled(CREP_MARCH_MAP_UNIT, f.rectifiedDepth),
      gpu::Resource::image(CREP_MARCH_SCATTERING_OUT_IMAGE, list ? list->output : f.output,
                           gpu::Access::WriteOnly),
      gpu::Resource::image(CREP_MARCH_STEPS_OUT_IMAGE, steps, gpu::Access::WriteOnly)};
  layoutBuffers_.appendResources(d.resources, CREP_LAYOUT_DEFAULT_BINDING, CREP_SLICES_DEFAULT_BINDING);
  if (info_.mode == Mode::MinMaxTree)
    d.resources.push_back(gpu::Resource::storage(CREP_MARCH_MIN_MAX_BINDING, f.minMaxBuffer));
  if (textured) // Klehm et al. 2014, Sec. 3.2: the light texture's colour per texel
    d.resources.push_back(gpu::Resource::sampled(CREP_MARCH_LIGHT_COLORS_UNIT, f.lightColors));
  if (list) { // Yusov 2012, Sec. 6.4: the selected samples only, one invocation per entry
    d.resources.push_back(gpu::Resource::storage(CREP_SAMPLE_LIST_DEFAULT_BINDING, list->buffer));
    d.indirect = list->buffer;
  } else {
    // 8 x 8 pixels per workgroup (gpu::dispatchMarch's choice): the block's bounding box or the image.
    d.groups = glm::uvec3(static_cast<unsigned>((params.region.z + 7) / 8),
                          static_cast<unsigned>((params.region.w + 7) / 8), 1u);
  }
  b.dispatch(d);
}

} // namespace crep
