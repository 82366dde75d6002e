// The built-in procedural scenes. Deterministic: a fixed-seed generator of our own (the standard
// distributions are not specified bit-for-bit across implementations).
#include <crep/core/error.h>
#include <crep/scenes/scene.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <numbers>

namespace crep::scenes {

namespace {

class Rng { // splitmix64
public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; } ///< [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

private:
  std::uint64_t state_;
};

void appendGround(Mesh& mesh, double halfSize) {
  appendQuad(mesh, {-halfSize, 0, -halfSize}, {0, 0, 2 * halfSize}, {2 * halfSize, 0, 0});
}

void computeBounds(Scene& s) {
  s.boundsMin = glm::dvec3(std::numeric_limits<double>::max());
  s.boundsMax = glm::dvec3(-std::numeric_limits<double>::max());
  for (const auto& p : s.mesh.positions) {
    s.boundsMin = glm::min(s.boundsMin, glm::dvec3(p));
    s.boundsMax = glm::max(s.boundsMax, glm::dvec3(p));
  }
}

// Ground, two rows of pillars along z, a roof with a grid of openings: clean shafts, simple depth.
Mesh colonnadeMesh() {
  Mesh m;
  appendGround(m, 60.0);
  const double pillarHalf = 0.6, height = 9.0;
  for (int row = 0; row < 2; ++row) {
    const double x = row == 0 ? -6.0 : 6.0;
    for (int i = 0; i < 10; ++i) {
      const double z = -30.0 + 6.0 * i;
      appendBox(m, {{x - pillarHalf, 0, z - pillarHalf}, {x + pillarHalf, height, z + pillarHalf}});
    }
  }
  // Roof slab from x = -8..8, z = -33..27 at y = 9..9.6, with 2 x 10 openings cut as a grid of beams.
  const double y0 = height, y1 = height + 0.6;
  const double x0 = -8.0, x1 = 8.0, z0 = -33.0, z1 = 27.0;
  // Beams along z (three: both edges and the centre line).
  for (double x : {x0, -1.0, 6.0})
    appendBox(m, {{x, y0, z0}, {x + 2.0, y1, z1}});
  // Cross beams along x between openings.
  for (int i = 0; i <= 10; ++i) {
    const double z = z0 + 6.0 * i;
    appendBox(m, {{x0, y0, z}, {x1, y1, z + 1.5}});
  }
  // A back wall closing the hall, so the far end is dark.
  appendBox(m, {{x0, 0, z0 - 1.0}, {x1, y1, z0}});
  return m;
}

// Hundreds of thin trunks and thousands of small leaf quads: high depth complexity.
Mesh forestMesh() {
  Mesh m;
  appendGround(m, 80.0);
  Rng rng(0xf04e57);
  const int trunks = 320, leavesPerTree = 16;
  for (int t = 0; t < trunks; ++t) {
    const double x = rng.uniform(-45.0, 45.0), z = rng.uniform(-60.0, 20.0);
    const double h = rng.uniform(7.0, 14.0), r = rng.uniform(0.12, 0.3);
    appendBox(m, {{x - r, 0, z - r}, {x + r, h, z + r}});
    for (int l = 0; l < leavesPerTree; ++l) {
      const glm::dvec3 c(x + rng.uniform(-2.5, 2.5), h + rng.uniform(-3.0, 1.0), z + rng.uniform(-2.5, 2.5));
      const double s = rng.uniform(0.4, 0.9);
      const double a = rng.uniform(0.0, 2.0 * std::numbers::pi), b = rng.uniform(0.2, 1.3);
      const glm::dvec3 u(std::cos(a) * s, 0.0, std::sin(a) * s);
      const glm::dvec3 v(-std::sin(a) * std::cos(b) * s, std::sin(b) * s, std::cos(a) * std::cos(b) * s);
      appendQuad(m, c - 0.5 * (u + v), u, v);
    }
  }
  return m;
}

double terrainHeight(double x, double z) {
  return 3.0 * std::sin(0.045 * x) * std::cos(0.038 * z) +
         1.6 * std::sin(0.11 * x + 0.7) * std::sin(0.09 * z + 1.3) + 0.5 * std::cos(0.23 * x - 0.31 * z) +
         0.002 * (x * x + z * z) * 0.2;
}

// A smooth height field with a few blockers: smooth shadow-map depth.
Mesh terrainMesh() {
  Mesh m;
  const int n = 160;
  const double half = 90.0, step = 2.0 * half / n;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = -half + i * step, z = -half + j * step;
      const double h = terrainHeight(x, z), e = 0.5 * step;
      const glm::dvec3 nrm =
          glm::normalize(glm::dvec3(terrainHeight(x - e, z) - terrainHeight(x + e, z), 2.0 * e,
                                    terrainHeight(x, z - e) - terrainHeight(x, z + e)));
      m.positions.emplace_back(x, h, z);
      m.normals.emplace_back(nrm);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const auto a = static_cast<std::uint32_t>(j * (n + 1) + i), b = a + 1,
                 c = a + static_cast<std::uint32_t>(n + 1), d = c + 1;
      for (std::uint32_t k : {a, c, b, b, c, d})
        m.indices.push_back(k);
    }
  // Blockers: a few tall slabs and towers standing on the terrain.
  const struct {
    double x, z, w, d, h;
  } blockers[] = {{-12, -25, 3, 3, 16},
                  {8, -40, 10, 2, 12},
                  {22, -15, 2, 2, 20},
                  {-30, -55, 14, 3, 10},
                  {0, -70, 4, 4, 25}};
  for (const auto& bl : blockers) {
    const double y = terrainHeight(bl.x, bl.z) - 1.0;
    appendBox(m, {{bl.x - bl.w / 2, y, bl.z - bl.d / 2}, {bl.x + bl.w / 2, y + bl.h, bl.z + bl.d / 2}});
  }
  return m;
}

