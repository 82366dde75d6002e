// GL rasterization of a built-in scene: camera depth buffers, shadow maps for any light matrix
// (standard or rectified), and a simple lit colour image. Requires a current OpenGL 4.5 context;
// owns only its own GL objects (mesh buffers, programs), not the context.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <crep/core/gl.h>
#include <crep/core/image.h>
#include <crep/rectify/rectify.h>
#include <crep/scenes/scene.h>

namespace crep::scenes {

struct DepthRenderOptions {
  /// GL_DEPTH_CLAMP: fragments outside the near/far planes are kept with clamped depth (rectified
  /// shadow maps need this so casters between the light and the frustum still cast).
  bool depthClamp = false;
  /// Depth comparison: GL_LESS semantics, cleared to 1.
  bool cullBackFaces = false;
};

class SceneRenderer {
public:
  explicit SceneRenderer(const Mesh& mesh);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  /// Rasterizes the mesh's depth with `clipFromWorld` into layer `layer` (0 for a 2D texture) of the
  /// caller's depth texture (GL_DEPTH_COMPONENT32F, 2D or 2D array), in the viewport (x, y, width,
  /// height). Clears that viewport to depth 1 first. Values are depth-buffer values in [0, 1].
  void renderDepth(const glm::dmat4& clipFromWorld, std::uint32_t depthTexture, int layer, int x, int y,
                   int width, int height, const DepthRenderOptions& options = {});

  /// Draws the mesh's depth with `clipFromWorld` into the currently bound framebuffer and viewport, with
  /// the caller's depth state: what an engine's caster callback does (crep::Scattering::FrameAttribs::
  /// drawCasters). Leaves program 0 and vertex array 0 bound.
  void drawDepth(const glm::dmat4& clipFromWorld);
  /// Renders a projective rectified shadow map: every split with its rectClipFromWorld into its
  /// viewport (Rectification::splitViewport) of the caller's width x height depth texture, with depth
  /// clamping (what rectify.h asks of an engine). Throws InvalidArgument unless `rectification` is
  /// projective.
  void renderRectified(const Rectification& rectification, std::uint32_t depthTexture, int width, int height);

  /// Inputs of the lit surface pass: Lambert with a standard shadow map plus a constant ambient term.
  struct ShadeInputs {
    glm::dmat4 clipFromWorld{1.0};
    glm::dmat4 shadowClipFromWorld{1.0}; ///< the light matrix the shadow map was rendered with
    std::uint32_t shadowMap = 0;         ///< GL_DEPTH_COMPONENT32F 2D texture (depth-buffer values)
    glm::dvec3 lightDirection{0, -1, 0}; ///< direction the light travels
    glm::dvec3 lightIrradiance{1.0};
    glm::dvec3 ambient{0.05};
    glm::dvec3 albedo{0.5};
    /// Spot lights lighting the surfaces (at most kMaxShadeSpots; the night scenes' lamps), each with its
    /// perspective shadow map (GL_DEPTH_COMPONENT32F) rendered with its shadowClipFromWorld.
    struct Spot {
      const SpotLight* light = nullptr;
      glm::dmat4 shadowClipFromWorld{1.0};
      std::uint32_t shadowMap = 0;
    };
    std::vector<Spot> spots;
    /// The sun's light texture (crep/scatter/light_texture.h), a GL_TEXTURE_2D whose RGB multiplies the
    /// sun's irradiance, projected with sunTextureClipFromWorld; 0 = none.
    std::uint32_t sunTexture = 0;
    glm::dmat4 sunTextureClipFromWorld{1.0};
  };
  static constexpr int kMaxShadeSpots = 4;
  /// Renders lit surfaces into the caller's colour texture (RGBA16F or RGBA32F) and depth texture
  /// (GL_DEPTH_COMPONENT32F), both width x height. Background: colour 0, depth 1.
  void renderShaded(const ShadeInputs& inputs, std::uint32_t colorTexture, std::uint32_t depthTexture,
                    int width, int height);

  /// Convenience: renders into a new width x height depth texture and reads it back as a 1-channel
  /// image of depth-buffer values (row 0 = bottom).
  Image renderDepthImage(const glm::dmat4& clipFromWorld, int width, int height,
                         const DepthRenderOptions& options = {});

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Creates a GL_DEPTH_COMPONENT32F 2D texture (nearest filtering, clamp to edge) of the given size;
/// checks the size against GL limits (throws InvalidArgument / GlError naming `parameter`).
gl::Handle createDepthTexture(int width, int height, const char* parameter = "depth texture size");
/// Reads back a depth texture (2D, or one layer of a 2D array) as a 1-channel image.
Image readDepthTexture(std::uint32_t texture, int width, int height, int layer = 0);

} // namespace crep::scenes
