// GPU prefilter and evaluation passes of prefiltered single scattering: Klehm, Seidel, Eisemann 2014,
// Sec. 3.3 (fused basis transform and weighted prefix filter, Listings 2-3; regions and bases per thread,
// Table 1; normalized storage, Appendix A) and the per-pixel evaluation (Listing 4). The shaders are
// glsl/passes/prefilter/prefilter.comp, glsl/passes/prefilter/evaluate.comp and the public
// glsl/crep/scattering.glsl; the host side here validates, computes the per-row weight data in double
// (gpu::RegionWeights), fills the shared blocks (gpu_structs.h) and dispatches. Contract:
// crep/prefilter/prefilter.h.
#include <crep/core/error.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/shader_library.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/scatter/airlight.h>
#include <crep/scatter/gpu_world_march.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <new>
#include <optional>
#include <string>
#include <utility>

namespace crep {

static_assert(static_cast<int>(WeightMode::AverageVisibility) == 0 &&
                  static_cast<int>(WeightMode::ConstantStep) == 1 &&
                  static_cast<int>(WeightMode::ConstantRatio) == 2 &&
                  static_cast<int>(WeightMode::Exact) == 3,
              "CREP_WEIGHTS_* of glsl/crep/scattering_structs.glsl");
static_assert(gpu::kMaxSplits == RectifyOptions::kMaxSplits, "CREP_MAX_SPLITS");

namespace {

// Binding points: the names of crep/bindings.h (the evaluation's defaults; layouts and work lists at
// CREP_EVALUATE_LAYOUT_BINDING, CREP_EVALUATE_SLICES_BINDING and CREP_EVALUATE_SAMPLE_LIST_BINDING, injected
// as defines).

std::string str(long long v) {
  return std::to_string(v);
}

int ceilDiv(int a, int b) {
  return (a + b - 1) / b;
}

/// Bases per invocation of the program: options.basesPerInvocation, or for a local light (the light-side
/// weights of a texel computed by every invocation of its row and region) all of M up to 32 in one.
/// GPU: 32 bases keep 8 vec4 accumulators live, and 1024 rows x 16 regions still fill a GPU; on llvmpipe one
/// invocation computing a texel's three light factors once is 23% faster (63 -> 49 ms at 1024^2, M = 32).
int basesPerInvocation(const PrefilterPass::CreateInfo& info, bool local) {
  const int b = info.options.basesPerInvocation;
  return local ? std::max(b, std::min(32, 4 * layerCount(info.options.bases))) : b;
}

/// Invocations per row and region: groups of basesPerInvocation / 4 layers (the last may be partial).
int baseGroups(const PrefilterPass::CreateInfo& info, bool local = false) {
  if (info.options.reconstruction == VisibilityReconstruction::Exact) return 1; // no bases
  return ceilDiv(layerCount(info.options.bases), basesPerInvocation(info, local) / 4);
}

void requireAtLeast(const char* parameter, int value, int minimum) {
  if (value < minimum) invalid(parameter, detail::formatValue(value), "must be >= " + str(minimum));
}

/// Local size and dispatch counts against the backend's compute limits (GL_MAX_COMPUTE_WORK_GROUP_{SIZE,
/// INVOCATIONS,COUNT} on GL).
void checkWorkgroup(const gpu::Backend& backend, const char* const names[3], const int local[3],
                    const int groups[3]) {
  const gpu::ComputeLimits limits = backend.computeLimits();
  long long invocations = 1;
  for (int axis = 0; axis < 3; ++axis) {
    if (local[axis] > limits.groupSize[axis])
      gpu::throwBeyondLimit(backend, names[axis], str(local[axis]),
                            "GL_MAX_COMPUTE_WORK_GROUP_SIZE[" + str(axis) + "]",
                            "work-group size on axis " + str(axis), limits.groupSize[axis]);
    if (groups[axis] > limits.groupCount[axis])
      gpu::throwBeyondLimit(backend, names[axis],
                            str(local[axis]) + " (" + str(groups[axis]) + " workgroups)",
                            "GL_MAX_COMPUTE_WORK_GROUP_COUNT[" + str(axis) + "]",
                            "work-group count on axis " + str(axis), limits.groupCount[axis]);
    invocations *= local[axis];
  }
  if (invocations > limits.invocations)
    gpu::throwBeyondLimit(backend, std::string(names[0]) + " x " + names[1] + " x " + names[2],
                          str(invocations), "GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS",
                          "invocations per work group", limits.invocations);
}

gpu::Format basisFormat(StorageFormat format);

/// The basis array's texel format: the options' storage, or for the exact reconstruction (depth, cumulative
/// weight) in RG32F, (depth, three colours' weights) in RGBA32F with a light texture (GPU: 8 bytes per texel
/// of the per-pixel walk instead of 16).
gpu::Format arrayFormat(const PrefilterOptions& o, bool textured) {
  if (o.reconstruction != VisibilityReconstruction::Exact) return basisFormat(o.format);
  return textured ? gpu::Format::RGBA32F : gpu::Format::RG32F;
}

gpu::Format basisFormat(StorageFormat format) {
  switch (format) {
  case StorageFormat::RGBA8:
    return gpu::Format::RGBA8;
  case StorageFormat::RGBA16F:
    return gpu::Format::RGBA16F;
  case StorageFormat::RGBA32F:
    break;
  }
  return gpu::Format::RGBA32F;
}

/// The GLSL image format qualifier of a basis array's texel format (arrayFormat()).
const char* imageFormatQualifier(gpu::Format format) {
  switch (format) {
  case gpu::Format::RGBA8:
    return "rgba8";
  case gpu::Format::RGBA16F:
    return "rgba16f";
  case gpu::Format::RG32F:
    return "rg32f";
  default:
    return "rgba32f";
  }
}

std::string sizeString(int w, int h) {
  return str(w) + " x " + str(h);
}

glm::vec4 vec4Of(const glm::dvec3& v, double w = 0.0) {
  return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z), static_cast<float>(w)};
}

/// Eq. 12 parameters as crep::regionMixFactors defines them (weights.h): first texel length D0 and the
/// log of the step ratio of the first three texel centres.
void ratioParameters(const DistanceProfile& p, int n, double& first, double& logRatio) {
  first = p.fromStart(1.0 / n);
  logRatio = 0.0;
  if (n >= 3) {
    const double t0 = p.fromStart(0.5 / n), t1 = p.fromStart(1.5 / n), t2 = p.fromStart(2.5 / n);
    const double ratio = (t2 - t1) / (t1 - t0);
    if (std::isfinite(ratio) && ratio > 0.0) logRatio = std::log(ratio);
  }
}

} // namespace

// ---------------------------------------------------------------------------------------------------

std::vector<gpu::RegionWeights> gpuRegionWeights(const std::vector<DistanceProfile>& profiles,
                                                 WeightMode mode, int texelsPerRegion) {
  if (texelsPerRegion < 1) invalid("texelsPerRegion", detail::formatValue(texelsPerRegion), "must be >= 1");
  const int n = texelsPerRegion;
  std::vector<gpu::RegionWeights> out(profiles.size());
  for (std::size_t i = 0; i < profiles.size(); ++i) {
    const DistanceProfile& p = profiles[i];
    gpu::RegionWeights& w = out[i];
    double scale = 0.0, c = 0.0, d = 0.0;
    bool valid = true;
    switch (mode) {
    case WeightMode::Exact:
      // tau(u) = u (b c - a d) / (c (c + d u)) = u scale / (c + d u) (DistanceProfile::fromStart).
      valid = p.c > 0.0;
      scale = valid ? (p.b * p.c - p.a * p.d) / p.c : 0.0;
      c = p.c;
      d = p.d;
      break;
    case WeightMode::ConstantStep:
      scale = p.fromStart(1.0) / n;
      break;
    case WeightMode::ConstantRatio: {
      double first = 0.0, logRatio = 0.0;
      ratioParameters(p, n, first, logRatio);
      scale = logRatio == 0.0 ? first : first / std::expm1(logRatio);
      c = logRatio;
      d = first;
      break;
    }
    case WeightMode::AverageVisibility:
      break;
    }
    valid = valid && std::isfinite(scale) && std::isfinite(c) && std::isfinite(d) &&
            std::abs(scale) <= std::numeric_limits<float>::max();
    w.scale = valid ? static_cast<float>(scale) : 0.0f;
    w.c = valid ? static_cast<float>(c) : 1.0f;
    w.d = valid ? static_cast<float>(d) : 0.0f;
    w.valid = valid ? 1 : 0;
  }
  return out;
}

