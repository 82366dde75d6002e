// The frame-level front door (crep/pipeline/scattering.h): Klehm, Seidel, Eisemann 2014 on every frame,
// projective rectification (Sec. 4.2) or epipolar resampling fallback (Sec. 4.1) plus the epipole block
// (Fig. 8), from the passes of scatter/, epipolar/ and prefilter/.
#include <crep/core/error.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_epipolar_sampling.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/resample.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/frame_timers.h>
#include <crep/gpu/gl.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/gl_state.h>
#include <crep/gpu/shader_library.h>
#include <crep/pipeline/reduced_resolution.h>
#include <crep/pipeline/scattering.h>
#include <crep/prefilter/fourier.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/rectify/gpu_layout.h>
#include <crep/scatter/gpu_light_texture.h>
#include <crep/scatter/gpu_world_march.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <deque>
#include <map>
#include <numbers>
#include <numeric>
#include <optional>
#include <span>
#include <string>

namespace crep {

int Scattering::CreateInfo::mapSizeMultiple() const {
  const int P = prefilter.regionsPerSplit;
  return std::lcm(rectify.splits * P, epipolarRegions * P);
}

const char* layoutToken(Scattering::Layout layout) {
  return layout == Scattering::Layout::Projective ? "projective" : "epipolar";
}

namespace {

const Scattering::CreateInfo& validated(const Scattering::CreateInfo& info) {
  // Against the limits of the backend (GL: the current context's, GlError beyond them).
  const auto checkSize = [&](const char* parameter, int width, int height) {
    if (info.backend != nullptr)
      gpu::checkTextureSize(*info.backend, parameter, width, height);
    else
      gl::checkTextureSize(parameter, width, height);
  };
  checkSize("Scattering::CreateInfo.width/height", info.width, info.height);
  checkSize("Scattering::CreateInfo.mapSize", info.mapSize, info.mapSize);
  checkSize("Scattering::CreateInfo.ownShadowMapSize", info.ownShadowMapSize, info.ownShadowMapSize);
  validate(info.rectify);
  if (info.rectify.layout != SplitLayout::Regions)
    invalid("Scattering::CreateInfo.rectify.layout", "not SplitLayout::Regions",
            "must be SplitLayout::Regions (the splits side by side in one map)");
  validate(info.prefilter, "Scattering::CreateInfo.prefilter");
  validate(info.evaluate, "Scattering::CreateInfo.evaluate");
  if (info.localLightBases != 0)
    validateBases(info.localLightBases, "Scattering::CreateInfo.localLightBases");
  if (info.spotLightBases != 0 && info.spotLightBases != -1)
    validateBases(info.spotLightBases, "Scattering::CreateInfo.spotLightBases");
  if (info.localLightTableSamples != 0 &&
      (info.localLightTableSamples < 2 || info.localLightTableSamples > kMaxVisibilityTableSamples))
    invalid("Scattering::CreateInfo.localLightTableSamples", std::to_string(info.localLightTableSamples),
            "must be 0 (evaluate.visibilityTableSamples) or in [2, " +
                std::to_string(kMaxVisibilityTableSamples) + "]");
  if (info.spotLightTableSamples != 0 &&
      (info.spotLightTableSamples < 2 || info.spotLightTableSamples > kMaxVisibilityTableSamples))
    invalid("Scattering::CreateInfo.spotLightTableSamples", std::to_string(info.spotLightTableSamples),
            "must be 0 (localLightTableSamples) or in [2, " + std::to_string(kMaxVisibilityTableSamples) +
                "]");
  if (info.prefilter.reconstruction == VisibilityReconstruction::Exact) // its histograms' shared memory
    for (const auto& [field, Z] :
         {std::pair{"evaluate.visibilityTableSamples", info.evaluate.visibilityTableSamples},
          std::pair{"localLightTableSamples", info.localLightTableSamples},
          std::pair{"spotLightTableSamples", info.spotLightTableSamples}})
      if (Z > kMaxExactTableSamples)
        invalid(std::string("Scattering::CreateInfo.") + field, std::to_string(Z),
                "must be at most kMaxExactTableSamples = " + std::to_string(kMaxExactTableSamples) +
                    " with prefilter.reconstruction Exact");
  validate(info.epipoleBlock);
  const int regions = info.rectify.splits * info.prefilter.regionsPerSplit;
  if (info.mapSize % regions != 0)
    invalid("Scattering::CreateInfo.mapSize", std::to_string(info.mapSize),
            "must be a multiple of rectify.splits * prefilter.regionsPerSplit = " + std::to_string(regions));
  if (info.epipolarRegions < 1 || info.epipolarRegions > RectifyOptions::kMaxSplits)
    invalid("Scattering::CreateInfo.epipolarRegions", std::to_string(info.epipolarRegions),
            "must be in [1, " + std::to_string(RectifyOptions::kMaxSplits) + "]");
  const int epipolarRegions = info.epipolarRegions * info.prefilter.regionsPerSplit;
  if (info.mapSize % epipolarRegions != 0)
    invalid("Scattering::CreateInfo.mapSize", std::to_string(info.mapSize),
            "must be a multiple of epipolarRegions * prefilter.regionsPerSplit = " +
                std::to_string(epipolarRegions));
  requireNonNegative("Scattering::CreateInfo.localLightDepthWarp", info.localLightDepthWarp);
  if (!(info.epipolarDepthWarp >= 0.0 && std::isfinite(info.epipolarDepthWarp)))
    invalid("Scattering::CreateInfo.epipolarDepthWarp", detail::formatValue(info.epipolarDepthWarp),
            "must be finite and >= 0 (radians; 0 = linear depth)");
  requireNonNegative("Scattering::CreateInfo.ownShadowMapBias", info.ownShadowMapBias);
  if (info.evaluationScale != 1.0 && info.evaluationScale != 0.5 && info.evaluationScale != 0.25)
    invalid("Scattering::CreateInfo.evaluationScale", detail::formatValue(info.evaluationScale),
            "must be 1, 0.5 or 0.25");
  const int factor = static_cast<int>(std::lround(1.0 / info.evaluationScale));
  if (info.width % factor != 0 || info.height % factor != 0)
    invalid("Scattering::CreateInfo.width/height",
            std::to_string(info.width) + " x " + std::to_string(info.height),
            "must be multiples of 1 / evaluationScale = " + std::to_string(factor));
  if (!(info.epipoleBlockRadius >= 0.0 && info.epipoleBlockRadius <= 0.5))
    invalid("Scattering::CreateInfo.epipoleBlockRadius", detail::formatValue(info.epipoleBlockRadius),
            "must be in [0, 0.5] (a fraction of the screen diagonal)");
  if (!(info.localLightBlockRadius >= 0.0 && info.localLightBlockRadius <= 0.5))
    invalid("Scattering::CreateInfo.localLightBlockRadius", detail::formatValue(info.localLightBlockRadius),
            "must be in [0, 0.5] (a fraction of the screen diagonal)");
  if (info.epipoleBlockMaxPixels < 0)
    invalid("Scattering::CreateInfo.epipoleBlockMaxPixels", std::to_string(info.epipoleBlockMaxPixels),
            "must be >= 0 (0: no bound)");
  if (info.epipoleBlockMethod != Scattering::EpipoleBlockMethod::TreeMarch &&
      info.epipoleBlockMethod != Scattering::EpipoleBlockMethod::WorldMarch)
    invalid("Scattering::CreateInfo.epipoleBlockMethod",
            std::to_string(static_cast<int>(info.epipoleBlockMethod)),
            "must be EpipoleBlockMethod::TreeMarch or EpipoleBlockMethod::WorldMarch");
  if (info.method != Scattering::Method::Prefiltered && info.method != Scattering::Method::MinMaxMarch)
    invalid("Scattering::CreateInfo.method", std::to_string(static_cast<int>(info.method)),
            "must be Method::Prefiltered or Method::MinMaxMarch");
  if (info.sampling != Scattering::Sampling::PerPixel && info.sampling != Scattering::Sampling::Epipolar)
    invalid("Scattering::CreateInfo.sampling", std::to_string(static_cast<int>(info.sampling)),
            "must be Sampling::PerPixel or Sampling::Epipolar");
  if (info.sampling == Scattering::Sampling::Epipolar) {
    validate(info.epipolarSampling, "Scattering::CreateInfo.epipolarSampling");
    if (factor != 1)
      invalid("Scattering::CreateInfo.evaluationScale", detail::formatValue(info.evaluationScale),
              "must be 1 with Sampling::Epipolar (epipolarSampling.downscale reduces its resolution)");
    const int F = info.epipolarSampling.downscale;
    if (info.width % F != 0 || info.height % F != 0)
      invalid("Scattering::CreateInfo.width/height",
              std::to_string(info.width) + " x " + std::to_string(info.height),
              "must be multiples of epipolarSampling.downscale = " + std::to_string(F));
  }
  return info;
}

/// Throws unless every direction of `directions` from `position` is inside the map of M (in front of it, NDC
/// x and y in [-1, 1] up to 1e-3): the map covers the light's cone or face sector.
void requireCovers(const std::string& field, const glm::dmat4& M, const glm::dvec3& position,
                   std::span<const glm::dvec3> directions, const std::string& what) {
  // Points max(1, |position|) away: seen from a centre within validateLocalLightMatrix's tolerance of the
  // position, their directions change by about 2e-4 radians at most.
  const double t = std::max(1.0, glm::length(position));
  for (const glm::dvec3& d : directions) {
    const glm::dvec4 q = M * glm::dvec4(position + t * glm::normalize(d), 1.0);
    if (!(q.w > 0.0) || !(std::abs(q.x / q.w) <= 1.001 && std::abs(q.y / q.w) <= 1.001))
      invalid(field,
              "direction (" + detail::formatValue(d.x) + ", " + detail::formatValue(d.y) + ", " +
                  detail::formatValue(d.z) + ") outside the map",
              "must cover " + what);
  }
}

/// One local light's given perspective map: texture, bias, matrix centred at `position`, coverage.
void validateLocalMap(const gpu::Backend& backend, const std::string& field, const Scattering::ShadowMap& map,
                      const glm::dvec3& position, std::span<const glm::dvec3> directions,
                      const std::string& what) {
  gpu::requireTexture2DOf(backend, (field + ".texture").c_str(), map.texture);
  gpu::requireDepthFormatOf(backend, (field + ".texture").c_str(), map.texture);
  requireFinite(field + ".bias", map.bias);
  try {
    validateLocalLightMatrix(map.lightClipFromWorld, position);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(field + ".lightClipFromWorld", e.what(),
                          "a perspective shadow matrix centred at the light's position");
  }
  requireCovers(field + ".lightClipFromWorld", map.lightClipFromWorld, position, directions, what);
}

/// The local lights' shadow inputs (Klehm et al. 2014, Sec. 3.2 "Local Lights"; scattering.h): span sizes,
/// each given map, drawCasters for the lights without maps.
void validateLocalShadowMaps(const gpu::Backend& backend, const Scattering::FrameAttribs& f,
                             const std::string& prefix) {
  if (!f.spotShadowMaps.empty() && f.spotShadowMaps.size() != f.spotLights.size())
    invalid(prefix + "spotShadowMaps", "size " + std::to_string(f.spotShadowMaps.size()),
            "must be 0 or spotLights.size() = " + std::to_string(f.spotLights.size()));
  if (!f.pointShadowMaps.empty() && f.pointShadowMaps.size() != 6 * f.pointLights.size())
    invalid(prefix + "pointShadowMaps", "size " + std::to_string(f.pointShadowMaps.size()),
            "must be 0 or 6 * pointLights.size() = " + std::to_string(6 * f.pointLights.size()));
  if (!f.drawCasters && !f.plan && !f.spotLights.empty() && f.spotShadowMaps.empty())
    invalid(prefix + "drawCasters", "empty",
            "spot lights without spotShadowMaps or a plan render their maps with it");
  if (!f.drawCasters && !f.plan && !f.pointLights.empty() && f.pointShadowMaps.empty())
    invalid(prefix + "drawCasters", "empty",
            "point lights without pointShadowMaps or a plan render their maps with it");
  for (std::size_t i = 0; i < f.spotShadowMaps.size(); ++i) {
    const SpotLight& spot = f.spotLights[i];
    // Eight directions on the outer cone: nothing is emitted beyond it.
    const glm::dvec3 a = spot.direction(), u = anyOrthogonal(a), v = glm::cross(a, u);
    std::array<glm::dvec3, 8> cone;
    for (int k = 0; k < 8; ++k) {
      const double phi = 0.25 * std::numbers::pi * k;
      cone[std::size_t(k)] = std::cos(spot.outerConeAngle()) * a +
                             std::sin(spot.outerConeAngle()) * (std::cos(phi) * u + std::sin(phi) * v);
    }
    validateLocalMap(backend, prefix + "spotShadowMaps[" + std::to_string(i) + "]", f.spotShadowMaps[i],
                     spot.position(), cone, "the spot's outer cone");
  }
  for (std::size_t j = 0; j < f.pointShadowMaps.size(); ++j) {
    const int face = static_cast<int>(j % 6);
    // The four corners of the face's sector (PointLight::faceOf): axis +- the two other axes.
    const glm::dvec3 A = PointLight::faceAxis(face), B = PointLight::faceAxis((face / 2 * 2 + 2) % 6),
                     C = PointLight::faceAxis((face / 2 * 2 + 4) % 6);
    const std::array<glm::dvec3, 4> corners{A + B + C, A + B - C, A - B + C, A - B - C};
    validateLocalMap(backend, prefix + "pointShadowMaps[" + std::to_string(j) + "]", f.pointShadowMaps[j],
                     f.pointLights[j / 6].position(), corners,
                     "face " + std::to_string(face) + "'s sector of directions (PointLight::faceOf)");
  }
}

/// The light textures (scattering.h "Light textures"): the directional light's and the spots' (span size,
/// each texture and projection), and the evaluation options without a textured variant.
void validateLightTextures(const gpu::Backend& backend, const Scattering::FrameAttribs& f,
                           const EvaluateOptions& evaluate, const std::string& prefix) {
  if (!f.spotLightTextures.empty() && f.spotLightTextures.size() != f.spotLights.size())
    invalid(prefix + "spotLightTextures", "size " + std::to_string(f.spotLightTextures.size()),
            "must be 0 or spotLights.size() = " + std::to_string(f.spotLights.size()));
  bool any = false;
  if (f.lightTexture) {
    if (!f.light)
      invalid(prefix + "lightTexture", "set without a directional light", "must be null when light is null");
    gpu::validateGpuLightTexture(backend, *f.lightTexture, f.light, nullptr, prefix + "lightTexture");
    any = true;
  }
  for (std::size_t i = 0; i < f.spotLightTextures.size(); ++i) {
    if (f.spotLightTextures[i].texture == 0) continue; // untextured entry
    const LocalLight light = LocalLight::spot(f.spotLights[i]);
    gpu::validateGpuLightTexture(backend, f.spotLightTextures[i], nullptr, &light,
                                 prefix + "spotLightTextures[" + std::to_string(i) + "]");
    any = true;
  }
  if (!any) return;
  const std::string field = f.lightTexture ? prefix + "lightTexture" : prefix + "spotLightTextures";
  if (evaluate.nearPlaneCorrection)
    invalid(field, "a light texture",
            "has no textured evaluation with Scattering::CreateInfo.evaluate.nearPlaneCorrection (set it "
            "false)");
  if (usesVisibilityTable(evaluate) && !usesScatteringPrefix(evaluate))
    invalid(field, "a light texture",
            "has no textured evaluation with the visibility table alone (Scattering::CreateInfo.evaluate: "
            "scatteringPrefix true, or visibilityTableSamples = 0)");
}

/// FrameAttribs::froxels (scattering.h "Froxel volumes"): grid, jitter, the volume's target, format, size.
void validateFroxelTarget(const gpu::Backend& backend, const Scattering::FroxelTarget& t,
                          const Camera& camera, const std::string& owner) {
  validate(t.grid, owner.c_str());
  froxelDepthRange(t.grid, camera, owner.c_str());
  validateFroxelJitter(t.jitter, owner + ".jitter");
  const gpu::TextureLevel v = gpu::textureLevelOf(backend, (owner + ".volume").c_str(), t.volume);
  if (v.type != gpu::TextureType::Texture3D ||
      (v.format != gpu::Format::RGBA16F && v.format != gpu::Format::RGBA32F))
    invalid(owner + ".volume", "texture " + std::to_string(t.volume),
            "must be a 3D texture of format RGBA16F or RGBA32F");
  if (v.width != t.grid.width || v.height != t.grid.height || v.depth != t.grid.depth)
    invalid(owner + ".volume",
            std::to_string(v.width) + " x " + std::to_string(v.height) + " x " + std::to_string(v.depth),
            "must have the grid's size " + std::to_string(t.grid.width) + " x " +
                std::to_string(t.grid.height) + " x " + std::to_string(t.grid.depth));
}

/// FrameAttribs::output is written while the inputs are read: it must be none of them.
void requireOutputNotAnInput(const Scattering::FrameAttribs& f, const std::string& prefix) {
  const auto check = [&](std::uint32_t input, const std::string& name) {
    if (input != 0 && input == f.output)
      invalid(prefix + "output", "texture " + std::to_string(f.output) + ", also " + name,
              "must not be one of the frame's inputs");
  };
  check(f.cameraDepth, "FrameAttribs.cameraDepth");
  if (f.shadowMap) check(f.shadowMap->texture, "FrameAttribs.shadowMap.texture");
  if (f.lightTexture) check(f.lightTexture->texture, "FrameAttribs.lightTexture.texture");
  for (std::size_t i = 0; i < f.spotLightTextures.size(); ++i)
    check(f.spotLightTextures[i].texture,
          "FrameAttribs.spotLightTextures[" + std::to_string(i) + "].texture");
  for (std::size_t i = 0; i < f.spotShadowMaps.size(); ++i)
    check(f.spotShadowMaps[i].texture, "FrameAttribs.spotShadowMaps[" + std::to_string(i) + "].texture");
  for (std::size_t i = 0; i < f.pointShadowMaps.size(); ++i)
    check(f.pointShadowMaps[i].texture, "FrameAttribs.pointShadowMaps[" + std::to_string(i) + "].texture");
  for (std::size_t i = 0; i < f.planMaps.size(); ++i)
    check(f.planMaps[i], "FrameAttribs.planMaps[" + std::to_string(i) + "]");
}

/// FrameAttribs::camera, and a light: what both plan() and validate() read first.
void requireCameraAndLight(const Scattering::FrameAttribs& f, const std::string& prefix) {
  if (!f.camera) invalid(prefix + "camera", "null", "must be set");
  if (!f.light && f.spotLights.empty() && f.pointLights.empty())
    invalid(prefix + "light", "null", "must be set unless local lights are given");
}

/// A frame's rectifications and the shadow-pass plan made of them (Scattering::plan; run() makes the same
/// from the same inputs, deterministically).
struct PlannedFrame {
  Rectification sun;                 ///< with FrameAttribs::light
  std::vector<Rectification> locals; ///< the spots, then the six faces of each point light
  ShadowPassPlan plan;
};

ShadowPass::Rect rectOf(const SplitViewport& v) {
  return {v.x, v.y, v.width, v.height};
}

// One light's pass: Sec. 4.2's rectified map of K splits when projective; the standard map of `standard`
// (OpenGL convention) that the fallback resamples (Sec. 4.1) or marches; nothing for an empty frustum.
ShadowPass plannedPass(const Scattering::CreateInfo& info, const ShadowPassPlanOptions& options,
                       const Rectification& rect, bool sun, const auto& standard, bool served) {
  ShadowPass p;
  p.status = rect.status;
  p.reason = rect.reason;
  p.message = rect.message;
  p.clearDepth = options.reversedZ ? 0.0 : 1.0;
  p.compare = options.reversedZ ? DepthCompare::Greater : DepthCompare::Less;
  if (rect.projective()) {
    p.kind = ShadowPass::Kind::Rectified;
    p.width = p.height = info.mapSize;
    for (int k = 0; k < rect.splitCount(); ++k) {
      const ShadowPass::Rect v = rectOf(rect.splitViewport(k, info.mapSize, info.mapSize));
      p.splits.push_back(
          {toClipConvention(rect.splits[static_cast<std::size_t>(k)].rectClipFromWorld, options), v, v});
    }
  } else if (sun || rect.status == RectifyStatus::Fallback) { // the sun's "empty" falls back too
    p.kind = ShadowPass::Kind::Standard;
    p.served = served;
    p.width = p.height = info.ownShadowMapSize;
    p.glClipFromWorld = standard();
    const ShadowPass::Rect all{0, 0, p.width, p.height};
    if (!served) p.splits.push_back({toClipConvention(p.glClipFromWorld, options), all, all});
  }
  return p;
}

PlannedFrame planFrame(const Scattering::CreateInfo& info, const Scattering::FrameAttribs& f,
                       const ShadowPassPlanOptions& options, std::uint64_t frame) {
  PlannedFrame planned;
  planned.plan.frame = frame;
  planned.plan.options = options;
  std::vector<ShadowPass>& passes = planned.plan.passes;
  if (f.light) {
    planned.sun = rectify(*f.camera, *f.light, info.rectify);
    // The fallback's standard map covers the view frustum (casters nearer the light kept by depth clamp).
    passes.push_back(plannedPass(
        info, options, planned.sun, true,
        [&] { return orthographicLightClipFromWorld(*f.light, f.camera->frustumCorners()); },
        f.shadowMap != nullptr));
  }
  for (std::size_t i = 0; i < f.spotLights.size(); ++i) {
    const SpotLight& spot = f.spotLights[i];
    planned.locals.push_back(rectify(*f.camera, spot, info.rectify));
    passes.push_back(plannedPass(
        info, options, planned.locals.back(), false, [&] { return spot.lightClipFromWorld(); },
        !f.spotShadowMaps.empty()));
    passes.back().light = ShadowPass::Light::Spot;
    passes.back().index = static_cast<int>(i);
  }
  for (std::size_t i = 0; i < f.pointLights.size(); ++i) {
    const PointLight& point = f.pointLights[i];
    const std::array<Rectification, 6> faces = rectifyPointLight(*f.camera, point, info.rectify);
    for (int face = 0; face < 6; ++face) {
      planned.locals.push_back(faces[static_cast<std::size_t>(face)]);
      passes.push_back(plannedPass(
          info, options, planned.locals.back(), false, [&] { return point.faceClipFromWorld(face); },
          !f.pointShadowMaps.empty()));
      passes.back().light = ShadowPass::Light::PointFace;
      passes.back().index = static_cast<int>(i);
      passes.back().face = face;
    }
  }
  return planned;
}

std::string describe(const ShadowPass& p) {
  const char* kinds[] = {"none", "rectified", "standard"};
  std::string light = p.light == ShadowPass::Light::Sun ? std::string("the sun")
                      : p.light == ShadowPass::Light::Spot
                          ? "spot " + std::to_string(p.index)
                          : "point light " + std::to_string(p.index) + " face " + std::to_string(p.face);
  return light + ", " + kinds[static_cast<int>(p.kind)] + " " + std::to_string(p.width) + "x" +
         std::to_string(p.height);
}

bool samePass(const ShadowPass& a, const ShadowPass& b) {
  if (a.light != b.light || a.index != b.index || a.face != b.face || a.kind != b.kind ||
      a.served != b.served || a.width != b.width || a.height != b.height ||
      a.glClipFromWorld != b.glClipFromWorld || a.splits.size() != b.splits.size())
    return false;
  for (std::size_t k = 0; k < a.splits.size(); ++k)
    if (a.splits[k].clipFromWorld != b.splits[k].clipFromWorld ||
        a.splits[k].viewport != b.splits[k].viewport || a.splits[k].scissor != b.splits[k].scissor)
      return false;
  return true;
}

/// FrameAttribs::plan and planMaps: this run's plan (`expected`, made from the frame) and one map per pass
/// that needs one, of its size and a depth format (or R32F).
void validatePlan(const gpu::Backend& backend, const Scattering::FrameAttribs& f,
                  const ShadowPassPlan& expected, const std::string& prefix) {
  const ShadowPassPlan& plan = *f.plan;
  if (f.drawCasters)
    invalid(prefix + "drawCasters", "set with a plan", "must be empty: the plan's maps are the engine's");
  if (plan.frame != expected.frame)
    invalid(prefix + "plan", "made for run " + std::to_string(plan.frame),
            "must be this run's (" + std::to_string(expected.frame) +
                "): call plan() every frame, before its shadow passes");
  if (plan.passes.size() != expected.passes.size())
    invalid(prefix + "plan", std::to_string(plan.passes.size()) + " passes",
            "must have this frame's " + std::to_string(expected.passes.size()) +
                " (one per light: the lights changed since plan())");
  if (plan.options.convention != expected.options.convention ||
      plan.options.reversedZ != expected.options.reversedZ)
    invalid(prefix + "plan.options", "changed", "must be those plan() was called with");
  for (std::size_t i = 0; i < plan.passes.size(); ++i)
    if (!samePass(plan.passes[i], expected.passes[i]))
      invalid(prefix + "plan.passes[" + std::to_string(i) + "]", describe(plan.passes[i]),
              "must be this frame's (" + describe(expected.passes[i]) +
                  "): the camera, the lights, the given maps or the options changed since plan()");
  if (f.planMaps.size() != plan.passes.size())
    invalid(prefix + "planMaps", "size " + std::to_string(f.planMaps.size()),
            "must have one entry per plan pass (" + std::to_string(plan.passes.size()) + ")");
  for (std::size_t i = 0; i < plan.passes.size(); ++i) {
    const ShadowPass& pass = plan.passes[i];
    const std::string field = prefix + "planMaps[" + std::to_string(i) + "]";
    if (!pass.needsMap()) {
      if (f.planMaps[i] != 0)
        invalid(field, "texture " + std::to_string(f.planMaps[i]),
                "must be 0: pass " + std::to_string(i) + " (" + describe(pass) +
                    (pass.served ? ", served" : "") + ") has no map");
      continue;
    }
    gpu::requireTexture2DOf(backend, field.c_str(), f.planMaps[i], pass.width, pass.height);
    gpu::requireDepthFormatOf(backend, field.c_str(), f.planMaps[i]);
  }
}

/// A depth-only render target: a GL_DEPTH_COMPONENT32F texture and its framebuffer.
struct DepthTarget {
  gl::Handle texture, framebuffer;
  int size = 0;
  explicit DepthTarget(int s) : size(s) {
    texture = gl::createTexture2D(GL_DEPTH_COMPONENT32F, s, s, "depth target");
    framebuffer = gl::createFramebuffer();
    glNamedFramebufferTexture(framebuffer.get(), GL_DEPTH_ATTACHMENT, texture.get(), 0);
    glNamedFramebufferDrawBuffer(framebuffer.get(), GL_NONE);
    glNamedFramebufferReadBuffer(framebuffer.get(), GL_NONE);
  }
  /// The GL convenience of a plan's pass (OpenGL convention): clears once, then draws each split's casters
  /// in its viewport and scissor, with the contract's raster state (docs/GL_STATE.md), restored after;
  /// `callback` names the caller's callback when it leaves that state changed.
  void render(const char* callback, const ShadowPass& pass,
              const std::function<void(const glm::dmat4& clipFromWorld)>& draw) {
    gl::DepthPassScope scope(framebuffer.get(), size, size);
    const float clear = static_cast<float>(pass.clearDepth);
    glClearNamedFramebufferfv(framebuffer.get(), GL_DEPTH, 0, &clear); // once: the scissor box is the map
    for (const ShadowPass::Split& split : pass.splits) {
      const ShadowPass::Rect& v = split.viewport;
      scope.setViewport(v.x, v.y, v.width, v.height); // and the scissor box: a clear stays inside the split
      draw(split.clipFromWorld);
    }
    scope.requireUnchanged(callback);
    gl::checkError((std::string("the shadow map drawn by ") + callback).c_str()); // the callback's own errors
  }
  /// Made on first use; the same target for every frame.
  static DepthTarget& of(std::optional<DepthTarget>& target, int size) {
    if (!target) target.emplace(size);
    return *target;
  }
};

// Sec. 4.1's layout options of the front door: mapSize slices and the shared settings; the sun and the local
// lights differ in the depth warp and the epipole block's radius.
EpipolarOptions epipolarOptions(const Scattering::CreateInfo& info, double depthWarp, double blockRadius) {
  EpipolarOptions options;
  options.slices = info.mapSize;
  options.referenceRay = info.rectify.referenceRay;
  options.regions = info.epipolarRegions;
  options.depthWarp = depthWarp;
  options.epipoleBlockRadius = blockRadius;
  options.maxBlockPixels = info.epipoleBlockMaxPixels;
  return options;
}

/// The passes' CreateInfos on the object's backend.
PrefilterPass::CreateInfo prefilterInfo(int mapSize, const PrefilterOptions& options, gpu::Backend* backend) {
  PrefilterPass::CreateInfo c;
  c.mapWidth = c.mapHeight = mapSize;
  c.options = options;
  c.backend = backend;
  return c;
}

EvaluatePass::CreateInfo evaluateInfo(int bases, const EvaluateOptions& options,
                                      VisibilityReconstruction reconstruction, bool closedForm,
                                      gpu::Backend* backend) {
  EvaluatePass::CreateInfo c;
  c.bases = bases;
  c.options = options;
  c.reconstruction = reconstruction;
  c.localClosedForm = closedForm;
  c.backend = backend;
  return c;
}

} // namespace

struct Scattering::Impl {
  explicit Impl(const CreateInfo& i)
      : info(validated(i)), backend(&gpu::givenOrGl(i.backend, ownBackend)),
        gl(backend->kind() == gpu::BackendKind::OpenGL),
        prefilter(prefilterInfo(i.mapSize, i.prefilter, backend)),
        evaluate(evaluateInfo(i.prefilter.bases, i.evaluate, i.prefilter.reconstruction,
                              i.localLightClosedForm, backend)),
        resample({.mapWidth = i.mapSize, .mapHeight = i.mapSize, .backend = backend}),
        block({.options = i.epipoleBlock, .backend = backend}) {
    resampled = gpu::Texture(*backend, {gpu::TextureType::Texture2D, gpu::Format::R32F, i.mapSize, i.mapSize,
                                        1, "Scattering: resampled map"});
    // The min/max trees and their march: Method::MinMaxMarch's, or the prefiltered method's epipole block.
    // Made (and the block's program built) with the object, so the first frame with the sun in view
    // compiles nothing.
    const bool treeBlock = i.method == Method::Prefiltered &&
                           i.epipoleBlockMethod == EpipoleBlockMethod::TreeMarch &&
                           i.epipoleBlockRadius > 0.0;
    if (i.method == Method::MinMaxMarch || treeBlock) {
      trees.emplace(
          MinMaxTreePass::CreateInfo{.mapWidth = i.mapSize, .mapHeight = i.mapSize, .backend = backend});
      march.emplace(RectifiedMarchPass::CreateInfo{i.mapSize, i.mapSize, RectifiedMarchPass::Mode::MinMaxTree,
                                                   backend});
    }
    if (treeBlock) march->prepare(gpu::LayoutKind::Epipolar);
    if (i.sampling == Sampling::Epipolar) {
      // Its lines share the border arc of the sun's epipolar map (mapSize rows): none on a row boundary.
      sampling.emplace(
          EpipolarSamplingPass::CreateInfo{i.width, i.height, i.epipolarSampling, backend,
                                           epipolarLineOffset(i.mapSize, i.epipolarSampling.slices)});
    }
    const int factor = static_cast<int>(std::lround(1.0 / i.evaluationScale));
    if (factor > 1) {
      reduced.emplace(DepthAwareResamplePass::CreateInfo{i.width, i.height, factor, backend});
      const auto low = [&](gpu::Format format, const char* label) {
        return gpu::Texture(*backend, {gpu::TextureType::Texture2D, format, reduced->lowWidth(),
                                       reduced->lowHeight(), 1, label});
      };
      lowDepth = low(gpu::Format::R32F, "Scattering: reduced depth");
      lowOutput = low(gpu::Format::RGBA32F, "Scattering: reduced output");
    }
  }

