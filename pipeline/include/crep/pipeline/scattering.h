// The front door (Klehm, Seidel, Eisemann 2014): one object per view, one run() per frame, every frame
// prefiltered, on the projective layout (Sec. 4.2) or the epipolar fallback (Sec. 4.1). Shadow inputs, local
// lights, light textures, froxels, epipolar sampling, GL state: pipeline/README.md, "scattering.h".
// On the default GL backend it needs a current OpenGL 4.5 core context for its whole lifetime and never
// creates or owns one; CreateInfo::backend runs it on another (docs/BACKENDS.md).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/epipolar/epipolar_sampling.h>
#include <crep/gpu/backend.h>
#include <crep/pipeline/shadow_pass_plan.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/froxel_grid.h>
#include <crep/scatter/gpu_light_texture.h>
#include <crep/scatter/world_march.h>

namespace crep {

class Scattering {
public:
  /// How the directional light's in-scattering is computed from the frame's rectified map.
  enum class Method {
    Prefiltered, ///< Klehm et al. 2014: prefilter the map, evaluate each ray in constant time (default)
    MinMaxMarch, ///< the peer (Chen et al. 2011, Yusov 2012 Algorithm 2): 1D min/max trees, march each ray
  };
  /// How a local light whose rectification is not projective (in or near the view) is evaluated.
  enum class LocalLightFallback {
    Epipolar,   ///< prefiltered on its epipolar layout, its perspective map resampled into it (default)
    WorldMarch, ///< world-space march against its perspective map (CreateInfo::epipoleBlock): the reference
  };
  /// How the epipole block (the pixels next to the epipole on epipolar frames, Fig. 8) is evaluated.
  enum class EpipoleBlockMethod {
    TreeMarch,  ///< min/max tree march over the frame's epipolar map: exact on that map (default)
    WorldMarch, ///< world-space march against the standard shadow map: the reference, 16-23x the cost
  };
  /// Which rays the method evaluates.
  enum class Sampling {
    PerPixel, ///< every pixel's view ray (default)
    Epipolar, ///< Yusov 2012: selected samples along epipolar lines, interpolated, unwarped, corrected
  };
  struct CreateInfo {
    int width = 1280, height = 720; ///< camera image and output, pixels
    /// Rectified map texels per side on both layouts (epipolar: slices), a multiple of mapSizeMultiple().
    /// Cost: per frame, O(mapSize^2) in the shadow pass or resampling and the prefilter.
    int mapSize = 1024;
    /// Splits (logarithmic) and fallback thresholds; layout must be SplitLayout::Regions. Default 8 splits
    /// x 2 prefilter regions. Cost: the casters are drawn once per split.
    RectifyOptions rectify{.splits = 8};
    /// M (32), storage (RGBA8), weights (exact), regionsPerSplit P (2), ... of the directional light, and the
    /// visibility reconstruction of every light: Exact (default; the map's depths walked per pixel, no
    /// truncation; then M, storage and the local lights' M are unused) or Fourier (Klehm et al. 2014, Eq. 9).
    PrefilterOptions prefilter{.regionsPerSplit = 2, .reconstruction = VisibilityReconstruction::Exact};
    EvaluateOptions evaluate; ///< sampling (bilinear), near-plane correction, ringing filter
    /// M of the point-light faces (and of spots with spotLightBases -1): even, in [4, 128]; 0 =
    /// prefilter.bases. Cost when it differs: a second prefilter and evaluation pass; M / 4 basis fetches per
    /// pixel.
    int localLightBases = 64;
    /// M of the spot lights: 0 = prefilter.bases (default: the sun's passes), -1 = localLightBases, else even
    /// in [4, 128].
    int spotLightBases = 0;
    /// Depth samples Z of the local lights' scattering prefix table (0 = evaluate.visibilityTableSamples).
    /// Cost: per light and frame, O(Z) times the map's rows and regions; a local light's largest.
    int localLightTableSamples = 64;
    /// Z of spot lights off screen: 0 = localLightTableSamples, else in [2, kMaxVisibilityTableSamples].
    int spotLightTableSamples = 32;
    /// Local lights' sections in closed form (EvaluatePass::CreateInfo::localClosedForm; Sun et al. 2005).
    bool localLightClosedForm = false;
    /// Local lights in or near the view; world-marched anyway within the camera's near distance of the
    /// light and when epipolarRegions < 2.
    LocalLightFallback localLightFallback = LocalLightFallback::Epipolar;
    EpipoleBlockMethod epipoleBlockMethod = EpipoleBlockMethod::TreeMarch; ///< see the enum
    /// Sections and refinements of the world-space marches (EpipoleBlockMethod::WorldMarch, local fallback).
    WorldMarchOptions epipoleBlock;
    /// Epipole block radius, fraction of the screen diagonal in [0, 0.5], 0 = none; capped by
    /// epipoleBlockMaxPixels.
    double epipoleBlockRadius = 0.06;
    /// Most pixels of the epipole block (EpipolarOptions::maxBlockPixels; >= 0, 0 = no cap): bounds its cost.
    int epipoleBlockMaxPixels = 2048;
    /// Regions (logarithmic columns) of the epipolar layout, each cut into P prefilter regions like a split.
    int epipolarRegions = 8;
    /// Depth warp of the epipolar layout (EpipolarOptions::depthWarp; radians, >= 0, 0 = linear; Sec. 5).
    double epipolarDepthWarp = 0.1;
    double localLightDepthWarp = 0.03; ///< the same for a local light's epipolar layout (radians, >= 0)
    /// A local light's epipole block (fraction of the diagonal, [0, 0.5], 0 = none; capped like the
    /// sun's), marched in world space against its perspective map.
    double localLightBlockRadius = 0.01;
    /// Reduced-resolution evaluation (crep/pipeline/reduced_resolution.h): 1, 0.5 or 0.25; width and height
    /// multiples of 1 / evaluationScale. The epipole block stays at full resolution.
    double evaluationScale = 1.0;
    /// The directional light's method and sampling. MinMaxMarch: no prefilter, froxel fill or epipole block.
    Method method = Method::Prefiltered;
    Sampling sampling = Sampling::PerPixel;
    /// Options of Sampling::Epipolar (crep/epipolar/epipolar_sampling.h); evaluationScale must then be 1.
    EpipolarSamplingOptions epipolarSampling;
    /// Time every stage with the backend's GPU timer (FrameResult::stages, gpuTimes; pipeline/README.md).
    bool stageTimings = true;
    /// With stageTimings, wait for each stage's GPU time: a finish and a read per stage, which stall the
    /// pipeline; for tools and benchmarks (Stage::gpuMilliseconds in the same frame). false: run() never
    /// waits for the GPU (no finish, no read); the times arrive in a later frame's FrameResult::gpuTimes.
    bool blockingTimings = false;
    int ownShadowMapSize = 2048; ///< standard shadow map rendered with drawCasters on fallback frames
    /// lcm(rectify.splits * P, epipolarRegions * P), P = prefilter.regionsPerSplit (16 with the defaults).
    int mapSizeMultiple() const;
    /// Depth bias of that map in the world-space marches (depth-buffer units), finite and >= 0.
    double ownShadowMapBias = 1e-4;
    /// Runs the frame (must outlive the object); null: a gpu::GlBackend of its own on the current GL
    /// context. Other backends take the engine's shadow maps (no drawCasters).
    gpu::Backend* backend = nullptr;
  };