namespace {
/// makeScatteringParams() for a layout known to have a GPU mapping (checked by the caller).
gpu::ScatteringParams scatteringParamsOf(const FilteredBasisView& basis, const RectifiedLayout& layout,
                                         const DirectionalLight& light, const Medium& medium) {
  const auto* projective = dynamic_cast<const ProjectiveLayout*>(&layout);
  const int K = layout.regionCount();
  if (K != basis.layoutRegions)
    invalid("layout", "regionCount() " + str(K),
            "must equal FilteredBasisView.layoutRegions = " + str(basis.layoutRegions));
  if (K > gpu::kMaxSplits) invalid("layout", "regionCount() " + str(K), "must be <= " + str(gpu::kMaxSplits));
  validateBases(basis.bases, "FilteredBasisView.bases");
  if (basis.width <= 0 || basis.height <= 0 || basis.regionsPerSplit < 1 ||
      basis.width % basis.regions() != 0)
    invalid("FilteredBasisView",
            "size " + sizeString(basis.width, basis.height) + ", regions " + str(basis.regions()),
            "width and height must be > 0 and the width a multiple of the regions");

  gpu::ScatteringParams p;
  p.frameOrigin = vec4Of(layout.origin());
  if (projective) {
    // The projective frame (Klehm et al. 2014, Sec. 4.2); other layouts are mapped by their own block
    // (CREP_EVAL_LAYOUT, gpu::LayoutBuffers).
    const RectifiedFrame& f = projective->rectification().frame;
    p.frameOrigin = vec4Of(f.origin);
    p.frameAxisX = vec4Of(f.axisX, f.inverseLightDistance);
    p.frameAxisY = vec4Of(f.axisY);
    p.frameAxisZ = vec4Of(f.axisZ);
    p.slopes = glm::vec4(
        static_cast<float>(f.rowSlopeMin), static_cast<float>(1.0 / (f.rowSlopeMax - f.rowSlopeMin)),
        static_cast<float>(f.depthSlopeMin), static_cast<float>(1.0 / (f.depthSlopeMax - f.depthSlopeMin)));
    for (int k = 0; k < K; ++k) {
      const Split& s = projective->rectification().splits[static_cast<std::size_t>(k)];
      p.splitZeta[k] = glm::vec4(static_cast<float>(s.zetaBegin), static_cast<float>(s.zetaEnd), 0.0f, 0.0f);
    }
  }
  p.extinction = vec4Of(medium.extinction(), basis.extinction);
  p.mieScattering = vec4Of(medium.mieScattering(), medium.hgG());
  p.rayleighScattering = vec4Of(medium.rayleighScattering());
  p.lightIrradiance = vec4Of(light.irradiance());
  p.lightDirection = vec4Of(light.direction());
  p.mapSize = glm::ivec4(basis.width, basis.height, basis.regions(), K);
  p.basisInfo = glm::ivec4(basis.bases, layerCount(basis.bases), basis.regionsPerSplit,
                           static_cast<int>(basis.weights));
  p.depthMargin = glm::vec4(static_cast<float>(basis.depthMargin), 0.0f, 0.0f, 0.0f);
  return p;
}
} // namespace

gpu::ScatteringParams makeScatteringParams(const FilteredBasisView& basis, const RectifiedLayout& layout,
                                           const DirectionalLight& light, const Medium& medium) {
  if (dynamic_cast<const ProjectiveLayout*>(&layout) == nullptr) gpu::requireGpuLayout(layout);
  return scatteringParamsOf(basis, layout, light, medium);
}

// ---------------------------------------------------------------------------------------------------
// PrefilterPass

/// The prefilter program's sources: the options compiled in; `local` the local-light variant.
std::vector<ShaderStageSource> prefilterStages(const PrefilterPass::CreateInfo& info, bool local,
                                               bool textured = false) {
  const PrefilterOptions& o = info.options;
  const gpu::Format format = arrayFormat(o, textured);
  return {{ShaderStage::Compute,
           "passes/prefilter/prefilter.comp",
           {{"CREP_BASES_PER_INVOCATION", str(basesPerInvocation(info, local))},
            {"CREP_BASIS_FORMAT", imageFormatQualifier(format)},
            {"CREP_BASIS_UNORM8", format == gpu::Format::RGBA8 ? "1" : "0"},
            {"CREP_BASIS_HALF", format == gpu::Format::RGBA16F ? "1" : "0"},
            {"CREP_EXACT_VISIBILITY", o.reconstruction == VisibilityReconstruction::Exact ? "1" : "0"},
            {"CREP_LOCAL_SIZE_X", str(info.workgroupRows)},
            {"CREP_LOCAL_SIZE_Y", str(info.workgroupBaseGroups)},
            {"CREP_LOCAL_SIZE_Z", str(info.workgroupRegions)},
            {"CREP_MEMORY_LIMIT", info.memoryLimit ? "1" : "0"},
            {"CREP_LOCAL_LIGHT", local ? "1" : "0"},
            {"CREP_LIGHT_TEXTURE", textured ? "1" : "0"}}}};
}

/// The local-light block of a light and medium (gpu::LocalLightParams) seen from `origin`.
gpu::LocalLightParams localLightParams(const LocalLight& light, const Medium& medium,
                                       const glm::dvec3& origin, double greyExtinction) {
  gpu::LocalLightParams p;
  p.origin = glm::vec4(glm::vec3(origin), static_cast<float>(greyExtinction));
  p.position = glm::vec4(glm::vec3(light.position), static_cast<float>(light.nearPlane));
  p.axis = glm::vec4(glm::vec3(light.axis), static_cast<float>(light.face));
  p.cone = glm::vec4(static_cast<float>(light.cosInner), static_cast<float>(light.cosOuter),
                     light.cone ? 1.0f : 0.0f, 0.0f);
  p.intensity = glm::vec4(glm::vec3(light.intensity), 0.0f);
  p.mieScattering = glm::vec4(glm::vec3(medium.mieScattering()), static_cast<float>(medium.hgG()));
  p.rayleighScattering = glm::vec4(glm::vec3(medium.rayleighScattering()), 0.0f);
  return p;
}

PrefilterPass::PrefilterPass(const CreateInfo& info) : info_(info) {
  requireAtLeast("PrefilterPass::CreateInfo.mapWidth", info.mapWidth, 1);
  requireAtLeast("PrefilterPass::CreateInfo.mapHeight", info.mapHeight, 1);
  const PrefilterOptions& o = info.options;
  crep::validate(o, "PrefilterPass::CreateInfo.options");
  if (info.memoryLimit && o.reconstruction == VisibilityReconstruction::Exact)
    invalid("PrefilterPass::CreateInfo.options.reconstruction", "exact",
            "must be fourier with CreateInfo.memoryLimit (a benchmark variant of the Fourier pass)");
  if (o.regionsPerSplit > info.mapWidth)
    invalid("PrefilterPass::CreateInfo.options.regionsPerSplit", detail::formatValue(o.regionsPerSplit),
            "must be in [1, width = " + str(info.mapWidth) + "]");
  requireAtLeast("PrefilterPass::CreateInfo.workgroupRows", info.workgroupRows, 1);
  requireAtLeast("PrefilterPass::CreateInfo.workgroupBaseGroups", info.workgroupBaseGroups, 1);
  requireAtLeast("PrefilterPass::CreateInfo.workgroupRegions", info.workgroupRegions, 1);

  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  gpu::Backend& b = *backend_;
  const int maxSize = b.maxTextureSize();
  if (info.mapWidth > maxSize)
    gpu::throwBeyondLimit(b, "PrefilterPass::CreateInfo.mapWidth", str(info.mapWidth), "GL_MAX_TEXTURE_SIZE",
                          "maximum texture size", maxSize);
  if (info.mapHeight > maxSize)
    gpu::throwBeyondLimit(b, "PrefilterPass::CreateInfo.mapHeight", str(info.mapHeight),
                          "GL_MAX_TEXTURE_SIZE", "maximum texture size", maxSize);
  const int maxLayers = b.maxArrayLayers();
  if (layers() > maxLayers)
    gpu::throwBeyondLimit(b, "PrefilterPass::CreateInfo.options.bases",
                          str(o.bases) + " (" + str(layers()) + " layers)", "GL_MAX_ARRAY_TEXTURE_LAYERS",
                          "array layers", maxLayers);
  {
    const char* names[3] = {"PrefilterPass::CreateInfo.workgroupRows",
                            "PrefilterPass::CreateInfo.workgroupBaseGroups",
                            "PrefilterPass::CreateInfo.workgroupRegions"};
    const int local[3] = {info.workgroupRows, info.workgroupBaseGroups, info.workgroupRegions};
    // The most regions a run can have is one per column.
    const int groups[3] = {ceilDiv(info.mapHeight, info.workgroupRows),
                           ceilDiv(baseGroups(info), info.workgroupBaseGroups),
                           ceilDiv(info.mapWidth, info.workgroupRegions)};
    checkWorkgroup(b, names, local, groups);
  }

  const ShaderStageSource stage = prefilterStages(info, false)[0];
  b.prepareProgram(stage.path, stage.defines);
  texture_ = gpu::Texture(b, {gpu::TextureType::Texture2DArray, arrayFormat(o, false), info.mapWidth,
                              info.mapHeight, layers(), "PrefilterPass: filtered basis"});
  paramsBuffer_ = gpu::Buffer(b, sizeof(gpu::PrefilterParams), "PrefilterPass: parameters");
}