  CreateInfo info;
  std::unique_ptr<gpu::Backend> ownBackend; ///< CreateInfo::backend null: a GlBackend of its own
  gpu::Backend* backend;                    ///< runs every pass (CreateInfo::backend or ownBackend)
  bool gl;                                  ///< the backend is OpenGL: the GL-only stages are available
  PrefilterPass prefilter;
  EvaluatePass evaluate;
  ShadowResamplePass resample;
  WorldMarchPass block;
  std::optional<DepthTarget> rectified; ///< GL: the projective map rasterized with drawCasters
  /// R32F: a map resampled from a standard shadow map, or a reversed-Z plan map turned back
  gpu::Texture resampled;
  std::optional<DepthTarget> ownShadowMap;       ///< fallback frames with drawCasters only
  gpu::Texture unreversedStandard;               ///< a reversed-Z plan's standard map turned back (R32F)
  std::optional<DepthAwareResamplePass> reduced; ///< evaluationScale < 1
  gpu::Texture lowDepth, lowOutput;              ///< its camera depth (R32F) and scattering (RGBA32F)
  /// Method::MinMaxMarch, or the prefiltered method's tree-marched epipole block: the map's trees ...
  std::optional<MinMaxTreePass> trees;
  std::optional<RectifiedMarchPass> march;      ///< ... and the tree march
  std::optional<EpipolarSamplingPass> sampling; ///< Sampling::Epipolar
  bool running = false;                         ///< inside run(): a call from drawCasters is refused
  /// Deferred stage timings (stageTimings, not blockingTimings): the spans of the frames waiting for their
  /// GPU times, and what each frame reports with them.
  struct FrameRecord {
    std::uint64_t frame = 0;
    std::vector<Stage> stages;    ///< as its FrameResult::stages, one per span
    std::vector<int> stageLights; ///< per stage: its LightResult's index, or -1
    std::size_t lights = 0;       ///< its LightResult count
  };
  gpu::FrameTimers frameTimers;
  std::deque<FrameRecord> frameRecords; ///< oldest first, the frames frameTimers holds
  std::vector<int> spanLights;          ///< this frame's spans so far: their LightResult's index, or -1
  int currentLight = -1;                ///< inside a local light's stages: its LightResult's index
  std::uint64_t frames = 0;             ///< run() calls so far
  void reportTimes(FrameResult& r);
  /// Local lights: one light's scattering (RGBA32F, width x height) and the pass adding it to the output,
  /// made on the first frame with local lights; their fallback's perspective shadow map.
  gpu::Texture localScattering;
  std::optional<DepthTarget> localShadowMap;
  std::optional<DepthTarget> localRectified; ///< keeps FrameResult::rectifiedMap the directional one
  /// R32F mapSize^2: a local light's map resampled from the engine's map, or its reversed-Z plan map turned
  /// back; the same for its standard map.
  gpu::Texture localResampled, localUnreversedStandard;
  gpu::Texture& localMap() {
    if (!localResampled)
      localResampled = gpu::Texture(*backend, {gpu::TextureType::Texture2D, gpu::Format::R32F, info.mapSize,
                                               info.mapSize, 1, "Scattering: local map"});
    return localResampled;
  }
  /// A reversed-Z map of the engine's plan (ShadowPassPlanOptions::reversedZ) as depth-buffer values into
  /// `target` (R32F, made here at the map's size on first use): one pass over its texels.
  std::uint32_t unreversed(std::uint32_t map, const ShadowPass& pass, gpu::Texture& target,
                           const char* label) {
    if (!target)
      target = gpu::Texture(
          *backend, {gpu::TextureType::Texture2D, gpu::Format::R32F, pass.width, pass.height, 1, label});
    gpu::Dispatch d;
    d.label = "Scattering::run (reversed-Z map)";
    d.program = "passes/pipeline/reverse_depth.comp";
    d.resources = {gpu::Resource::sampled(CREP_REVERSE_DEPTH_MAP_UNIT, map),
                   gpu::Resource::image(CREP_REVERSE_DEPTH_OUT_IMAGE, target.id(), gpu::Access::WriteOnly)};
    d.groups = glm::uvec3(static_cast<unsigned>((pass.width + 7) / 8),
                          static_cast<unsigned>((pass.height + 7) / 8), 1u);
    backend->dispatch(d);
    return target.id();
  }
  /// The local lights' own passes for an M (CreateInfo::spotLightBases, localLightBases) or table samples
  /// (spotLightTableSamples, localLightTableSamples) that differ from the directional light's, made on
  /// first use; the evaluations keyed by (M, Z).
  std::map<int, PrefilterPass> localPrefilters;
  std::map<std::pair<int, int>, EvaluatePass> localEvaluates;
  /// The exact reconstruction has no bases: every light shares the directional light's M (one pass each).
  bool exact() const { return info.prefilter.reconstruction == VisibilityReconstruction::Exact; }
  int localBases() const {
    return info.localLightBases == 0 || exact() ? info.prefilter.bases : info.localLightBases;
  }
  int spotBases() const {
    return info.spotLightBases == -1             ? localBases()
           : info.spotLightBases == 0 || exact() ? info.prefilter.bases
                                                 : info.spotLightBases;
  }
  int localTableSamples() const {
    const int Z = info.evaluate.visibilityTableSamples;
    return Z == 0 || info.localLightTableSamples == 0 ? Z : info.localLightTableSamples;
  }
  int spotTableSamples() const {
    return info.evaluate.visibilityTableSamples == 0 || info.spotLightTableSamples == 0
               ? localTableSamples()
               : info.spotLightTableSamples;
  }
  /// The prefilter and evaluation of local lights with M bases (their own passes, or the directional
  /// light's).
  PrefilterPass& localLightPrefilter(int M) {
    if (M == info.prefilter.bases) return prefilter;
    auto it = localPrefilters.find(M);
    if (it == localPrefilters.end()) {
      PrefilterOptions options = info.prefilter;
      options.bases = M;
      it = localPrefilters.emplace(M, prefilterInfo(info.mapSize, options, backend)).first;
    }
    return it->second;
  }
  EvaluatePass& localLightEvaluate(int M, int Z) {
    if (M == info.prefilter.bases && Z == info.evaluate.visibilityTableSamples) return evaluate;
    auto it = localEvaluates.find({M, Z});
    if (it == localEvaluates.end()) {
      EvaluateOptions options = info.evaluate;
      options.visibilityTableSamples = Z;
      it = localEvaluates
               .emplace(std::pair(M, Z), evaluateInfo(M, options, info.prefilter.reconstruction,
                                                      info.localLightClosedForm, backend))
               .first;
    }
    return it->second;
  }
  /// Light textures: the colour map of a rectified map (mapSize^2), made on the first textured frame.
  std::optional<LightColorMapPass> colorMap;
  /// Runs the colour map pass for `layout` and returns its texture.
  std::uint32_t lightColors(const RectifiedLayout& layout, const GpuLightTexture& texture,
                            const DirectionalLight* light, const LocalLight* localLight) {
    if (!colorMap) colorMap.emplace(LightColorMapPass::CreateInfo{info.mapSize, info.mapSize, backend});
    colorMap->run({.layout = &layout, .lightTexture = texture, .light = light, .localLight = localLight});
    return colorMap->colorMapTexture();
  }
  /// Night frames (no directional light): the transmittance pass's parameters.
  gpu::Buffer transmittanceParams;

