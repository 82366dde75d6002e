// GPU passes of prefiltered single scattering (Klehm, Seidel, Eisemann 2014, Sec. 3.3, Listings 2-4,
// Appendix A) on OpenGL 4.5 compute shaders: PrefilterPass turns the caller's rectified depth texture
// into the filtered-basis texture array, EvaluatePass turns the caller's camera depth texture into the
// scattering image. They implement the rules of crep::prefilter() and crep::evaluate() (prefilter.h,
// the CPU reference and contract) in float; tests/prefilter/PrefilterGpuGLTest.cpp states how closely.
//
// Effect-module conventions (docs/ARCHITECTURE.md): a CreateInfo fixes sizes, formats and quality once
// (programs and textures are built in the constructor, owned by RAII and released in the destructor); a
// FrameAttribs carries the per-frame inputs. Inputs are non-owning: GL names of the caller's textures and
// pointers to CPU objects that must outlive the call. No pass creates, owns or changes the current GL
// context; each needs one (OpenGL 4.5 core) current on the calling thread for its whole lifetime.
//
// GL state (docs/GL_STATE.md has the whole contract): run() binds its own programs, textures, samplers,
// images and buffers to the units and binding points below and unbinds them (0) before returning; it does not
// restore the caller's bindings there. It issues glMemoryBarrier so that the results can be sampled /
// image-loaded afterwards.
//   PrefilterPass::run: texture unit 0 (+ sampler), image unit 0, uniform buffer 0, storage buffer 0.
//   EvaluatePass::run:  texture units 0 and 1 (+ samplers), image unit 0 (the output, then the froxel
//                       volume), uniform buffers 0 and 1, storage buffer 1 (near-plane correction), the
//                       froxel program's uniforms (locations 0, 1); for a non-projective layout also
//                       uniform buffer 2 and storage buffer 2 (its layout block and row table); with the
//                       scattering prefix table (EvaluateOptions::scatteringPrefix, the default) texture
//                       unit 7, or with the region visibility table alone texture unit 6 (+ sampler), and
//                       storage buffer 0 for the table pass that runs first.
// Engines that evaluate in their own shader use crep/scattering.glsl with filteredBasis() and
// makeScatteringParams() (see that file's header).
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include <crep/core/camera.h>
#include <crep/core/gl.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/prefilter/gpu_structs.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/froxel_grid.h>
#include <crep/scatter/gpu_layout_buffers.h>
#include <crep/scatter/gpu_sample_list.h>

namespace crep {

/// A filtered basis on the GPU: the texture array and the parameters it was prefiltered with
/// (everything evaluation needs besides the layout). Non-owning GL names.
struct FilteredBasisView {
  std::uint32_t texture = 0;       ///< GL_TEXTURE_2D_ARRAY, width x height x ceil(bases / 4) layers, RGBA
  std::uint32_t regionWeights = 0; ///< buffer of height * R gpu::RegionWeights (near-plane correction)
  int width = 0;                   ///< W, texels
  int height = 0;                  ///< H, texels
  int bases = kDefaultBases;       ///< M
  int layoutRegions = 1;           ///< K, the layout's regionCount()
  int regionsPerSplit = 1;         ///< P; prefilter regions R = K P
  WeightMode weights = WeightMode::Exact; ///< weight mode used
  double extinction = 0.0;                ///< scalar weight extinction s used (1/world unit)
  double depthMargin = 0.0625;            ///< m of fourier.h used
  bool localLight = false;                ///< prefiltered with a local light's factor in the weights
  /// Prefiltered with a light texture's colour map (prefilter.h, "Light textures"): `texture` has 3 ceil(M /
  /// 4) layers (colour c from layer c ceil(M / 4)) and `meanColor` is the prefix mean colour.
  bool textured = false;
  std::uint32_t meanColor = 0; ///< textured: GL_TEXTURE_2D, width x height, GL_RGBA32F (rgb cbar)