// A ground plane and a few boxes: an arrangement simple enough for exact tests.
Mesh boxesMesh() {
  Mesh m;
  appendGround(m, 20.0);
  appendBox(m, {{-4, 0, -6}, {-2, 3, -4}});
  appendBox(m, {{1, 0, -9}, {3, 5, -7}});
  appendBox(m, {{-1, 4, -3}, {1, 4.5, -1}}); // floating slab
  appendBox(m, {{4, 0, -3}, {5, 2, 1}});
  return m;
}

/// The stained-glass hall: a side wall at x = 6 with a large window (z in [-16, 0], y in [2.5, 12.5]) split
/// by a mullion and a transom, a roof, a far wall and a back wall, on a ground plane.
constexpr double kWindowX = 6.0, kWindowZ0 = -16.0, kWindowZ1 = 0.0, kWindowY0 = 2.5, kWindowY1 = 12.5;

Mesh stainedGlassMesh() {
  Mesh m;
  appendGround(m, 60.0);
  const double t = 0.6, height = 14.0, z0 = -32.0, z1 = 24.0;
  const double x0 = kWindowX, x1 = kWindowX + t;
  // The window wall, around the opening.
  appendBox(m, {{x0, 0, z0}, {x1, height, kWindowZ0}});
  appendBox(m, {{x0, 0, kWindowZ1}, {x1, height, z1}});
  appendBox(m, {{x0, 0, kWindowZ0}, {x1, kWindowY0, kWindowZ1}});
  appendBox(m, {{x0, kWindowY1, kWindowZ0}, {x1, height, kWindowZ1}});
  // Mullion and transom (the shafts' dark crosses, also in the shadow map).
  const double zm = 0.5 * (kWindowZ0 + kWindowZ1), ym = 0.5 * (kWindowY0 + kWindowY1);
  appendBox(m, {{x0, kWindowY0, zm - 0.2}, {x1, kWindowY1, zm + 0.2}});
  appendBox(m, {{x0, ym - 0.15, kWindowZ0}, {x1, ym + 0.15, kWindowZ1}});
  // Roof, far wall, back wall: the window is the hall's only opening toward the sun.
  appendBox(m, {{-12.0, height, z0}, {x1, height + 0.6, z1}});
  appendBox(m, {{-12.6, 0, z0}, {-12.0, height, z1}});
  appendBox(m, {{-12.6, 0, z0 - 0.6}, {x1, height + 0.6, z0}});
  // Two pillars in the hall, in the shafts.
  appendBox(m, {{-3.0, 0, -10.0}, {-2.2, height, -9.2}});
  appendBox(m, {{-3.0, 0, -2.0}, {-2.2, height, -1.2}});
  return m;
}