  /// An engine's shadow map: depth-buffer values of lightClipFromWorld, GL conventions, cleared to 1.
  struct ShadowMap {
    std::uint32_t texture = 0; ///< GL_TEXTURE_2D depth (or R32F) texture, any size (read from the texture)
    /// The sun's: orthographic along the light (validateLightMatrix); a spot's or point-light face's:
    /// perspective, centred at the light (validateLocalLightMatrix).
    glm::dmat4 lightClipFromWorld{1.0};
    double bias = 0.0; ///< added to the stored depth by the world-space marches
  };

  /// A froxel volume filled by the same frame's prefiltered evaluation (Wronski 2014's frustum grid).
  struct FroxelTarget {
    /// GL_TEXTURE_3D of grid.width x grid.height x grid.depth, GL_RGBA16F or GL_RGBA32F: RGB in-scattering
    /// to the cell's sample point, A grey transmittance to it.
    std::uint32_t volume = 0;
    FroxelGrid grid;        ///< the volume's cells and depth range (crep/scatter/froxel_grid.h)
    glm::dvec3 jitter{0.0}; ///< sample offset in cells, each component in [-0.5, 0.5] (froxelJitter())
  };

  struct FrameAttribs {
    /// The camera of cameraDepth, in your conventions (Camera::fromMatrices); integrated up to camera->far().
    const Camera* camera = nullptr;
    /// The sun; may be null when a local light is given (a night frame: shadowMap then ignored).
    const DirectionalLight* light = nullptr;
    const Medium* medium = nullptr;
    /// GL_TEXTURE_2D, width x height, depth-buffer values of `camera`: D32F, D24S8 / D24 or R32F; 0 only when
    /// `output` is 0.
    std::uint32_t cameraDepth = 0;
    /// GL_TEXTURE_2D RGBA32F width x height: RGB in-scattering, A transmittance. 0 only with `froxels` and no
    /// local light.
    std::uint32_t output = 0;
    /// Draws your casters (GL backend): the front door renders its plan's maps with it; may be empty.
    std::function<void(const glm::dmat4& clipFromWorld)> drawCasters;
    const ShadowMap* shadowMap = nullptr; ///< your standard map; may be null
    /// Local lights added to the result; they need drawCasters unless their maps are given.
    std::span<const SpotLight> spotLights;
    std::span<const PointLight> pointLights;    ///< six cube-map faces each
    std::span<const ShadowMap> spotShadowMaps;  ///< empty, or one per spotLights entry
    std::span<const ShadowMap> pointShadowMaps; ///< empty, or 6 per point light, face k of light i at 6 i + k
    /// The sun's light texture (orthographic along the light), or null (untextured, no cost); needs `light`.
    const GpuLightTexture* lightTexture = nullptr;
    /// Empty, or one per spot (perspective from its position); an entry whose texture is 0 is untextured.
    std::span<const GpuLightTexture> spotLightTextures;
    /// A volume to fill with this frame's basis, or null; needs `light`. At least one of output and froxels.
    const FroxelTarget* froxels = nullptr;
    /// This frame's plan (plan() before the engine's shadow passes), whose maps the engine rasterized; null:
    /// none. It must be the plan of this run (ShadowPassPlan::frame) for these camera, lights and given maps;
    /// then drawCasters must be empty.
    const ShadowPassPlan* plan = nullptr;
    /// With `plan`: one texture per ShadowPass in its order: for a pass that needsMap(), the map the engine
    /// rasterized for it (its width x height, a depth format or R32F); 0 for the others.
    std::span<const std::uint32_t> planMaps;
  };
  /// The frame's shadow passes for the engine to rasterize in its own clip conventions, before any GPU work
  /// (crep/pipeline/shadow_pass_plan.h; docs/INTEGRATION.md, "The plan"). Reads the camera, the lights and
  /// which shadow maps are given (those serve the standard passes); textures, output and medium are not read
  /// (they may be 0 or null yet). CPU only: no GL or backend call. InvalidArgument naming the field for a
  /// null camera, no light, or a light matrix validate() would refuse.
  ShadowPassPlan plan(const FrameAttribs& frame, const ShadowPassPlanOptions& options = {}) const;
  /// Throws what run(frame) would for its inputs before any GL work: InvalidArgument naming the field after
  /// `owner` (e.g. "Scattering::FrameAttribs.camera"), or naming "Scattering" for a moved-from object.
  void validate(const FrameAttribs& frame, std::string_view owner = "Scattering::FrameAttribs") const;

