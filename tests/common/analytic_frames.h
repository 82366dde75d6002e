// The analytic cases of the accuracy and flicker measurements (tests/accuracy/error_budget.cpp,
// tests/pipeline/AnalyticCasesGLTest.cpp): the ground camera over a ground plane, a plane occluder, the sun
// from four directions or a spot, both planes as casters in the engine's maps (so that the receivers are in
// the maps, as in an engine), and the closed form of each ray's lit part; the front door run on them, the
// world-space reference march and the brute-force march over the frame's rectified map; the flicker figure.
#pragma once

#include "common/analytic_reference.h"
#include "common/local_light_scene.h"

#include <crep/epipolar/gpu_march.h>
#include <crep/gpu/gl.h>
#include <crep/pipeline/scattering.h>
#include <crep/scatter/gpu_world_march.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <epoxy/gl.h>

#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace crep::test {

inline constexpr int kStandardMap =
    2048; // the engine's standard map of the resampled input and the world march

/// One analytic case: the ground camera, a light and its plane occluder (a sun's, or the local lights' wall).
struct Case {
  std::string name;
  std::optional<DirectionalLight> sun;
  std::optional<SpotLight> spot;
  HalfSpace plane;
};

/// The sun cases' occluder, oriented so that its shadowed side (normal side) faces away from the light.
inline HalfSpace sunPlane(const glm::dvec3& direction) {
  HalfSpace p;
  if (glm::dot(p.normal, direction) < 0.0) p.normal = -p.normal;
  return p;
}

inline Case sunCase(std::string name, const glm::dvec3& direction) {
  return {std::move(name), DirectionalLight(direction, glm::dvec3(2.0, 1.8, 1.5)), std::nullopt,
          sunPlane(glm::normalize(direction))};
}

inline std::vector<Case> allCases() {
  return {sunCase("sun to the side", {1.0, -1.0, -0.3}),
          sunCase("sun in view", {0.3, -0.3, 1.0}),
          sunCase("sun oblique", {0.6, -0.5, -0.8}),
          sunCase("sun behind", {0.2, -0.4, -1.0}),
          {"spot near the view", std::nullopt, analyticViewSpot(), wall()},
          {"spot to the side", std::nullopt, analyticSpot(), wall()}};
}

/// A square of half-size `extent` in the plane through `point` with `normal`: two triangles.
inline void addQuad(scenes::Mesh& mesh, const glm::dvec3& point, const glm::dvec3& normal, double extent) {
  const glm::dvec3 a = glm::normalize(
      glm::cross(normal, std::abs(normal.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0)));
  const glm::dvec3 b = glm::cross(normal, a);
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  for (const auto& [s, t] : {std::pair{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}}) {
    mesh.positions.push_back(glm::vec3(point + extent * (s * a + t * b)));
    mesh.normals.push_back(glm::vec3(normal));
  }
  for (const std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u})
    mesh.indices.push_back(base + i);
}

/// The casters of a case: the ground (it shadows nothing above it, but it is in every map, as in an engine)
/// and the occluder's plane, both 4000 units wide.
inline scenes::Mesh casters(const Case& c) {
  scenes::Mesh mesh;
  addQuad(mesh, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, 2000.0);
  addQuad(mesh, c.plane.point, c.plane.normal, 2000.0);
  return mesh;
}

/// A camera at `position` with the ground camera's orientation turned by `yaw` radians about +y (60 degrees,
/// near 0.1, far 80).
inline Camera caseCamera(const glm::dvec3& position, double yaw, double aspect) {
  const glm::dvec3 forward(std::sin(-yaw) * 10.0, -0.5, -std::cos(-yaw) * 10.0);
  return Camera::lookAt(position, position + forward, {0, 1, 0}, glm::radians(60.0), aspect, 0.1, 80.0);
}

inline Image truthOf(const Case& c, const Camera& camera, const Image& depth, const Medium& medium) {
  if (c.sun) return closedForm(depth, camera, *c.sun, medium, c.plane);
  return closedFormLocal(depth, camera, {LocalLight::spot(*c.spot)}, medium);
}

inline double rgbRelativeRmse(const Image& actual, const Image& reference) {
  return rgbMetrics(actual, reference).relativeRmse;
}

/// How the frame gets its shadow maps.
enum class Input { Rasterized, Resampled };

/// The GL side of one case at one camera: camera depth, casters, the engine's standard map and the marches.
class CaseFrame {
public:
  CaseFrame(const Case& c, const Camera& camera, int width, int height)
      : case_(c), camera_(camera), width_(width), height_(height), medium_(colouredMedium()),
        renderer_(casters(c)) {
    depth_ = groundDepth(camera_, width_, height_);
    depthTexture_ = gl::createTexture2D(GL_R32F, width_, height_); // (uploadR32F asserts through doctest)
    glTextureSubImage2D(depthTexture_.get(), 0, 0, 0, width_, height_, GL_RED, GL_FLOAT,
                        depth_.data().data());
    output_ = gl::createTexture2D(GL_RGBA32F, width_, height_);
    standard_.texture = standardTexture_.get();
    standard_.bias = 1e-4;
    standard_.lightClipFromWorld = c.sun ? analyticLightMatrix(*c.sun) : c.spot->lightClipFromWorld();
    renderer_.renderDepth(standard_.lightClipFromWorld, standardTexture_.get(), 0, 0, 0, kStandardMap,
                          kStandardMap, {.depthClamp = true});
  }
  const Image& depth() const { return depth_; }
  const Medium& medium() const { return medium_; }

