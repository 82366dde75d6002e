// GPU prefilter fixtures (the prefilter/ GL tests, and the textured and local-light prefilter tests of
// scatter/, epipolar/ and pipeline/): a rectified map and a camera depth buffer rendered from a built-in
// scene (one GL texture each, read back for the CPU reference), a CPU filtered basis uploaded, and the
// comparison of a GPU basis with the CPU one per storage format. GL tests only.
#pragma once

#include "common/gl_util.h"

#include <crep/core/image.h>
#include <crep/gpu/gl.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/prefilter/prefilter.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cmath>
#include <sstream>

#include <memory>
#include <string>
#include <vector>

namespace crep::test {

/// A scene with its rectified map (GL texture + CPU copy) and camera depth (GL texture + CPU copy).
struct GpuScene {
  scenes::Scene scene;
  std::shared_ptr<const ProjectiveLayout> layout;
  gl::Handle mapTexture;   ///< GL_DEPTH_COMPONENT32F, mapWidth x mapHeight
  RectifiedMap map;        ///< the same values on the CPU
  gl::Handle depthTexture; ///< camera depth, GL_DEPTH_COMPONENT32F, screenWidth x screenHeight
  Image cameraDepth;       ///< the same values on the CPU
};

/// A CPU filtered basis uploaded to the GPU (texture array in `format`, region-weights buffer), and
/// the view the evaluation pass takes.
struct UploadedBasis {
  gl::Handle texture, weights;
  FilteredBasisView view;
};

/// GPU filtered basis against the CPU one (stored values e = 0.5 + 0.5 F).
struct BasisDifference {
  double maxAbs = 0.0;            ///< max |gpu - cpu| (NaN counts as the maximum)
  double meanAbs = 0.0;           ///< mean |gpu - cpu|
  int x = -1, y = -1, basis = -1; ///< where the maximum is
  float gpu = 0.0f, cpu = 0.0f;   ///< the values there
  long long over = 0;             ///< values with |gpu - cpu| > tolerance(cpu) (or NaN)
};

inline double ulpHalf(double e) {
  if (e < std::ldexp(1.0, -14)) return std::ldexp(1.0, -24);
  int exponent = 0;
  std::frexp(e, &exponent);
  return std::ldexp(1.0, exponent - 11);
}

/// The per-value tolerance of a storage format for GPU vs CPU basis values (PrefilterGpuGLTest.cpp says
/// how it was measured): one RGBA8 step, one binary16 ulp, 4e-6 for RGBA32F.
struct FormatTolerance {
  StorageFormat format;
  double operator()(float cpu) const {
    switch (format) {
    case StorageFormat::RGBA8:
      return 1.0 / 255.0 + 1e-6;
    case StorageFormat::RGBA16F:
      return ulpHalf(cpu) + 1e-6;
    case StorageFormat::RGBA32F:
      break;
    }
    return 4e-6;
  }
};

/// Compares GPU read-back values with FilteredBasis::texels; counts values with |d| > tolerance(cpu).
template <class Tolerance>
BasisDifference compareBasis(const std::vector<float>& gpu, const FilteredBasis& cpu,
                             const Tolerance& tolerance) {
  BasisDifference d;
  const std::size_t count = cpu.texels.size();
  double sum = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    const double e = std::abs(static_cast<double>(gpu[i]) - static_cast<double>(cpu.texels[i]));
    sum += e;
    if (!(e <= tolerance(cpu.texels[i]))) ++d.over;
    if (e > d.maxAbs || e != e) {
      d.maxAbs = e;
      const std::size_t texel = i / 4,
                        plane = static_cast<std::size_t>(cpu.width) * static_cast<std::size_t>(cpu.height);
      const std::size_t layer = texel / plane, inLayer = texel % plane;
      d.x = static_cast<int>(inLayer % static_cast<std::size_t>(cpu.width));
      d.y = static_cast<int>(inLayer / static_cast<std::size_t>(cpu.width));
      d.basis = static_cast<int>(layer * 4 + i % 4);
      d.gpu = gpu[i];
      d.cpu = cpu.texels[i];
    }
  }
  d.meanAbs = count > 0 ? sum / static_cast<double>(count) : 0.0;
  return d;
}

/// Renders `sceneName` (built-in scene, camera aspect = screen aspect) into a rectified map with
/// `splits` logarithmic splits (SplitLayout::Regions, GL_DEPTH_CLAMP) and a camera depth buffer.
/// Requires a projective rectification (REQUIREs it).
inline GpuScene renderGpuScene(const std::string& sceneName, int mapWidth, int mapHeight, int splits,
                               int screenWidth, int screenHeight) {
  GpuScene s{
      scenes::makeScene(sceneName, static_cast<double>(screenWidth) / screenHeight), {}, {}, {}, {}, {}};
  RectifyOptions options;
  options.splits = splits;
  Rectification r = rectify(s.scene.camera, s.scene.sun, options);
  INFO(r.message);
  REQUIRE(r.projective());
  s.layout = std::make_shared<const ProjectiveLayout>(std::move(r));
  scenes::SceneRenderer renderer(s.scene.mesh);
  s.mapTexture = scenes::createDepthTexture(mapWidth, mapHeight, "rectified map size");
  for (int k = 0; k < s.layout->regionCount(); ++k) {
    const SplitViewport v = s.layout->rectification().splitViewport(k, mapWidth, mapHeight);
    renderer.renderDepth(s.layout->rectification().splits[static_cast<std::size_t>(k)].rectClipFromWorld,
                         s.mapTexture.get(), v.layer, v.x, v.y, v.width, v.height, {.depthClamp = true});
  }
  s.map = makeRectifiedMap(s.layout, scenes::readDepthTexture(s.mapTexture.get(), mapWidth, mapHeight));
  s.depthTexture = scenes::createDepthTexture(screenWidth, screenHeight, "screen size");
  renderer.renderDepth(s.scene.camera.clipFromWorld(), s.depthTexture.get(), 0, 0, 0, screenWidth,
                       screenHeight);
  s.cameraDepth = scenes::readDepthTexture(s.depthTexture.get(), screenWidth, screenHeight);
  return s;
}