  /// A night frame's output before the local lights are added: RGB 0, A the transmittance to the surface
  /// (the surface radiance's factor in Klehm et al. 2014, Eq. 1).
  void writeTransmittance(const FrameAttribs& f) {
    if (!transmittanceParams)
      transmittanceParams = gpu::Buffer(*backend, sizeof(gpu::MarchParams), "Scattering: transmittance");
    // The pass reads the camera and the medium's extinction only: any light fills the rest.
    const gpu::MarchParams params =
        gpu::makeMarchParams(*f.camera, DirectionalLight(glm::dvec3(0.0, -1.0, 0.0), glm::dvec3(0.0)),
                             *f.medium, info.width, info.height, 1, 1);
    backend->writeBuffer(transmittanceParams.id(), 0, std::as_bytes(std::span(&params, 1)));
    gpu::Dispatch d;
    d.label = "Scattering::run (transmittance)";
    d.program = "passes/pipeline/transmittance.comp";
    d.resources = {gpu::Resource::uniform(CREP_MARCH_PARAMS_BINDING, transmittanceParams.id()),
                   gpu::Resource::sampled(CREP_MARCH_CAMERA_DEPTH_UNIT, f.cameraDepth),
                   gpu::Resource::image(CREP_MARCH_SCATTERING_OUT_IMAGE, f.output, gpu::Access::WriteOnly)};
    d.groups =
        glm::uvec3(static_cast<unsigned>((info.width + 7) / 8), static_cast<unsigned>((info.height + 7) / 8),
                   1u); // gpu::dispatchMarch's 8 x 8 groups
    backend->dispatch(d);
  }

