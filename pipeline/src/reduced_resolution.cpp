// Reduced-resolution evaluation: checkerboard min/max depth downsample and depth-aware upsample
// (crep/pipeline/reduced_resolution.h), CPU reference and GL pass.
#include <crep/core/error.h>
#include <crep/core/shader_library.h>
#include <crep/pipeline/reduced_resolution.h>
#include <crep/scatter/gpu_world_march.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

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

DepthAwareResamplePass::DepthAwareResamplePass(const CreateInfo& info) : info_(info) {
  checkFactor("DepthAwareResamplePass::CreateInfo.factor", info.factor);
  checkMultiple("DepthAwareResamplePass::CreateInfo.width/height", info.width, info.height, info.factor);
  gl::checkTextureSize("DepthAwareResamplePass::CreateInfo.width/height", info.width, info.height);
  const std::string f = std::to_string(info.factor);
  downsampleProgram_ =
      buildProgram({{ShaderStage::Compute, "passes/pipeline/depth_downsample.comp", {{"CREP_FACTOR", f}}}});
  upsampleProgram_ =
      buildProgram({{ShaderStage::Compute,
                     "passes/pipeline/depth_upsample.comp",
                     {{"CREP_FACTOR", f}, {"CREP_DEPTH_EPSILON", std::to_string(kUpsampleDepthEpsilon)}}}});
  sampler_ = gl::createClampSampler(GL_NEAREST);
}

DepthAwareResamplePass::~DepthAwareResamplePass() = default;
DepthAwareResamplePass::DepthAwareResamplePass(DepthAwareResamplePass&&) noexcept = default;
DepthAwareResamplePass& DepthAwareResamplePass::operator=(DepthAwareResamplePass&&) noexcept = default;

void DepthAwareResamplePass::downsample(std::uint32_t fullDepth, std::uint32_t lowDepth) {
  gl::requireNotMovedFrom(sampler_, "DepthAwareResamplePass");
  gl::requireTexture2D("DepthAwareResamplePass::downsample.fullDepth", fullDepth, info_.width, info_.height);
  gl::requireDepthFormat("DepthAwareResamplePass::downsample.fullDepth", fullDepth);
  gl::requireTexture2D("DepthAwareResamplePass::downsample.lowDepth", lowDepth, lowWidth(), lowHeight(),
                       GL_R32F);
  glUseProgram(downsampleProgram_.get());
  glProgramUniform2i(downsampleProgram_.get(), 0, lowWidth(), lowHeight());
  glBindTextureUnit(CREP_DEPTH_DOWNSAMPLE_FULL_DEPTH_UNIT, fullDepth);
  glBindSampler(CREP_DEPTH_DOWNSAMPLE_FULL_DEPTH_UNIT, sampler_.get());
  glBindImageTexture(CREP_DEPTH_DOWNSAMPLE_LOW_DEPTH_IMAGE, lowDepth, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
  glDispatchCompute(static_cast<GLuint>((lowWidth() + 7) / 8), static_cast<GLuint>((lowHeight() + 7) / 8), 1);
  gl::passOutputBarrier();
  gl::unbindPassState(1);
  gl::checkError("DepthAwareResamplePass::downsample");
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
  gl::requireNotMovedFrom(sampler_, "DepthAwareResamplePass");
  gl::requireTexture2D("DepthAwareResamplePass::upsample.low", low, lowWidth(), lowHeight(), GL_RGBA32F);
  gl::requireTexture2D("DepthAwareResamplePass::upsample.lowDepth", lowDepth, lowWidth(), lowHeight(),
                       GL_R32F);
  gl::requireTexture2D("DepthAwareResamplePass::upsample.fullDepth", fullDepth, info_.width, info_.height);
  gl::requireDepthFormat("DepthAwareResamplePass::upsample.fullDepth", fullDepth);
  gl::requireTexture2D("DepthAwareResamplePass::upsample.output", output, info_.width, info_.height,
                       GL_RGBA32F);
  const GLuint p = upsampleProgram_.get();
  glUseProgram(p);
  glProgramUniform4i(p, 0, info_.width, info_.height, lowWidth(), lowHeight());
  glProgramUniform4f(p, 1, depthMap.x, depthMap.y, depthMap.z, depthMap.w);
  const std::pair<GLuint, GLuint> textures[3] = {{CREP_DEPTH_UPSAMPLE_LOW_UNIT, low},
                                                 {CREP_DEPTH_UPSAMPLE_LOW_DEPTH_UNIT, lowDepth},
                                                 {CREP_DEPTH_UPSAMPLE_FULL_DEPTH_UNIT, fullDepth}};
  for (const auto& [unit, texture] : textures) {
    glBindTextureUnit(unit, texture);
    glBindSampler(unit, sampler_.get());
  }
  glBindImageTexture(CREP_DEPTH_UPSAMPLE_OUTPUT_IMAGE, output, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glDispatchCompute(static_cast<GLuint>((info_.width + 7) / 8), static_cast<GLuint>((info_.height + 7) / 8),
                    1);
  gl::passOutputBarrier();
  gl::unbindPassState(3);
  gl::checkError("DepthAwareResamplePass::upsample");
}

} // namespace crep