PrefilterPass::~PrefilterPass() = default;

PrefilterPass::PrefilterPass(PrefilterPass&& o) noexcept
    : info_(o.info_), ownBackend_(std::move(o.ownBackend_)), backend_(std::exchange(o.backend_, nullptr)),
      texture_(std::move(o.texture_)), paramsBuffer_(std::move(o.paramsBuffer_)),
      weightsBuffer_(std::move(o.weightsBuffer_)), localBuffer_(std::move(o.localBuffer_)),
      raysBuffer_(std::move(o.raysBuffer_)), texturedTexture_(std::move(o.texturedTexture_)),
      meanColor_(std::move(o.meanColor_)), ran_(o.ran_), lastLocal_(o.lastLocal_),
      lastTextured_(o.lastTextured_), lastLayoutRegions_(o.lastLayoutRegions_),
      lastExtinction_(o.lastExtinction_) {}

PrefilterPass& PrefilterPass::operator=(PrefilterPass&& o) noexcept {
  if (this != &o) {
    this->~PrefilterPass(); // the textures and buffers go before the backend that made them
    new (this) PrefilterPass(std::move(o));
  }
  return *this;
}

/// A validated frame of the prefilter pass (PrefilterPass::validate) and what run() derives from it.
struct PrefilterPass::Plan {
  double extinction = 0.0; ///< the weight extinction s
  int K = 1, R = 1, n = 1; ///< layout regions, prefilter regions R = K P, texels per region
  bool local = false, textured = false;
};

void PrefilterPass::validate(const FrameAttribs& frame, std::string_view owner) const {
  plan(frame, owner);
}

PrefilterPass::Plan PrefilterPass::plan(const FrameAttribs& frame, std::string_view owner) const {
  const std::string f = std::string(owner) + ".";
  if (frame.layout == nullptr) invalid(f + "layout", "null", "must point to the map's layout");
  const gpu::TextureLevel depth =
      gpu::textureLevelOf(*backend_, (f + "rectifiedDepth").c_str(), frame.rectifiedDepth);
  if (depth.type != gpu::TextureType::Texture2D)
    invalid(f + "rectifiedDepth", "texture " + str(frame.rectifiedDepth), "must be a 2D texture");
  gpu::requireDepthFormatOf(*backend_, (f + "rectifiedDepth").c_str(), frame.rectifiedDepth);
  if (depth.width != info_.mapWidth || depth.height != info_.mapHeight)
    invalid(f + "rectifiedDepth", sizeString(depth.width, depth.height),
            "must be the created size " + sizeString(info_.mapWidth, info_.mapHeight));
  Plan p;
  p.extinction = frame.extinctionOverride;
  if (p.extinction < 0.0) {
    if (frame.medium == nullptr) invalid(f + "medium", "null", "must be set unless extinctionOverride >= 0");
    p.extinction = weightExtinction(*frame.medium);
  }
  requireFinite(f + "extinctionOverride", p.extinction);

  const int P = info_.options.regionsPerSplit, W = info_.mapWidth, H = info_.mapHeight;
  p.K = frame.layout->regionCount();
  p.R = p.K * P;
  if (p.K < 1 || W % p.R != 0)
    invalid(f + "layout", "regionCount() " + str(p.K),
            "regionCount() x regionsPerSplit (" + str(p.K) + " x " + str(P) + ") must divide the map width " +
                str(W));
  p.n = W / p.R;
  p.local = frame.localLight != nullptr;
  p.textured = frame.lightColors != 0;
  if (p.textured) {
    if (backend_->kind() == gpu::BackendKind::OpenGL)
      gl::requireTexture2D((f + "lightColors").c_str(), frame.lightColors, W, H);
    else
      gpu::requireTexture(*backend_, (f + "lightColors").c_str(), frame.lightColors, W, H,
                          {gpu::Format::RGBA32F, gpu::Format::RGBA16F, gpu::Format::RGBA8});
    if (info_.memoryLimit)
      invalid(f + "lightColors", str(frame.lightColors),
              "must be 0 with CreateInfo.memoryLimit (a benchmark variant of the untextured pass)");
    // Light textures (prefilter.h): three bases and the prefix mean colour, allocated on first use.
    if (!texturedTexture_) {
      const int maxLayers = backend_->maxArrayLayers();
      if (3 * layers() > maxLayers)
        gpu::throwBeyondLimit(*backend_, "PrefilterPass::CreateInfo.options.bases",
                              str(info_.options.bases) + " (" + str(3 * layers()) +
                                  " layers with a light texture)",
                              "GL_MAX_ARRAY_TEXTURE_LAYERS", "array layers", maxLayers);
    }
  }
  if (p.local && frame.medium == nullptr) invalid(f + "medium", "null", "must be set with a localLight");
  if (p.local && info_.options.weights != WeightMode::Exact)
    invalid("PrefilterPass::CreateInfo.options.weights", weightModeToken(info_.options.weights),
            "must be exact with a localLight");
  return p;
}

void PrefilterPass::run(const FrameAttribs& frame) {
  gpu::requireNotMovedFrom(backend_, "PrefilterPass");
  const Plan p = plan(frame, "PrefilterPass::FrameAttribs");
  if (p.textured) prepareTextured(p.local);
  const std::size_t weightBytes = upload(frame, p);
  dispatch(frame, p, weightBytes);
  ran_ = true;
  lastTextured_ = p.textured;
  lastLayoutRegions_ = p.K;
  lastExtinction_ = p.extinction;
  lastLocal_ = p.local;
}

void PrefilterPass::prepareTextured(bool local) {
  const int W = info_.mapWidth, H = info_.mapHeight;
  gpu::Backend& b = *backend_;
  if (!texturedTexture_) {
    // Light textures (prefilter.h): three bases and the prefix mean colour, allocated on first use.
    texturedTexture_ = gpu::Texture(b, {gpu::TextureType::Texture2DArray, arrayFormat(info_.options, true), W,
                                        H, exact() ? layers() : 3 * layers(),
                                        "PrefilterPass: filtered basis (light textures)"});
    // RGBA32F: a light texture's HDR texels (projector images in physical units) are kept whole; half
    // floats clipped them at 65504. GPU: one fetch per region per pixel, so the extra bytes are cheap.
    meanColor_ = gpu::Texture(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, W, H, 1,
                                  "PrefilterPass: mean colour (light textures)"});
  }
  const ShaderStageSource stage = prefilterStages(info_, local, true)[0];
  b.prepareProgram(stage.path, stage.defines);
}

std::size_t PrefilterPass::upload(const FrameAttribs& frame, const Plan& p) {
  const int W = info_.mapWidth, H = info_.mapHeight;
  const std::vector<DistanceProfile> profiles =
      referenceProfiles(*frame.layout, H, info_.options.regionsPerSplit);
  const std::vector<gpu::RegionWeights> weights = gpuRegionWeights(profiles, info_.options.weights, p.n);
  if (p.local) uploadLocalLight(frame, p, profiles);
  const std::size_t bytes = weights.size() * sizeof(gpu::RegionWeights);
  gpu::writeGrowing(*backend_, weightsBuffer_, std::as_bytes(std::span(weights)),
                    "PrefilterPass: region weights");

  gpu::PrefilterParams params;
  params.mapSize = glm::ivec4(W, H, p.R, p.n);
  params.basisInfo = glm::ivec4(info_.options.bases, basesPerInvocation(info_, p.local),
                                static_cast<int>(info_.options.weights), 0);
  params.weights =
      glm::vec4(static_cast<float>(p.extinction), static_cast<float>(info_.options.depthMargin), 0.0f, 0.0f);
  backend_->writeBuffer(paramsBuffer_.id(), 0, std::as_bytes(std::span(&params, 1)));
  return bytes;
}