  /// Runs `work` as one stage: with stageTimings, the backend's GPU timer (GL_TIME_ELAPSED, Vulkan
  /// timestamps) and the wall clock, both ended by the backend's finish with blockingTimings; without, the
  /// span ended without waiting (its id kept for a later frame's gpuTimes) and the wall clock of recording.
  template <class Work>
  Stage timedStage(const char* name, const Work& work) {
    if (!info.stageTimings) {
      work();
      return {name, 0.0, 0.0};
    }
    const auto start = std::chrono::steady_clock::now();
    backend->beginTimer();
    try {
      work();
    } catch (...) {
      backend->cancelTimer(); // GL: no GL_TIME_ELAPSED query left active in the caller's context
      throw;
    }
    double gpu = 0.0;
    if (info.blockingTimings) {
      gpu = backend->endTimer();
    } else {
      frameTimers.add(backend->endTimerDeferred());
      spanLights.push_back(currentLight);
    }
    const std::chrono::duration<double, std::milli> wall = std::chrono::steady_clock::now() - start;
    return {name, gpu, wall.count()};
  }
  /// timedStage() appended to the frame's stages.
  template <class Work>
  void stage(FrameResult& r, const char* name, const Work& work) {
    r.stages.push_back(timedStage(name, work));
  }

  /// The directional light's map of a frame: its layout and texture, the standard shadow map of an
  /// epipolar frame (the engine's, or `own` rendered with drawCasters), the light colours.
  struct DirectionalMap {
    std::shared_ptr<const RectifiedLayout> layout;
    std::uint32_t map = 0, colors = 0;
    ShadowMap own;
    const ShadowMap* shadow = nullptr;
    bool treesFromResample = false; ///< the resampling wrote the trees' low levels
  };
  bool marching() const { return info.method == Method::MinMaxMarch; }
  void projectiveMap(const FrameAttribs& f, FrameResult& r, DirectionalMap& d, const ShadowPass& pass,
                     std::uint32_t planMap);
  void epipolarMap(const FrameAttribs& f, FrameResult& r, DirectionalMap& d, const ShadowPass& pass,
                   std::uint32_t planMap);
  void evaluateRays(const FrameAttribs& f, const DirectionalMap& d, std::uint32_t depth, std::uint32_t output,
                    const gpu::SampleList* list, bool reuseTable);
  void evaluatePixels(const FrameAttribs& f, FrameResult& r, const DirectionalMap& d);
  void epipoleBlock(const FrameAttribs& f, FrameResult& r, const DirectionalMap& d);

