// Reduced-resolution evaluation: checkerboard min/max depth downsample and depth-aware upsample
// (crep/pipeline/reduced_resolution.h), CPU reference and the pass on a gpu::Backend.
#include <crep/core/error.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/shader_library.h>
#include <crep/pipeline/reduced_resolution.h>
#include <crep/scatter/gpu_world_march.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace crep {

namespace {

void checkFactor(const std::string& parameter, int factor) {
  if (factor != 2 && factor != 4) throw InvalidArgument(parameter, std::to_string(factor), "must be 2 or 4");
}

void checkMultiple(const std::string& parameter, int width, int height, int factor) {
  if (width <= 0 || height <= 0 || width % factor != 0 || height % factor != 0)
    throw InvalidArgument(parameter, std::to_string(width) + " x " + std::to_string(height),
                          "must be positive multiples of the factor " + std::to_string(factor));
}

/// View-space distance of a depth-buffer value; the sky (d >= 1) is the far plane. (The GLSL twin uses
/// near far / (near + (1 - d)(far - near)); Camera::linearDepth is the same value.)
double viewDepth(const Camera& camera, double d) {
  return camera.surfaceViewDepth(d);
}

} // namespace

Image downsampleDepth(const Image& depth, int factor) {
  checkFactor("downsampleDepth.factor", factor);
  checkMultiple("downsampleDepth.depth", depth.width(), depth.height(), factor);
  const int w = depth.width() / factor, h = depth.height() / factor;
  Image low(w, h, 1);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const bool nearest = ((i + j) & 1) == 0;
      float d = nearest ? 3.0e38f : -3.0e38f;
      for (int y = 0; y < factor; ++y)
        for (int x = 0; x < factor; ++x) {
          const float v = depth.at(i * factor + x, j * factor + y, 0);
          d = nearest ? std::min(d, v) : std::max(d, v);
        }
      low.at(i, j) = d;
    }
  return low;
}

Image depthAwareUpsample(const Image& low, const Image& lowDepth, const Image& fullDepth,
                         const Camera& camera, int factor) {
  checkFactor("depthAwareUpsample.factor", factor);
  checkMultiple("depthAwareUpsample.fullDepth", fullDepth.width(), fullDepth.height(), factor);
  const int w = fullDepth.width() / factor, h = fullDepth.height() / factor;
  if (low.width() != w || low.height() != h)
    throw InvalidArgument("depthAwareUpsample.low",
                          std::to_string(low.width()) + " x " + std::to_string(low.height()),
                          "must be fullDepth's size / factor");
  if (lowDepth.width() != w || lowDepth.height() != h)
    throw InvalidArgument("depthAwareUpsample.lowDepth",
                          std::to_string(lowDepth.width()) + " x " + std::to_string(lowDepth.height()),
                          "must be fullDepth's size / factor");
  const int W = fullDepth.width(), H = fullDepth.height(), C = low.channels();
  Image out(W, H, C);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const double Z = viewDepth(camera, fullDepth.at(x, y, 0));
      const double u = (x + 0.5) / factor - 0.5, v = (y + 0.5) / factor - 0.5;
      const int i0 = static_cast<int>(std::floor(u)), j0 = static_cast<int>(std::floor(v));
      const double fx = u - i0, fy = v - j0;
      std::array<double, 4> sum{};
      double total = 0.0;
      for (int k = 0; k < 4; ++k) {
        const int ox = k & 1, oy = k >> 1;
        const int qi = std::clamp(i0 + ox, 0, w - 1), qj = std::clamp(j0 + oy, 0, h - 1);
        const double b = (ox == 1 ? fx : 1.0 - fx) * (oy == 1 ? fy : 1.0 - fy);
        const double Zk = viewDepth(camera, lowDepth.at(qi, qj, 0));
        const double weight = b / (kUpsampleDepthEpsilon + std::abs(Z - Zk) / Z);
        for (int c = 0; c < C && c < 4; ++c)
          sum[static_cast<std::size_t>(c)] += weight * low.at(qi, qj, c);
        total += weight;
      }
      for (int c = 0; c < C && c < 4; ++c)
        out.at(x, y, c) = static_cast<float>(sum[static_cast<std::size_t>(c)] / total);
    }
  return out;
}

namespace {
ShaderStageSource downsampleStage(int factor) {
  return {ShaderStage::Compute,
          "passes/pipeline/depth_downsample.comp",
          {{"CREP_FACTOR", std::to_string(factor)}}};
}
ShaderStageSource upsampleStage(int factor) {
  return {ShaderStage::Compute,
          "passes/pipeline/depth_upsample.comp",
          {{"CREP_FACTOR", std::to_string(factor)},
           {"CREP_DEPTH_EPSILON", std::to_string(kUpsampleDepthEpsilon)}}};
}
void dispatch(gpu::Backend& b, const char* label, const ShaderStageSource& stage,
              std::vector<gpu::Resource> resources, std::vector<gpu::PushValue> push, int width, int height) {
  gpu::Dispatch d;
  d.label = label;
  d.program = stage.path;
  d.defines = stage.defines;
  d.resources = std::move(resources);
  d.push = std::move(push);
  d.groups = glm::uvec3(static_cast<unsigned>((width + 7) / 8), static_cast<unsigned>((height + 7) / 8), 1u);
  b.dispatch(d);
}
} // namespace

