// The prefiltered method on the epipolar fallback layout on the GPU (Klehm et al. 2014, Sec. 4.1): the
// GPU prefilter of a map resampled into an EpipolarLayout and the GPU evaluation through the layout's
// block (CREP_EVAL_LAYOUT), against the CPU reference prefilter() + evaluate() of the same map. Sun in
// view (epipole on screen) and sun behind the camera (anti-epipole on screen). 160 x 90 screen.
#include "common/analytic_reference.h"
#include "common/gl_fixture.h"
#include "common/image_check.h"
#include "common/prefilter_gpu.h"

#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/resample.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/prefilter/prefilter.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <memory>
#include <string>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kWidth = 160, kHeight = 90, kShadowSize = 512, kMapWidth = 256;

struct EpipolarCase {
  const char* name;
  double forward, right, up; ///< direction toward the light in camera axes
  EpipoleKind kind;
};

void checkEpipolarEvaluation(const EpipolarCase& c, StorageFormat format) {
  scenes::Scene scene = scenes::makeScene("forest", static_cast<double>(kWidth) / kHeight);
  const Camera& cam = scene.camera;
  const glm::dvec3 towardLight =
      glm::normalize(c.forward * cam.forward() + c.right * cam.right() + c.up * cam.up());
  scene.sun = DirectionalLight(-towardLight, scene.sun.irradiance());
  scenes::SceneRenderer renderer(scene.mesh);
  const gl::Handle depthTexture = scenes::createDepthTexture(kWidth, kHeight);
  renderer.renderDepth(cam.clipFromWorld(), depthTexture.get(), 0, 0, 0, kWidth, kHeight);
  const Image cameraDepth = scenes::readDepthTexture(depthTexture.get(), kWidth, kHeight);
  const glm::dmat4 lightMatrix =
      scenes::standardLightClipFromWorld(scene.sun, scene.boundsMin, scene.boundsMax);
  const gl::Handle shadow = scenes::createDepthTexture(kShadowSize, kShadowSize);
  renderer.renderDepth(lightMatrix, shadow.get(), 0, 0, 0, kShadowSize, kShadowSize, {.depthClamp = true});

  const auto layout = std::make_shared<const EpipolarLayout>(cam, scene.sun, kWidth, kHeight);
  REQUIRE(layout->epipoleOnScreen());
  REQUIRE(layout->epipoleKind() == c.kind);
  const int W = kMapWidth, H = layout->sliceCount();
  const RectifiedMap map = resampleShadowMap(
      layout, W, H, scenes::readDepthTexture(shadow.get(), kShadowSize, kShadowSize), lightMatrix);
  const gl::Handle mapTexture = gl::createTexture2D(GL_R32F, W, H);
  glTextureSubImage2D(mapTexture.get(), 0, 0, 0, W, H, GL_RED, GL_FLOAT, map.depth.data().data());

  PrefilterPass::CreateInfo info;
  info.mapWidth = W;
  info.mapHeight = H;
  info.options.format = format;
  PrefilterPass prefilterPass(info);
  PrefilterPass::FrameAttribs pf;
  pf.rectifiedDepth = mapTexture.get();
  pf.layout = layout.get();
  pf.medium = &scene.medium;
  prefilterPass.run(pf);
  const FilteredBasis cpu = prefilter(map, scene.medium, info.options);
  const std::vector<float> gpuBasis =
      readTextureArray(prefilterPass.filteredBasisTexture(), W, H, prefilterPass.layers());
  const FormatTolerance basisTolerance{format};
  const BasisDifference d = compareBasis(gpuBasis, cpu, basisTolerance);
  const std::string basisReport =
      std::string(c.name) + " " + storageFormatToken(format) + ", basis: " + describe(d);
  MESSAGE(basisReport);
  CHECK(d.over == 0);

  EvaluatePass evaluatePass({});
  const gl::Handle out = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
  EvaluatePass::FrameAttribs ef;
  ef.cameraDepth = depthTexture.get();
  ef.output = out.get();
  ef.camera = &cam;
  ef.light = &scene.sun;
  ef.medium = &scene.medium;
  ef.layout = layout.get();
  ef.basis = prefilterPass.filteredBasis();
  evaluatePass.run(ef);
  const Image gpu = gl::readTexture(out.get(), kWidth, kHeight, gl::TexelData::Rgba);
  const Image reference = evaluate(cpu, cameraDepth, cam, scene.sun, scene.medium);
  const ImageMetrics m = rgbMetrics(gpu, reference);
  report(std::string(c.name) + ", " + storageFormatToken(format) + ": GPU vs CPU evaluation (epipolar)", m);
  CHECK(m.nanCount == 0);
  // Measured (llvmpipe): relative RMSE 6e-6 (sun in view) and 1.2e-5 (behind) for RGBA32F, 1.4e-3 and 1.0e-3
  // for RGBA8; max abs 8e-5 of the peak for RGBA32F (the float slice mapping, atan and border position, puts
  // a pixel next to a slice boundary on the neighbouring row now and then). RGBA8: the sampler's 8-bit
  // bilinear weights on 1/255 steps, as on the projective layout.
  ImageTolerance t;
  const bool exact = format == StorageFormat::RGBA32F;
  t.relativeRmse = exact ? 5e-5 : 5e-3;
  t.overThreshold = (exact ? 2e-4 : 1e-2) * m.peak;
  t.maxFractionOver = 1e-3;
  CHECK(checkImage(rgb(gpu), rgb(reference), t, std::string("prefilter_epipolar_gpu_vs_cpu_") + c.name));
}

} // namespace

TEST_CASE("prefilter GL: GPU prefilter and evaluation on the epipolar layout agree with the CPU reference") {
  CREP_REQUIRE_GL();
  const EpipolarCase cases[] = {
      {"sun in view", 1.0, 0.25, 0.2, EpipoleKind::Epipole},
      {"sun behind the camera", -1.0, -0.3, 0.4, EpipoleKind::AntiEpipole},
  };
  for (const EpipolarCase& c : cases)
    for (const StorageFormat f : {StorageFormat::RGBA32F, StorageFormat::RGBA8}) {
      CAPTURE(c.name);
      checkEpipolarEvaluation(c, f);
    }
}
