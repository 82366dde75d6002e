// Point resampling of a standard shadow map into a rectified map with blocker clamping (Klehm et al. 2014,
// Sec. 4.1); rules in crep/epipolar/resample.h. Shader: passes/epipolar_resample.comp.
#include <crep/core/error.h>
#include <crep/core/parallel.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_layout.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/epipolar/resample.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/shader_library.h>

#include <crep/scatter/gpu_layout_buffers.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

namespace crep {

void validateLightMatrix(const glm::dmat4& M, const glm::dvec3& lightDirection) {
  requireFinite("lightClipFromWorld", M);
  if (M[0][3] != 0.0 || M[1][3] != 0.0 || M[2][3] != 0.0 || M[3][3] == 0.0)
    throw InvalidArgument("lightClipFromWorld", "a perspective matrix",
                          "must be affine (an orthographic shadow matrix: last row 0 0 0 w)");
  if (std::abs(glm::determinant(M)) < 1e-300)
    throw InvalidArgument("lightClipFromWorld", "a singular matrix", "must be invertible");
  // The light direction must map to a pure depth increase: every light ray is one texel, and the depth
  // buffer keeps the occluder nearest to the light. The tolerance admits matrices stored in float (an
  // engine's): 1e-3 of the matrix scale moves a point 1e-3 texel-space units per unit of depth at most.
  const glm::dvec4 d = M * glm::dvec4(lightDirection, 0.0);
  const double scale =
      std::max({glm::length(glm::dvec3(M[0])), glm::length(glm::dvec3(M[1])), glm::length(glm::dvec3(M[2]))});
  if (!(std::hypot(d.x, d.y) <= 1e-3 * scale) || !(d.z > 0.0))
    throw InvalidArgument("lightClipFromWorld",
                          "light direction maps to clip (" + detail::formatValue(d.x) + ", " +
                              detail::formatValue(d.y) + ", " + detail::formatValue(d.z) + ")",
                          "must look along the light direction: (0, 0, > 0) expected");
}

// A perspective projection centred at the light (Klehm et al. 2014, Sec. 3.2 "Local Lights": the light's
// own shadow frustum): clip x = y = w = 0 at the light position.
void validateLocalLightMatrix(const glm::dmat4& M, const glm::dvec3& lightPosition) {
  requireFinite("lightClipFromWorld", M);
  requireFinite("lightPosition", lightPosition);
  if (std::abs(glm::determinant(M)) < 1e-300)
    throw InvalidArgument("lightClipFromWorld", "a singular matrix", "must be invertible");
  // Each of rows x, y, w must vanish at the light: the light is the centre of projection, every light ray
  // from it is one texel. The tolerance is relative to the terms the row sums, which bound the rounding of
  // a matrix stored in float (about 1e-7 of them).
  const glm::dvec4 q = M * glm::dvec4(lightPosition, 1.0);
  const double distance = glm::length(lightPosition);
  for (const int r : {0, 1, 3}) {
    const double terms = glm::length(glm::dvec3(M[0][r], M[1][r], M[2][r])) * distance + std::abs(M[3][r]);
    if (!(std::abs(q[r]) <= 1e-4 * terms))
      throw InvalidArgument("lightClipFromWorld",
                            "light position maps to clip (" + detail::formatValue(q.x) + ", " +
                                detail::formatValue(q.y) + ", " + detail::formatValue(q.z) + ", " +
                                detail::formatValue(q.w) + ")",
                            "must be a perspective projection centred at the light position (clip x = y = "
                            "w = 0 there expected, up to 1e-4 of the terms summed)");
  }
}

std::optional<glm::dvec3> localLightPosition(const RectifiedLayout& layout) {
  return layout.localLightPosition();
}

void validateLayoutLightMatrix(const RectifiedLayout& layout, const glm::dmat4& lightClipFromWorld) {
  if (const std::optional<glm::dvec3> position = localLightPosition(layout))
    validateLocalLightMatrix(lightClipFromWorld, *position);
  else
    validateLightMatrix(lightClipFromWorld, layout.lightRay(0.5, 0.5).direction);
}

namespace {

/// How far along a layout's light ray the projected point lies (rule in resample.h): 0 for a directional
/// light (the ray origin), the light-camera distance 1 / rho for a local one.
double projectedPointDistance(const RectifiedLayout& layout) {
  if (const std::optional<glm::dvec3> position = layout.localLightPosition())
    return glm::length(*position - layout.origin());
  return 0.0;
}

} // namespace

// Sec. 4.1: point resampling over the texels of the rectified map, blockers clamped to the slice's range.
RectifiedMap resampleShadowMap(std::shared_ptr<const RectifiedLayout> layout, int width, int height,
                               const Image& shadowDepth, const glm::dmat4& lightClipFromWorld,
                               const ResampleOptions& options) {
  if (!layout) throw InvalidArgument("resampleShadowMap.layout", "null", "must be set");
  if (width <= 0 || height <= 0 || width > Image::kMaxDimension || height > Image::kMaxDimension ||
      width % layout->regionCount() != 0)
    throw InvalidArgument("resampleShadowMap.size", std::to_string(width) + " x " + std::to_string(height),
                          "must be positive, <= " + std::to_string(Image::kMaxDimension) +
                              ", the width a multiple of the region count " +
                              std::to_string(layout->regionCount()));
  if (const auto* e = dynamic_cast<const EpipolarLayout*>(layout.get()); e && e->sliceCount() != height)
    throw InvalidArgument("resampleShadowMap.size", "height " + std::to_string(height),
                          "must be the EpipolarLayout's slice count " + std::to_string(e->sliceCount()));
  if (options.threads < 0)
    throw InvalidArgument("ResampleOptions.threads", detail::formatValue(options.threads), "must be >= 0");
  if (shadowDepth.empty() || shadowDepth.channels() != 1)
    throw InvalidArgument(
        "shadowDepth", shadowDepth.empty() ? "empty" : std::to_string(shadowDepth.channels()) + " channels",
        "must be a 1-channel depth image");
  const int Ws = shadowDepth.width(), Hs = shadowDepth.height();
  for (int j = 0; j < Hs; ++j)
    for (int i = 0; i < Ws; ++i)
      if (std::isnan(shadowDepth.at(i, j)))
        throw InvalidArgument("shadowDepth",
                              "texel (" + std::to_string(i) + ", " + std::to_string(j) + ") = NaN",
                              "depth-buffer values must not be NaN");
  const RectifiedLayout& L = *layout;
  validateLayoutLightMatrix(L, lightClipFromWorld);
  const glm::dmat4 worldFromClip = glm::inverse(lightClipFromWorld);
  const double ahead = projectedPointDistance(L);

  Image depth(width, height, 1, 1.0f);
  parallelRows(height, options.threads, [&](int j) {
    const double row = (j + 0.5) / height;
    for (int i = 0; i < width; ++i) {
      const LightRay ray = L.lightRay((i + 0.5) / width, row);
      const glm::dvec4 q = lightClipFromWorld * glm::dvec4(ray.origin + ahead * ray.direction, 1.0);
      if (ahead > 0.0 && !(q.w > 0.0)) continue; // behind the local light's map
      const double x = q.x / q.w, y = q.y / q.w;
      if (!(x >= -1.0 && x <= 1.0 && y >= -1.0 && y <= 1.0)) continue;
      const int si = std::min(static_cast<int>((x + 1.0) * 0.5 * Ws), Ws - 1);
      const int sj = std::min(static_cast<int>((y + 1.0) * 0.5 * Hs), Hs - 1);
      const double d = shadowDepth.at(si, sj);
      if (d >= 1.0) continue;
      const glm::dvec4 h = worldFromClip * glm::dvec4(x, y, 2.0 * d - 1.0, 1.0);
      try {
        depth.at(i, j) = static_cast<float>(std::clamp(L.toRectified(glm::dvec3(h) / h.w).depth, 0.0, 1.0));
      } catch (const InvalidArgument&) {
        // An occluder the layout cannot map (on the light axis through the camera): nothing stored.
      }
    }
  });
  return makeRectifiedMap(std::move(layout), std::move(depth));
}

// ---------------------------------------------------------------------------------------------------
// ShadowResamplePass

ShadowResamplePass::ShadowResamplePass(const CreateInfo& info) : info_(info) {
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  gpu::checkTextureSize(*backend_, "ShadowResamplePass::CreateInfo.mapWidth/mapHeight", info.mapWidth,
                        info.mapHeight);
  layoutBuffers_ = gpu::LayoutBuffers(backend_);
  params_ = gpu::Buffer(*backend_, sizeof(gpu::MarchParams), "ShadowResamplePass: march block");
}

/// A validated frame of the pass (ShadowResamplePass::validate) and what run() derives from it.
struct ShadowResamplePass::Plan {
  int shadowWidth = 0, shadowHeight = 0; ///< the standard shadow map's level 0
  GpuLayoutData layoutData;              ///< the map's layout block
};

void ShadowResamplePass::validate(const FrameAttribs& frame, std::string_view owner) const {
  plan(frame, owner);
}

ShadowResamplePass::Plan ShadowResamplePass::plan(const FrameAttribs& f, std::string_view owner) const {
  const std::string p = std::string(owner) + ".";
  if (!f.layout) invalid(p + "layout", "null", "must be set");
  const int W = info_.mapWidth, H = info_.mapHeight;
  gpu::requireMapSize(*f.layout, W, H, "ShadowResamplePass::CreateInfo.mapWidth/mapHeight");
  Plan plan;
  const gpu::TextureLevel shadow = gpu::requireTexture2DOf(*backend_, (p + "shadowMap").c_str(), f.shadowMap);
  plan.shadowWidth = shadow.width;
  plan.shadowHeight = shadow.height;
  gpu::requireDepthFormatOf(*backend_, (p + "shadowMap").c_str(), f.shadowMap);
  gpu::requireTexture2DOf(*backend_, (p + "output").c_str(), f.output, W, H, gpu::Format::R32F);
  validateLayoutLightMatrix(*f.layout, f.lightClipFromWorld);
  if (f.minMaxBuffer != 0) {
    if (MinMaxTreePass::lowLevels(W) < 1)
      invalid(p + "minMaxBuffer", std::to_string(f.minMaxBuffer),
              "needs a map wider than 64 texels (no low tree levels below the top 6)");
    requireMinMaxBuffer(*backend_, (p + "minMaxBuffer").c_str(), f.minMaxBuffer, W, H,
                        "its low levels are written here");
  }
  plan.layoutData = gpu::requireGpuLayout(*f.layout);
  gpu::LayoutBuffers::requireUploadable(plan.layoutData, H);
  return plan;
}

void ShadowResamplePass::run(const FrameAttribs& f) {
  const Plan checked = plan(f, "ShadowResamplePass::FrameAttribs");
  const int W = info_.mapWidth, H = info_.mapHeight;
  const bool trees = f.minMaxBuffer != 0;
  const gpu::LayoutKind kind = layoutBuffers_.upload(checked.layoutData, H);
  gpu::MarchParams params;
  params.sizes = glm::ivec4(checked.shadowWidth, checked.shadowHeight, W, H);
  params.lightClipFromWorld = glm::mat4(f.lightClipFromWorld);
  backend_->writeBuffer(params_.id(), 0, std::as_bytes(std::span(&params, 1)));

  gpu::Dispatch d;
  d.label = "ShadowResamplePass::run";
  d.program = "passes/epipolar/resample.comp";
  d.defines = {{"CREP_LAYOUT", std::to_string(static_cast<int>(kind))},
               {"CREP_RESAMPLE_TREES", trees ? "1" : "0"}};
  d.resources = {gpu::Resource::uniform(CREP_RESAMPLE_MARCH_BINDING, params_.id()),
                 gpu::Resource::sampled(CREP_RESAMPLE_SHADOW_MAP_UNIT, f.shadowMap),
                 gpu::Resource::image(CREP_RESAMPLE_RECTIFIED_OUT_IMAGE, f.output, gpu::Access::WriteOnly)};
  layoutBuffers_.appendResources(d.resources, CREP_LAYOUT_DEFAULT_BINDING, CREP_SLICES_DEFAULT_BINDING);
  d.push = {gpu::PushValue::of(0, glm::mat4(glm::inverse(f.lightClipFromWorld))),
            gpu::PushValue::of(1, static_cast<float>(projectedPointDistance(*f.layout)))};
  if (trees) { // one work group of 64 per row, 2^lowLevels texels per invocation
    d.push.push_back(
        gpu::PushValue::of(2, glm::ivec4(MinMaxTrees::levelCount(W), MinMaxTrees::rowStrideFor(W),
                                         MinMaxTreePass::lowLevels(W), 0)));
    d.resources.push_back(gpu::Resource::storage(CREP_RESAMPLE_MIN_MAX_BINDING, f.minMaxBuffer));
    d.groups = glm::uvec3(static_cast<unsigned>(H), 1u, 1u);
  } else {
    d.groups = glm::uvec3(static_cast<unsigned>((W + 7) / 8), static_cast<unsigned>((H + 7) / 8), 1u);
  }
  backend_->dispatch(d);
}

} // namespace crep
