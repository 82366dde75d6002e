// GL test of the projective rectification: the built-in analytic arrangement (boxes over a plane) rasterized
// with each split's rectClipFromWorld, as an engine would (one depth texture, one viewport per split,
// GL_DEPTH_CLAMP), stores at every sampled texel the depth of the first occluder along that texel's light
// ray, computed on the CPU by an exact ray cast.
#include "common/gl_fixture.h"

#include <crep/rectify/rectify.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

using namespace crep;
using namespace crep::scenes;

namespace {

/// The CPU reference for one texel: the first hit along its light ray.
struct Occluder {
  double depth = 1.0; ///< clamped to [0, 1] as GL_DEPTH_CLAMP does; 1 without a hit (cleared)
  bool hit = false;
  glm::dvec3 point{0.0}; ///< the hit, when there is one
};

struct Comparison {
  int compared = 0, edges = 0, occluded = 0, clampedToZero = 0, bad = 0;
  double worst = 0.0;
};

// Depth tolerance, absolute in depth-buffer units: GL_DEPTH_COMPONENT32F stores 2^-24 near 1, but the
// float pipeline before it (vertex transform, clipping of the large ground triangles against the side
// planes, screen-space interpolation) is what limits: 1e-5 = 84 float epsilons. Measured: 1.5e-6
// (directional), 1.7e-7 (spot) on llvmpipe. Exact 0 and 1 where GL_DEPTH_CLAMP or the clear apply.
constexpr double kDepthTolerance = 1e-5;

/// The first hit along the light ray from `origin`, with its rectified depth.
Occluder firstOccluder(const Rectification& r, const RayCaster& caster, const glm::dvec3& origin,
                       const glm::dvec3& direction) {
  Occluder o;
  if (const auto t = caster.firstHit(origin, direction, 0.0, 1e30)) {
    o.hit = true;
    o.point = origin + *t * direction;
    o.depth = std::clamp(r.toRectified(o.point).depth, 0.0, 1.0);
  }
  return o;
}

/// Renders all splits of `r` into one W x H map and compares sampled texels with the first occluder
/// along the texel's light ray (`reference(column, row)`).
Comparison renderAndCompare(const Scene& scene, const Rectification& r, int W, int H,
                            const std::function<Occluder(double column, double row)>& reference,
                            bool depthClamp = true) {
  SceneRenderer renderer(scene.mesh);
  const gl::Handle texture = createDepthTexture(W, H, "rectified map size");
  for (int k = 0; k < r.splitCount(); ++k) {
    const SplitViewport v = r.splitViewport(k, W, H);
    renderer.renderDepth(r.splits[static_cast<std::size_t>(k)].rectClipFromWorld, texture.get(), v.layer, v.x,
                         v.y, v.width, v.height, {.depthClamp = depthClamp});
  }
  const Image map = readDepthTexture(texture.get(), W, H);

  Comparison c;
  for (int j = 1; j < H - 1; j += 3)
    for (int i = 1; i < W - 1; i += 3) {
      const double column = (i + 0.5) / W, row = (j + 0.5) / H;
      const Occluder occluder = reference(column, row);
      const double expected = occluder.depth;
      // Texels whose light ray passes within half a texel of a silhouette or a crease may show the
      // neighbour surface: skip those where the CPU depth is not linear across the texel's footprint
      // (the rasterized depth of a plane is exact at the texel centre; a kink or a jump is not).
      bool edge = false;
      for (const glm::dvec2 d : {glm::dvec2(0.5 / W, 0), glm::dvec2(0, 0.5 / H)}) {
        const double plus = reference(column + d.x, row + d.y).depth;
        const double minus = reference(column - d.x, row - d.y).depth;
        edge = edge || std::abs(plus + minus - 2.0 * expected) > 1e-5;
      }
      if (edge) {
        ++c.edges;
        continue;
      }
      ++c.compared;
      c.occluded += expected < 1.0;
      c.clampedToZero += expected == 0.0;
      const double err = std::abs(map.at(i, j) - expected);
      c.worst = std::max(c.worst, err);
      if (err > kDepthTolerance && ++c.bad <= 5 && depthClamp)
        MESSAGE("texel (" << i << ", " << j << "): stored " << map.at(i, j) << ", expected " << expected);
    }
  return c;
}

void check(const char* name, const Comparison& c) {
  MESSAGE(std::string(name) << ": compared " << c.compared << " texels (" << c.occluded << " occluded, "
                            << c.clampedToZero << " with the occluder in front of the frustum, depth 0), "
                            << c.edges << " silhouette texels skipped; worst |depth error| " << c.worst
                            << " (tolerance " << kDepthTolerance << "), " << c.bad << " beyond tolerance");
  CHECK(c.compared > 2000);
  CHECK(c.occluded > c.compared / 10); // the boxes and the ground do cast into the map
  CHECK(c.bad == 0);
}

} // namespace

TEST_CASE(
    "rectify GL: each split's map stores the first occluder along the texel's light ray (directional)") {
  CREP_REQUIRE_GL();
  Scene scene = makeScene("boxes", 16.0 / 9.0);
  // A caster above the camera frustum, between the light and the visible ground: it must be kept by
  // GL_DEPTH_CLAMP at depth 0 (Sec. 4.2), not clipped.
  appendBox(scene.mesh, {{-6.0, 12.0, -2.0}, {-4.0, 13.0, 0.0}});
  RectifyOptions options;
  options.splits = 4;
  const Rectification r = rectify(scene.camera, scene.sun, options);
  INFO(r.message);
  REQUIRE(r.projective());
  const RayCaster caster(scene.mesh);
  const double reach = 100.0; // start far behind every caster (the scene spans 40 units)
  const auto reference = [&](double column, double row) {
    const LightRay ray = r.lightRay(column, row);
    return firstOccluder(r, caster, ray.origin - reach * ray.direction, ray.direction);
  };
  const Comparison c = renderAndCompare(scene, r, 512, 256, reference);
  check("directional", c);
  CHECK(c.clampedToZero > 20);
  // Negative control: without GL_DEPTH_CLAMP the caster above the frustum is clipped away.
  const Comparison noClamp = renderAndCompare(scene, r, 512, 256, reference, false);
  MESSAGE("without GL_DEPTH_CLAMP: " << noClamp.bad << " texels wrong");
  CHECK(noClamp.bad >= c.clampedToZero);
}

TEST_CASE("rectify GL: each split's map stores the first occluder along the texel's light ray (spot)") {
  CREP_REQUIRE_GL();
  const Scene scene = makeScene("boxes", 16.0 / 9.0);
  // High above and behind-left of the camera, aimed at the boxes: off screen by ~20 degrees.
  const SpotLight spot({.position = {-8.0, 14.0, 2.0},
                        .direction = {8.0, -14.0, -7.0},
                        .innerConeAngle = glm::radians(25.0),
                        .outerConeAngle = glm::radians(35.0),
                        .range = 40.0});
  RectifyOptions options;
  options.splits = 3;
  const Rectification r = rectify(scene.camera, spot, options);
  INFO(r.message);
  REQUIRE(r.projective());
  const RayCaster caster(scene.mesh);
  const auto reference = [&](double column, double row) {
    const LightRay ray = r.lightRay(column, row); // starts at the light
    return firstOccluder(r, caster, ray.origin, ray.direction);
  };
  check("spot", renderAndCompare(scene, r, 384, 256, reference));
}
