// GPU passes of prefiltered single scattering (Klehm, Seidel, Eisemann 2014, Sec. 3.3, Listings 2-4,
// Appendix A): PrefilterPass (rectified depth -> filtered basis), EvaluatePass (camera depth -> scattering),
// prefilter.h's rules in float. Conventions, bindings: prefilter/README.md, "gpu_pass.h". Each runs on the
// gpu::Backend of its CreateInfo; by default a GL backend on the current OpenGL 4.5 core context, which it
// needs for its whole lifetime and never creates, owns or changes.
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/gpu/backend.h>
#include <crep/gpu/gl.h>
#include <crep/prefilter/gpu_structs.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/froxel_grid.h>
#include <crep/scatter/gpu_layout_buffers.h>
#include <crep/scatter/gpu_sample_list.h>

namespace crep {

/// A filtered basis on the GPU: the texture array and the parameters it was prefiltered with
/// (everything evaluation needs besides the layout). Non-owning ids of the passes' backend (GL names).
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
  bool textured = false; ///< with a light texture: 3 ceil(M / 4) layers (colour c from layer c ceil(M / 4))
  /// Exact: `texture` has two layers: (depth, cumulative weight W) per texel in RG32F (RGBA32F with a light
  /// texture: W of colour 0, 1, 2; prefilter.h), and in layer 1 each block of 8 texels' (min, max) depth at
  /// texel (region n + block).
  VisibilityReconstruction reconstruction = VisibilityReconstruction::Fourier;
  std::uint32_t meanColor = 0; ///< textured: GL_TEXTURE_2D, width x height, GL_RGBA32F (rgb cbar)

  int regions() const noexcept { return layoutRegions * regionsPerSplit; } ///< R
};

/// The per-row weight data (index row * R + region) of referenceProfiles() for regions of `texelsPerRegion`
/// texels, in double: the CPU half of the prefilter pass. InvalidArgument ("texelsPerRegion") if < 1.
std::vector<gpu::RegionWeights> gpuRegionWeights(const std::vector<DistanceProfile>& profiles,
                                                 WeightMode mode, int texelsPerRegion);

/// The uniform block of crep/scattering.glsl for `basis` on its `layout` with a directional light. Throws
/// InvalidArgument ("layout": no GPU mapping or wrong region count; "FilteredBasisView": bad sizes).
gpu::ScatteringParams makeScatteringParams(const FilteredBasisView& basis, const RectifiedLayout& layout,
                                           const DirectionalLight& light, const Medium& medium);

/// The prefilter pass (Listing 3 + 2): one compute dispatch over rows x groups of bases x regions.
class PrefilterPass {
public:
  struct CreateInfo {
    int mapWidth = 1024;         ///< map width W, texels; a multiple of the regions R = K P at run()
    int mapHeight = 1024;        ///< map height H, texels (rows = epipolar slices)
    PrefilterOptions options;    ///< as crep::prefilter() takes them; `threads` is not used
    int workgroupRows = 64;      ///< local_size_x: rows per workgroup, >= 1
    int workgroupBaseGroups = 1; ///< local_size_y: groups of bases per workgroup, >= 1
    int workgroupRegions = 1;    ///< local_size_z: regions per workgroup, >= 1
    bool memoryLimit = false;    ///< benchmarks only: the memory traffic alone, output meaningless
    /// Runs the pass (must outlive it); null: a gpu::GlBackend of its own on the current GL context.
    gpu::Backend* backend = nullptr;
  };

  struct FrameAttribs {
    /// The rectified map: 2D texture of mapWidth x mapHeight, any depth or float format (r = depth value); a
    /// GL name, or a texture id of the backend.
    std::uint32_t rectifiedDepth = 0;
    const RectifiedLayout* layout = nullptr; ///< the map's layout (reference-ray profiles); not owned
    const Medium* medium = nullptr;   ///< weight extinction = weightExtinction(*medium), unless overridden
    double extinctionOverride = -1.0; ///< >= 0: use this weight extinction s instead (1/world unit)
    /// A local light whose factor goes into the weights (needs `medium`, Exact weights); null: directional.
    const LocalLight* localLight = nullptr;
    /// The map's light colours (GL_TEXTURE_2D of the map's size, rgb; LightColorMapPass) or 0. Cost: 3x the
    /// basis memory and filter work, + 8 bytes per texel, allocated on first use.
    std::uint32_t lightColors = 0;
  };
  /// Throws what run(frame) would before its first GL change: InvalidArgument naming the field after
  /// `owner`, GlError when a light texture's basis exceeds GL_MAX_ARRAY_TEXTURE_LAYERS.
  void validate(const FrameAttribs& frame, std::string_view owner = "PrefilterPass::FrameAttribs") const;