  Image run(Scattering& s, Input input, Scattering::FrameResult* result = nullptr) {
    Scattering::FrameAttribs a;
    a.camera = &camera_;
    a.medium = &medium_;
    a.cameraDepth = depthTexture_.get();
    a.output = output_.get();
    if (input == Input::Rasterized)
      a.drawCasters = [this](const glm::dmat4& clipFromWorld) { renderer_.drawDepth(clipFromWorld); };
    if (case_.sun) {
      a.light = &*case_.sun;
      if (input == Input::Resampled) a.shadowMap = &standard_;
    } else {
      a.spotLights = std::span<const SpotLight>(&*case_.spot, 1);
      if (input == Input::Resampled) a.spotShadowMaps = std::span<const Scattering::ShadowMap>(&standard_, 1);
    }
    Scattering::FrameResult r = s.run(a);
    if (result) *result = std::move(r);
    return read();
  }

  /// The world-space reference march (256 sections, 12 refinements) against the standard map.
  Image worldMarch() {
    static WorldMarchPass pass({{.steps = 256, .refinements = 12}});
    WorldMarchPass::FrameAttribs f;
    f.camera = &camera_;
    const std::optional<LocalLight> local =
        case_.spot ? std::optional<LocalLight>(LocalLight::spot(*case_.spot)) : std::nullopt;
    if (case_.sun)
      f.light = &*case_.sun;
    else
      f.localLight = &*local;
    f.medium = &medium_;
    f.cameraDepth = depthTexture_.get();
    f.shadowMap = standard_.texture;
    f.lightClipFromWorld = standard_.lightClipFromWorld;
    f.bias = standard_.bias;
    f.output = output_.get();
    pass.run(f);
    return read();
  }

  /// The brute-force march over the rectified map a sun frame used (exact visibility per texel).
  Image marchSameMap(const Scattering::FrameResult& r) {
    const Scattering::FrameResult::RectifiedMapView& m = r.rectifiedMap;
    RectifiedMarchPass pass({m.width, m.height, RectifiedMarchPass::Mode::BruteForce});
    RectifiedMarchPass::FrameAttribs a;
    a.layout = m.layout.get();
    a.camera = &camera_;
    a.light = &*case_.sun;
    a.medium = &medium_;
    a.cameraDepth = depthTexture_.get();
    a.rectifiedDepth = m.texture;
    a.output = output_.get();
    pass.run(a);
    return read();
  }

private:
  Image read() const { return gl::readTexture(output_.get(), width_, height_, gl::TexelData::Rgba); }

  const Case& case_;
  Camera camera_;
  int width_, height_;
  Medium medium_;
  scenes::SceneRenderer renderer_;
  Image depth_;
  gl::Handle depthTexture_, output_,
      standardTexture_ = scenes::createDepthTexture(kStandardMap, kStandardMap);
  Scattering::ShadowMap standard_;
};

/// A slow camera motion per frame: a strafe along +x, or a turn about +y.
struct CameraMotion {
  const char* name;
  glm::dvec3 step; ///< world units per frame
  double yaw;      ///< radians per frame
};
/// The motions of the flicker figure: a strafe of 0.05 units and a rotation of 0.25 degrees per frame.
inline std::vector<CameraMotion> slowMotions() {
  return {{"strafe 0.05 / frame", {0.05, 0.0, 0.0}, 0.0},
          {"rotation 0.25 deg / frame", {0.0, 0.0, 0.0}, glm::radians(0.25)}};
}

/// The flicker of a method: the mean over consecutive frames of the RMS of the change of its error, relative
/// to the RMS of the truth (Sec. "Flicker" of docs/MEASUREMENTS.md).
struct FlickerTrack {
  std::vector<Image> errors;
  double rmsTruth = 0.0;
  void add(const Image& image, const Image& truth) {
    Image e(image.width(), image.height(), 3);
    double t2 = 0.0;
    for (int y = 0; y < image.height(); ++y)
      for (int x = 0; x < image.width(); ++x)
        for (int ch = 0; ch < 3; ++ch) {
          e.at(x, y, ch) = image.at(x, y, ch) - truth.at(x, y, ch);
          t2 += double(truth.at(x, y, ch)) * truth.at(x, y, ch);
        }
    rmsTruth += std::sqrt(t2 / (3.0 * image.width() * image.height()));
    errors.push_back(std::move(e));
  }
  double flicker() const {
    double sum = 0.0;
    for (std::size_t f = 1; f < errors.size(); ++f) {
      double d2 = 0.0;
      const Image &a = errors[f - 1], &b = errors[f];
      for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x)
          for (int ch = 0; ch < 3; ++ch) {
            const double d = double(b.at(x, y, ch)) - a.at(x, y, ch);
            d2 += d * d;
          }
      sum += std::sqrt(d2 / (3.0 * a.width() * a.height()));
    }
    return sum / double(errors.size() - 1) / (rmsTruth / double(errors.size()));
  }
};

} // namespace crep::test