  int regions() const noexcept { return layoutRegions * regionsPerSplit; } ///< R
};

/// The GPU per-row data of the weights (gpu::RegionWeights, index row * R + region) from the reference
/// profiles of referenceProfiles() (height * R of them) for regions of `texelsPerRegion` texels: the
/// CPU half of the prefilter pass, computed in double. Throws InvalidArgument ("texelsPerRegion") if < 1.
std::vector<gpu::RegionWeights> gpuRegionWeights(const std::vector<DistanceProfile>& profiles,
                                                 WeightMode mode, int texelsPerRegion);

/// The uniform block of crep/scattering.glsl for evaluating `basis` on `layout` (the one it was
/// prefiltered from; a non-projective layout also needs its own block, gpu::LayoutBuffers + CREP_EVAL_LAYOUT)
/// with a directional light and a medium. Throws InvalidArgument naming the parameter ("layout": no GPU
/// mapping, or its region count differs from basis.layoutRegions or exceeds gpu::kMaxSplits;
/// "FilteredBasisView": inconsistent sizes).
gpu::ScatteringParams makeScatteringParams(const FilteredBasisView& basis, const RectifiedLayout& layout,
                                           const DirectionalLight& light, const Medium& medium);

/// The prefilter pass (Listing 3 + 2): one compute dispatch over rows x groups of bases x regions.
class PrefilterPass {
public:
  struct CreateInfo {
    int mapWidth = 1024;  ///< map width W, texels; a multiple of the regions R = K P at run()
    int mapHeight = 1024; ///< map height H, texels (rows = epipolar slices)
    /// The prefilter it runs: M (ceil(M / 4) RGBA layers), storage format (Sec. 3.3), weights
    /// (weights.h), regions per split P (Table 1 "regions", <= width), depth margin, bases per invocation
    /// (Table 1). The same options give the CPU reference crep::prefilter(); `threads` is not used.
    /// basesPerInvocation: default 16 (see PrefilterOptions); on llvmpipe 32 is fastest (more invocations
    /// only repeat the depth reads and weights on a CPU); the paper chose 8 on an NVIDIA Titan with 1-3
    /// regions per row.
    PrefilterOptions options;
    int workgroupRows = 64;      ///< local_size_x: rows per workgroup, >= 1
    int workgroupBaseGroups = 1; ///< local_size_y: groups of bases per workgroup, >= 1
    int workgroupRegions = 1;    ///< local_size_z: regions per workgroup, >= 1
    /// Benchmarks only (the output is meaningless): the pass stripped to its memory traffic, the same map
    /// reads and the same filtered-basis writes in the same order without the Fourier basis and the
    /// weights (CREP_MEMORY_LIMIT), to measure how close the pass is to its bandwidth limit.
    bool memoryLimit = false;
  };

  struct FrameAttribs {
    /// The caller's rectified map: a GL_TEXTURE_2D of width x height texels (any depth or float
    /// format; channel r = depth-buffer value in [0, 1]), e.g. rendered with the split matrices and
    /// SplitLayout::Regions. Read with texelFetch through the pass's own sampler (no compare mode).
    std::uint32_t rectifiedDepth = 0;
    const RectifiedLayout* layout = nullptr; ///< the map's layout (reference-ray profiles); not owned
    const Medium* medium = nullptr;   ///< weight extinction = weightExtinction(*medium), unless overridden
    double extinctionOverride = -1.0; ///< >= 0: use this weight extinction s instead (1/world unit)
    /// A local light (a spot, or one point-light face; the map of its rectification): its light-side factor
    /// goes into the weights as crep::prefilter(map, medium, light) does (CREP_LOCAL_LIGHT variant, built on
    /// first use; needs `medium` and options.weights = Exact). Null: a directional light.
    const LocalLight* localLight = nullptr;
    /// Light textures (prefilter.h, "Light textures"; crep/scatter/light_texture.h): the colour map of the
    /// rectified map, a GL_TEXTURE_2D of width x height whose rgb is each texel's light-ray colour (e.g.
    /// LightColorMapPass::colorMapTexture(), read with texelFetch), or 0 (no texture: the untextured
    /// program, nothing else bound). With it the pass runs its CREP_LIGHT_TEXTURE variant (built on first
    /// use) into a second basis array of 3 ceil(M / 4) layers and a GL_RGBA16F mean-colour texture, both
    /// allocated on first use (3x the basis memory and filter work, + 8 bytes per texel); filteredBasis()
    /// then describes them (FilteredBasisView::textured).
    std::uint32_t lightColors = 0;
  };
  /// Throws what run(frame) would before its first GL change: InvalidArgument naming the field after
  /// `owner`, GlError when a light texture's basis exceeds GL_MAX_ARRAY_TEXTURE_LAYERS.
  void validate(const FrameAttribs& frame, std::string_view owner = "PrefilterPass::FrameAttribs") const;