  /// One-time: validates (InvalidArgument naming the field; GlError beyond GL limits), builds, allocates.
  explicit PrefilterPass(const CreateInfo& info);
  ~PrefilterPass();
  /// Moved from: valid but empty (run() throws InvalidArgument naming "PrefilterPass", memoryBytes() is 0).
  PrefilterPass(PrefilterPass&&) noexcept;
  PrefilterPass& operator=(PrefilterPass&&) noexcept;
  PrefilterPass(const PrefilterPass&) = delete;
  PrefilterPass& operator=(const PrefilterPass&) = delete;

  /// Per frame, O(W H M): prefilters the map into filteredBasisTexture(). Throws InvalidArgument naming the
  /// FrameAttribs field.
  void run(const FrameAttribs& frame);

  const CreateInfo& createInfo() const noexcept { return info_; }
  /// Layers of the basis array: ceil(M / 4), or 2 for VisibilityReconstruction::Exact ((depth, W) per texel
  /// and the blocks' (min, max) depth).
  int layers() const noexcept { return exact() ? 2 : layerCount(info_.options.bases); }
  /// GPU memory it owns, bytes: the filtered basis (filteredBasisBytes) and its buffers.
  std::size_t memoryBytes() const noexcept;
  /// 2D array texture of the last run's basis (linear, clamp to edge; 3 bases when textured).
  std::uint32_t filteredBasisTexture() const noexcept {
    return lastTextured_ ? texturedTexture_.id() : texture_.id();
  }
  /// 2D texture of the last textured run's prefix mean colour (RGBA32F, linear), or 0.
  std::uint32_t meanColorTexture() const noexcept { return meanColor_.id(); }
  /// Buffer of gpu::RegionWeights of the last run (for the near-plane correction).
  std::uint32_t regionWeightsBuffer() const noexcept { return weightsBuffer_.id(); }
  /// The filtered basis of the last run. Throws Error before the first run().
  FilteredBasisView filteredBasis() const;

private:
  struct Plan;
  Plan plan(const FrameAttribs& frame, std::string_view owner) const;
  void prepareTextured(bool local);
  bool exact() const noexcept { return info_.options.reconstruction == VisibilityReconstruction::Exact; }
  std::size_t upload(const FrameAttribs& frame, const Plan& plan);
  void uploadLocalLight(const FrameAttribs& frame, const Plan& plan,
                        const std::vector<DistanceProfile>& profiles);
  void dispatch(const FrameAttribs& frame, const Plan& plan, std::size_t weightBytes);

  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr; ///< null when moved from
  gpu::Texture texture_;
  gpu::Buffer paramsBuffer_, weightsBuffer_, localBuffer_, raysBuffer_;
  /// Light textures: 3-basis array, mean colour; allocated on first use.
  gpu::Texture texturedTexture_, meanColor_;
  bool ran_ = false, lastLocal_ = false, lastTextured_ = false;
  int lastLayoutRegions_ = 1;
  double lastExtinction_ = 0.0;
};

/// The evaluation pass (Listing 4): the scattering image of a camera depth buffer.
class EvaluatePass {
public:
  struct CreateInfo {
    int bases = kDefaultBases; ///< M compiled into the shader; must equal the filtered basis's M
    EvaluateOptions options;   ///< as crep::evaluate() takes them; `threads` is not used
    /// Compiled into the shader; must equal the filtered basis's (FilteredBasisView::reconstruction).
    VisibilityReconstruction reconstruction = VisibilityReconstruction::Fourier;
    StorageFormat outputFormat = StorageFormat::RGBA32F; ///< of the caller's output: RGBA32F or RGBA16F
    int workgroupWidth = 8;                              ///< local_size_x, pixels, >= 1
    int workgroupHeight = 8;                             ///< local_size_y, pixels, >= 1
    /// Local lights: a section's unshadowed in-scattering in closed form (Sun et al. 2005 extended,
    /// crep/scatter/airlight.h) instead of the quadrature (crep_localSegment, default).
    bool localClosedForm = false;
    bool memoryLimit = false; ///< benchmarks only: the memory traffic alone, output meaningless
    /// Runs the pass (must outlive it); null: a gpu::GlBackend of its own on the current GL context.
    gpu::Backend* backend = nullptr;
  };

  /// A froxel volume to fill (Wronski 2014; crep::evaluateFroxels is its CPU reference).
  struct FroxelTarget {
    /// 3D texture (GL_TEXTURE_3D) of grid.width x grid.height x grid.depth, RGBA16F or RGBA32F, or 0 (none):
    /// RGB in-scattered radiance to the cell's sample point, A grey transmittance to it.
    std::uint32_t volume = 0;
    FroxelGrid grid;        ///< cells and depth range (crep/scatter/froxel_grid.h)
    glm::dvec3 jitter{0.0}; ///< sample offset in cells, each component in [-0.5, 0.5] (froxelJitter())
  };