DepthAwareResamplePass::DepthAwareResamplePass(const CreateInfo& info) : info_(info) {
  checkFactor("DepthAwareResamplePass::CreateInfo.factor", info.factor);
  checkMultiple("DepthAwareResamplePass::CreateInfo.width/height", info.width, info.height, info.factor);
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  gpu::checkTextureSize(*backend_, "DepthAwareResamplePass::CreateInfo.width/height", info.width,
                        info.height);
  for (const ShaderStageSource& stage : {downsampleStage(info.factor), upsampleStage(info.factor)})
    backend_->prepareProgram(stage.path, stage.defines);
}

DepthAwareResamplePass::~DepthAwareResamplePass() = default;
DepthAwareResamplePass::DepthAwareResamplePass(DepthAwareResamplePass&& o) noexcept
    : info_(o.info_), ownBackend_(std::move(o.ownBackend_)), backend_(std::exchange(o.backend_, nullptr)) {}
DepthAwareResamplePass& DepthAwareResamplePass::operator=(DepthAwareResamplePass&& o) noexcept {
  if (this != &o) {
    info_ = o.info_;
    ownBackend_ = std::move(o.ownBackend_);
    backend_ = std::exchange(o.backend_, nullptr);
  }
  return *this;
}

void DepthAwareResamplePass::downsample(std::uint32_t fullDepth, std::uint32_t lowDepth) {
  gpu::requireNotMovedFrom(backend_, "DepthAwareResamplePass");
  gpu::Backend& b = *backend_;
  gpu::requireTexture2DOf(b, "DepthAwareResamplePass::downsample.fullDepth", fullDepth, info_.width,
                          info_.height);
  gpu::requireDepthFormatOf(b, "DepthAwareResamplePass::downsample.fullDepth", fullDepth);
  gpu::requireTexture2DOf(b, "DepthAwareResamplePass::downsample.lowDepth", lowDepth, lowWidth(), lowHeight(),
                          gpu::Format::R32F);
  dispatch(b, "DepthAwareResamplePass::downsample", downsampleStage(info_.factor),
           {gpu::Resource::sampled(CREP_DEPTH_DOWNSAMPLE_FULL_DEPTH_UNIT, fullDepth),
            gpu::Resource::image(CREP_DEPTH_DOWNSAMPLE_LOW_DEPTH_IMAGE, lowDepth, gpu::Access::WriteOnly)},
           {gpu::PushValue::of(0, glm::ivec2(lowWidth(), lowHeight()))}, lowWidth(), lowHeight());
}

void DepthAwareResamplePass::upsample(std::uint32_t low, std::uint32_t lowDepth, std::uint32_t fullDepth,
                                      std::uint32_t output, double zNear, double zFar) {
  if (!(zNear > 0.0 && zFar > zNear && std::isfinite(zFar)))
    throw InvalidArgument("DepthAwareResamplePass::upsample.zNear/zFar",
                          std::to_string(zNear) + ", " + std::to_string(zFar), "must satisfy 0 < near < far");
  upsample(low, lowDepth, fullDepth, output,
           glm::vec4(static_cast<float>(zNear), static_cast<float>(zFar), static_cast<float>(zFar), 0.0f));
}

void DepthAwareResamplePass::upsample(std::uint32_t low, std::uint32_t lowDepth, std::uint32_t fullDepth,
                                      std::uint32_t output, const Camera& camera) {
  upsample(low, lowDepth, fullDepth, output, gpu::gpuCamera(camera).depth); // crep_cameraViewDepth's map
}

void DepthAwareResamplePass::upsample(std::uint32_t low, std::uint32_t lowDepth, std::uint32_t fullDepth,
                                      std::uint32_t output, const glm::vec4& depthMap) {
  gpu::requireNotMovedFrom(backend_, "DepthAwareResamplePass");
  gpu::Backend& b = *backend_;
  gpu::requireTexture2DOf(b, "DepthAwareResamplePass::upsample.low", low, lowWidth(), lowHeight(),
                          gpu::Format::RGBA32F);
  gpu::requireTexture2DOf(b, "DepthAwareResamplePass::upsample.lowDepth", lowDepth, lowWidth(), lowHeight(),
                          gpu::Format::R32F);
  gpu::requireTexture2DOf(b, "DepthAwareResamplePass::upsample.fullDepth", fullDepth, info_.width,
                          info_.height);
  gpu::requireDepthFormatOf(b, "DepthAwareResamplePass::upsample.fullDepth", fullDepth);
  gpu::requireTexture2DOf(b, "DepthAwareResamplePass::upsample.output", output, info_.width, info_.height,
                          gpu::Format::RGBA32F);
  dispatch(b, "DepthAwareResamplePass::upsample", upsampleStage(info_.factor),
           {gpu::Resource::sampled(CREP_DEPTH_UPSAMPLE_LOW_UNIT, low),
            gpu::Resource::sampled(CREP_DEPTH_UPSAMPLE_LOW_DEPTH_UNIT, lowDepth),
            gpu::Resource::sampled(CREP_DEPTH_UPSAMPLE_FULL_DEPTH_UNIT, fullDepth),
            gpu::Resource::image(CREP_DEPTH_UPSAMPLE_OUTPUT_IMAGE, output, gpu::Access::WriteOnly)},
           {gpu::PushValue::of(0, glm::ivec4(info_.width, info_.height, lowWidth(), lowHeight())),
            gpu::PushValue::of(1, depthMap)},
           info_.width, info_.height);
}

} // namespace crep
