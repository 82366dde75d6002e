// GPU passes of the rectified marches (OpenGL 4.5 compute shaders): the min/max trees of a rectified map
// and the tree-accelerated and brute-force marches along its rows. They implement the rules of
// crep/epipolar/march.h and crep/scatter/rectified_march.h in float precision (the CPU functions there are
// their references). The world-space reference march on the GPU is WorldMarchPass
// (crep/scatter/gpu_world_march.h).
//
// Every pass requires a current OpenGL 4.5 context and never creates or owns one. It owns its programs,
// buffers and sampler (RAII); the textures of FrameAttribs are the caller's (non-owning GL names).
// Conventions: depth textures hold depth-buffer values in [0, 1] (GL_DEPTH_COMPONENT32F or GL_R32F, read
// with texelFetch through the pass's own nearest sampler, so the texture's compare mode does not matter);
// outputs are GL_RGBA32F (scattering: RGB radiance, A grey transmittance) and GL_R32F (steps per pixel).
// A pass leaves GL state as follows: program 0; texture units 0-2 with no texture and no sampler; image
// units 0-1, uniform buffer bindings 0-1 and storage buffer bindings 0-1 (0-2 with a work list) unbound. It
// issues the memory barriers its outputs need for texture fetches, image loads, readback and buffer reads.
// NaN in a GPU input is not checked (it would cost a readback): a NaN camera depth is treated as the sky
// (far plane), a NaN rectified-map texel as shadowing every ray (every comparison with it is false),
// a NaN standard shadow-map texel as empty (lit). The CPU functions reject NaN with InvalidArgument.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/gl.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/epipolar/gpu_layout.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/gpu_layout_buffers.h>
#include <crep/scatter/gpu_sample_list.h>
#include <crep/scatter/gpu_world_march.h>

namespace crep {

/// Builds the 1D min/max trees of every row of a W x H rectified map (march.h MinMaxTrees; Yusov 2012
/// Sec. 6.3) into a storage buffer it owns, in exactly MinMaxTrees' layout (the values are bit-identical).
class MinMaxTreePass {
public:
  struct CreateInfo {
    int mapWidth = 0;  ///< W texels (> 0, <= GL_MAX_TEXTURE_SIZE)
    int mapHeight = 0; ///< H texels (> 0, <= GL_MAX_TEXTURE_SIZE)
  };
  /// Throws InvalidArgument ("MinMaxTreePass::CreateInfo.mapWidth/mapHeight") for sizes <= 0, GlError beyond
  /// GL_MAX_TEXTURE_SIZE or above 2^16 columns (16 tree levels), ShaderError if the shader does not build.
  explicit MinMaxTreePass(const CreateInfo& info);

  /// Builds the trees of `rectifiedDepth` (the caller's W x H depth texture).
  void run(std::uint32_t rectifiedDepth);
  /// Levels 1..lowLevels(W) are written by whoever makes the map (ShadowResamplePass::FrameAttribs::
  /// minMaxBuffer): max(0, levelCount(W) - 6), so the top level of them has at most 64 nodes a row.
  static int lowLevels(int mapWidth);
  /// Builds levels lowLevels(W) + 1..L from the low levels already in treeBuffer() (the producer must have
  /// issued GL_SHADER_STORAGE_BARRIER_BIT); the map itself is not read. Same nodes as run() of that map.
  void completeUpperLevels();