void PrefilterPass::uploadLocalLight(const FrameAttribs& frame, const Plan& p,
                                     const std::vector<DistanceProfile>& profiles) {
  const int H = info_.mapHeight, P = info_.options.regionsPerSplit, R = p.R;
  // Sec. 3.2: the reference rays the light-side factor is sampled along (direction, start distance).
  std::vector<gpu::RegionRay> rays(profiles.size());
  for (int j = 0; j < H; ++j) {
    const double row = (j + 0.5) / H;
    for (int r = 0; r < R; ++r) {
      const glm::vec3 direction(
          frame.layout->viewRayDirection(row, frame.layout->regionReferenceDepth(row, r / P)));
      const std::size_t k =
          static_cast<std::size_t>(j) * static_cast<std::size_t>(R) + static_cast<std::size_t>(r);
      const double t0 = profiles[k](0.0);
      rays[k] = gpu::RegionRay(direction, std::isfinite(t0) ? static_cast<float>(t0) : -1.0f);
    }
  }
  gpu::writeGrowing(*backend_, raysBuffer_, std::as_bytes(std::span(rays)), "PrefilterPass: region rays");
  if (!localBuffer_)
    localBuffer_ = gpu::Buffer(*backend_, sizeof(gpu::LocalLightParams), "PrefilterPass: light");
  gpu::LocalLightParams lp =
      localLightParams(*frame.localLight, *frame.medium, frame.layout->origin(), p.extinction);
  lp.cone.w = static_cast<float>(static_cast<int>(info_.options.localLightWeights));
  backend_->writeBuffer(localBuffer_.id(), 0, std::as_bytes(std::span(&lp, 1)));
  const ShaderStageSource stage = prefilterStages(info_, true)[0];
  backend_->prepareProgram(stage.path, stage.defines);
}

void PrefilterPass::dispatch(const FrameAttribs& frame, const Plan& p, std::size_t weightBytes) {
  const bool local = p.local, textured = p.textured;
  const ShaderStageSource stage = prefilterStages(info_, local, textured)[0];
  gpu::Dispatch d;
  d.label = "PrefilterPass::run";
  d.program = stage.path;
  d.defines = stage.defines;
  d.resources = {
      gpu::Resource::sampled(CREP_PREFILTER_RECTIFIED_DEPTH_UNIT, frame.rectifiedDepth),
      gpu::Resource::image(CREP_PREFILTER_FILTERED_BASIS_OUT_IMAGE,
                           textured ? texturedTexture_.id() : texture_.id(),
                           exact() ? gpu::Access::ReadWrite : gpu::Access::WriteOnly), // exact: read back
      gpu::Resource::uniform(CREP_PREFILTER_PARAMS_BINDING, paramsBuffer_.id()),
      gpu::Resource::storage(CREP_PREFILTER_REGION_WEIGHTS_BINDING, weightsBuffer_.id(), 0, weightBytes)};
  if (textured) {
    d.resources.push_back(gpu::Resource::sampled(CREP_PREFILTER_LIGHT_COLORS_UNIT, frame.lightColors));
    d.resources.push_back(
        gpu::Resource::image(CREP_PREFILTER_MEAN_COLOR_OUT_IMAGE, meanColor_.id(), gpu::Access::WriteOnly));
  }
  if (local) {
    d.resources.push_back(gpu::Resource::uniform(CREP_PREFILTER_LOCAL_LIGHT_BINDING, localBuffer_.id()));
    d.resources.push_back(gpu::Resource::storage(CREP_PREFILTER_REGION_RAYS_BINDING, raysBuffer_.id()));
  }
  d.groups = glm::uvec3(static_cast<unsigned>(ceilDiv(info_.mapHeight, info_.workgroupRows)),
                        static_cast<unsigned>(ceilDiv(baseGroups(info_, local), info_.workgroupBaseGroups)),
                        static_cast<unsigned>(ceilDiv(p.R, info_.workgroupRegions)));
  backend_->dispatch(d);
}

FilteredBasisView PrefilterPass::filteredBasis() const {
  if (!ran_) throw Error("PrefilterPass::filteredBasis: run() has not been called yet");
  FilteredBasisView v;
  v.texture = filteredBasisTexture();
  v.textured = lastTextured_;
  v.meanColor = lastTextured_ ? meanColor_.id() : 0;
  v.regionWeights = weightsBuffer_.id();
  v.width = info_.mapWidth;
  v.height = info_.mapHeight;
  v.bases = info_.options.bases;
  v.layoutRegions = lastLayoutRegions_;
  v.regionsPerSplit = info_.options.regionsPerSplit;
  v.localLight = lastLocal_;
  v.weights = info_.options.weights;
  v.extinction = lastExtinction_;
  v.depthMargin = info_.options.depthMargin;
  v.reconstruction = info_.options.reconstruction;
  return v;
}

// ---------------------------------------------------------------------------------------------------
// EvaluatePass

namespace {
/// CREP_EVAL_LAYOUT and its bindings for a layout of kind `layoutKind` (nothing for < 0: the projective frame
/// of the scattering block), shared by the evaluation and the scattering prefix programs.
void addLayoutDefines(std::vector<ShaderDefine>& defines, int layoutKind) {
  if (layoutKind < 0) return;
  defines.push_back({"CREP_EVAL_LAYOUT", str(layoutKind)});
  defines.push_back({"CREP_LAYOUT_BINDING", str(CREP_EVALUATE_LAYOUT_BINDING)});
  defines.push_back({"CREP_SLICES_BINDING", str(CREP_EVALUATE_SLICES_BINDING)});
}

/// The evaluation program's stages: projective frame of the scattering block (layoutKind < 0), or the
/// layout block of kind `layoutKind` (CREP_EVAL_LAYOUT) at CREP_EVALUATE_LAYOUT_BINDING /
/// CREP_EVALUATE_SLICES_BINDING.
std::vector<ShaderStageSource> evaluateStages(const EvaluatePass::CreateInfo& info, int layoutKind,
                                              bool local = false, bool textured = false, bool froxels = false,
                                              bool list = false) {
  std::vector<ShaderStageSource> stages = {
      {ShaderStage::Compute,
       "passes/prefilter/evaluate.comp",
       {{"CREP_BASES", str(info.bases)},
        // A work list's output is RGBA32F (crep/scatter/gpu_sample_list.h) whatever the pass's format.
        {"CREP_OUTPUT_FORMAT", list ? "rgba32f" : storageFormatToken(info.outputFormat)},
        {"CREP_NEAR_PLANE_CORRECTION", info.options.nearPlaneCorrection ? "1" : "0"},
        {"CREP_RINGING_LANCZOS", info.options.ringing == RingingFilter::Lanczos ? "1" : "0"},
        {"CREP_EXACT_VISIBILITY", info.reconstruction == VisibilityReconstruction::Exact ? "1" : "0"},
        {"CREP_EXACT_NEAREST", info.options.sampling == Sampling::Nearest ? "1" : "0"},
        {"CREP_LOCAL_SIZE_X", str(info.workgroupWidth)},
        {"CREP_LOCAL_SIZE_Y", str(info.workgroupHeight)},
        {"CREP_MEMORY_LIMIT", info.memoryLimit ? "1" : "0"}}}};
  if (usesVisibilityTable(info.options))
    stages[0].defines.push_back({"CREP_VISIBILITY_TABLE_SAMPLES", str(info.options.visibilityTableSamples)});
  if (usesScatteringPrefix(info.options)) stages[0].defines.push_back({"CREP_SCATTERING_PREFIX", "1"});
  addLayoutDefines(stages[0].defines, layoutKind);
  if (local) {
    stages[0].defines.push_back({"CREP_LOCAL_LIGHT", "1"});
    stages[0].defines.push_back({"CREP_AIRLIGHT", info.localClosedForm ? "1" : "0"});
    stages[0].defines.push_back({"CREP_LOCAL_SECTIONS", usesLocalSectionTable(info.options) ? "1" : "0"});
  }
  if (textured) {
    stages[0].defines.push_back({"CREP_LIGHT_TEXTURE", "1"});
  }
  if (froxels) stages[0].defines.push_back({"CREP_FROXELS", "1"});
  if (list) {
    stages[0].defines.push_back({"CREP_SAMPLE_LIST", "1"});
    stages[0].defines.push_back({"CREP_SAMPLE_LIST_BINDING", str(CREP_EVALUATE_SAMPLE_LIST_BINDING)});
  }
  return stages;
}

/// Samples per workgroup of the scattering prefix table: 64, or 128 for the exact reconstruction, whose
/// workgroups each build their row's histograms (one workgroup per row at the default Z = 128).
int prefixLocalSize(const EvaluatePass::CreateInfo& info) {
  return info.reconstruction == VisibilityReconstruction::Exact ? 128 : 64;
}

/// The scattering prefix table's program (EvaluateOptions::scatteringPrefix), on the same layout block as
/// evaluateStages(info, layoutKind).
std::vector<ShaderStageSource> prefixStages(const EvaluatePass::CreateInfo& info, int layoutKind,
                                            bool local = false, bool textured = false) {
  std::vector<ShaderStageSource> stages = {
      {ShaderStage::Compute,
       "passes/prefilter/scattering_prefix.comp",
       {{"CREP_BASES", str(info.bases)},
        {"CREP_VISIBILITY_TABLE_SAMPLES", str(info.options.visibilityTableSamples)},
        {"CREP_EXACT_VISIBILITY", info.reconstruction == VisibilityReconstruction::Exact ? "1" : "0"},
        {"CREP_PREFIX_LOCAL_SIZE", str(prefixLocalSize(info))},
        {"CREP_MEMORY_LIMIT", info.memoryLimit ? "1" : "0"}}}};
  addLayoutDefines(stages[0].defines, layoutKind);
  if (local) {
    stages[0].defines.push_back({"CREP_LOCAL_LIGHT", "1"});
    stages[0].defines.push_back({"CREP_AIRLIGHT", info.localClosedForm ? "1" : "0"});
    stages[0].defines.push_back({"CREP_LOCAL_SECTIONS", usesLocalSectionTable(info.options) ? "1" : "0"});
  }
  if (textured) {
    stages[0].defines.push_back({"CREP_LIGHT_TEXTURE", "1"});
    stages[0].defines.push_back({"CREP_SCATTERING_PREFIX", "1"}); // the table this program builds
  }
  return stages;
}
} // namespace