  /// Validates `info` (InvalidArgument naming the field, e.g. "PrefilterPass::CreateInfo.options.bases";
  /// GlError naming it when a size exceeds GL_MAX_TEXTURE_SIZE, GL_MAX_ARRAY_TEXTURE_LAYERS or the compute
  /// workgroup limits), compiles the program and allocates the filtered-basis texture array.
  explicit PrefilterPass(const CreateInfo& info);
  ~PrefilterPass();
  /// Moved from: valid but empty (run() throws InvalidArgument naming "PrefilterPass", memoryBytes() is 0).
  PrefilterPass(PrefilterPass&&) noexcept;
  PrefilterPass& operator=(PrefilterPass&&) noexcept;
  PrefilterPass(const PrefilterPass&) = delete;
  PrefilterPass& operator=(const PrefilterPass&) = delete;

  /// Prefilters the frame's map into filteredBasisTexture(). Computes the per-row weights on the CPU
  /// (height x R profiles of the layout, double) and uploads them, then dispatches. Throws
  /// InvalidArgument naming the FrameAttribs field (null layout / medium, texture 0 or not a 2D texture of
  /// the created size, width not a multiple of R, negative extinction).
  void run(const FrameAttribs& frame);

  const CreateInfo& createInfo() const noexcept { return info_; }
  int layers() const noexcept { return layerCount(info_.options.bases); }
  /// GPU memory it owns, bytes: the filtered basis (filteredBasisBytes) and its buffers.
  std::size_t memoryBytes() const noexcept;
  /// GL_TEXTURE_2D_ARRAY of the filtered basis (GL_LINEAR, clamp to edge), valid after run(); after a run
  /// with lightColors the textured array (3 bases).
  std::uint32_t filteredBasisTexture() const noexcept {
    return lastTextured_ ? texturedTexture_.get() : texture_.get();
  }
  /// GL_TEXTURE_2D of the prefix mean colour (GL_RGBA16F, GL_LINEAR, clamp to edge) of the last textured
  /// run, or 0.
  std::uint32_t meanColorTexture() const noexcept { return meanColor_.get(); }
  /// GL buffer of gpu::RegionWeights of the last run (for the near-plane correction).
  std::uint32_t regionWeightsBuffer() const noexcept { return weightsBuffer_.get(); }
  /// The filtered basis of the last run. Throws Error before the first run().
  FilteredBasisView filteredBasis() const;

private:
  struct Plan;
  Plan plan(const FrameAttribs& frame, std::string_view owner) const;
  void prepareTextured(bool local);
  std::size_t upload(const FrameAttribs& frame, const Plan& plan);
  void uploadLocalLight(const FrameAttribs& frame, const Plan& plan,
                        const std::vector<DistanceProfile>& profiles);
  void dispatch(const FrameAttribs& frame, const Plan& plan, std::size_t weightBytes);