  struct LocalLightRun;
  void runLocalLight(const FrameAttribs& f, FrameResult& r, const LocalLight& light,
                     const Rectification& rect, const ShadowPass& pass, std::uint32_t planMap,
                     const ShadowMap* given, const GpuLightTexture* texture, LightResult result);
  void runLocalLights(const FrameAttribs& f, FrameResult& r, const PlannedFrame& planned);
  void validate(const FrameAttribs& f, const std::string& p, std::optional<PlannedFrame>* planned) const;
  /// The index of the run a frame validated or planned now belongs to: inside run() it is counted already.
  std::uint64_t thisRun() const { return running ? frames - 1 : frames; }
  /// The map the engine rendered for plan pass `i` (FrameAttribs::planMaps), 0 without a plan.
  static std::uint32_t planMap(const FrameAttribs& f, std::size_t i) {
    return f.plan != nullptr && i < f.planMaps.size() ? f.planMaps[i] : 0u;
  }
  /// Adds the local light's scattering to the output.
  void addLocalScattering(const FrameAttribs& f);
};

Scattering::Scattering(const CreateInfo& info) : impl_(std::make_unique<Impl>(info)) {}
Scattering::~Scattering() = default;
Scattering::Scattering(Scattering&&) noexcept = default;
Scattering& Scattering::operator=(Scattering&&) noexcept = default;

const Scattering::CreateInfo& Scattering::createInfo() const noexcept {
  static const CreateInfo movedFrom{};
  return impl_ ? impl_->info : movedFrom;
}

std::size_t Scattering::memoryBytes() const noexcept {
  if (!impl_) return 0; // moved from
  const Impl& m = *impl_;
  const std::size_t map =
      static_cast<std::size_t>(m.info.mapSize) * static_cast<std::size_t>(m.info.mapSize) * 4;
  // The R32F resampled map, and the D32F rasterized one once a frame has drawn casters into it.
  std::size_t bytes = m.prefilter.memoryBytes() + m.evaluate.memoryBytes() + (m.rectified ? map : 0) + map;
  if (m.reduced)
    bytes += static_cast<std::size_t>(m.reduced->lowWidth()) *
             static_cast<std::size_t>(m.reduced->lowHeight()) * 20;
  if (m.trees) bytes += m.trees->memoryBytes();
  if (m.sampling) bytes += m.sampling->memoryBytes();
  if (m.localRectified) bytes += map;
  if (m.unreversedStandard || m.localUnreversedStandard) {
    const std::size_t standard = static_cast<std::size_t>(m.info.ownShadowMapSize) *
                                 static_cast<std::size_t>(m.info.ownShadowMapSize) * 4;
    bytes += (m.unreversedStandard ? standard : 0) + (m.localUnreversedStandard ? standard : 0);
  }
  for (const auto& [M, pass] : m.localPrefilters)
    bytes += pass.memoryBytes();
  for (const auto& [M, pass] : m.localEvaluates)
    bytes += pass.memoryBytes();
  if (m.localResampled) bytes += map;
  if (m.colorMap) bytes += m.colorMap->memoryBytes();
  if (m.localScattering)
    bytes += static_cast<std::size_t>(m.info.width) * static_cast<std::size_t>(m.info.height) * 16;
  if (m.localShadowMap)
    bytes += static_cast<std::size_t>(m.localShadowMap->size) *
             static_cast<std::size_t>(m.localShadowMap->size) * 4;
  if (m.ownShadowMap)
    bytes +=
        static_cast<std::size_t>(m.ownShadowMap->size) * static_cast<std::size_t>(m.ownShadowMap->size) * 4;
  return bytes;
}

Scattering::FrameResult Scattering::run(const FrameAttribs& f) {
  if (!impl_)
    invalid("Scattering", "a moved-from object",
            "owns no GPU resources: assign a constructed Scattering first");
  Impl& m = *impl_;
  if (m.running)
    invalid("Scattering::run",
            "called while a frame of the same object runs (from FrameAttribs.drawCasters?)",
            "must not be re-entered");
  // What the caller's state must not be, since the library cannot set it aside (docs/GL_STATE.md).
  if (m.gl) {
    gl::requireNoPendingError("Scattering::run");
    gl::requireNoActiveTransformFeedback("Scattering::run");
    if (m.info.stageTimings) gl::requireNoActiveTimerQuery("Scattering::run (CreateInfo.stageTimings)");
  }
  // However the frame ends: no query of ours active, program 0 and units / binding points 0-7 unbound
  // (docs/GL_STATE.md), and the object ready for the next frame. The raster state is restored by the
  // depth passes' own scopes.
  m.running = true;
  const std::uint64_t frame = m.frames++;
  struct OnExit {
    Impl& m;
    ~OnExit() {
      m.backend->cancelTimer();
      if (m.gl) gl::unbindPassState(8);
      m.running = false;
      m.currentLight = -1;
    }
  } onExit{m};
  try {
    FrameResult r = runFrame(f);
    r.frame = frame;
    if (m.info.stageTimings && !m.info.blockingTimings) m.reportTimes(r);
    return r;
  } catch (...) {
    // Raised during this call (by a pass or the caller's callback): not left to the caller. The frame's
    // spans are never reported.
    m.frameTimers.discardFrame();
    m.spanLights.clear();
    if (m.gl) gl::drainErrors();
    throw;
  }
}

double Scattering::GpuTimes::totalMilliseconds() const {
  double sum = 0.0;
  for (const Stage& s : stages)
    sum += s.gpuMilliseconds;
  return sum;
}

// The frame's spans wait for their GPU times; the latest earlier frame whose times have all arrived is
// reported (polled, never waited for).
void Scattering::Impl::reportTimes(FrameResult& r) {
  const std::optional<gpu::FrameTimers::Times> arrived = frameTimers.poll(*backend); // earlier frames only
  frameTimers.endFrame(r.frame);
  frameRecords.push_back({r.frame, r.stages, std::move(spanLights), r.localLights.size()});
  spanLights.clear();
  if (frameRecords.size() > gpu::FrameTimers::kMaxPendingFrames) frameRecords.pop_front();
  if (!arrived) return;
  const auto it = std::find_if(frameRecords.begin(), frameRecords.end(),
                               [&](const FrameRecord& record) { return record.frame == arrived->frame; });
  if (it == frameRecords.end()) return;
  GpuTimes times;
  times.frame = it->frame;
  times.stages = std::move(it->stages);
  times.localLights.assign(it->lights, 0.0);
  for (std::size_t i = 0; i < times.stages.size() && i < arrived->milliseconds.size(); ++i) {
    times.stages[i].gpuMilliseconds = arrived->milliseconds[i];
    const int light = it->stageLights[i];
    if (light >= 0) times.localLights[static_cast<std::size_t>(light)] += arrived->milliseconds[i];
  }
  frameRecords.erase(frameRecords.begin(), it + 1);
  r.gpuTimes = std::move(times);
}

ShadowPassPlan Scattering::plan(const FrameAttribs& f, const ShadowPassPlanOptions& options) const {
  if (!impl_)
    invalid("Scattering", "a moved-from object",
            "owns no GPU resources: assign a constructed Scattering first");
  requireCameraAndLight(f, "Scattering::FrameAttribs.");
  return planFrame(impl_->info, f, options, impl_->thisRun()).plan;
}

// Scattering::validate's checks, `p` the owner with its dot. With a plan, the frame's own plan is made to
// compare it with and left in `planned` for run().
void Scattering::Impl::validate(const FrameAttribs& f, const std::string& p,
                                std::optional<PlannedFrame>* planned) const {
  const gpu::Backend& b = *backend;
  const bool local = !f.spotLights.empty() || !f.pointLights.empty();
  requireCameraAndLight(f, p);
  if (!f.medium) invalid(p + "medium", "null", "must be set");
  if (f.output != 0 || !f.froxels) { // a froxel volume alone reads no camera depth
    gpu::requireTexture2DOf(b, (p + "cameraDepth").c_str(), f.cameraDepth, info.width, info.height);
    gpu::requireTexture2DOf(b, (p + "output").c_str(), f.output, info.width, info.height,
                            gpu::Format::RGBA32F);
    requireOutputNotAnInput(f, p);
    gpu::requireDepthFormatOf(b, (p + "cameraDepth").c_str(), f.cameraDepth);
  }
  if (f.froxels) {
    if (!f.light)
      invalid(p + "froxels", "set without a directional light",
              "needs FrameAttribs::light (local lights are not added to froxel volumes)");
    if (f.output == 0 && local)
      invalid(p + "output", "0",
              "must be set with local lights (they are added to the per-pixel output only)");
    validateFroxelTarget(b, *f.froxels, *f.camera, p + "froxels");
    if (info.method != Method::Prefiltered)
      invalid(p + "froxels", "set with CreateInfo.method = Method::MinMaxMarch",
              "needs Method::Prefiltered (the fill evaluates the prefiltered basis)");
  }
  if (f.light && !f.drawCasters && !f.shadowMap && !f.plan)
    invalid(p + "drawCasters/shadowMap", "both empty, and no plan",
            "one shadow input must be given (drawCasters, shadowMap, or plan and planMaps)");
  if (f.drawCasters && !gl)
    invalid(p + "drawCasters", "set on the " + std::string(b.name()) + " backend",
            "draws with GL, on the OpenGL backend only: give shadowMap, spotShadowMaps and pointShadowMaps");
  validateLocalShadowMaps(b, f, p);
  validateLightTextures(b, f, info.evaluate, p);
  if (f.plan) {
    PlannedFrame expected = planFrame(info, f, f.plan->options, thisRun());
    validatePlan(b, f, expected.plan, p);
    if (planned) *planned = std::move(expected);
  }
  if (f.light && f.shadowMap) {
    gpu::requireTexture2DOf(b, (p + "shadowMap.texture").c_str(), f.shadowMap->texture);
    gpu::requireDepthFormatOf(b, (p + "shadowMap.texture").c_str(), f.shadowMap->texture);
    requireFinite(p + "shadowMap.bias", f.shadowMap->bias);
    try {
      validateLightMatrix(f.shadowMap->lightClipFromWorld, f.light->direction());
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(p + "shadowMap.lightClipFromWorld", e.what(),
                            "an orthographic shadow matrix looking along the light");
    }
  }
}

void Scattering::validate(const FrameAttribs& f, std::string_view owner) const {
  if (!impl_)
    invalid("Scattering", "a moved-from object",
            "owns no GPU resources: assign a constructed Scattering first");
  impl_->validate(f, std::string(owner) + ".", nullptr);
}

Scattering::FrameResult Scattering::runFrame(const FrameAttribs& f) {
  Impl& m = *impl_;
  std::optional<PlannedFrame> made; // the frame's plan, made by validate() when the engine gave one
  m.validate(f, "Scattering::FrameAttribs.", &made);
  FrameResult r;
  // The frame's plan: the engine's (FrameAttribs::plan, checked equal by validate()), or the GL
  // convenience's, whose maps drawCasters renders.
  if (!made) made = planFrame(m.info, f, ShadowPassPlanOptions{}, m.thisRun());
  const PlannedFrame& planned = *made;
  if (!f.light) {
    // A night frame: the transmittance, then the local lights added.
    m.stage(r, "transmittance", [&] { m.writeTransmittance(f); });
    m.runLocalLights(f, r, planned);
    if (m.gl) gl::checkError("Scattering::run");
    return r;
  }
  r.rectification = planned.sun;
  Impl::DirectionalMap d;
  d.shadow = f.shadowMap;
  if (r.rectification.projective())
    m.projectiveMap(f, r, d, planned.plan.passes[0], Impl::planMap(f, 0));
  else
    m.epipolarMap(f, r, d, planned.plan.passes[0], Impl::planMap(f, 0));
  r.rectifiedMap = {d.layout, d.map, m.info.mapSize, m.info.mapSize};
  // Light textures (Klehm et al. 2014, Sec. 3.2): the colour of every texel's light ray on this frame's
  // layout (projective or epipolar), prefiltered per colour channel.
  if (f.lightTexture)
    m.stage(r, "light colours",
            [&] { d.colors = m.lightColors(*d.layout, *f.lightTexture, f.light, nullptr); });
  if (m.marching())
    m.stage(r, "min/max trees", [&] { m.trees->run(d.map); });
  else
    m.stage(r, "prefilter", [&] {
      m.prefilter.run(
          {.rectifiedDepth = d.map, .layout = d.layout.get(), .medium = f.medium, .lightColors = d.colors});
    });
  const bool pixels = f.output != 0;
  if (pixels) m.evaluatePixels(f, r, d);
  if (f.froxels)
    m.stage(r, "froxels", [&] {
      // The same basis evaluated at the volume's cells (EvaluatePass::FrameAttribs::froxels), from the
      // scattering prefix table the per-pixel evaluation built (reuseTable), so the stage times the fill.
      EvaluatePass::FrameAttribs e;
      e.camera = f.camera;
      e.light = f.light;
      e.medium = f.medium;
      e.layout = d.layout.get();
      e.basis = m.prefilter.filteredBasis();
      e.froxels = {f.froxels->volume, f.froxels->grid, f.froxels->jitter};
      e.reuseTable = pixels;
      m.evaluate.run(e);
    });
  if (r.layout == Layout::Epipolar && pixels && !m.marching()) m.epipoleBlock(f, r, d);
  m.runLocalLights(f, r, planned);
  if (m.gl) gl::checkError("Scattering::run");
  return r;
}

// Klehm et al. 2014, Sec. 4.2: the engine's map of the plan's pass, or the casters rendered once per split
// with its matrix (drawCasters), or the engine's standard map resampled.
void Scattering::Impl::projectiveMap(const FrameAttribs& f, FrameResult& r, DirectionalMap& d,
                                     const ShadowPass& pass, std::uint32_t planMap) {
  r.layout = Layout::Projective;
  auto projective = std::make_shared<const ProjectiveLayout>(r.rectification);
  d.layout = projective;
  if (planMap != 0) {
    d.map = planMap;
    if (f.plan->options.reversedZ)
      stage(r, "reversed-Z map",
            [&] { d.map = unreversed(planMap, pass, resampled, "Scattering: resampled map"); });
  } else if (f.drawCasters) {
    DepthTarget& target = DepthTarget::of(rectified, info.mapSize);
    stage(r, "shadow pass (rectified)",
          [&] { target.render("Scattering::FrameAttribs.drawCasters", pass, f.drawCasters); });
    d.map = target.texture.get();
  } else {
    stage(r, "resample (projective)", [&] {
      resample.run({projective.get(), d.shadow->texture, d.shadow->lightClipFromWorld, resampled.id()});
    });
    d.map = resampled.id();
  }
}

// Sec. 4.1: the standard shadow map resampled into epipolar slices (mapSize of them, so the cost of the frame
// stays that of a projective one).
void Scattering::Impl::epipolarMap(const FrameAttribs& f, FrameResult& r, DirectionalMap& d,
                                   const ShadowPass& pass, std::uint32_t planMap) {
  r.layout = Layout::Epipolar;
  const EpipolarOptions options = epipolarOptions(info, info.epipolarDepthWarp, info.epipoleBlockRadius);
  auto epipolar =
      std::make_shared<const EpipolarLayout>(*f.camera, *f.light, info.width, info.height, options);
  d.layout = epipolar;
  if (!d.shadow) {
    // The plan's standard map covering the frustum (casters between the light and it kept by depth clamp):
    // the engine's, or rendered with drawCasters.
    d.own.lightClipFromWorld = pass.glClipFromWorld;
    d.own.bias = info.ownShadowMapBias;
    if (planMap != 0) {
      d.own.texture = planMap;
      if (f.plan->options.reversedZ)
        stage(r, "reversed-Z map", [&] {
          d.own.texture = unreversed(planMap, pass, unreversedStandard, "Scattering: standard map");
        });
    } else {
      DepthTarget& target = DepthTarget::of(ownShadowMap, info.ownShadowMapSize);
      d.own.texture = target.texture.get();
      stage(r, "shadow pass (standard)",
            [&] { target.render("Scattering::FrameAttribs.drawCasters", pass, f.drawCasters); });
    }
    d.shadow = &d.own;
  }
  r.shadowMap = *d.shadow;
  // A tree-marched epipole block (Fig. 8's block on screen) needs the map's min/max trees: their low levels
  // are written by the resampling itself (the map read once), the rest after it (the block's stage).
  const bool treeMarchedBlock =
      info.method == Method::Prefiltered && info.epipoleBlockMethod == EpipoleBlockMethod::TreeMarch &&
      epipolar->epipolePixel().has_value() && epipolar->epipoleBlockRadiusPixels() > 0.0;
  d.treesFromResample = treeMarchedBlock && f.output != 0 && MinMaxTreePass::lowLevels(info.mapSize) >= 1;
  stage(r, "resample (epipolar)", [&] {
    resample.run({epipolar.get(), d.shadow->texture, d.shadow->lightClipFromWorld, resampled.id(),
                  d.treesFromResample ? trees->treeBuffer() : 0u});
  });
  d.map = resampled.id();
}

// The method on a camera depth image into `output`, or on a GPU work list (epipolar sampling's samples and
// corrections: EvaluatePass / RectifiedMarchPass FrameAttribs::list).
void Scattering::Impl::evaluateRays(const FrameAttribs& f, const DirectionalMap& d, std::uint32_t depth,
                                    std::uint32_t output, const gpu::SampleList* list, bool reuseTable) {
  if (marching()) {
    RectifiedMarchPass::FrameAttribs a;
    a.layout = d.layout.get();
    a.camera = f.camera;
    a.light = f.light;
    a.medium = f.medium;
    a.cameraDepth = depth;
    a.rectifiedDepth = d.map;
    a.minMaxBuffer = trees->treeBuffer();
    a.output = output;
    a.lightColors = d.colors;
    a.list = list;
    if (list) {
      a.imageWidth = info.width;
      a.imageHeight = info.height;
    }
    march->run(a);
  } else {
    EvaluatePass::FrameAttribs e;
    e.cameraDepth = depth;
    e.output = output;
    e.camera = f.camera;
    e.light = f.light;
    e.medium = f.medium;
    e.layout = d.layout.get();
    e.basis = prefilter.filteredBasis();
    e.list = list;
    if (list) {
      e.imageWidth = info.width;
      e.imageHeight = info.height;
    }
    e.reuseTable = reuseTable;
    evaluate.run(e);
  }
}

// The per-pixel output: every pixel (at evaluationScale), or epipolar sampling's samples and corrections.
void Scattering::Impl::evaluatePixels(const FrameAttribs& f, FrameResult& r, const DirectionalMap& d) {
  if (reduced) stage(r, "downsample depth", [&] { reduced->downsample(f.cameraDepth, lowDepth.id()); });
  if (!sampling)
    stage(r, marching() ? "march" : "evaluate", [&] {
      evaluateRays(f, d, reduced ? lowDepth.id() : f.cameraDepth, reduced ? lowOutput.id() : f.output,
                   nullptr, false);
    });
  if (sampling) {
    // Yusov 2012, Sec. 6: samples along epipolar lines, refined at breaks; the method evaluates the
    // selected ones and the pixels the unwarp cannot serve (the lists, no read-back).
    const EpipolarSamplingPass::FrameAttribs s{f.camera, f.light, f.medium, f.cameraDepth, f.output};
    EpipolarSamplingPass& pass = *sampling;
    stage(r, "epipolar samples", [&] { pass.placeSamples(s); });
    stage(r, "refine samples", [&] { pass.refine(); });
    stage(r, marching() ? "march samples" : "evaluate samples",
          [&] { evaluateRays(f, d, 0, 0, &pass.sampleList(), false); });
    stage(r, "interpolate", [&] { pass.interpolate(); });
    stage(r, "unwarp", [&] { pass.unwarp(s); });
    stage(r, "correct", [&] { evaluateRays(f, d, 0, 0, &pass.correctionList(), true); });
    if (info.epipolarSampling.downscale > 1) {
      stage(r, "upscale", [&] { pass.upscale(s); });
      stage(r, "correct (full)", [&] { evaluateRays(f, d, 0, 0, &pass.upscaleCorrectionList(), true); });
    }
    if (info.stageTimings && info.blockingTimings) { // a read-back: it waits for the GPU
      const EpipolarSamplingPass::Statistics st = pass.statistics();
      r.sampling = {st.validSamples, st.marchedSamples, st.correctedPixels, st.correctedFullPixels};
    }
  }
  if (reduced)
    stage(r, "upsample",
          [&] { reduced->upsample(lowOutput.id(), lowDepth.id(), f.cameraDepth, f.output, *f.camera); });
}

// Fig. 8: the pixels next to the epipole, where the slices converge and the prefilter's weights, exact for
// one reference ray per region, fit the rays nearly parallel to the light worst.
void Scattering::Impl::epipoleBlock(const FrameAttribs& f, FrameResult& r, const DirectionalMap& d) {
  const auto& epipolar = static_cast<const EpipolarLayout&>(*d.layout);
  const auto centre = epipolar.epipolePixel();
  const double radius = epipolar.epipoleBlockRadiusPixels();
  if (!centre || !(radius > 0.0)) return;
  r.epipoleBlockRadius = radius;
  if (info.epipoleBlockMethod == EpipoleBlockMethod::TreeMarch) {
    // The min/max tree march over the same epipolar map (Chen et al. 2011; Yusov 2012, Algorithm 2): exact
    // visibility on the map, the walk skipping lit and shadowed runs of texels whole, so the cost is the
    // block's pixels (at most epipoleBlockMaxPixels) times a short walk.
    stage(r, "min/max trees (epipole block)", [&] {
      if (d.treesFromResample)
        trees->completeUpperLevels();
      else
        trees->run(d.map);
    });
    stage(r, "epipole block (tree march)", [&] {
      RectifiedMarchPass::FrameAttribs a;
      a.layout = d.layout.get();
      a.camera = f.camera;
      a.light = f.light;
      a.medium = f.medium;
      a.cameraDepth = f.cameraDepth;
      a.rectifiedDepth = d.map;
      a.minMaxBuffer = trees->treeBuffer();
      a.output = f.output;
      a.lightColors = d.colors;
      a.blockCenter = *centre;
      a.blockRadius = radius;
      march->run(a);
    });
  } else {
    stage(r, "epipole block (world march)", [&] {
      WorldMarchPass::FrameAttribs b;
      b.camera = f.camera;
      b.light = f.light;
      b.medium = f.medium;
      b.cameraDepth = f.cameraDepth;
      b.shadowMap = d.shadow->texture;
      b.lightClipFromWorld = d.shadow->lightClipFromWorld;
      b.bias = d.shadow->bias;
      b.output = f.output;
      b.blockCenter = *centre;
      b.blockRadius = radius;
      if (f.lightTexture) b.lightTexture = *f.lightTexture;
      block.run(b);
    });
  }
}

/// One local light of a frame (a spot, or one point-light face) and its stages, timed into `result` and
/// the frame's stages.
struct Scattering::Impl::LocalLightRun {
  Impl& m;
  const FrameAttribs& f;
  FrameResult& r;
  const LocalLight& light;
  const ShadowPass& pass; ///< the plan's (the engine's, or the GL convenience's)
  std::uint32_t planMap;  ///< the engine's map of `pass`, or 0
  const ShadowMap* given;
  const GpuLightTexture* texture;
  LightResult& result;