std::size_t PrefilterPass::memoryBytes() const noexcept {
  if (backend_ == nullptr) return 0; // moved from
  const std::size_t area =
      static_cast<std::size_t>(info_.mapWidth) * static_cast<std::size_t>(info_.mapHeight);
  const std::size_t basis = exact() ? exactBasisBytes(info_.mapWidth, info_.mapHeight)
                                    : filteredBasisBytes(info_.mapWidth, info_.mapHeight, info_.options.bases,
                                                         info_.options.format);
  // Light textures: three bases (exact: two RGBA32F layers, twice the RG32F pair) and the mean colour.
  const std::size_t textured = texturedTexture_ ? (exact() ? 2 : 3) * basis + area * 16 : 0;
  return textured + basis + weightsBuffer_.bytes() + sizeof(gpu::PrefilterParams) + raysBuffer_.bytes() +
         (localBuffer_ ? sizeof(gpu::LocalLightParams) : 0);
}

namespace {
/// The region visibility table's program (EvaluateOptions::visibilityTableSamples without the prefix table).
ShaderStageSource tableStage(const EvaluatePass::CreateInfo& info) {
  return {ShaderStage::Compute,
          "passes/prefilter/visibility_table.comp",
          {{"CREP_BASES", str(info.bases)},
           {"CREP_TABLE_SAMPLES", str(info.options.visibilityTableSamples)},
           {"CREP_EXACT_VISIBILITY", info.reconstruction == VisibilityReconstruction::Exact ? "1" : "0"},
           {"CREP_MEMORY_LIMIT", info.memoryLimit ? "1" : "0"}}};
}

/// A dispatch of the first stage of `stages` (the passes' programs have one).
gpu::Dispatch dispatchOf(const char* label, const std::vector<ShaderStageSource>& stages) {
  gpu::Dispatch d;
  d.label = label;
  d.program = stages[0].path;
  d.defines = stages[0].defines;
  return d;
}

} // namespace

EvaluatePass::EvaluatePass(const CreateInfo& info) : info_(info) {
  validateBases(info.bases, "EvaluatePass::CreateInfo.bases");
  crep::validate(info.options, "EvaluatePass::CreateInfo.options");
  if (info.reconstruction != VisibilityReconstruction::Fourier &&
      info.reconstruction != VisibilityReconstruction::Exact)
    invalid("EvaluatePass::CreateInfo.reconstruction", str(static_cast<int>(info.reconstruction)),
            "must be Fourier or Exact");
  if (info.reconstruction == VisibilityReconstruction::Exact &&
      info.options.visibilityTableSamples > kMaxExactTableSamples)
    invalid("EvaluatePass::CreateInfo.options.visibilityTableSamples",
            str(info.options.visibilityTableSamples),
            "must be at most kMaxExactTableSamples = " + str(kMaxExactTableSamples) +
                " with the exact reconstruction (its histograms in 32 KB of shared memory)");
  if (info.outputFormat != StorageFormat::RGBA32F && info.outputFormat != StorageFormat::RGBA16F)
    invalid("EvaluatePass::CreateInfo.outputFormat", storageFormatToken(info.outputFormat),
            "must be RGBA32F or RGBA16F");
  requireAtLeast("EvaluatePass::CreateInfo.workgroupWidth", info.workgroupWidth, 1);
  requireAtLeast("EvaluatePass::CreateInfo.workgroupHeight", info.workgroupHeight, 1);
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  gpu::Backend& b = *backend_;
  layoutBuffers_ = gpu::LayoutBuffers(backend_);
  {
    const char* names[3] = {"EvaluatePass::CreateInfo.workgroupWidth",
                            "EvaluatePass::CreateInfo.workgroupHeight", "(none)"};
    const int local[3] = {info.workgroupWidth, info.workgroupHeight, 1};
    const int groups[3] = {1, 1, 1};
    checkWorkgroup(b, names, local, groups);
  }
  const auto prepare = [&b](const ShaderStageSource& s) { b.prepareProgram(s.path, s.defines); };
  prepare(evaluateStages(info, -1)[0]);
  if (usesScatteringPrefix(info.options))
    prepare(prefixStages(info, -1)[0]);
  else if (usesVisibilityTable(info.options))
    prepare(tableStage(info));
  scatteringBuffer_ = gpu::Buffer(b, sizeof(gpu::ScatteringParams), "EvaluatePass: scattering block");
  evaluateBuffer_ = gpu::Buffer(b, sizeof(gpu::EvaluateParams), "EvaluatePass: evaluate block");
}

std::size_t EvaluatePass::memoryBytes() const noexcept {
  if (backend_ == nullptr) return 0; // moved from
  const std::size_t texels = static_cast<std::size_t>(tableWidth_) * static_cast<std::size_t>(tableHeight_);
  const std::size_t airlight =
      airlightTable_ ? std::size_t(AirlightTable::kDefaultUSamples) * AirlightTable::kDefaultXiSamples * 8
                     : 0;
  const std::size_t sections = sectionTexture_ ? texels * 16 : 0;
  return texels * (usesScatteringPrefix(info_.options) ? 16 : 4) + tableCoefficients_.bytes() + airlight +
         sections + sizeof(gpu::ScatteringParams) + sizeof(gpu::EvaluateParams);
}

EvaluatePass::~EvaluatePass() = default;

EvaluatePass::EvaluatePass(EvaluatePass&& o) noexcept
    : info_(o.info_), ownBackend_(std::move(o.ownBackend_)), backend_(std::exchange(o.backend_, nullptr)),
      scatteringBuffer_(std::move(o.scatteringBuffer_)), evaluateBuffer_(std::move(o.evaluateBuffer_)),
      localBuffer_(std::move(o.localBuffer_)), tableCoefficients_(std::move(o.tableCoefficients_)),
      airlightTable_(std::move(o.airlightTable_)), sectionTexture_(std::move(o.sectionTexture_)),
      tableTexture_(std::move(o.tableTexture_)), airlightG_(o.airlightG_), tableBasis_(o.tableBasis_),
      tableVariant_(o.tableVariant_), tableMargin_(o.tableMargin_), tableWidth_(o.tableWidth_),
      tableHeight_(o.tableHeight_), layoutBuffers_(std::move(o.layoutBuffers_)) {}