  CreateInfo info_;
  gl::Handle program_, programLocal_, texture_, sampler_, paramsBuffer_, weightsBuffer_, localBuffer_,
      raysBuffer_;
  /// Light textures: the CREP_LIGHT_TEXTURE programs (directional, local), the 3-basis array and the mean
  /// colour, built on the first textured run.
  gl::Handle programTextured_[2], texturedTexture_, meanColor_;
  std::size_t weightsCapacity_ = 0, raysCapacity_ = 0;
  bool ran_ = false, lastLocal_ = false, lastTextured_ = false;
  int lastLayoutRegions_ = 1;
  double lastExtinction_ = 0.0;
};

/// The evaluation pass (Listing 4): the scattering image of a camera depth buffer.
class EvaluatePass {
public:
  struct CreateInfo {
    int bases = kDefaultBases; ///< M compiled into the shader; must equal the filtered basis's M
    /// Sampling of the filtered basis (GL_LINEAR / GL_NEAREST), near-plane correction (Sec. 3.1) and
    /// ringing filter: the same options give the CPU reference crep::evaluate(); `threads` is not used.
    EvaluateOptions options;
    /// Format of the caller's output texture: RGBA32F (default) or RGBA16F.
    StorageFormat outputFormat = StorageFormat::RGBA32F;
    int workgroupWidth = 8;  ///< local_size_x, pixels, >= 1
    int workgroupHeight = 8; ///< local_size_y, pixels, >= 1
    /// Local lights: integrate a section's unshadowed in-scattering in closed form (Sun et al. 2005 extended,
    /// crep/scatter/airlight.h; GLSL crep_airlightSegment: a table end per channel where the intensity is
    /// constant, the quadrature on a spot's falloff band) instead of the quadrature throughout
    /// (crep_localSegment, default). Same result within 2.3e-3 of a ray's sum (the table's interpolation).
    /// Slower on llvmpipe (README "Local lights"): a software rasterizer samples a texture at the cost of
    /// several quadrature points. On GPUs (texture units beside the ALUs) the fetches are the cheap side;
    /// unmeasured here.
    bool localClosedForm = false;
    /// Benchmarks only (the output is meaningless): the pass stripped to its memory traffic, the same
    /// camera-depth fetch, the same filtered-basis fetches per pixel (count, format, filtering; the
    /// mapping that addresses them is kept) and the same store, without the coefficients, the
    /// transmittance integrals and the phase function (CREP_MEMORY_LIMIT).
    bool memoryLimit = false;
  };

  /// A froxel volume to fill (prefilter.h, "Froxel volumes"; crep::evaluateFroxels is its CPU reference).
  struct FroxelTarget {
    /// Caller's GL_TEXTURE_3D of grid.width x grid.height x grid.depth, GL_RGBA16F or GL_RGBA32F (any
    /// CreateInfo::outputFormat), or 0 (no volume). Texel (x, y, z): RGB in-scattered radiance from the
    /// camera to the cell's sample point, A grey transmittance to it.
    std::uint32_t volume = 0;
    FroxelGrid grid;        ///< cells and depth range (crep/scatter/froxel_grid.h)
    glm::dvec3 jitter{0.0}; ///< sample offset in cells, each component in [-0.5, 0.5] (froxelJitter())
  };

