// The prefiltered method for local lights on the CPU (crep::prefilter(map, medium, LocalLight) and
// crep::evaluate(..., LocalLight)): the spot and point light of the analytic scene
// (common/local_light_scene.h) against their closed forms, unoccluded and with the half-space shadow of the
// wall; the point light's six faces added, and the error along the face borders compared with the rest.
#include "common/analytic_reference.h"
#include "common/analytic_scene.h"
#include "common/local_light_scene.h"
#include "prefilter/colonnade_point_light.h"

#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scenes/scene.h>

#include <doctest/doctest.h>

#include <memory>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kW = 160, kH = 90, kMapW = 512, kMapH = 256;

PrefilterOptions options() {
  PrefilterOptions o;
  o.regionsPerSplit = 2;
  return o;
}

/// The prefiltered image of one local light with its rectification (the wall cast into the map or not).
Image prefiltered(const Rectification& rect, const LocalLight& light, const Camera& camera,
                  const Image& depth, const Medium& medium, bool withWall) {
  const auto layout = std::make_shared<const ProjectiveLayout>(rect);
  const RectifiedMap map = castRectifiedMap(layout, kMapW, kMapH, [&](const LightRay& ray) {
    return withWall ? wallHitFromLight(ray) : std::nullopt;
  });
  const FilteredBasis basis = prefilter(map, medium, light, options());
  return evaluate(basis, depth, camera, light, medium);
}

} // namespace

TEST_CASE("prefiltered spot light: closed forms without and with the half-space shadow") {
  const auto [camera, depth, medium, ro] = localLightView(kW, kH);
  const SpotLight spot = analyticSpot();
  const Rectification rect = rectify(camera, spot, ro);
  REQUIRE(rect.projective());
  const LocalLight light = LocalLight::spot(spot);
  for (const bool withWall : {false, true}) {
    CAPTURE(withWall);
    const Image ours = prefiltered(rect, light, camera, depth, medium, withWall);
    const ImageMetrics m = rgbMetrics(ours, closedFormLocal(depth, camera, {light}, medium, withWall));
    report(std::string("spot light, ") + (withWall ? "half-space shadow" : "no occluder") +
               ": prefiltered vs closed form",
           m);
    CHECK(m.nanCount == 0);
    CHECK(m.relativeRmse < 0.01);
  }
}

TEST_CASE("prefiltered point light: six faces against the closed form, no seam at the face borders") {
  const auto [camera, depth, medium, ro] = localLightView(kW, kH);
  const PointLight point = analyticPoint();
  const std::array<Rectification, 6> faces = rectifyPointLight(camera, point, ro);
  Image sum(kW, kH, 4);
  std::vector<LocalLight> lights;
  int projective = 0;
  for (int face = 0; face < 6; ++face) {
    lights.push_back(LocalLight::pointFace(point, face));
    const Rectification& r = faces[static_cast<std::size_t>(face)];
    MESSAGE("face " << face << ": " << r.message);
    if (r.status == RectifyStatus::Empty) continue;
    REQUIRE(r.projective());
    ++projective;
    const Image img = prefiltered(r, lights.back(), camera, depth, medium, true);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        for (int c = 0; c < 3; ++c)
          sum.at(x, y, c) += img.at(x, y, c);
        sum.at(x, y, 3) = img.at(x, y, 3);
      }
  }
  CHECK(projective >= 2);
  const Image truth = closedFormLocal(depth, camera, lights, medium, true);
  const ImageMetrics m = rgbMetrics(sum, truth);
  report("point light (six faces), half-space shadow: prefiltered vs closed form", m);
  CHECK(m.nanCount == 0);
  CHECK(m.relativeRmse < 0.01);

  // Seams: the pixels whose lit ray gets at least 10% of its light from each of two faces (their rays
  // cross a face border) have no larger error than the others. Per-pixel relative error (green channel,
  // pixels above 1% of the peak), RMS per group: the border pixels are the bright ones near the light, so
  // errors relative to the peak would compare brightness, not seams.
  std::vector<Image> perFace;
  for (const LocalLight& l : lights)
    perFace.push_back(closedFormLocal(depth, camera, {l}, medium, true));
  double peak = 0.0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      peak = std::max(peak, double(truth.at(x, y, 1)));
  double border2 = 0.0, other2 = 0.0;
  int borderCount = 0, otherCount = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const double total = truth.at(x, y, 1);
      if (!(total > 0.01 * peak)) continue;
      int sharing = 0;
      for (const Image& f : perFace)
        sharing += f.at(x, y, 1) > 0.1 * total ? 1 : 0;
      const double e = (sum.at(x, y, 1) - total) / total;
      (sharing >= 2 ? border2 : other2) += e * e;
      ++(sharing >= 2 ? borderCount : otherCount);
    }
  REQUIRE(borderCount > 50);
  REQUIRE(otherCount > 50);
  const double border = std::sqrt(border2 / borderCount), other = std::sqrt(other2 / otherCount);
  MESSAGE("face borders: " << borderCount << " pixels, RMS relative error " << border << "; elsewhere "
                           << otherCount << " pixels, " << other);
  CHECK(border <= 1.5 * other + 1e-3);
}

TEST_CASE("prefiltered point light: every region's reference ray is finite where the row's rays cross it") {
  // Regression (colonnade, point light 3 units behind the camera, face -Z): the row's reference ray (depth
  // ~0.3 of [0.003, 0.95]) reached its horizon (t = +inf) in the middle of the map while the row's
  // shallower rays crossed the rest of it, so the exact weights of those texels were 0 and the prefiltered
  // face showed a lit wedge (24% from the brute-force march over the same map; tests/prefilter/
  // PrefilterPointFaceGLTest.cpp). ProjectiveLayout::regionReferenceDepth takes the row's ray reaching
  // furthest instead.
  const scenes::Scene scene = scenes::makeScene("colonnade", 160.0 / 90.0);
  const Camera& c = scene.camera;
  const PointLight point = colonnadePointLight(c);
  const auto faces = colonnadePointFaces(c, point);
  REQUIRE(faces[5].projective());
  const ProjectiveLayout layout(faces[5]);
  const int H = 512, P = 2, K = layout.regionCount();
  const std::vector<DistanceProfile> profiles = referenceProfiles(layout, H, P);
  int crossed = 0, invalid = 0;
  for (int j = 0; j < H; ++j) {
    const double row = (j + 0.5) / H;
    const RowReference ref = faces[5].rowReference(row);
    for (int k = 0; k < K; ++k) {
      // Some ray of the row crosses layout region k with finite distances.
      if (!layout.rayProfile(row, ref.depthLo, k).valid() && !layout.rayProfile(row, ref.depthHi, k).valid())
        continue;
      for (int q = 0; q < P; ++q) {
        ++crossed;
        invalid += profiles[static_cast<std::size_t>(j * K * P + k * P + q)].valid() ? 0 : 1;
      }
    }
  }
  MESSAGE("regions crossed by the row's rays: " << crossed
                                                << ", with an infinite reference profile: " << invalid);
  CHECK(crossed > 0);
  CHECK(invalid == 0);
}