EvaluatePass& EvaluatePass::operator=(EvaluatePass&& o) noexcept {
  if (this != &o) {
    this->~EvaluatePass(); // the textures and buffers go before the backend that made them
    new (this) EvaluatePass(std::move(o));
  }
  return *this;
}

/// A validated frame of the evaluation (EvaluatePass::validate) and what run() derives from it.
struct EvaluatePass::Plan {
  bool local = false, textured = false, froxels = false, pixels = false, projective = true;
  bool table = false, prefix = false, reuse = false;
  const gpu::SampleList* list = nullptr;
  FroxelDepthRange froxelRange;
  /// The pixels' camera depth size, or with a work list the camera image's size (0 for froxels alone).
  int imageWidth = 0, imageHeight = 0;
  std::optional<GpuLayoutData> layoutData; ///< a non-projective layout's block
  int layoutKind = -1;  ///< CREP_EVAL_LAYOUT: -1 the projective frame, else gpu::LayoutKind
  int layoutSlot = 0;   ///< program variants: 0 projective frame, 1 + layoutKind
  int variantIndex = 0; ///< (local ? 3 : 0) + layoutSlot
  gpu::ScatteringParams scattering;
};

namespace {

/// EvaluatePass::FrameAttribs::basis against the pass (`f`: the FrameAttribs' name and a dot).
void validateBasisView(const gpu::Backend& backend, const EvaluatePass::CreateInfo& info,
                       const FilteredBasisView& basis, const std::string& f) {
  if (basis.bases != info.bases)
    invalid(f + "basis.bases", detail::formatValue(basis.bases),
            "must equal EvaluatePass::CreateInfo.bases = " + str(info.bases));
  if (basis.reconstruction != info.reconstruction)
    invalid(f + "basis.reconstruction", visibilityReconstructionToken(basis.reconstruction),
            std::string("must equal EvaluatePass::CreateInfo.reconstruction = ") +
                visibilityReconstructionToken(info.reconstruction));
  const int basisLayers = basis.reconstruction == VisibilityReconstruction::Exact
                              ? 2 // (depth, W) and the blocks' (min, max)
                              : (basis.textured ? 3 : 1) * layerCount(basis.bases);
  const gpu::TextureLevel b = gpu::textureLevelOf(backend, (f + "basis.texture").c_str(), basis.texture);
  if (b.type != gpu::TextureType::Texture2DArray || b.width != basis.width || b.height != basis.height ||
      b.depth < basisLayers)
    invalid(f + "basis.texture", "texture " + str(basis.texture),
            "must be a 2D array texture of " + sizeString(basis.width, basis.height) + " x " +
                str(basisLayers) + " layers");
  if (basis.textured) {
    // Light textures (prefilter.h): the textured variants exist for the scattering prefix table (the
    // default) and the direct path without a table.
    const gpu::TextureLevel mean =
        gpu::textureLevelOf(backend, (f + "basis.meanColor").c_str(), basis.meanColor);
    if (mean.type != gpu::TextureType::Texture2D || mean.width != basis.width || mean.height != basis.height)
      invalid(f + "basis.meanColor", "texture " + str(basis.meanColor),
              "must be a 2D texture of " + sizeString(basis.width, basis.height));
    if (info.options.nearPlaneCorrection)
      invalid(f + "basis.textured", "true",
              "a light texture is not supported with CreateInfo.options.nearPlaneCorrection");
    if (usesVisibilityTable(info.options) && !usesScatteringPrefix(info.options))
      invalid(f + "basis.textured", "true",
              "a light texture needs CreateInfo.options.scatteringPrefix or visibilityTableSamples = 0 (no "
              "textured variant of the visibility table alone)");
    if (info.memoryLimit)
      invalid(f + "basis.textured", "true",
              "not with CreateInfo.memoryLimit (a benchmark variant of the untextured pass)");
  }
  if (info.options.nearPlaneCorrection)
    gpu::requireBufferOf(backend, (f + "basis.regionWeights").c_str(), basis.regionWeights,
                         "must name the region-weights buffer (near-plane correction)");
}

/// Froxel volumes (prefilter.h, "Froxel volumes"): the directional light's evaluation at the cells.
FroxelDepthRange validateFroxels(const gpu::Backend& backend, const EvaluatePass::CreateInfo& info,
                                 const EvaluatePass::FroxelTarget& froxels, const Camera& camera, bool local,
                                 const std::string& f) {
  const std::string owner = f + "froxels";
  validate(froxels.grid, owner.c_str());
  validateFroxelJitter(froxels.jitter, owner + ".jitter");
  const FroxelDepthRange range = froxelDepthRange(froxels.grid, camera, owner.c_str());
  if (local) invalid(owner, "with localLight", "froxel volumes are filled for the directional light only");
  if (info.memoryLimit)
    invalid(owner, "a volume",
            "must be 0 with CreateInfo.memoryLimit (a benchmark variant of the per-pixel pass)");
  const gpu::TextureLevel v = gpu::textureLevelOf(backend, (owner + ".volume").c_str(), froxels.volume);
  const FroxelGrid& g = froxels.grid;
  if (v.type != gpu::TextureType::Texture3D ||
      (v.format != gpu::Format::RGBA16F && v.format != gpu::Format::RGBA32F))
    invalid(owner + ".volume", "texture " + str(froxels.volume),
            "must be a 3D texture of format RGBA16F or RGBA32F");
  if (v.width != g.width || v.height != g.height || v.depth != g.depth)
    invalid(owner + ".volume", sizeString(v.width, v.height) + " x " + str(v.depth),
            "must have the grid's size " + sizeString(g.width, g.height) + " x " + str(g.depth));
  const std::string depthName = owner + ".grid.depth";
  const char* names[3] = {"EvaluatePass::CreateInfo.workgroupWidth",
                          "EvaluatePass::CreateInfo.workgroupHeight", depthName.c_str()};
  const int localSize[3] = {info.workgroupWidth, info.workgroupHeight, 1};
  const int groups[3] = {ceilDiv(g.width, info.workgroupWidth), ceilDiv(g.height, info.workgroupHeight),
                         g.depth};
  checkWorkgroup(backend, names, localSize, groups);
  return range;
}

/// The camera depth and output textures of the per-pixel evaluation; returns the depth's level.
gpu::TextureLevel validatePixelTextures(const gpu::Backend& backend, const EvaluatePass::CreateInfo& info,
                                        const EvaluatePass::FrameAttribs& frame, const std::string& f) {
  const gpu::TextureLevel depth =
      gpu::textureLevelOf(backend, (f + "cameraDepth").c_str(), frame.cameraDepth);
  if (depth.type != gpu::TextureType::Texture2D)
    invalid(f + "cameraDepth", "texture " + str(frame.cameraDepth), "must be a 2D texture");
  gpu::requireDepthFormatOf(backend, (f + "cameraDepth").c_str(), frame.cameraDepth);
  const gpu::TextureLevel out = gpu::textureLevelOf(backend, (f + "output").c_str(), frame.output);
  if (out.type != gpu::TextureType::Texture2D || out.format != basisFormat(info.outputFormat))
    invalid(f + "output", "texture " + str(frame.output),
            std::string("must be a 2D texture of format ") + storageFormatToken(info.outputFormat));
  if (out.width != depth.width || out.height != depth.height)
    invalid(f + "output", sizeString(out.width, out.height),
            "must have the size of cameraDepth " + sizeString(depth.width, depth.height));
  return depth;
}

} // namespace

void EvaluatePass::validate(const FrameAttribs& frame, std::string_view owner) const {
  plan(frame, owner);
}