/// A procedural stained-glass window (size x size, linear RGB, row 0 at the bottom): Voronoi panes in
/// saturated glass colours, dark lead lines between them (about 2.5% of the window wide) and a lead frame;
/// coarse enough for the reference march's 512 steps per ray (finer lead lines alias in its midpoint
/// samples).
Image stainedGlassTexture(int size) {
  Rng rng(0x57a1ed);
  const int cells = 24;
  std::vector<glm::dvec2> sites;
  std::vector<glm::dvec3> colors;
  const glm::dvec3 palette[] = {{1.0, 0.12, 0.08}, {0.12, 0.25, 1.0}, {1.0, 0.78, 0.15}, {0.15, 0.85, 0.3},
                                {0.6, 0.15, 0.95}, {0.1, 0.8, 0.9},   {1.0, 0.45, 0.1},  {0.95, 0.95, 0.8}};
  for (int i = 0; i < cells; ++i) {
    sites.emplace_back(rng.uniform(), rng.uniform());
    colors.push_back(palette[rng.next() % std::size(palette)]);
  }
  const double lead = 0.012, frame = 0.03;
  Image image(size, size, 3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const glm::dvec2 p((x + 0.5) / size, (y + 0.5) / size);
      double d1 = 1e9, d2 = 1e9;
      int nearest = 0;
      for (int i = 0; i < cells; ++i) {
        const double d = glm::length(p - sites[static_cast<std::size_t>(i)]);
        if (d < d1) {
          d2 = d1;
          d1 = d;
          nearest = i;
        } else if (d < d2) {
          d2 = d;
        }
      }
      // Distance to the pane's border: half the difference of the two nearest sites' distances (a lower
      // bound of the distance to the bisector, close enough for lead lines).
      const double border = 0.5 * (d2 - d1);
      const double edge = std::min({p.x, p.y, 1.0 - p.x, 1.0 - p.y});
      const bool leaded = border < lead || edge < frame;
      const glm::dvec3 c = leaded ? glm::dvec3(0.02) : colors[static_cast<std::size_t>(nearest)];
      for (int k = 0; k < 3; ++k)
        image.at(x, y, k) = static_cast<float>(c[k]);
    }
  return image;
}

/// The window's texture projection: orthographic along `sun`, its NDC square the window's silhouette seen
/// along the sun (the bounds of the opening's four corners in the light's view).
glm::dmat4 windowTextureClipFromWorld(const DirectionalLight& sun) {
  const glm::dvec3 d = sun.direction();
  const glm::dvec3 centre(kWindowX, 0.5 * (kWindowY0 + kWindowY1), 0.5 * (kWindowZ0 + kWindowZ1));
  const glm::dmat4 view = glm::lookAt(centre - 100.0 * d, centre, glm::dvec3(0.0, 1.0, 0.0));
  glm::dvec2 lo(1e30), hi(-1e30);
  for (const double y : {kWindowY0, kWindowY1})
    for (const double z : {kWindowZ0, kWindowZ1}) {
      const glm::dvec4 v = view * glm::dvec4(kWindowX, y, z, 1.0);
      lo = glm::min(lo, glm::dvec2(v));
      hi = glm::max(hi, glm::dvec2(v));
    }
  return glm::ortho(lo.x, hi.x, lo.y, hi.y, 1.0, 300.0) * view;
}

