// GL rasterization of a built-in scene: camera depth, shadow maps for any light matrix, a lit colour
// image. Requires a current OpenGL 4.5 context; owns only its own GL objects. Details: examples/README.md.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <crep/core/image.h>
#include <crep/gpu/gl.h>
#include <crep/rectify/rectify.h>
#include <crep/scenes/scene.h>

namespace crep::scenes {

struct DepthRenderOptions {
  /// GL_DEPTH_CLAMP (rectified shadow maps need it: casters between the light and the frustum cast).
  bool depthClamp = false;
  /// GL_CULL_FACE with back faces culled. The depth test is GL_LESS, cleared to 1.
  bool cullBackFaces = false;
};

class SceneRenderer {
public:
  explicit SceneRenderer(const Mesh& mesh);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  /// The mesh's depth into layer `layer` (0 for 2D) of the caller's GL_DEPTH_COMPONENT32F texture, in the
  /// viewport, cleared to 1 first.
  void renderDepth(const glm::dmat4& clipFromWorld, std::uint32_t depthTexture, int layer, int x, int y,
                   int width, int height, const DepthRenderOptions& options = {});

  /// The mesh's depth into the bound framebuffer with the caller's depth state (a caster callback).
  void drawDepth(const glm::dmat4& clipFromWorld);
  /// A projective rectified shadow map, every split into its viewport, with depth clamping. Throws
  /// InvalidArgument unless `rectification` is projective.
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
    /// Spot lights (at most kMaxShadeSpots), each with its perspective shadow map and matrix.
    struct Spot {
      const SpotLight* light = nullptr;
      glm::dmat4 shadowClipFromWorld{1.0};
      std::uint32_t shadowMap = 0;
    };
    std::vector<Spot> spots;
    /// The sun's light texture (GL_TEXTURE_2D, projected with sunTextureClipFromWorld); 0 = none.
    std::uint32_t sunTexture = 0;
    glm::dmat4 sunTextureClipFromWorld{1.0};
  };
  static constexpr int kMaxShadeSpots = 4;
  /// Lit surfaces into the caller's colour (RGBA16F / RGBA32F) and depth textures; background 0, depth 1.
  void renderShaded(const ShadeInputs& inputs, std::uint32_t colorTexture, std::uint32_t depthTexture,
                    int width, int height);

  /// Renders into a new depth texture and reads it back (1 channel, row 0 = bottom). A GPU sync.
  Image renderDepthImage(const glm::dmat4& clipFromWorld, int width, int height,
                         const DepthRenderOptions& options = {});

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A GL_DEPTH_COMPONENT32F 2D texture (nearest, clamp to edge); InvalidArgument / GlError naming `parameter`.
gl::Handle createDepthTexture(int width, int height, const char* parameter = "depth texture size");
/// Reads back a depth texture (2D, or one layer of a 2D array) as a 1-channel image.
Image readDepthTexture(std::uint32_t texture, int width, int height, int layer = 0);

} // namespace crep::scenes