EvaluatePass::Plan EvaluatePass::plan(const FrameAttribs& frame, std::string_view owner) const {
  const std::string f = std::string(owner) + ".";
  if (frame.camera == nullptr) invalid(f + "camera", "null", "must be set");
  Plan p;
  p.local = frame.localLight != nullptr;
  if ((frame.light == nullptr) == !p.local)
    invalid(f + "light/localLight", p.local ? "both set" : "both null", "exactly one must be set");
  if (frame.medium == nullptr) invalid(f + "medium", "null", "must be set");
  if (frame.layout == nullptr) invalid(f + "layout", "null", "must be set");
  const FilteredBasisView& basis = frame.basis;
  validateBasisView(*backend_, info_, basis, f);
  p.textured = basis.textured;
  p.froxels = frame.froxels.volume != 0;
  // Work lists (Yusov 2012, Sec. 6.4 and 6.7): the list's entries instead of every pixel.
  p.list = frame.list;
  p.pixels = !p.list && (frame.output != 0 || !p.froxels);
  if (p.froxels) p.froxelRange = validateFroxels(*backend_, info_, frame.froxels, *frame.camera, p.local, f);
  if (p.list) {
    const gpu::TextureLevel image = gpu::listImageSize(*backend_, frame.imageWidth, frame.imageHeight,
                                                       frame.cameraDepth, std::string(owner));
    gpu::validateSampleList(*backend_, *p.list, f + "list");
    p.imageWidth = image.width;
    p.imageHeight = image.height;
  }
  if (p.pixels) {
    const gpu::TextureLevel depth = validatePixelTextures(*backend_, info_, frame, f);
    p.imageWidth = depth.width;
    p.imageHeight = depth.height;
  }

  // A projective layout is evaluated from the scattering block's frame (the default program); any other
  // layout with a GPU mapping through its own block (Klehm et al. 2014, Sec. 4.1 for the epipolar one),
  // serialized once here.
  p.projective = dynamic_cast<const ProjectiveLayout*>(frame.layout) != nullptr;
  if (p.local != basis.localLight)
    invalid(
        f + "basis.localLight", basis.localLight ? "true" : "false",
        p.local
            ? "the basis must be prefiltered with the local light (PrefilterPass::FrameAttribs::localLight)"
            : "a basis prefiltered for a local light needs FrameAttribs::localLight");
  if (p.local && info_.options.nearPlaneCorrection)
    invalid("EvaluatePass::CreateInfo.options.nearPlaneCorrection", "true", "not supported for local lights");
  if (!p.projective) {
    p.layoutData = gpu::requireGpuLayout(*frame.layout);
    p.layoutKind = static_cast<int>(p.layoutData->kind);
  }
  // The program variants' slot: the projective frame (0) or the layout block of a kind (1 + kind).
  p.layoutSlot = p.projective ? 0 : 1 + p.layoutKind;
  p.variantIndex = (p.local ? 3 : 0) + p.layoutSlot;
  // A local light has no constant C: the block's directional light is unused (zero irradiance).
  const DirectionalLight unusedLight(glm::dvec3(0.0, 0.0, -1.0), glm::dvec3(0.0));
  p.scattering =
      scatteringParamsOf(basis, *frame.layout, p.local ? unusedLight : *frame.light, *frame.medium);
  if (!p.projective)
    gpu::LayoutBuffers::requireUploadable(*p.layoutData, basis.height, (f + "layout").c_str());

  p.table = usesVisibilityTable(info_.options);
  p.prefix = usesScatteringPrefix(info_.options);
  p.reuse = p.table && frame.reuseTable;
  if (p.reuse &&
      (tableBasis_ != basis.texture || tableVariant_ != p.variantIndex + 6 * int(p.textured) ||
       tableWidth_ != basis.regions() * info_.options.visibilityTableSamples || tableHeight_ != basis.height))
    invalid(f + "reuseTable", "true",
            "the previous run() built no table for this basis (texture, size, regions, layout kind)");
  return p;
}

void EvaluatePass::run(const FrameAttribs& frame) {
  gpu::requireNotMovedFrom(backend_, "EvaluatePass");
  const Plan p = plan(frame, "EvaluatePass::FrameAttribs");
  if (p.local) uploadLocalLight(frame);
  if (!p.projective)
    layoutBuffers_.upload(*p.layoutData, frame.basis.height, "EvaluatePass::FrameAttribs.layout");
  gpu::EvaluateParams params;
  gpu::assignCamera(params, *frame.camera);
  params.imageSize = glm::ivec4(p.imageWidth, p.imageHeight, 0, 0);
  backend_->writeBuffer(scatteringBuffer_.id(), 0, std::as_bytes(std::span(&p.scattering, 1)));
  backend_->writeBuffer(evaluateBuffer_.id(), 0, std::as_bytes(std::span(&params, 1)));
  if (p.table && !p.reuse) buildTable(frame.basis, p);
  if (p.pixels) {
    gpu::Dispatch d = evaluation(frame, p, false, false);
    d.resources.push_back(gpu::Resource::sampled(CREP_CAMERA_DEPTH_DEFAULT_UNIT, frame.cameraDepth));
    d.resources.push_back(
        gpu::Resource::image(CREP_EVALUATE_SCATTERING_OUT_IMAGE, frame.output, gpu::Access::WriteOnly));
    d.groups = glm::uvec3(static_cast<unsigned>(ceilDiv(p.imageWidth, info_.workgroupWidth)),
                          static_cast<unsigned>(ceilDiv(p.imageHeight, info_.workgroupHeight)), 1u);
    backend_->dispatch(d);
  }
  if (p.list) { // one invocation per entry, groups of 64 (gpu::kSampleListGroupSize), counts from the list
    gpu::Dispatch d = evaluation(frame, p, false, true);
    d.resources.push_back(gpu::Resource::sampled(CREP_CAMERA_DEPTH_DEFAULT_UNIT, p.list->coordinates));
    d.resources.push_back(
        gpu::Resource::image(CREP_EVALUATE_SCATTERING_OUT_IMAGE, p.list->output, gpu::Access::WriteOnly));
    d.resources.push_back(gpu::Resource::storage(CREP_EVALUATE_SAMPLE_LIST_BINDING, p.list->buffer));
    d.indirect = p.list->buffer;
    backend_->dispatch(d);
  }
  if (p.froxels) dispatchFroxels(frame, p, params);
}

void EvaluatePass::uploadLocalLight(const FrameAttribs& frame) {
  gpu::Backend& b = *backend_;
  if (!localBuffer_) localBuffer_ = gpu::Buffer(b, sizeof(gpu::LocalLightParams), "EvaluatePass: light");
  const gpu::LocalLightParams lp = localLightParams(
      *frame.localLight, *frame.medium, frame.camera->position(), weightExtinction(*frame.medium));
  b.writeBuffer(localBuffer_.id(), 0, std::as_bytes(std::span(&lp, 1)));
  // The airlight table of the medium's g (made on the CPU in double, a few ms, when g changes).
  if (info_.localClosedForm && (!airlightTable_ || airlightG_ != frame.medium->hgG())) {
    const AirlightTable t = makeAirlightTable(frame.medium->hgG());
    airlightTable_ = gpu::Texture(b, {gpu::TextureType::Texture2D, gpu::Format::RG32F, t.xiSamples,
                                      t.uSamples, 1, "EvaluatePass: airlight table"});
    std::vector<float> texels(t.values.begin(), t.values.end());
    b.writeTexture(airlightTable_.id(), texels);
    airlightG_ = frame.medium->hgG();
  }
}

/// The local light's block and, in closed form, its airlight table (filtered linearly), for the evaluation
/// and the prefix programs.
void EvaluatePass::appendLocalResources(std::vector<gpu::Resource>& out) const {
  // GL: a uniform block; the Vulkan form of the shader reads it as a storage buffer (crep/scattering.glsl).
  out.push_back(backend_->kind() == gpu::BackendKind::OpenGL
                    ? gpu::Resource::uniform(CREP_LOCAL_LIGHT_DEFAULT_BINDING, localBuffer_.id())
                    : gpu::Resource::storage(CREP_LOCAL_LIGHT_STORAGE_DEFAULT_BINDING, localBuffer_.id()));
  if (info_.localClosedForm)
    out.push_back(
        gpu::Resource::sampled(CREP_AIRLIGHT_DEFAULT_UNIT, airlightTable_.id(), gpu::Filter::Linear));
}