  /// What a local light (or one point-light face) cost and how it was computed.
  struct LightResult {
    enum class Kind { Spot, PointFace } kind = Kind::Spot;
    int index = 0; ///< into FrameAttribs::spotLights or pointLights
    int face = -1; ///< point light face 0-5 (+X, -X, +Y, -Y, +Z, -Z), -1 for a spot
    /// Projective, Fallback (in or near the view: `epipolar` or world-marched) or Empty (nothing done).
    RectifyStatus status = RectifyStatus::Empty;
    bool epipolar = false; ///< a Fallback light prefiltered on its epipolar layout, else marched
    /// Its shadow input was the given perspective map (spotShadowMaps, pointShadowMaps), not a plan's map
    /// or drawCasters.
    bool preRenderedMap = false;
    std::string message;           ///< the rectification's explanation
    double wallMilliseconds = 0.0; ///< its stages' Stage::wallMilliseconds summed (0 without stageTimings)
    /// With blockingTimings the backend's GPU timer over its stages; else 0: a later frame's
    /// GpuTimes::localLights has it.
    double gpuMilliseconds = 0.0;
  };

  enum class Layout { Projective, Epipolar };

  struct Stage {
    std::string name;
    /// With blockingTimings the backend's GPU timer (some GL drivers report 0); else 0: a later frame's
    /// FrameResult::gpuTimes has it.
    double gpuMilliseconds = 0.0;
    /// CPU wall clock of the stage: with blockingTimings ended by the backend's finish (the GPU's work
    /// included); else the time to record it.
    double wallMilliseconds = 0.0;
  };