  std::uint32_t treeBuffer() const noexcept { return buffer_.get(); } ///< GL_SHADER_STORAGE_BUFFER
  int levels() const noexcept { return levels_; }
  int rowStride() const noexcept { return rowStride_; }
  /// Reads the buffer back: 2 floats per node, MinMaxTrees::data()'s layout.
  std::vector<float> readNodes() const;
  /// GPU memory it owns, bytes: the trees (rowStride() x mapHeight nodes of 2 floats).
  std::size_t memoryBytes() const noexcept {
    return static_cast<std::size_t>(rowStride_ > 0 ? rowStride_ : 1) *
           static_cast<std::size_t>(info_.mapHeight) * 8;
  }

private:
  CreateInfo info_;
  int levels_ = 0, rowStride_ = 0;
  gl::Handle program_, upperProgram_, buffer_, sampler_;
};

/// GlError naming `parameter` (a map width field) when a map of `mapWidth` columns needs more than the 16
/// tree levels the GPU walk supports.
void requireTreeLevels(const char* parameter, int mapWidth);
/// Throws InvalidArgument naming `parameter` unless `buffer` is an existing buffer large enough for the trees
/// of a mapWidth x mapHeight map (MinMaxTreePass::treeBuffer() of it); `use` says what reads them.
void requireMinMaxBuffer(const char* parameter, std::uint32_t buffer, int mapWidth, int mapHeight,
                         const std::string& use);

/// The march of every camera pixel's view ray along its row of a rectified map (march.h "Rectified
/// marches"), with the map's min/max trees (MinMaxTree) or texel by texel (BruteForce).
class RectifiedMarchPass {
public:
  enum class Mode { MinMaxTree, BruteForce };
  struct CreateInfo {
    int mapWidth = 0;  ///< W texels of the maps it will march (> 0, <= GL_MAX_TEXTURE_SIZE)
    int mapHeight = 0; ///< H texels
    Mode mode = Mode::MinMaxTree;
  };
  /// Per-frame inputs: non-owning.
  struct FrameAttribs {
    /// The map's layout: a ProjectiveLayout or an EpipolarLayout (gpu::layoutKind()); not stored.
    const RectifiedLayout* layout = nullptr;
    const Camera* camera = nullptr;
    const DirectionalLight* light = nullptr;
    const Medium* medium = nullptr;
    /// GL_TEXTURE_2D of depth-buffer values of `camera` (its convention); the image size is its size
    std::uint32_t cameraDepth = 0;
    std::uint32_t rectifiedDepth =
        0;                          ///< mapWidth x mapHeight depth texture rendered / resampled for `layout`
    std::uint32_t minMaxBuffer = 0; ///< MinMaxTreePass::treeBuffer() of that map (MinMaxTree mode)
    std::uint32_t output = 0;       ///< GL_RGBA32F texture, the size of cameraDepth
    std::uint32_t stepsOutput = 0;  ///< GL_R32F texture, the size of cameraDepth, or 0 (steps not written)
    /// Instead of `light`: a local light (a spot, or one point-light face) on a map of its rectification;
    /// each lit section is integrated by crep_localSegment (crep::bruteForceMarch / minMaxMarch with a
    /// LocalLight on the CPU).
    const LocalLight* localLight = nullptr;
    /// A light texture's colour map of the map (LightColorMapPass::colorMapTexture(), as
    /// PrefilterPass::FrameAttribs::lightColors takes it: a mapWidth x mapHeight GL_TEXTURE_2D, RGB read
    /// with texelFetch) or 0 (untextured: the untextured program, no extra binding). Each lit texel's
    /// section times its colour (crep::bruteForceMarch / minMaxMarch with lightColors; the tree walks lit
    /// nodes texel by texel, skipping only shadowed nodes whole). Bound at texture unit 2 (left unbound).
    std::uint32_t lightColors = 0;
    /// A GPU work list (crep/scatter/gpu_sample_list.h; Yusov 2012, Sec. 6.4: epipolar sampling's marched
    /// samples) or null. Set: the pass marches only the list's entries (the CREP_SAMPLE_LIST variant, work
    /// groups of 64 entries dispatched indirectly with gpu::dispatchSampleList): entry texel t's ray is
    /// crep_screenRay at list->coordinates(t).xy (continuous camera pixel coordinates) ending at its
    /// depth-buffer value list->coordinates(t).z (.w, the view depth, is not read), and its result is
    /// written to texel t of list->output (GL_RGBA32F, list->width x list->height) and of stepsOutput (0, or
    /// GL_R32F of the list's size); no other texel is written. `output` is ignored and `cameraDepth` may be
    /// 0. Every other field (layout, lights, maps, lightColors, localLight) composes with it. The producer
    /// must have issued GL_COMMAND_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT (and the barriers its
    /// coordinates texture needs). The list is bound at storage buffer binding 2 and the coordinates at
    /// texture unit 0 (both left unbound).
    const gpu::SampleList* list = nullptr;
    /// With `list`: the camera image's full size W x H in pixels (ndc = 2 (x, y) / (W, H) - 1; not the list
    /// texture's size). 0 x 0 (the default): cameraDepth's size (then cameraDepth must be set). Both > 0
    /// or both 0, else InvalidArgument "RectifiedMarchPass::FrameAttribs.imageWidth/imageHeight". Ignored
    /// without a list (the image is cameraDepth's).
    int imageWidth = 0, imageHeight = 0;
    /// A disc of the image (without `list`): when blockRadius >= 0, only the pixels whose centre is within
    /// blockRadius pixels of blockCenter (pixel coordinates, origin at the bottom-left corner) are marched
    /// and written, the dispatch covering its bounding box (crep::Scattering's epipole block, Klehm et al.
    /// 2014, Fig. 8, marched over the frame's epipolar map). -1 (default): every pixel. Must be -1 with a
    /// list (InvalidArgument "RectifiedMarchPass::FrameAttribs.blockRadius").
    glm::dvec2 blockCenter{0.0};
    double blockRadius = -1.0;
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "RectifiedMarchPass::FrameAttribs") const;
  /// Throws InvalidArgument ("RectifiedMarchPass::CreateInfo.mapWidth/mapHeight") / GlError like
  /// MinMaxTreePass.
  explicit RectifiedMarchPass(const CreateInfo& info);
  /// Throws InvalidArgument naming the field of FrameAttribs (null pointers, zero names, sizes that do not
  /// match the textures, wrong output formats, a layout with no GPU mapping or too many regions).
  void run(const FrameAttribs& frame);
  /// Builds now the program run() uses for maps of `kind`, with light colours or not (`textured`) and a
  /// work list or not (`list`); run() builds it on first use otherwise. For a caller that wants no shader
  /// compilation inside a frame (crep::Scattering's epipole block: no hitch when the sun enters the view).
  void prepare(gpu::LayoutKind kind, bool textured = false, bool list = false);

private:
  struct Plan;
  Plan plan(const FrameAttribs& frame, std::string_view owner) const;
  std::uint32_t program(gpu::LayoutKind kind, bool textured, bool list);
  CreateInfo info_;
  gpu::LayoutBuffers layoutBuffers_;
  gl::Handle programs_[2][2][2], params_, sampler_, dummySteps_; ///< [list][textured][layout kind]
  int dummyWidth_ = 0, dummyHeight_ = 0;
};

} // namespace crep