gpu::Dispatch EvaluatePass::evaluation(const FrameAttribs& frame, const Plan& p, bool froxels,
                                       bool list) const {
  gpu::Dispatch d = dispatchOf(froxels ? "EvaluatePass::run (froxels)" : "EvaluatePass::run",
                               evaluateStages(info_, p.layoutKind, p.local, p.textured, froxels, list));
  const FilteredBasisView& basis = frame.basis;
  // The basis and the light textures' mean colour are filtered as EvaluateOptions::sampling says.
  const gpu::Filter basisFilter =
      info_.options.sampling == Sampling::Bilinear ? gpu::Filter::Linear : gpu::Filter::Nearest;
  d.resources = {gpu::Resource::sampled(CREP_FILTERED_BASIS_DEFAULT_UNIT, basis.texture, basisFilter),
                 gpu::Resource::uniform(CREP_SCATTERING_DEFAULT_BINDING, scatteringBuffer_.id()),
                 gpu::Resource::uniform(CREP_EVALUATE_DEFAULT_BINDING, evaluateBuffer_.id())};
  if (p.textured)
    d.resources.push_back(gpu::Resource::sampled(CREP_MEAN_COLOR_DEFAULT_UNIT, basis.meanColor, basisFilter));
  if (p.table) {
    const std::uint32_t unit =
        p.prefix ? CREP_SCATTERING_PREFIX_DEFAULT_UNIT : CREP_VISIBILITY_TABLE_DEFAULT_UNIT;
    d.resources.push_back(gpu::Resource::sampled(unit, tableTexture_.id(), gpu::Filter::Linear));
    if (p.local && usesLocalSectionTable(info_.options))
      d.resources.push_back(
          gpu::Resource::sampled(CREP_LOCAL_SECTION_DEFAULT_UNIT, sectionTexture_.id(), gpu::Filter::Linear));
  }
  if (p.local) appendLocalResources(d.resources);
  if (!p.projective)
    layoutBuffers_.appendResources(d.resources, CREP_EVALUATE_LAYOUT_BINDING, CREP_EVALUATE_SLICES_BINDING);
  if (info_.options.nearPlaneCorrection)
    d.resources.push_back(gpu::Resource::storage(CREP_REGION_WEIGHTS_DEFAULT_BINDING, basis.regionWeights));
  return d;
}

void EvaluatePass::uploadTableCoefficients(double depthMargin) {
  // a(z_s) of every sample (the CPU reference's values), as M / 4 vec4 per sample (zero beyond M).
  const int Z = info_.options.visibilityTableSamples, M = info_.bases, layers = layerCount(M);
  const std::vector<double> as = visibilityTableCoefficients(Z, M, depthMargin, info_.options.ringing);
  std::vector<float> a(static_cast<std::size_t>(Z) * static_cast<std::size_t>(layers) * 4, 0.0f);
  for (int k = 0; k < Z; ++k)
    for (int m = 0; m < M; ++m)
      a[static_cast<std::size_t>(k) * static_cast<std::size_t>(layers) * 4 + static_cast<std::size_t>(m)] =
          static_cast<float>(
              as[static_cast<std::size_t>(k) * static_cast<std::size_t>(M) + static_cast<std::size_t>(m)]);
  tableCoefficients_ = gpu::Buffer(*backend_, a.size() * sizeof(float), "EvaluatePass: table coefficients");
  backend_->writeBuffer(tableCoefficients_.id(), 0, std::as_bytes(std::span(a)));
  tableMargin_ = depthMargin;
}

void EvaluatePass::buildTable(const FilteredBasisView& basis, const Plan& p) {
  // The per-frame table of this basis (EvaluateOptions::visibilityTableSamples / scatteringPrefix): the
  // scattering prefix table (RGBA32F, the default) or the region visibility table (R32F), rebuilt every
  // run; both R Z x H texels.
  gpu::Backend& b = *backend_;
  const int Z = info_.options.visibilityTableSamples, R = basis.regions();
  const bool sections = p.local && usesLocalSectionTable(info_.options);
  if (sections && (!sectionTexture_ || tableWidth_ != R * Z || tableHeight_ != basis.height))
    sectionTexture_ = gpu::Texture(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, R * Z, basis.height,
                                       1, "EvaluatePass: local section table (regions x samples, rows)"});
  if (tableWidth_ != R * Z || tableHeight_ != basis.height) {
    tableTexture_ =
        gpu::Texture(b, {gpu::TextureType::Texture2D, p.prefix ? gpu::Format::RGBA32F : gpu::Format::R32F,
                         R * Z, basis.height, 1,
                         p.prefix ? "EvaluatePass: scattering prefix table (regions x samples, rows)"
                                  : "EvaluatePass: visibility table (regions x samples, rows)"});
    tableWidth_ = R * Z;
    tableHeight_ = basis.height;
  }
  if (!tableCoefficients_ || tableMargin_ != basis.depthMargin) uploadTableCoefficients(basis.depthMargin);
  if (p.prefix) {
    // One workgroup per (64 samples, row), on the layout of the evaluation (scattering_prefix.comp); the
    // basis and coefficients through crep/scattering.glsl's names, read with texelFetch.
    gpu::Dispatch d = dispatchOf("EvaluatePass: scattering prefix table",
                                 prefixStages(info_, p.layoutKind, p.local, p.textured));
    d.resources = {gpu::Resource::storage(CREP_TABLE_COEFFICIENTS_DEFAULT_BINDING, tableCoefficients_.id()),
                   gpu::Resource::sampled(CREP_FILTERED_BASIS_DEFAULT_UNIT, basis.texture),
                   gpu::Resource::uniform(CREP_SCATTERING_DEFAULT_BINDING, scatteringBuffer_.id()),
                   gpu::Resource::image(CREP_SCATTERING_PREFIX_PREFIX_OUT_IMAGE, tableTexture_.id(),
                                        gpu::Access::WriteOnly)};
    if (p.textured) // texelFetch at the regions' last texels
      d.resources.push_back(gpu::Resource::sampled(CREP_MEAN_COLOR_DEFAULT_UNIT, basis.meanColor));
    if (sections)
      d.resources.push_back(gpu::Resource::image(CREP_SCATTERING_PREFIX_SECTION_OUT_IMAGE,
                                                 sectionTexture_.id(), gpu::Access::WriteOnly));
    if (p.local) appendLocalResources(d.resources);
    if (!p.projective)
      layoutBuffers_.appendResources(d.resources, CREP_EVALUATE_LAYOUT_BINDING, CREP_EVALUATE_SLICES_BINDING);
    d.groups = glm::uvec3(static_cast<unsigned>(ceilDiv(Z, prefixLocalSize(info_))),
                          static_cast<unsigned>(basis.height), 1u);
    b.dispatch(d);
  } else {
    gpu::Dispatch d = dispatchOf("EvaluatePass: visibility table", {tableStage(info_)});
    d.resources = {
        gpu::Resource::storage(CREP_VISIBILITY_TABLE_TABLE_COEFFICIENTS_BINDING, tableCoefficients_.id()),
        gpu::Resource::sampled(CREP_VISIBILITY_TABLE_BASIS_UNIT, basis.texture),
        gpu::Resource::image(CREP_VISIBILITY_TABLE_TABLE_OUT_IMAGE, tableTexture_.id(),
                             gpu::Access::WriteOnly)};
    d.push = {gpu::PushValue::of(0, glm::ivec4(basis.height, R, basis.width / R, 0))};
    d.groups = glm::uvec3(static_cast<unsigned>(ceilDiv(basis.height, 64)), static_cast<unsigned>(R), 1u);
    b.dispatch(d);
  }
  tableBasis_ = basis.texture;
  tableVariant_ = p.variantIndex + 6 * int(p.textured);
}

void EvaluatePass::dispatchFroxels(const FrameAttribs& frame, const Plan& p, gpu::EvaluateParams params) {
  // The froxel variant of the same program (CREP_FROXELS) on the same resources; the evaluate block's
  // imageSize holds the grid's size.
  const FroxelGrid& g = frame.froxels.grid;
  params.imageSize = glm::ivec4(g.width, g.height, g.depth, 0);
  backend_->writeBuffer(evaluateBuffer_.id(), 0, std::as_bytes(std::span(&params, 1)));
  gpu::Dispatch d = evaluation(frame, p, true, false);
  d.resources.push_back(
      gpu::Resource::image(CREP_EVALUATE_FROXELS_OUT_IMAGE, frame.froxels.volume, gpu::Access::WriteOnly));
  d.push = {gpu::PushValue::of(0, glm::vec4(glm::vec3(frame.froxels.jitter), 0.0f)),
            gpu::PushValue::of(
                1, glm::vec2(static_cast<float>(p.froxelRange.near), static_cast<float>(p.froxelRange.far)))};
  d.groups = glm::uvec3(static_cast<unsigned>(ceilDiv(g.width, info_.workgroupWidth)),
                        static_cast<unsigned>(ceilDiv(g.height, info_.workgroupHeight)),
                        static_cast<unsigned>(g.depth));
  backend_->dispatch(d);
}

} // namespace crep