inline UploadedBasis uploadBasis(const FilteredBasis& basis, StorageFormat format) {
  UploadedBasis u;
  const GLenum internal = format == StorageFormat::RGBA8     ? GL_RGBA8
                          : format == StorageFormat::RGBA16F ? GL_RGBA16F
                                                             : GL_RGBA32F;
  u.texture = gl::createTexture(GL_TEXTURE_2D_ARRAY);
  glTextureStorage3D(u.texture.get(), 1, internal, basis.width, basis.height, basis.layers);
  glTextureParameteri(u.texture.get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(u.texture.get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(u.texture.get(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(u.texture.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage3D(u.texture.get(), 0, 0, 0, 0, basis.width, basis.height, basis.layers, GL_RGBA, GL_FLOAT,
                      basis.texels.data());
  const std::vector<gpu::RegionWeights> weights =
      gpuRegionWeights(basis.profiles, basis.weights, basis.regionWidth());
  u.weights = gl::createBuffer();
  glNamedBufferStorage(u.weights.get(), static_cast<GLsizeiptr>(weights.size() * sizeof(gpu::RegionWeights)),
                       weights.data(), 0);
  u.view.texture = u.texture.get();
  u.view.regionWeights = u.weights.get();
  u.view.width = basis.width;
  u.view.height = basis.height;
  u.view.bases = basis.bases;
  u.view.layoutRegions = basis.layout->regionCount();
  u.view.regionsPerSplit = basis.regionsPerSplit;
  u.view.weights = basis.weights;
  u.view.extinction = basis.extinction;
  u.view.depthMargin = basis.depthMargin;
  return u;
}

/// The boxes frame of the GPU prefilter tests: a 250 x 37 map with 2 splits and a 161 x 93 screen, sizes that
/// are deliberately not multiples of the workgroup sizes; rendered once per process.
inline constexpr int kBoxesMapW = 250, kBoxesMapH = 37, kBoxesScreenW = 161, kBoxesScreenH = 93,
                     kBoxesSplits = 2;
inline const GpuScene& boxesGpuScene() {
  static const GpuScene scene =
      renderGpuScene("boxes", kBoxesMapW, kBoxesMapH, kBoxesSplits, kBoxesScreenW, kBoxesScreenH);
  return scene;
}

/// Runs the GPU prefilter on the scene's map texture (or `mapTexture`); returns the pass (its texture holds
/// the result).
inline PrefilterPass runPrefilter(const GpuScene& s, const PrefilterPass::CreateInfo& info,
                                  double extinctionOverride = -1.0, std::uint32_t mapTexture = 0) {
  PrefilterPass pass(info);
  PrefilterPass::FrameAttribs frame;
  frame.rectifiedDepth = mapTexture != 0 ? mapTexture : s.mapTexture.get();
  frame.layout = s.layout.get();
  frame.medium = &s.scene.medium;
  frame.extinctionOverride = extinctionOverride;
  pass.run(frame);
  return pass;
}

/// EvaluatePass's attributes for the sun of `s` with `basis`: the scene's camera depth, camera, sun, medium
/// and layout; the output texture is `output`.
inline EvaluatePass::FrameAttribs sunEvaluation(const GpuScene& s, const FilteredBasisView& basis,
                                                std::uint32_t output) {
  EvaluatePass::FrameAttribs f;
  f.cameraDepth = s.depthTexture.get();
  f.output = output;
  f.camera = &s.scene.camera;
  f.light = &s.scene.sun;
  f.medium = &s.scene.medium;
  f.layout = s.layout.get();
  f.basis = basis;
  return f;
}

/// A local light's map prefiltered and evaluated on the GPU: `map` uploaded (R32F) and run through
/// `prefilterPass` on `layout`, the basis evaluated by `evaluatePass` over the camera depth texture
/// `cameraDepth` (width x height); the image read back.
inline Image prefilterEvaluateLocal(PrefilterPass& prefilterPass, EvaluatePass& evaluatePass,
                                    const RectifiedMap& map, const RectifiedLayout* layout,
                                    const Camera& camera, std::uint32_t cameraDepth, int width, int height,
                                    const Medium& medium, const LocalLight& light) {
  const gl::Handle texture = uploadR32F(map.depth);
  prefilterPass.run(
      {.rectifiedDepth = texture.get(), .layout = layout, .medium = &medium, .localLight = &light});
  const gl::Handle out = createTexture2D(GL_RGBA32F, width, height);
  evaluatePass.run({.cameraDepth = cameraDepth,
                    .output = out.get(),
                    .camera = &camera,
                    .medium = &medium,
                    .layout = layout,
                    .basis = prefilterPass.filteredBasis(),
                    .localLight = &light});
  return readRgbaTexture(out.get(), width, height);
}

inline std::string describe(const BasisDifference& d) {
  std::ostringstream s;
  s.precision(4);
  s << "max |gpu - cpu| " << d.maxAbs << " (basis " << d.basis << " at texel (" << d.x << ", " << d.y
    << "): gpu " << d.gpu << ", cpu " << d.cpu << "), mean " << d.meanAbs << ", " << d.over
    << " values beyond tolerance";
  return s.str();
}

} // namespace crep::test