  template <class Work>
  void timed(const char* name, const Work& work) {
    const Stage s = m.timedStage(name, work);
    r.stages.push_back(s);
    result.wallMilliseconds += s.wallMilliseconds;
    result.gpuMilliseconds += s.gpuMilliseconds;
  }

  // The light's perspective map: the given one, else the plan's standard pass (the engine's map, or rendered
  // with drawCasters).
  ShadowMap perspectiveMap() {
    if (given) return *given;
    ShadowMap map{planMap, pass.glClipFromWorld, m.info.ownShadowMapBias};
    if (planMap != 0) {
      if (f.plan->options.reversedZ)
        timed("local light: reversed-Z map", [&] {
          map.texture =
              m.unreversed(planMap, pass, m.localUnreversedStandard, "Scattering: local standard map");
        });
      return map;
    }
    DepthTarget& target = DepthTarget::of(m.localShadowMap, m.info.ownShadowMapSize);
    timed("local light: shadow pass (perspective)",
          [&] { target.render("Scattering::FrameAttribs.drawCasters", pass, f.drawCasters); });
    map.texture = target.texture.get();
    return map;
  }

  // Sec. 4.1's point resampling of a perspective map into `layout` (no casters drawn).
  std::uint32_t resampled(const RectifiedLayout& layout, const ShadowMap& shadow, const char* name) {
    const std::uint32_t target = m.localMap().id();
    timed(name, [&] { m.resample.run({&layout, shadow.texture, shadow.lightClipFromWorld, target}); });
    return target;
  }

