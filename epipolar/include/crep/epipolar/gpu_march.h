// GPU passes of the rectified marches: min/max trees and the tree / brute-force row marches, the rules of
// march.h and crep/scatter/rectified_march.h in float. Requires a current OpenGL 4.5 context (never owns
// one). GL state left, NaN inputs, work lists: epipolar/README.md, "crep/epipolar/gpu_march.h".
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/epipolar/gpu_layout.h>
#include <crep/gpu/backend.h>
#include <crep/gpu/gl.h>
#include <crep/rectify/rectified_map.h>
#include <crep/scatter/gpu_layout_buffers.h>
#include <crep/scatter/gpu_sample_list.h>
#include <crep/scatter/gpu_world_march.h>

namespace crep {

/// The 1D min/max trees of every row of a W x H rectified map (Yusov 2012, Sec. 6.3) in a storage buffer
/// it owns, in MinMaxTrees' layout (bit-identical values). Runs on any gpu::Backend.
class MinMaxTreePass {
public:
  struct CreateInfo {
    int mapWidth = 0;  ///< W texels (> 0, <= the backend's maximum texture size)
    int mapHeight = 0; ///< H texels (> 0, <= the backend's maximum texture size)
    /// Runs the pass (must outlive it); null: a gpu::GlBackend of its own on the current GL context.
    gpu::Backend* backend = nullptr;
  };
  /// Throws InvalidArgument ("MinMaxTreePass::CreateInfo.mapWidth/mapHeight") for sizes <= 0, GlError
  /// beyond GL_MAX_TEXTURE_SIZE or 2^16 columns, ShaderError. One-time.
  explicit MinMaxTreePass(const CreateInfo& info);

  /// Builds the trees of `rectifiedDepth` (the caller's W x H depth texture: a GL name, or a texture id of
  /// the backend). Per frame, O(W H).
  void run(std::uint32_t rectifiedDepth);
  /// max(0, levelCount(W) - 6): the levels the map's producer may write (README, split build).
  static int lowLevels(int mapWidth);
  /// Builds levels lowLevels(W) + 1..L from the low levels in treeBuffer(); same nodes as run().
  void completeUpperLevels();

  /// The trees: a GL_SHADER_STORAGE_BUFFER name, or a buffer id of the backend.
  std::uint32_t treeBuffer() const noexcept { return buffer_.id(); }
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
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr;
  int levels_ = 0, rowStride_ = 0;
  gpu::Buffer buffer_;
  gpu::Dispatch dispatch(bool upperOnly, std::uint32_t rectifiedDepth) const;
};

/// InvalidArgument naming `parameter` when a map of `mapWidth` columns needs more than the GPU walk's 16
/// levels.
void requireTreeLevels(const char* parameter, int mapWidth);
/// InvalidArgument naming `parameter` unless `buffer` holds the trees of a mapWidth x mapHeight map.
void requireMinMaxBuffer(const char* parameter, std::uint32_t buffer, int mapWidth, int mapHeight,
                         const std::string& use);
/// The same for a buffer of `backend`.
void requireMinMaxBuffer(const gpu::Backend& backend, const char* parameter, std::uint32_t buffer,
                         int mapWidth, int mapHeight, const std::string& use);

/// The march of every camera pixel's view ray along its row of a rectified map, with the map's min/max
/// trees (MinMaxTree) or texel by texel (BruteForce). Per frame, O(pixels x steps).
class RectifiedMarchPass {
public:
  enum class Mode { MinMaxTree, BruteForce };
  struct CreateInfo {
    int mapWidth = 0;  ///< W texels of the maps it will march (> 0, <= GL_MAX_TEXTURE_SIZE)
    int mapHeight = 0; ///< H texels
    Mode mode = Mode::MinMaxTree;
    /// Runs the pass (must outlive it); null: a gpu::GlBackend of its own on the current GL context.
    gpu::Backend* backend = nullptr;
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
    /// Instead of `light`: a spot or one point-light face, on a map of its rectification.
    const LocalLight* localLight = nullptr;
    /// LightColorMapPass::colorMapTexture() of the map, or 0 (untextured). Texture unit 2.
    std::uint32_t lightColors = 0;
    /// A GPU work list (Yusov 2012, Sec. 6.4) or null: march only its entries, into list->output; `output`
    /// is then ignored and `cameraDepth` may be 0 (README).
    const gpu::SampleList* list = nullptr;
    /// With `list`: the camera image's size in pixels, both > 0, or 0 x 0 = cameraDepth's size.
    int imageWidth = 0, imageHeight = 0;
    /// blockRadius >= 0 (pixels): march only the disc around blockCenter (Klehm et al. 2014, Fig. 8);
    /// -1 = every pixel; -1 with a list.
    glm::dvec2 blockCenter{0.0};
    double blockRadius = -1.0;
  };
  /// Throws what run(frame) would before any GL work: InvalidArgument naming the field after `owner`.
  void validate(const FrameAttribs& frame, std::string_view owner = "RectifiedMarchPass::FrameAttribs") const;
  /// Throws InvalidArgument ("RectifiedMarchPass::CreateInfo.mapWidth/mapHeight") / GlError like
  /// MinMaxTreePass.
  explicit RectifiedMarchPass(const CreateInfo& info);
  /// Throws InvalidArgument naming the FrameAttribs field (null pointers, sizes, formats, the layout).
  void run(const FrameAttribs& frame);
  /// Builds now the program run() would build on first use (no shader compilation inside a frame).
  void prepare(gpu::LayoutKind kind, bool textured = false, bool list = false);

private:
  struct Plan;
  Plan plan(const FrameAttribs& frame, std::string_view owner) const;
  ShaderStageSource program(gpu::LayoutKind kind, bool textured, bool list) const;
  CreateInfo info_;
  std::unique_ptr<gpu::Backend> ownBackend_;
  gpu::Backend* backend_ = nullptr;
  gpu::LayoutBuffers layoutBuffers_;
  gpu::Buffer params_;
  gpu::Texture dummySteps_; ///< R32F: the step counts when FrameAttribs::stepsOutput is 0
  int dummyWidth_ = 0, dummyHeight_ = 0;
};

} // namespace crep
