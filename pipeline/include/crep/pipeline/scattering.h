// The front door: one object per view, one call per frame, every frame prefiltered (Klehm, Seidel,
// Eisemann 2014). Scattering decides the layout itself: the projective rectification (Sec. 4.2) when
// rectify() accepts the frame, else the epipolar resampling fallback (Sec. 4.1) with the pixels next to the
// epipole (Fig. 8's block) tree-marched over the same epipolar map (Chen et al. 2011; Yusov 2012). It owns
// every pass and texture it needs; it never creates or
// owns the GL context (an OpenGL 4.5 core context must be current for its whole lifetime).
//
//   crep::Scattering scattering({.width = 1920, .height = 1080});           // once per view
//   ...
//   crep::Scattering::FrameAttribs f;                                      // every frame
//   f.camera = &camera; f.light = &sun; f.medium = &fog;
//   f.cameraDepth = depthTexture; f.output = scatteringTexture;           // your GL textures
//   f.drawCasters = [&](const glm::dmat4& clipFromWorld) { drawShadowCasters(clipFromWorld); };
//   crep::Scattering::FrameResult r = scattering.run(f);                  // r.layout, r.stages
//   color = surface * output.a + output.rgb                                // your composite
//
// Shadow inputs of the directional light (at least one when FrameAttribs::light is set):
//   - drawCasters: a callback that draws the shadow casters with the given clip-from-world matrix (your
//     depth-only shaders, your geometry). Scattering binds its own framebuffer and depth texture, sets
//     the viewport of each split, GL_DEPTH_TEST with GL_LESS, depth writes, GL_DEPTH_CLAMP (casters between
//     the light and the frustum must still shadow it), no face culling, and clears depth to 1; the callback
//     only binds its program and vertex data and draws. On fallback frames without `shadowMap` it is also
//     called once to render a standard shadow map fitted to the camera frustum.
//   - shadowMap: your standard (orthographic, along the light) shadow map and its matrix. With it and no
//     drawCasters the projective map is point-resampled from it (Sec. 4.1's rule on the projective layout);
//     fallback frames always resample it into the epipolar layout.
//
// Local lights (Klehm et al. 2014, Sec. 3.2 "Local Lights"): FrameAttribs::spotLights and pointLights
// (six faces each) are added to the directional light's result. Without a directional light (a night
// frame) FrameAttribs::light may be null when at least one local light is given: the output is then the
// local lights' sum and the transmittance (A) as usual. Each light is rectified for the camera; its
// shadow input is either
//   - drawCasters: a projective light (the light off screen) is rendered into its rectified map
//     (RectifiedShadowPass); a light whose rectification is not projective (in or near the view) gets a
//     perspective shadow map rendered with its own matrix (SpotLight::lightClipFromWorld,
//     PointLight::faceClipFromWorld);
//   - or your pre-rendered perspective maps, FrameAttribs::spotShadowMaps (one per spot) and pointShadowMaps
//     (six per point light, GL cube-map face order): any perspective matrix centred at the light
//     (validateLocalLightMatrix) covering the spot's cone or the face's sector (PointLight::faceOf), e.g. an
//     engine's cube-map face matrices. A projective light's rectified map is then point-resampled from it
//     (ShadowResamplePass, Sec. 4.1's rule on the light's layout), a fallback light marches it directly.
// A projective light is prefiltered with its light-side factor in the weights and evaluated with every
// ray's own in-scattering (the regions it crosses whole from the scattering prefix table, its last region
// from the local section table times its share, EvaluateOptions::localSectionTable; pixels the light never
// reaches, outside the spot's cone or the face's sector, return at once); a fallback light (in or near the
// view) is prefiltered the same way on its epipolar layout (the light's image is the epipole; its
// perspective map resampled into it, CreateInfo::localLightFallback), or marched in world space against
// that map (WorldMarchPass, the reference); one that does not reach the camera frustum costs nothing. Local
// lights are evaluated at full resolution.
//
// Light textures (README "Light textures"; Klehm et al. 2014, Sec. 3.2: a coloured light texture is a
// light-side factor stored per colour channel): FrameAttribs::lightTexture (the directional light's, e.g. a
// stained-glass window; an orthographic projection along the light) and spotLightTextures (one per spot, a
// gobo; a perspective projection centred at the spot). A textured light's colour map is made for the
// layout its frame uses (LightColorMapPass: the projective or the epipolar layout) and prefiltered with it
// (three bases, PrefilterPass::FrameAttribs::lightColors), the evaluation follows the textured basis; the
// tree-marched epipole block reads the same colour map (RectifiedMarchPass::FrameAttribs::lightColors), the
// world-space marches (EpipoleBlockMethod::WorldMarch, LocalLightFallback::WorldMarch) take the texture
// itself (WorldMarchPass::FrameAttribs::lightTexture). A constant white texture gives the untextured result
// bit for bit, except inside a tree-marched epipole block, where the textured walk sums each lit texel alone
// (the untextured one a lit node at once): equal there to float rounding (7e-7 of a 1.5 peak, tested). Not
// with CreateInfo::evaluate.nearPlaneCorrection or the visibility table alone (scatteringPrefix
// false with visibilityTableSamples > 0): those have no textured variant (InvalidArgument). Point lights
// take no texture. Without textures nothing of this runs or is allocated.
//
// Froxel volumes (Wronski 2014's frustum-aligned volume for transparent surfaces and particles at any depth;
// crep/scatter/froxel_grid.h): FrameAttribs::froxels fills a caller's 3D texture with the same frame's
// prefiltered evaluation (EvaluatePass::FrameAttribs::froxels), texel (x, y, z) = the evaluation of the ray
// through the cell's (u, v) up to its sample view depth, no accumulation pass and no exponential-shadow-map
// light leaking. `output` (and cameraDepth) may then be 0 (only the volume). Directional light (and its
// texture) only: local lights are not added to the volume, and on epipolar frames the cells inside the
// epipole block are evaluated by the prefiltered method too (not marched: the marches have no 3D target;
// measured against the world-space reference at the cells with the sun in view: 1.9% / 3.3% relative RMSE
// inside the block, 2.8% / 2.7% outside, forest / colonnade, tests/pipeline/ScatteringFroxelGLTest.cpp).
// The stage "froxels" times the fill (it reuses the per-frame table the per-pixel evaluation built).
//
// Epipolar sampling (Yusov 2012, Sec. 5-6; crep/epipolar/epipolar_sampling.h has the rules): with
// CreateInfo::sampling = Sampling::Epipolar the method evaluates only samples along epipolar lines (lines
// from the epipole to the screen border, CreateInfo::epipolarSampling.slices x samples): every
// initialStep-th sample and the samples next to depth or in-scattering breaks; the others are interpolated
// along their line, each pixel takes its two nearest lines' samples with depth-aware (bilateral) weights,
// and the pixels without a valid sample near them are evaluated directly (the correction). With
// Method::Prefiltered the samples and corrections are the prefiltered evaluation (a hybrid: the
// prefiltered method's constant cost per ray on Yusov's reduced set of rays); with Method::MinMaxMarch
// this is Yusov's method itself. The stages are named "epipolar samples", "refine samples", "evaluate
// samples" / "march samples", "interpolate", "unwarp", "correct" and, with downscale > 1, "upscale" and
// "correct (full)"; FrameResult::sampling counts the samples.
//
// GL state (docs/GL_STATE.md): the depth passes drawn with drawCasters set every raster state their maps
// depend on (clip control, depth range, depth state, polygon mode and offset, culling, scissor, discard,
// clip distances, ...) whatever the caller left, and restore it; run() leaves program 0 and texture /
// sampler / image units and uniform / storage buffer bindings 0-7 unbound, and every other unit as it was.
// It throws GlError for states it cannot set aside: an active transform feedback, or with stageTimings an
// active GL_TIME_ELAPSED query of the caller.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/epipolar/epipolar_sampling.h>
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
    /// Prefiltered on the light's epipolar layout (EpipolarLayout for its position: the light's image is the
    /// epipole), its perspective map resampled into it (default): the projective light's passes.
    Epipolar,
    /// The world-space march against its perspective map (CreateInfo::epipoleBlock's steps): the reference.
    WorldMarch,
  };
  /// How the epipole block (the pixels next to the epipole on epipolar frames) is evaluated.
  enum class EpipoleBlockMethod {
    /// The min/max tree march over the frame's epipolar map (default): exact visibility on the map the
    /// frame prefiltered, cost bounded by the block's pixels times a short tree walk.
    TreeMarch,
    /// The world-space march against the standard shadow map (CreateInfo::epipoleBlock's steps): the
    /// reference, a world-space march per pixel (16-23x the tree march per pixel, README "Sun in view").
    WorldMarch,
  };
  /// Which rays the method evaluates (see "Epipolar sampling" at the top).
  enum class Sampling {
    PerPixel, ///< every pixel's view ray (default)
    Epipolar, ///< Yusov 2012: selected samples along epipolar lines, interpolated, unwarped, corrected
  };
  struct CreateInfo {
    int width = 1280, height = 720; ///< camera image and output, pixels
    /// Rectified map: mapSize x mapSize texels on both layouts (the fallback uses mapSize epipolar slices),
    /// so a fallback frame costs what a projective one does. A multiple of rectify.splits * P and of
    /// epipolarRegions * P (P = prefilter.regionsPerSplit).
    int mapSize = 1024;
    /// Splits (logarithmic) and fallback thresholds. layout must be SplitLayout::Regions (side by side in
    /// one texture). Default 8 splits with 2 prefilter regions each (below): 16 prefilter regions on both
    /// layouts, so both cost the same per pixel. A projective row's rays have world steps up to 11.5x
    /// apart (rectify.minEpipoleAngleDegrees), and the prefilter's weights, exact for one reference ray
    /// per region, fit the others only over short regions. Measured over 18 random projective frames near
    /// the thresholds (tests/pipeline/ThresholdStudyGLTest.cpp, README "Sun in view"), relative RMSE
    /// against the world-space reference: 4 splits 1.0-12.1%; 4 x 2 regions 1.0-6.5%; 8 splits 0.9-4.0%;
    /// 8 x 2 regions (default) 0.9-3.0%; 16 splits 0.9-3.0%; the map itself (brute-force march) 0.6-2.2%.
    /// Cost: the casters are drawn once per split; the evaluation reads one tabulated visibility per region
    /// a ray crosses whole and the basis (M / 4 fetches) for the last one (EvaluateOptions::
    /// visibilityTableSamples): on llvmpipe 16 regions evaluate in 41-47 ms at 640x360 (forest, colonnade,
    /// terrain, boxes), 69-79 ms without the table, 34 ms with 4 regions without it (bench/README.md).
    RectifyOptions rectify{.splits = 8};
    /// M (32), storage (RGBA8), weights (exact), regions per split (default 2, see rectify), ...
    PrefilterOptions prefilter{.regionsPerSplit = 2};
    EvaluateOptions evaluate; ///< sampling (bilinear), near-plane correction, ringing filter
    /// M of the point-light faces' prefilter and evaluation (and of spot lights with spotLightBases = -1;
    /// even, in [4, 128]; 0 = prefilter.bases). A point light's faces see the whole depth range of the view
    /// from close by, and M = 32 smooths their visibility steps over too much of it. Measured on the
    /// colonnade (tests/pipeline/ScatteringLocalGLTest.cpp, map 512, relative RMSE against the world-space
    /// reference): point light M = 32 2.67%, 48 1.57%, 64 (default) 1.08%; spot light off screen 0.45%,
    /// 0.30%, 0.31%. Cost when it differs from prefilter.bases: a second PrefilterPass and EvaluatePass
    /// (made on the first frame with a projective local light), M / 4 RGBA layers per texel of the local
    /// map (2x at 64) and M / 4 basis fetches per pixel in its evaluation.
    int localLightBases = 64;
    /// M of the spot lights' prefilter and evaluation: 0 = prefilter.bases (default: the directional
    /// light's passes serve them, no second basis), -1 = localLightBases (the rule before this field), or
    /// even in [4, 128]. A spot lights a cone, seen from outside the view: M = 32 keeps it within 0.45% of
    /// the world-space reference on the colonnade (0.31% at 64, table above) for half the prefilter and the
    /// basis fetches of 64.
    int spotLightBases = 0;
    /// Depth samples of the local lights' scattering prefix table (EvaluateOptions::visibilityTableSamples
    /// of their evaluation; 0 = evaluate.visibilityTableSamples; no table when that is 0). The table holds
    /// each region's in-scattering along R x Z x H sample rays, a quadrature per entry for a local light:
    /// it dominates a local light's cost, and halving Z halves it. Measured on the colonnade (relative
    /// RMSE against the world-space reference, map 512): Z = 128: point light 1.08%, spot 0.235%; 64
    /// (default): 1.17%, 0.245%; 32: 2.5%, 0.32%. Cost: see README "Local lights".
    int localLightTableSamples = 64;
    /// Depth samples of the prefix table of spot lights off screen (projective; 0 = localLightTableSamples,
    /// else in [2, kMaxVisibilityTableSamples]). The table is a spot's largest per-frame cost and halves
    /// with Z, while its accuracy moves little (colonnade: 0.46% at 64, 0.52% at 32). A spot in or near the
    /// view keeps localLightTableSamples: its epipolar depth is warped toward the light, the table's samples
    /// are not (1.35% at 64, 3.5% at 32).
    int spotLightTableSamples = 32;
    /// Local lights' sections in closed form (EvaluatePass::CreateInfo::localClosedForm: Sun et al. 2005
    /// extended, crep/scatter/airlight.h) instead of the quadrature (default false: slower on llvmpipe,
    /// measured there; see that field).
    bool localLightClosedForm = false;
    /// Local lights in or near the view: prefiltered on their epipolar layout (default) or marched in world
    /// space. Marched in any case: a light within the camera's near distance (no camera-light axis), and all
    /// of them when epipolarRegions < 2.
    LocalLightFallback localLightFallback = LocalLightFallback::Epipolar;
    /// How the epipole block is evaluated: TreeMarch (default) or the world-space reference.
    EpipoleBlockMethod epipoleBlockMethod = EpipoleBlockMethod::TreeMarch;
    /// World-space march of the epipole block with EpipoleBlockMethod::WorldMarch (and of local lights in or
    /// near the view): sections and refinements (bias comes with the shadow map).
    WorldMarchOptions epipoleBlock;
    /// Radius of the epipole block as a fraction of the screen diagonal (0 = none), in [0, 0.5], bounded by
    /// epipoleBlockMaxPixels. Default 6%: the pixels whose view rays are nearly parallel to the light, where
    /// the prefilter's weights fit worst (Fig. 8), including those at the screen edge when the sun is just
    /// outside it. Measured with the sun 5% of the diagonal beyond the right edge: 2% -> 2.1% relative RMSE,
    /// 6% -> 1.9%; with the sun in view the bound (below) sets the radius on large screens.
    double epipoleBlockRadius = 0.06;
    /// Most pixels of the epipole block on screen (EpipolarOptions::maxBlockPixels; >= 0, 0 = no bound):
    /// with the sun in view the block's radius shrinks so it holds at most this many pixels, so its cost
    /// does not grow with the screen (6% of a 1920x1080 diagonal is 55,000 pixels). Default 2048: radius
    /// 25.5 px (1.2% of the diagonal at 1920x1080, 3.5% at 640x360, the full 6% at 320x180 and below).
    int epipoleBlockMaxPixels = 2048;
    /// Regions of the epipolar layout (its columns, logarithmic in the distance from the light axis; the
    /// fallback's splits), each cut into P prefilter regions like a split. A slice's view rays range from
    /// nearly parallel to the light (next to the epipole) to the screen border, so their world steps per
    /// column differ by up to 20x. Measured with the sun in view (README "Sun in view"; 1024^2 map),
    /// prefilter regions in all: 4 -> 4-7% relative RMSE on the forest and colonnade, 8 -> 1.8-2.3%,
    /// 16 (8 x 2, the default, or 16 x 1) -> 1.5-1.75%.
    int epipolarRegions = 8;
    /// Depth warp of the epipolar layout (EpipolarOptions::depthWarp, radians, >= 0; 0 = linear in psi):
    /// more depth resolution for the view rays next to the light axis (Klehm et al. 2014, Sec. 5), which
    /// lowers the light bleeding around the epipole block. Measured (README "Sun in view"): 0 -> 3.0%
    /// relative RMSE with the sun just outside the screen, 0.1 -> 2.1%, 0.3 -> 2.4%, 1 -> 2.8%.
    double epipolarDepthWarp = 0.1;
    /// The same for a local light's epipolar layout (localLightFallback Epipolar; radians, >= 0): its glow
    /// lies on the view rays next to the light, at small psi, so a smaller warp than the sun's serves it
    /// (figures in README "Local lights").
    double localLightDepthWarp = 0.03;
    /// Radius of a local light's epipole block on its epipolar layout (fraction of the screen diagonal, in
    /// [0, 0.5], 0 = none; bounded by epipoleBlockMaxPixels): the pixels around the light's image, where
    /// every slice meets and a ray crosses every light ray next to the light, are marched in world space
    /// against its perspective map. A light texture's colours need it most there (figures in README "Local
    /// lights").
    double localLightBlockRadius = 0.01;
    /// Reduced-resolution evaluation (crep/pipeline/reduced_resolution.h; not in the paper): 1 (full), 0.5
    /// or 0.25. Below 1 the evaluation runs on a camera image 2x or 4x smaller per axis (checkerboard
    /// min/max depth) and a depth-aware upsample brings it back; the epipole block is still marched at full
    /// resolution. width and height must then be multiples of 1 / evaluationScale. Cost and added error:
    /// README "Reduced resolution".
    double evaluationScale = 1.0;
    /// The directional light's method and sampling (see "Epipolar sampling" at the top). MinMaxMarch skips
    /// the prefilter and builds the map's min/max trees instead; it has no froxel fill and no epipole
    /// block (the tree march over the epipolar map is exact there). Local lights are prefiltered either way.
    Method method = Method::Prefiltered;
    Sampling sampling = Sampling::PerPixel;
    /// Slices, samples per slice, initial step, refinement criteria and thresholds, bilateral threshold and
    /// downscale of Sampling::Epipolar (crep/epipolar/epipolar_sampling.h). evaluationScale must then be 1
    /// (the sampling's downscale is its reduced resolution).
    EpipolarSamplingOptions epipolarSampling;
    /// Measure every stage (FrameResult::stages): a GL_TIME_ELAPSED query and a glFinish per stage, which
    /// stalls the pipeline; turn off in production (stages then lists names with zero times).
    bool stageTimings = true;
    int ownShadowMapSize = 2048; ///< standard shadow map rendered with drawCasters on fallback frames
    /// The multiple mapSize must be: lcm(rectify.splits * P, epipolarRegions * P), P =
    /// prefilter.regionsPerSplit (16 with the defaults).
    int mapSizeMultiple() const;
    /// Depth bias of that map in the epipole block march (depth-buffer units of a map whose depth range
    /// spans the camera frustum along the light), finite and >= 0.
    double ownShadowMapBias = 1e-4;
  };

  /// The engine's shadow map of a light (depth-buffer values of lightClipFromWorld in GL conventions,
  /// glDepthRange(0, 1) of NDC z in [-1, 1], cleared to 1).
  struct ShadowMap {
    std::uint32_t texture = 0; ///< GL_TEXTURE_2D depth (or R32F) texture, any size (read from the texture)
    /// The directional light's: orthographic, looking along the light (validateLightMatrix). A spot light's
    /// or point-light face's: perspective, centred at the light (validateLocalLightMatrix).
    glm::dmat4 lightClipFromWorld{1.0};
    double bias =
        0.0; ///< added to the stored depth by the world-space marches (epipole block, local fallback)
  };

  /// A froxel volume filled by the same frame's prefiltered evaluation (see "Froxel volumes" at the top).
  struct FroxelTarget {
    /// GL_TEXTURE_3D of grid.width x grid.height x grid.depth texels, GL_RGBA16F or GL_RGBA32F: texel (x, y,
    /// z) = RGB in-scattered radiance from the camera to the cell's sample point along the pixel ray
    /// through its (u, v), A = grey transmittance exp(-sbar d) to it (crep/scatter/ray.h's convention).
    std::uint32_t volume = 0;
    FroxelGrid grid; ///< the volume's cells and depth range (crep/scatter/froxel_grid.h)
    /// The sample point's offset in cells, each component in [-0.5, 0.5] (e.g. froxelJitter(frame)).
    glm::dvec3 jitter{0.0};
  };

  struct FrameAttribs {
    /// The camera of cameraDepth, in your conventions: Camera::fromMatrices(viewFromWorld, clipFromView,
    /// clipDepth, maxDistance) (reversed-Z, [0, 1] clip depth, infinite far plane, jitter, asymmetric
    /// frusta; crep/core/camera.h). The scattering is integrated up to camera->far().
    const Camera* camera = nullptr;
    /// The directional light; may be null when at least one local light is given (a night frame: no
    /// directional shadow input needed; shadowMap is then ignored, drawCasters serves the local lights).
    const DirectionalLight* light = nullptr;
    const Medium* medium = nullptr;
    /// GL_TEXTURE_2D, width x height, depth-buffer values of `camera` in its convention: D32F, D24S8 / D24
    /// (read as depth) or R32F. May be 0 when `output` is 0 (a froxel volume alone reads no camera depth).
    std::uint32_t cameraDepth = 0;
    /// GL_TEXTURE_2D RGBA32F width x height: RGB in-scattering, A transmittance. May be 0 when `froxels` is
    /// given and no local light is (only the volume is filled; the per-pixel evaluation and the epipole
    /// block are skipped).
    std::uint32_t output = 0;
    std::function<void(const glm::dmat4& clipFromWorld)> drawCasters; ///< see the top; may be empty
    const ShadowMap* shadowMap = nullptr;                             ///< see the top; may be null
    /// Local lights added to the result (see the top); they need drawCasters unless their maps are given.
    std::span<const SpotLight> spotLights;
    std::span<const PointLight> pointLights;    ///< six cube-map faces each
    std::span<const ShadowMap> spotShadowMaps;  ///< empty, or one per spotLights entry
    std::span<const ShadowMap> pointShadowMaps; ///< empty, or six per pointLights entry (face k of light i
                                                ///< at 6 i + k; faces +X, -X, +Y, -Y, +Z, -Z)
    /// Light textures (see the top): the directional light's texture (its projection orthographic along
    /// the light), or null (untextured, no cost). Requires `light`.
    const GpuLightTexture* lightTexture = nullptr;
    /// Empty, or one per spotLights entry (its projection perspective from the spot's position); an entry
    /// whose texture is 0 is untextured.
    std::span<const GpuLightTexture> spotLightTextures;
    /// Froxel volumes (see the top): null, or a volume to fill with this frame's basis; needs `light`. At
    /// least one of `output` and `froxels` must be given.
    const FroxelTarget* froxels = nullptr;
  };
  /// Throws what run(frame) would for its inputs before any GL work: InvalidArgument naming the field after
  /// `owner` (e.g. "Scattering::FrameAttribs.camera"), or naming "Scattering" for a moved-from object.
  void validate(const FrameAttribs& frame, std::string_view owner = "Scattering::FrameAttribs") const;

  /// What a local light (or one point-light face) cost and how it was computed.
  struct LightResult {
    enum class Kind { Spot, PointFace } kind = Kind::Spot;
    int index = 0; ///< into FrameAttribs::spotLights or pointLights
    int face = -1; ///< point light face 0-5 (+X, -X, +Y, -Y, +Z, -Z), -1 for a spot
    /// The rectification's status: Projective (prefiltered on the projective layout), Fallback (in or near
    /// the view: `epipolar` or marched in world space), Empty (outside the view, nothing done).
    RectifyStatus status = RectifyStatus::Empty;
    /// A Fallback light prefiltered on its epipolar layout (CreateInfo::localLightFallback Epipolar); false:
    /// marched in world space.
    bool epipolar = false;
    /// Its shadow input: the given perspective map (FrameAttribs::spotShadowMaps / pointShadowMaps,
    /// resampled when projective) rather than drawCasters.
    bool preRenderedMap = false;
    std::string message;           ///< the rectification's explanation
    double wallMilliseconds = 0.0; ///< CPU wall clock of its stages (0 without stageTimings)
    double gpuMilliseconds = 0.0;  ///< GL_TIME_ELAPSED of its stages
  };

  enum class Layout { Projective, Epipolar };

  struct Stage {
    std::string name;
    double gpuMilliseconds = 0.0;  ///< GL_TIME_ELAPSED of the stage (llvmpipe reports 0 for compute work)
    double wallMilliseconds = 0.0; ///< CPU wall clock of the stage, ended by glFinish
  };

  /// Without a directional light (FrameAttribs::light null) the directional members keep their defaults
  /// (rectification not projective, rectifiedMap and shadowMap texture 0) and stages start with
  /// "transmittance".
  struct FrameResult {
    Layout layout = Layout::Projective;
    Rectification rectification; ///< the decision (reason, measure, threshold when not projective)
    /// Pixels, after CreateInfo::epipoleBlockMaxPixels; 0 without a block (projective, or epipole at
    /// infinity).
    double epipoleBlockRadius = 0.0;
    /// In order: shadow / resample, light colours (with FrameAttribs::lightTexture), prefilter, evaluate
    /// (with an output), froxels (with FrameAttribs::froxels: the volume's fill alone, from the per-frame
    /// table the evaluation built), and with the epipole on screen "min/max trees (epipole block)" and
    /// "epipole block (tree march)" (or "epipole block (world march)" with EpipoleBlockMethod::WorldMarch).
    std::vector<Stage> stages;
    /// Epipolar frames: the standard shadow map resampled and marched (the engine's, or the one rendered
    /// with drawCasters, valid until the next run()); texture 0 on projective frames.
    ShadowMap shadowMap;
    /// The local lights, in order (spots, then the faces of each point light).
    std::vector<LightResult> localLights;
    /// Sampling::Epipolar with stageTimings: the frame's sample and correction counts (read back from the
    /// GPU lists; zeros otherwise).
    struct SamplingStatistics {
      int validSamples = 0;        ///< epipolar samples on screen
      int marchedSamples = 0;      ///< evaluated by the method (the rest interpolated)
      int correctedPixels = 0;     ///< evaluated directly after the unwarp (no valid sample near them)
      int correctedFullPixels = 0; ///< the same after the upscale (downscale > 1)
    } sampling;
    /// The rectified map the frame was prefiltered from (rasterized or resampled; depth-buffer values or
    /// R32F, mapSize x mapSize) and its layout, valid until the next run(): for debug views, and for
    /// running the peers of the prefiltered method (RectifiedMarchPass, MinMaxTreePass) on the same data.
    struct RectifiedMapView {
      std::shared_ptr<const RectifiedLayout> layout;
      std::uint32_t texture = 0;
      int width = 0, height = 0;
    } rectifiedMap;
  };

  /// Validates (InvalidArgument naming the field, e.g. "Scattering::CreateInfo.mapSize"; GlError beyond
  /// the GL limits) and builds the passes (the light textures' colour map pass on the first textured
  /// frame).
  explicit Scattering(const CreateInfo& info);
  ~Scattering();
  /// Moved from: valid but empty (run() throws InvalidArgument naming "Scattering", memoryBytes() is 0).
  Scattering(Scattering&&) noexcept;
  Scattering& operator=(Scattering&&) noexcept;
  Scattering(const Scattering&) = delete;
  Scattering& operator=(const Scattering&) = delete;

  /// One frame. Throws InvalidArgument naming the FrameAttribs field (null pointers; textures of the wrong
  /// target, size or format class, or an output that is also an input; no shadow input; span sizes; bad
  /// local maps, e.g. "Scattering::FrameAttribs.spotShadowMaps[0].lightClipFromWorld"; bad light textures,
  /// e.g. "Scattering::FrameAttribs.spotLightTextures[0].textureClipFromWorld"; a moved-from object; a
  /// call from inside its own drawCasters), GlError for GL errors pending before the call and for the
  /// states of docs/GL_STATE.md it cannot set aside. Whatever it throws, the context is left as the
  /// contract says (no query active, raster state restored, units 0-7 unbound, no GL error pending from
  /// the call) and the next frame of this object or of a new one is right.
  FrameResult run(const FrameAttribs& frame);

  /// A moved-from object: the defaults (it owns nothing).
  const CreateInfo& createInfo() const noexcept;
  /// GPU memory it owns now, bytes: the filtered basis and the region visibility table, the rasterized
  /// (D32F) and resampled (R32F) rectified maps, its own standard shadow map once a fallback frame needed
  /// it, the reduced-resolution depth and scattering (evaluationScale < 1), the local lights' targets once
  /// used (scattering, rasterized and resampled rectified maps, perspective map), the light textures' colour
  /// map once used (and the prefilters' textured bases: PrefilterPass::memoryBytes) and the passes'
  /// buffers. 0 for a moved-from object.
  std::size_t memoryBytes() const noexcept;

private:
  FrameResult runFrame(const FrameAttribs& frame);
  void runLocalLights(const FrameAttribs& frame, FrameResult& result);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// "projective" / "epipolar".
const char* layoutToken(Scattering::Layout layout);

} // namespace crep