  struct FrameAttribs {
    /// caller's GL_TEXTURE_2D, depth-buffer values of `camera` in [0, 1]; may be 0 when output is 0
    std::uint32_t cameraDepth = 0;
    /// caller's GL_TEXTURE_2D of cameraDepth's size in outputFormat: RGB L, A T; may be 0 with a froxel
    /// volume
    std::uint32_t output = 0;
    const Camera* camera = nullptr;          ///< the camera of cameraDepth (normally the rectified one)
    const DirectionalLight* light = nullptr; ///< the light of the rectification (or null with localLight)
    const Medium* medium = nullptr;          ///< the medium (C of Eq. 1, per-channel extinction)
    /// The layout the basis was prefiltered from: a ProjectiveLayout, or any layout with a GPU mapping
    /// (an EpipolarLayout: the fallback of Klehm et al. 2014, Sec. 4.1), evaluated through its layout block.
    const RectifiedLayout* layout = nullptr;
    /// e.g. PrefilterPass::filteredBasis(). A textured basis (FilteredBasisView::textured: prefiltered with a
    /// light texture's colour map) runs the CREP_LIGHT_TEXTURE variants (built on first use; the mean colour
    /// at texture unit 2): with the scattering prefix table (the default) or without a table; the
    /// near-plane correction and the visibility table alone reject it (InvalidArgument naming
    /// "EvaluatePass::FrameAttribs.basis.textured").
    FilteredBasisView basis;
    /// Instead of `light`: a local light (a spot, or one point-light face) whose rectification the basis
    /// was prefiltered from with PrefilterPass::FrameAttribs::localLight. Every region segment of a pixel
    /// ray contributes its visibility times the ray's own in-scattering (crep_localSegment of
    /// crep/local_light.glsl; crep::evaluate(..., LocalLight) on the CPU). A ProjectiveLayout, or an
    /// EpipolarLayout built for the light's position (in or near the view); no near-plane correction
    /// (InvalidArgument naming the field).
    const LocalLight* localLight = nullptr;
    /// Froxel volumes (prefilter.h, "Froxel volumes"): one more dispatch over width x height x depth cells
    /// (workgroups of CreateInfo::workgroupWidth x workgroupHeight x 1 cells: neighbouring cells of one
    /// slice map to neighbouring rows and columns of the basis, so a GPU's texture cache serves their
    /// fetches), writing the volume with imageStore after the per-pixel output (if any), from the same
    /// per-frame table. Directional light only (InvalidArgument "EvaluatePass::FrameAttribs.froxels" with
    /// localLight); every layout and option of the per-pixel evaluation, textured bases included.
    FroxelTarget froxels{};
    /// Skip the per-frame table pass and use the table of the previous run(), which must have been built
    /// for this basis (same texture, size, regions and layout kind; its contents unchanged since: the
    /// caller's promise), e.g. a second run of the same frame that fills a froxel volume alone. Ignored
    /// without a table (EvaluateOptions::visibilityTableSamples 0 or the direct path).
    bool reuseTable = false;
    /// A GPU work list (crep/scatter/gpu_sample_list.h; Yusov 2012, Sec. 6.4 and 6.7: epipolar sampling's
    /// marched samples and corrections) or null. Set: instead of the per-pixel dispatch the pass evaluates
    /// only the list's entries (the CREP_SAMPLE_LIST variant of every program, work groups of 64 entries
    /// dispatched indirectly with gpu::dispatchSampleList): entry texel t's ray goes through
    /// list->coordinates(t).xy (continuous camera pixel coordinates: ndc = 2 (x, y) / (W, H) - 1) to the
    /// surface of depth-buffer value list->coordinates(t).z (.w is not read), as crep::evaluate() does at a
    /// pixel centre; its result goes to texel t of list->output (GL_RGBA32F whatever
    /// CreateInfo::outputFormat, list->width x list->height) and nothing else is written. `output` is
    /// ignored and `cameraDepth` may be 0. Composes with every layout, light, basis (textured, local) and
    /// option, CreateInfo::memoryLimit included, and with a froxel volume (filled by its own dispatch after
    /// the list's). The list is bound at storage buffer binding 3 and the coordinates at the camera-depth
    /// texture unit (left unbound). The producer must have issued GL_COMMAND_BARRIER_BIT |
    /// GL_SHADER_STORAGE_BARRIER_BIT.
    const gpu::SampleList* list = nullptr;
    /// With `list`: the camera image's full size W x H (both > 0, or both 0 for cameraDepth's size; else
    /// InvalidArgument "EvaluatePass::FrameAttribs.imageWidth/imageHeight"). Ignored without a list.
    int imageWidth = 0, imageHeight = 0;
  };
  /// Throws what run(frame) would before its first GL change: InvalidArgument naming the field after
  /// `owner` (GlError beyond the froxel dispatch's workgroup limits).
  void validate(const FrameAttribs& frame, std::string_view owner = "EvaluatePass::FrameAttribs") const;

  /// Validates `info` (InvalidArgument naming the field, GlError beyond the workgroup limits) and
  /// compiles the program.
  explicit EvaluatePass(const CreateInfo& info);
  ~EvaluatePass();
  /// Moved from: valid but empty (run() throws InvalidArgument naming "EvaluatePass", memoryBytes() is 0).
  EvaluatePass(EvaluatePass&&) noexcept;
  EvaluatePass& operator=(EvaluatePass&&) noexcept;
  EvaluatePass(const EvaluatePass&) = delete;
  EvaluatePass& operator=(const EvaluatePass&) = delete;

