// The shadow passes of one crep::Scattering frame, planned on the CPU before any GPU work
// (Scattering::plan): for the sun, each spot and each point-light face, which depth map the engine
// rasterizes (a rectified map of K splits, Klehm et al. 2014 Sec. 4.2, or a standard map for the epipolar
// fallback, Sec. 4.1), with every matrix, viewport and raster state in the engine's clip conventions. The
// engine records those passes in its own render graph, then hands the maps to Scattering::run
// (FrameAttribs::plan, planMaps). Conventions and the render-graph order: docs/INTEGRATION.md, "The plan".
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include <crep/gpu/backend.h>
#include <crep/rectify/rectify.h>

namespace crep {

/// The clip space of the API the engine rasterizes with. Whatever the convention, a map's first row in
/// memory is the light's NDC y = -1 as OpenGL stores it, and its texels hold OpenGL's depth-buffer values of
/// the library's matrices (or 1 minus them with reversed-Z): that is how the library reads every map.
enum class ClipConvention {
  OpenGL,          ///< NDC z in [-1, 1] (glClipControl GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE: GL's default)
  OpenGLZeroToOne, ///< NDC z in [0, 1] (glClipControl GL_LOWER_LEFT, GL_ZERO_TO_ONE)
  Vulkan,          ///< NDC z in [0, 1], a positive-height VkViewport (NDC y = -1 at the first row)
  Direct3D12,      ///< NDC z in [0, 1], NDC y = +1 at the first row: the matrices negate y
  Metal,           ///< as Direct3D12 (the same clip space)
};

/// "opengl", "opengl-zero-to-one", "vulkan", "d3d12", "metal".
const char* conventionToken(ClipConvention convention);

/// What the engine's shadow passes are like.
struct ShadowPassPlanOptions {
  ClipConvention convention = ClipConvention::OpenGL;
  /// Reversed-Z: the matrices put the near side at depth 1, the maps are cleared to 0 and tested with
  /// GREATER, and hold 1 minus the usual values. Cost: run() turns each map back (one pass over its
  /// texels). Default false.
  bool reversedZ = false;
};

/// An OpenGL clip-from-world matrix (NDC z in [-1, 1]) in `options`' convention: rasterized there, it stores
/// at each texel what ShadowPassPlanOptions says (OpenGL's depth-buffer value, or 1 minus it).
glm::dmat4 toClipConvention(const glm::dmat4& glClipFromWorld, const ShadowPassPlanOptions& options);

/// The depth comparison of a pass (Vulkan VK_COMPARE_OP_LESS / GREATER, D3D12_COMPARISON_FUNC_LESS /
/// GREATER, Metal's MTLCompareFunctionLess / Greater, GL_LESS / GL_GREATER).
enum class DepthCompare { Less, Greater };

/// One light's shadow pass of a frame (the sun, a spot or one face of a point light).
struct ShadowPass {
  enum class Light { Sun, Spot, PointFace };
  enum class Kind {
    None,      ///< nothing to render: the light's frustum misses the view (status Empty)
    Rectified, ///< the rectified map (status Projective): one draw of the casters per split
    Standard,  ///< the standard map of the epipolar fallback or world march (status Fallback): one draw
  };
  /// An integer rectangle in texels; y counts rows from the map's first row in memory (as glViewport on a
  /// texture, VkViewport and VkRect2D, D3D12_VIEWPORT::TopLeftY and MTLViewport::originY all do).
  struct Rect {
    int x = 0, y = 0, width = 0, height = 0;
    bool operator==(const Rect&) const = default;
  };
  /// One draw of the casters: gl_Position = clipFromWorld * world, into `viewport` (depth range [0, 1]) with
  /// `scissor` set, so that nothing drawn leaves the split's columns.
  struct Split {
    glm::dmat4 clipFromWorld{1.0}; ///< in the plan's convention (toClipConvention)
    Rect viewport, scissor;
  };

  Light light = Light::Sun;
  int index = 0; ///< into FrameAttribs::spotLights or pointLights (0 for the sun)
  int face = -1; ///< point-light face 0-5 (+X, -X, +Y, -Y, +Z, -Z), else -1
  Kind kind = Kind::None;
  RectifyStatus status = RectifyStatus::Empty; ///< the rectification's decision ...
  FallbackReason reason = FallbackReason::None;
  std::string message; ///< ... and why, with its numbers
  /// Standard passes only: the frame's own map serves it (FrameAttribs::shadowMap, spotShadowMaps or
  /// pointShadowMaps were given to plan()): render nothing, planMaps entry 0.
  bool served = false;

  /// The depth target: width x height texels (mapSize^2 rectified, ownShadowMapSize^2 standard), sampled
  /// afterwards by the library's compute passes. Format: a 32-bit float depth format (D32_SFLOAT,
  /// DXGI_FORMAT_D32_FLOAT, MTLPixelFormatDepth32Float, GL_DEPTH_COMPONENT32F; D24 works, at its precision).
  int width = 0, height = 0;
  gpu::Format format = gpu::Format::Depth32F;
  double clearDepth = 1.0;                   ///< the whole target, once, before the first split (0 reversed)
  DepthCompare compare = DepthCompare::Less; ///< depth test on, depth writes on
  /// Depth clamp on (VkPipelineRasterizationStateCreateInfo::depthClampEnable,
  /// D3D12_RASTERIZER_DESC::DepthClipEnable = FALSE, MTLDepthClipModeClamp, GL_DEPTH_CLAMP): casters between
  /// the light and the lit region still cast. Always true.
  bool depthClamp = true;
  /// Face culling off: a rectification may mirror the winding. Always false.
  bool cullFaces = false;
  /// Draws of the casters, in order: K for a rectified map (Rectification::splits), one for a standard map.
  std::vector<Split> splits;
  /// Standard passes: the matrix of the map in OpenGL's convention, what FrameResult::shadowMap and the
  /// world-space marches read it with (Scattering::ShadowMap::lightClipFromWorld).
  glm::dmat4 glClipFromWorld{1.0};

  /// Rendered by the engine: a Rectified pass, or a Standard one not served.
  bool needsMap() const noexcept { return kind == Kind::Rectified || (kind == Kind::Standard && !served); }
};

/// The frame's passes, one per light in FrameResult order: the sun (when FrameAttribs::light is set), each
/// spot, then the six faces of each point light.
struct ShadowPassPlan {
  /// The run it belongs to: FrameResult::frame of the next run() of the object that planned it.
  std::uint64_t frame = 0;
  ShadowPassPlanOptions options;
  std::vector<ShadowPass> passes;

  int mapCount() const noexcept; ///< passes that needsMap()
};

/// One JSON object (what `crep plan` prints):
///   {"frame": N, "convention": "<conventionToken>", "reversedZ": bool, "passes": [{"light": "sun" | "spot" |
///    "point-face", "index": i, "face": f, "kind": "none" | "rectified" | "standard", "status":
///    "<statusToken>", "reason": "<reasonToken>", "message": "...", "served": bool, "width": w, "height": h,
///    "format": "depth32f", "clearDepth": c, "compare": "less" | "greater", "depthClamp": true, "cullFaces":
///    false, "glClipFromWorld": [16], "splits": [{"clipFromWorld": [16 numbers, column-major as in GLSL],
///    "viewport": [x, y, w, h], "scissor": [x, y, w, h]}, ...]}, ...]}
/// Numbers with 17 significant digits (they round-trip).
std::string toJson(const ShadowPassPlan& plan);

} // namespace crep
