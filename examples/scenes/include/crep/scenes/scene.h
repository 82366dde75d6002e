// Built-in procedural scenes used by the crep tool, the tests and the benchmarks. Each scene is a
// triangle mesh with a default camera, sun direction and medium, plus an exact CPU ray cast so tests
// can compute ground truth without any shadow map.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <crep/core/camera.h>
#include <crep/core/image.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>

namespace crep::scenes {

/// Indexed triangle list, world space.
struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals; ///< one per position
  std::vector<std::uint32_t> indices;
  std::size_t triangleCount() const { return indices.size() / 3; }
};

/// Axis-aligned box, world space.
struct Box {
  glm::dvec3 min, max;
};

/// A light texture of a scene (crep/scatter/light_texture.h): linear RGB, row 0 at the bottom, and its
/// projection along the light's rays.
struct SceneLightTexture {
  Image rgb;
  glm::dmat4 textureClipFromWorld{1.0};
};

struct Scene {
  std::string name;
  Mesh mesh;
  Camera camera;
  DirectionalLight sun;
  Medium medium;
  glm::dvec3 boundsMin, boundsMax; ///< world-space bounds of the mesh
  /// false: a night scene without a directional light (`sun` has zero irradiance and is unused)
  bool hasSun = true;
  /// Local lights (Klehm et al. 2014, Sec. 3.2), added to the sun's scattering.
  std::vector<SpotLight> spotLights;
  std::vector<PointLight> pointLights;
  /// The sun's light texture (a stained-glass window), if any.
  std::optional<SceneLightTexture> sunTexture;
};

/// The sunlit scenes accepted by makeScene: "colonnade" (default), "forest", "terrain", "boxes" (an
/// analytic arrangement: a ground plane and a few boxes, for exact tests), "sunset" (the forest looking
/// toward a low sun behind the canopy: the sun in view, an epipolar-layout frame).
std::vector<std::string> sceneNames();
/// The scenes with local lights, also accepted by makeScene: "colonnade-night" (the colonnade without a
/// sun, three spot lamps outside the view shining through the pillars and along the hall).
std::vector<std::string> localLightSceneNames();
/// The scenes with a light texture, also accepted by makeScene: "stained-glass" (a hall whose side wall has a
/// large window; the sun shines through it, textured with a procedural stained-glass pattern projected
/// orthographically over the window).
std::vector<std::string> lightTextureSceneNames();
/// Builds a scene. `aspect` sets the default camera's aspect ratio. Throws InvalidArgument naming
/// "scene" for an unknown name.
Scene makeScene(std::string_view name, double aspect = 16.0 / 9.0);

/// Mesh helpers used by the generators (and by tests building their own arrangements).
void appendBox(Mesh& mesh, const Box& box);
void appendQuad(Mesh& mesh, const glm::dvec3& corner, const glm::dvec3& edgeU, const glm::dvec3& edgeV);

/// Exact first hit of the ray origin + t * direction (direction need not be unit) against the
/// mesh's triangles for t in (tMin, tMax); returns t. Uses a BVH built on first use.
class RayCaster {
public:
  explicit RayCaster(const Mesh& mesh);
  ~RayCaster();
  RayCaster(RayCaster&&) noexcept;
  RayCaster& operator=(RayCaster&&) noexcept;
  std::optional<double> firstHit(const glm::dvec3& origin, const glm::dvec3& direction, double tMin,
                                 double tMax) const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

} // namespace crep::scenes

namespace crep::scenes {
/// A standard (non-rectified) orthographic light matrix for a directional light: looks along the
/// light direction and tightly encloses the axis-aligned box [boundsMin, boundsMax], so every caster
/// of the scene is in the map. OpenGL clip conventions (depth-buffer value 0 nearest to the light).
glm::dmat4 standardLightClipFromWorld(const DirectionalLight& light, const glm::dvec3& boundsMin,
                                      const glm::dvec3& boundsMax);
} // namespace crep::scenes