  /// The GPU times of one earlier frame, arrived without waiting (stageTimings, not blockingTimings).
  struct GpuTimes {
    std::uint64_t frame = 0; ///< the FrameResult::frame they belong to, earlier than the reporting frame
    /// That frame's stages as its FrameResult::stages (names, order, wallMilliseconds), gpuMilliseconds
    /// filled: the backend's GPU timer (0 where it measures none).
    std::vector<Stage> stages;
    /// GPU milliseconds of that frame's local lights, one per LightResult in its order (0 for Empty).
    std::vector<double> localLights;
    double totalMilliseconds() const; ///< the stages' gpuMilliseconds summed
  };

  /// Without a directional light the directional members keep their defaults; stages start "transmittance".
  struct FrameResult {
    /// This run's index: the run() calls of the object before it (those that threw included).
    std::uint64_t frame = 0;
    /// stageTimings without blockingTimings: the GPU times of the latest earlier frame whose stages' times
    /// have all arrived (never waited for), or std::nullopt when none arrived since the last report. A
    /// frame is reported once at most: earlier ones that arrived with it are skipped, and at most
    /// gpu::FrameTimers::kMaxPendingFrames wait. Always std::nullopt with blockingTimings or without
    /// stageTimings.
    std::optional<GpuTimes> gpuTimes;
    Layout layout = Layout::Projective;
    Rectification rectification;     ///< the decision (reason, measure, threshold when not projective)
    double epipoleBlockRadius = 0.0; ///< pixels, after epipoleBlockMaxPixels; 0 without a block
    std::vector<Stage> stages;       ///< in order; names in pipeline/README.md, "scattering.h"
    /// Epipolar frames: the standard shadow map used (valid until the next run()); texture 0 if projective.
    ShadowMap shadowMap;
    std::vector<LightResult> localLights; ///< spots, then the faces of each point light
    /// Sampling::Epipolar with stageTimings and blockingTimings: the frame's sample and correction counts,
    /// read back from the GPU (zeros otherwise).
    struct SamplingStatistics {
      int validSamples = 0;        ///< epipolar samples on screen
      int marchedSamples = 0;      ///< evaluated by the method (the rest interpolated)
      int correctedPixels = 0;     ///< evaluated directly after the unwarp (no valid sample near them)
      int correctedFullPixels = 0; ///< the same after the upscale (downscale > 1)
    } sampling;
    /// The frame's rectified map (depth values or R32F, mapSize^2) and layout, valid until the next run().
    struct RectifiedMapView {
      std::shared_ptr<const RectifiedLayout> layout;
      std::uint32_t texture = 0;
      int width = 0, height = 0;
    } rectifiedMap;
  };

  /// One-time: validates (InvalidArgument naming the field; GlError beyond the GL limits), builds the passes.
  explicit Scattering(const CreateInfo& info);
  ~Scattering();
  /// Moved from: valid but empty (run() throws InvalidArgument naming "Scattering", memoryBytes() is 0).
  Scattering(Scattering&&) noexcept;
  Scattering& operator=(Scattering&&) noexcept;
  Scattering(const Scattering&) = delete;
  Scattering& operator=(const Scattering&) = delete;

  /// One frame. Throws InvalidArgument naming the FrameAttribs field, GlError for pending GL errors and
  /// states it cannot set aside; after a throw the GL state still follows docs/GL_STATE.md.
  FrameResult run(const FrameAttribs& frame);

  /// A moved-from object: the defaults (it owns nothing).
  const CreateInfo& createInfo() const noexcept;
  /// GPU memory it owns now, bytes (what it counts: pipeline/README.md); 0 for a moved-from object.
  std::size_t memoryBytes() const noexcept;

private:
  FrameResult runFrame(const FrameAttribs& frame);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// "projective" / "epipolar".
const char* layoutToken(Scattering::Layout layout);

} // namespace crep