  // The light's map on `layout` prefiltered with its light-side factor and evaluated into its image.
  void prefiltered(const RectifiedLayout& layout, std::uint32_t map) {
    std::uint32_t colors = 0;
    if (texture)
      timed("local light: light colours", [&] { colors = m.lightColors(layout, *texture, nullptr, &light); });
    const int M = light.cone ? m.spotBases() : m.localBases();
    const int Z = light.cone && dynamic_cast<const ProjectiveLayout*>(&layout) != nullptr
                      ? m.spotTableSamples()
                      : m.localTableSamples();
    timed("local light: prefilter", [&] {
      m.localLightPrefilter(M).run({.rectifiedDepth = map,
                                    .layout = &layout,
                                    .medium = f.medium,
                                    .localLight = &light,
                                    .lightColors = colors});
    });
    timed("local light: evaluate", [&] {
      EvaluatePass::FrameAttribs e;
      e.cameraDepth = f.cameraDepth;
      e.output = m.localScattering.id();
      e.camera = f.camera;
      e.medium = f.medium;
      e.layout = &layout;
      e.basis = m.localLightPrefilter(M).filteredBasis();
      e.localLight = &light;
      m.localLightEvaluate(M, Z).run(e);
    });
  }

  // The world-space march of the light against a perspective map, into the light's image: every pixel, or
  // those within `radius` pixels of `centre` (radius >= 0).
  void worldMarch(const ShadowMap& shadow, glm::dvec2 centre, double radius, const char* name) {
    timed(name, [&] {
      WorldMarchPass::FrameAttribs b;
      b.camera = f.camera;
      b.localLight = &light;
      b.medium = f.medium;
      b.cameraDepth = f.cameraDepth;
      b.shadowMap = shadow.texture;
      b.lightClipFromWorld = shadow.lightClipFromWorld;
      b.bias = shadow.bias;
      b.output = m.localScattering.id();
      b.blockCenter = centre;
      b.blockRadius = radius;
      if (texture) b.lightTexture = *texture;
      m.block.run(b);
    });
  }