  /// Writes the scattering image into frame.output and / or the froxel volume (at least one). Throws
  /// InvalidArgument naming the FrameAttribs field (null pointers, texture 0, wrong target / format / size,
  /// bases mismatch, froxels.grid / froxels.jitter / froxels.volume, reuseTable
  /// without a matching table).
  void run(const FrameAttribs& frame);

  const CreateInfo& createInfo() const noexcept { return info_; }
  /// GPU memory it owns, bytes: the scattering prefix table (scatteringPrefixBytes, once run) or the region
  /// visibility table (visibilityTableBytes) and buffers.
  std::size_t memoryBytes() const noexcept;

private:
  struct Plan;
  Plan plan(const FrameAttribs& frame, std::string_view owner) const;
  void uploadLocalLight(const FrameAttribs& frame);
  std::uint32_t evaluationProgram(const Plan& plan);
  void uploadTableCoefficients(double depthMargin);
  void buildTable(const FilteredBasisView& basis, const Plan& plan);
  void bindEvaluation(const FrameAttribs& frame, const Plan& plan, std::uint32_t program);
  void dispatchFroxels(const FrameAttribs& frame, const Plan& plan, gpu::EvaluateParams params);
  void unbindEvaluation(const Plan& plan);

  CreateInfo info_;
  gl::Handle program_, basisSampler_, depthSampler_, scatteringBuffer_, evaluateBuffer_;
  /// The local-light variants (CREP_LOCAL_LIGHT): evaluation and scattering prefix programs on the
  /// projective frame, then per gpu::LayoutKind, built on first use, and their light block.
  gl::Handle localPrograms_[3], localPrefixPrograms_[3], localBuffer_;
  /// Local lights: the airlight table (crep/scatter/airlight.h, RG32F) of the medium's g, and its sampler.
  gl::Handle airlightTable_, airlightSampler_;
  /// Local lights: the local section table (EvaluateOptions::localSectionTable), the prefix table's size.
  gl::Handle sectionTexture_;
  double airlightG_ = 0.0;
  gl::Handle layoutPrograms_[2]; ///< per gpu::LayoutKind, built on first use (non-projective layouts)
  /// The region visibility table (EvaluateOptions::visibilityTableSamples): its pass, R32F texture
  /// (R Z x H, reallocated when the basis's size changes) and linear sampler.
  /// With scatteringPrefix the texture holds the scattering prefix table instead (RGBA32F, same size),
  /// built by prefixPrograms_ (projective frame, then per gpu::LayoutKind, built on first use).
  gl::Handle tableProgram_, tableTexture_, tableSampler_;
  gl::Handle prefixPrograms_[3];
  /// Light textures (CREP_LIGHT_TEXTURE): evaluation and scattering prefix programs, index 0 projective
  /// frame, 1 + gpu::LayoutKind for layouts, 3 + the same for a local light; built on first use.
  gl::Handle texturedPrograms_[6], texturedPrefixPrograms_[6];
  /// Froxel volumes (CREP_FROXELS): index [textured][0 projective frame, 1 + gpu::LayoutKind], built on
  /// first use.
  gl::Handle froxelPrograms_[2][3];
  /// Work lists (CREP_SAMPLE_LIST): index [textured][0 projective frame, 1 + gpu::LayoutKind, 3 + the same
  /// for a local light], built on first use.
  gl::Handle listPrograms_[2][6];
  /// What the table was last built for (FrameAttribs::reuseTable): basis texture, program variant.
  std::uint32_t tableBasis_ = 0;
  int tableVariant_ = -1;
  gl::Handle tableCoefficients_; ///< a(z_s) of the table's samples (storage buffer), for tableMargin_
  double tableMargin_ = -1.0;
  int tableWidth_ = 0, tableHeight_ = 0;
  gpu::LayoutBuffers layoutBuffers_;
};

} // namespace crep