Medium defaultMedium() {
  return Medium(
      {.mieScattering = glm::dvec3(0.02, 0.022, 0.025), .hgG = 0.6, .absorption = glm::dvec3(0.004)});
}

} // namespace

std::vector<std::string> sceneNames() {
  return {"colonnade", "forest", "terrain", "boxes", "sunset"};
}

std::vector<std::string> localLightSceneNames() {
  return {"colonnade-night"};
}

std::vector<std::string> lightTextureSceneNames() {
  return {"stained-glass"};
}

namespace {

constexpr double kFov = 60.0 * std::numbers::pi / 180.0;

/// A scene of one mesh under the sun (no local lights, no light texture), its bounds computed.
Scene sunScene(const char* name, Mesh mesh, const Camera& camera, const DirectionalLight& sun,
               const Medium& medium) {
  Scene s{name, std::move(mesh), camera, sun, medium, {}, {}, true, {}, {}, {}};
  computeBounds(s);
  return s;
}

Scene colonnadeScene(double aspect) {
  return sunScene(
      "colonnade", colonnadeMesh(),
      Camera::lookAt({-2.0, 2.0, 22.0}, {1.0, 4.5, -20.0}, {0, 1, 0}, kFov, aspect, 0.1, 120.0),
      DirectionalLight(glm::dvec3(0.75, -0.55, 0.35), glm::dvec3(5.0, 4.6, 4.0)),
      Medium({.mieScattering = glm::dvec3(0.04, 0.042, 0.045), .hgG = 0.5, .absorption = glm::dvec3(0.004)}));
}

Scene forestScene(double aspect) {
  return sunScene(
      "forest", forestMesh(),
      Camera::lookAt({0.0, 2.0, 28.0}, {0.0, 6.0, -30.0}, {0, 1, 0}, kFov, aspect, 0.1, 150.0),
      DirectionalLight(glm::dvec3(-0.45, -0.6, -0.65), glm::dvec3(4.0, 3.8, 3.4)),
      Medium({.mieScattering = glm::dvec3(0.025, 0.027, 0.03), .hgG = 0.7, .absorption = glm::dvec3(0.005)}));
}

Scene terrainScene(double aspect) {
  return sunScene("terrain", terrainMesh(),
                  Camera::lookAt({0.0, 12.0, 40.0}, {0.0, 6.0, -40.0}, {0, 1, 0}, kFov, aspect, 0.1, 200.0),
                  DirectionalLight(glm::dvec3(0.8, -0.45, 0.2), glm::dvec3(4.0, 3.5, 2.8)),
                  Medium({.mieScattering = glm::dvec3(0.012, 0.014, 0.018),
                          .hgG = 0.5,
                          .rayleighScattering = glm::dvec3(0.002, 0.004, 0.008),
                          .absorption = glm::dvec3(0.002)}));
}

Scene boxesScene(double aspect) {
  return sunScene("boxes", boxesMesh(),
                  Camera::lookAt({0.0, 3.0, 10.0}, {0.0, 1.5, -5.0}, {0, 1, 0}, kFov, aspect, 0.1, 60.0),
                  DirectionalLight(glm::dvec3(0.5, -0.8, -0.3), glm::dvec3(3.0)), defaultMedium());
}

/// The forest toward a low sun behind the canopy: the sun is in view (about 12 degrees up, 10 degrees
/// right of the view axis), so every frame takes the epipolar layout; the classic god-ray picture.
Scene sunsetScene(double aspect) {
  return sunScene(
      "sunset", forestMesh(),
      Camera::lookAt({0.0, 2.0, 28.0}, {0.0, 6.0, -30.0}, {0, 1, 0}, kFov, aspect, 0.1, 150.0),
      DirectionalLight(-glm::normalize(glm::dvec3(0.18, 0.22, -1.0)), glm::dvec3(6.0, 4.4, 2.8)),
      Medium({.mieScattering = glm::dvec3(0.025, 0.027, 0.03), .hgG = 0.7, .absorption = glm::dvec3(0.005)}));
}

/// The colonnade at night (Klehm et al. 2014, Sec. 3.2 "Local Lights"): no sun; three warm spot lamps
/// outside the view, each projective: two outside the rows of pillars behind the camera shining in
/// through them, one above and behind the camera shining down the hall past the roof beams.
Scene colonnadeNightScene(double aspect) {
  Scene s{
      "colonnade-night",
      colonnadeMesh(),
      Camera::lookAt({-2.0, 2.0, 22.0}, {1.0, 4.5, -20.0}, {0, 1, 0}, kFov, aspect, 0.1, 120.0),
      DirectionalLight(glm::dvec3(0.75, -0.55, 0.35), glm::dvec3(0.0)),
      Medium({.mieScattering = glm::dvec3(0.04, 0.042, 0.045), .hgG = 0.5, .absorption = glm::dvec3(0.004)}),
      {},
      {},
      false,
      {},
      {},
      {}};
  const auto lamp = [](const glm::dvec3& position, const glm::dvec3& target, const glm::dvec3& color) {
    return SpotLight({.position = position,
                      .direction = target - position,
                      .innerConeAngle = 20.0 * std::numbers::pi / 180.0,
                      .outerConeAngle = 30.0 * std::numbers::pi / 180.0,
                      .color = color,
                      .intensity = 1000.0,
                      .range = 70.0,
                      .nearPlane = 0.3});
  };
  s.spotLights.push_back(lamp({-11.0, 7.5, 16.0}, {0.0, 0.0, 0.0}, {1.0, 0.75, 0.45}));
  s.spotLights.push_back(lamp({9.0, 8.5, 20.0}, {2.0, 0.0, 0.0}, {1.0, 0.8, 0.55}));
  s.spotLights.push_back(lamp({0.0, 8.8, 26.0}, {0.0, 0.0, 6.0}, {0.7, 0.8, 1.0}));
  computeBounds(s);
  return s;
}

/// Light textures (Klehm et al. 2014, Sec. 3.2; Yusov 2012's coloured shafts): a hall lit only through a
/// large window in its side wall; the sun, low and from the side, textured with a procedural
/// stained-glass pattern projected orthographically over the window, paints coloured shafts across
/// the hall and coloured patches on its floor and far wall.
Scene stainedGlassScene(double aspect) {
  Scene s{
      "stained-glass",
      stainedGlassMesh(),
      Camera::lookAt({-9.0, 2.0, 9.0}, {2.0, 6.0, -10.0}, {0, 1, 0}, kFov, aspect, 0.1, 120.0),
      DirectionalLight(glm::dvec3(-0.75, -0.5, -0.22), glm::dvec3(10.0, 9.5, 8.5)),
      Medium({.mieScattering = glm::dvec3(0.05, 0.052, 0.055), .hgG = 0.55, .absorption = glm::dvec3(0.004)}),
      {},
      {},
      true,
      {},
      {},
      {}};
  s.sunTexture = SceneLightTexture{stainedGlassTexture(128), windowTextureClipFromWorld(s.sun)};
  computeBounds(s);
  return s;
}

} // namespace

Scene makeScene(std::string_view name, double aspect) {
  if (name == "colonnade") return colonnadeScene(aspect);
  if (name == "forest") return forestScene(aspect);
  if (name == "terrain") return terrainScene(aspect);
  if (name == "boxes") return boxesScene(aspect);
  if (name == "sunset") return sunsetScene(aspect);
  if (name == "colonnade-night") return colonnadeNightScene(aspect);
  if (name == "stained-glass") return stainedGlassScene(aspect);
  throw InvalidArgument("scene", std::string(name),
                        "must be one of colonnade, forest, terrain, boxes, sunset, colonnade-night, "
                        "stained-glass");
}

} // namespace crep::scenes