  struct FrameAttribs {
    /// 2D texture (a GL name or the backend's id), depth-buffer values of `camera` in [0, 1]; may be 0 when
    /// output is 0.
    std::uint32_t cameraDepth = 0;
    /// GL_TEXTURE_2D of cameraDepth's size in outputFormat: RGB L, A T; may be 0 with a froxel volume.
    std::uint32_t output = 0;
    const Camera* camera = nullptr;          ///< the camera of cameraDepth (normally the rectified one)
    const DirectionalLight* light = nullptr; ///< the light of the rectification (or null with localLight)
    const Medium* medium = nullptr;          ///< the medium (C of Eq. 1, per-channel extinction)
    /// The basis's layout: projective, or any with a GPU mapping (EpipolarLayout, Sec. 4.1's fallback).
    const RectifiedLayout* layout = nullptr;
    /// e.g. PrefilterPass::filteredBasis(); a textured one needs the prefix table or no table (README).
    FilteredBasisView basis;
    /// Instead of `light`: the local light the basis was prefiltered for, on its projective or epipolar
    /// layout; no near-plane correction.
    const LocalLight* localLight = nullptr;
    /// A volume to fill from the same per-frame table (directional light only). Cost: O(cells), one dispatch.
    FroxelTarget froxels{};
    /// Reuse the previous run()'s table, built for this same, unchanged basis (the caller's promise).
    bool reuseTable = false;
    /// A GPU work list (Yusov 2012, Sec. 6.4, 6.7) or null: evaluate only its entries, into list->output.
    /// The producer must have issued GL_COMMAND_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT.
    const gpu::SampleList* list = nullptr;
    int imageWidth = 0, imageHeight = 0; ///< with `list`: the camera image's W x H (0, 0: cameraDepth's)
  };
  /// Throws what run(frame) would before its first GL change: InvalidArgument naming the field after
  /// `owner` (GlError beyond the froxel dispatch's workgroup limits).
  void validate(const FrameAttribs& frame, std::string_view owner = "EvaluatePass::FrameAttribs") const;

  /// One-time: validates (InvalidArgument naming the field, GlError beyond the workgroup limits), compiles.
  explicit EvaluatePass(const CreateInfo& info);
  ~EvaluatePass();
  /// Moved from: valid but empty (run() throws InvalidArgument naming "EvaluatePass", memoryBytes() is 0).
  EvaluatePass(EvaluatePass&&) noexcept;
  EvaluatePass& operator=(EvaluatePass&&) noexcept;
  EvaluatePass(const EvaluatePass&) = delete;
  EvaluatePass& operator=(const EvaluatePass&) = delete;

  /// Per frame, O(pixels): writes frame.output and / or the froxel volume (at least one). Throws
  /// InvalidArgument naming the FrameAttribs field.
  void run(const FrameAttribs& frame);

  const CreateInfo& createInfo() const noexcept { return info_; }
  /// GPU memory it owns, bytes: its table (scatteringPrefixBytes or visibilityTableBytes) and buffers.
  std::size_t memoryBytes() const noexcept;

private:
  struct Plan;
  Plan plan(const FrameAttribs& frame, std::string_view owner) const;
  void uploadLocalLight(const FrameAttribs& frame);
  void appendLocalResources(std::vector<gpu::Resource>& out) const;
  gpu::Dispatch evaluation(const FrameAttribs& frame, const Plan& plan, bool froxels, bool list) const;
  void uploadTableCoefficients(double depthMargin);
  void buildTable(const FilteredBasisView& basis, const Plan& plan);
  void dispatchFroxels(const FrameAttribs& frame, const Plan& plan, gpu::EvaluateParams params);

  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr; ///< null when moved from
  gpu::Buffer scatteringBuffer_, evaluateBuffer_, localBuffer_;
  gpu::Buffer tableCoefficients_; ///< a(z_s) of the table's samples (storage buffer), for tableMargin_
  /// Local lights: the airlight table (RG32F) of the medium's g; the local section table (the table's size).
  gpu::Texture airlightTable_, sectionTexture_;
  /// The per-frame table: R32F visibility or RGBA32F prefix, R Z x H.
  gpu::Texture tableTexture_;
  double airlightG_ = 0.0;
  /// What the table was last built for (FrameAttribs::reuseTable).
  std::uint32_t tableBasis_ = 0;
  int tableVariant_ = -1;
  double tableMargin_ = -1.0;
  int tableWidth_ = 0, tableHeight_ = 0;
  gpu::LayoutBuffers layoutBuffers_;
};

} // namespace crep
