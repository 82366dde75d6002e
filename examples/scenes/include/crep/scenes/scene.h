// Built-in procedural scenes (tool, tests, benchmarks): a mesh, a default camera, sun and medium, and an
// exact CPU ray cast for ground truth. The scenes: examples/README.md, "crep/scenes/scene.h".
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

/// A light texture of a scene (crep/scatter/light_texture.h) and its projection along the light's rays.
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

/// The sunlit scenes accepted by makeScene ("colonnade" the default; README).
std::vector<std::string> sceneNames();
/// The scenes with local lights ("colonnade-night"), also accepted by makeScene.
std::vector<std::string> localLightSceneNames();
/// The scenes with a light texture ("stained-glass"), also accepted by makeScene.
std::vector<std::string> lightTextureSceneNames();
/// Builds a scene. `aspect` sets the default camera's aspect ratio. Throws InvalidArgument naming
/// "scene" for an unknown name.
Scene makeScene(std::string_view name, double aspect = 16.0 / 9.0);

/// Mesh helpers used by the generators (and by tests building their own arrangements).
void appendBox(Mesh& mesh, const Box& box);
void appendQuad(Mesh& mesh, const glm::dvec3& corner, const glm::dvec3& edgeU, const glm::dvec3& edgeV);

/// Exact first hit t in (tMin, tMax) of origin + t * direction (any length) on the mesh; BVH on first use.
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
/// An orthographic light matrix along the light that tightly encloses [boundsMin, boundsMax] (OpenGL clip
/// conventions: depth-buffer value 0 nearest to the light).
glm::dmat4 standardLightClipFromWorld(const DirectionalLight& light, const glm::dvec3& boundsMin,
                                      const glm::dvec3& boundsMax);
} // namespace crep::scenes