  // The projective rectification: the engine's map of the plan's pass, the given map resampled, or the
  // casters rendered per split (drawCasters).
  void projective(const Rectification& rect) {
    const ProjectiveLayout layout(rect);
    std::uint32_t map = planMap;
    if (planMap != 0) {
      if (f.plan->options.reversedZ)
        timed("local light: reversed-Z map",
              [&] { map = m.unreversed(planMap, pass, m.localMap(), "Scattering: local map"); });
    } else if (given) {
      map = resampled(layout, *given, "local light: resample (projective)");
    } else {
      DepthTarget& target = DepthTarget::of(m.localRectified, m.info.mapSize);
      timed("local light: shadow pass (rectified)",
            [&] { target.render("Scattering::FrameAttribs.drawCasters", pass, f.drawCasters); });
      map = target.texture.get();
    }
    prefiltered(layout, map);
  }

  // In or near the view: Sec. 4.1's epipolar layout around the camera-light axis (the light's image is the
  // epipole), mapSize slices, the light's perspective map resampled into it.
  void epipolar() {
    const CreateInfo& info = m.info;
    const EpipolarOptions options =
        epipolarOptions(info, info.localLightDepthWarp, info.localLightBlockRadius);
    const EpipolarLayout layout(*f.camera, light.position, info.width, info.height, options);
    result.epipolar = true;
    const ShadowMap shadow = perspectiveMap();
    prefiltered(layout, resampled(layout, shadow, "local light: resample (epipolar)"));
    // Fig. 8's epipole block around the light's image: there every slice meets and a pixel's rays cross
    // every light ray within a short distance of the light.
    const std::optional<glm::dvec2> centre = layout.epipolePixel();
    const double radius = layout.epipoleBlockRadiusPixels();
    if (centre && radius > 0.0)
      worldMarch(shadow, *centre, radius, "local light: epipole block (world march)");
  }
};

void Scattering::Impl::addLocalScattering(const FrameAttribs& f) {
  gpu::Dispatch d;
  d.label = "Scattering::run (add a local light)";
  d.program = "passes/pipeline/accumulate.comp";
  d.resources = {
      gpu::Resource::image(CREP_ACCUMULATE_ACCUMULATED_IMAGE, f.output, gpu::Access::ReadWrite),
      gpu::Resource::image(CREP_ACCUMULATE_ADDEND_IMAGE, localScattering.id(), gpu::Access::ReadOnly)};
  d.groups = glm::uvec3(static_cast<unsigned>((info.width + 7) / 8),
                        static_cast<unsigned>((info.height + 7) / 8), 1u);
  backend->dispatch(d);
}

void Scattering::Impl::runLocalLight(const FrameAttribs& f, FrameResult& r, const LocalLight& light,
                                     const Rectification& rect, const ShadowPass& pass, std::uint32_t planMap,
                                     const ShadowMap* given, const GpuLightTexture* texture,
                                     LightResult result) {
  result.status = rect.status;
  result.message = rect.message;
  result.preRenderedMap = given != nullptr;
  if (rect.status == RectifyStatus::Empty) {
    r.localLights.push_back(result);
    return;
  }
  LocalLightRun run{*this, f, r, light, pass, planMap, given, texture, result};
  currentLight = static_cast<int>(r.localLights.size()); // its deferred spans are its LightResult's
  if (rect.projective())
    run.projective(rect);
  else if (info.localLightFallback == LocalLightFallback::Epipolar && info.epipolarRegions >= 2 &&
           glm::length(light.position - f.camera->position()) > f.camera->near())
    run.epipolar();
  else // the world-space march against the light's perspective map (the reference)
    run.worldMarch(run.perspectiveMap(), glm::dvec2(0.0), -1.0, "local light: world-space march");
  currentLight = -1;
  addLocalScattering(f);
  r.localLights.push_back(result);
}

// Klehm et al. 2014, Sec. 3.2 "Local Lights": every spot light and point-light face rectified for the camera,
// prefiltered with its light-side factor on its projective layout, or in or near the view on its epipolar
// layout (or marched in world space, CreateInfo::localLightFallback), and added.
void Scattering::Impl::runLocalLights(const FrameAttribs& f, FrameResult& r, const PlannedFrame& planned) {
  Impl& m = *this;
  if (f.spotLights.empty() && f.pointLights.empty()) return;
  if (!m.localScattering)
    m.localScattering = gpu::Texture(*m.backend, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F,
                                                  info.width, info.height, 1, "Scattering: local light"});
  // Plan pass first + k is local light k (the sun's pass first).
  const std::size_t first = f.light ? 1 : 0;
  std::size_t k = 0;
  for (std::size_t i = 0; i < f.spotLights.size(); ++i) {
    const SpotLight& spot = f.spotLights[i];
    LightResult result;
    result.kind = LightResult::Kind::Spot;
    result.index = static_cast<int>(i);
    const GpuLightTexture* texture = i < f.spotLightTextures.size() && f.spotLightTextures[i].texture != 0
                                         ? &f.spotLightTextures[i]
                                         : nullptr;
    m.runLocalLight(f, r, LocalLight::spot(spot), planned.locals[k], planned.plan.passes[first + k],
                    planMap(f, first + k), f.spotShadowMaps.empty() ? nullptr : &f.spotShadowMaps[i], texture,
                    result);
    ++k;
  }
  for (std::size_t i = 0; i < f.pointLights.size(); ++i) {
    const PointLight& point = f.pointLights[i];
    for (int face = 0; face < 6; ++face) {
      LightResult result;
      result.kind = LightResult::Kind::PointFace;
      result.index = static_cast<int>(i);
      result.face = face;
      m.runLocalLight(f, r, LocalLight::pointFace(point, face), planned.locals[k],
                      planned.plan.passes[first + k], planMap(f, first + k),
                      f.pointShadowMaps.empty() ? nullptr
                                                : &f.pointShadowMaps[6 * i + static_cast<std::size_t>(face)],
                      nullptr, result);
      ++k;
    }
  }
}

} // namespace crep
