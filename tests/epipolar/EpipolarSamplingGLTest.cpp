// The GPU stage passes of epipolar sampling (crep/epipolar/gpu_epipolar_sampling.h) against their CPU
// references (crep/epipolar/epipolar_sampling.h), stage by stage: each CPU stage is fed with the GPU's own
// read-back inputs, so only the float arithmetic of the stage itself can differ. Scene: the analytic
// ground plane with a near box (depth breaks) and sky, 160 x 96, 128 slices x 64 samples; a light whose
// epipole is on screen (the lines wrap around it), the side light (epipole off screen) and a light parallel
// to the image plane (epipole clamped to 1e5 px: nearly parallel lines). Evaluator: the test shader
// tests/glsl/epipolar_sampling_eval.comp, (0.01 x, 0.01 y, 0.05 z, 1) of each list entry, and the same
// function on the CPU.
#include "common/analytic_scene.h"
#include "common/error_checks.h"
#include "common/gl_fixture.h"

#include <crep/core/error.h>
#include <crep/epipolar/epipolar_sampling.h>
#include <crep/epipolar/gpu_epipolar_sampling.h>
#include <crep/gpu/gl.h>
#include <crep/gpu/shader_library.h>
#include <crep/scatter/gpu_sample_list.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <set>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

constexpr int kWidth = 160, kHeight = 96; // multiples of F = 4

/// The scene of the tests: ground, sky and a near box (view depth 6) in the lower middle.
struct Scene {
  Camera camera = groundCamera(kWidth, kHeight);
  DirectionalLight light;
  Medium medium = colouredMedium();
  Image depth;
  gl::Handle depthTexture, output;

  /// depthFormat: GL_R32F or GL_DEPTH_COMPONENT32F.
  explicit Scene(const DirectionalLight& l, GLenum depthFormat = GL_R32F) : light(l) {
    depth = groundDepth(camera, kWidth, kHeight);
    const float box = static_cast<float>(depthBufferValue(camera, 6.0));
    for (int y = 20; y < 55; ++y)
      for (int x = 60; x < 95; ++x)
        depth.at(x, y) = box;
    depthTexture = gl::createTexture2D(depthFormat, kWidth, kHeight);
    glTextureSubImage2D(depthTexture.get(), 0, 0, 0, kWidth, kHeight,
                        depthFormat == GL_R32F ? GL_RED : GL_DEPTH_COMPONENT, GL_FLOAT, depth.data().data());
    output = gl::createTexture2D(GL_RGBA32F, kWidth, kHeight);
  }
  EpipolarSamplingPass::FrameAttribs frame() const {
    return {&camera, &light, &medium, depthTexture.get(), output.get()};
  }
};

/// The light sets of the tests: toward the camera's view (epipole on screen), from the side (off screen).
DirectionalLight frontLight() {
  return DirectionalLight(glm::dvec3(-0.2, -0.15, 1.0), glm::dvec3(2.0, 1.8, 1.5));
}

EpipolarSamplingOptions smallOptions(int downscale = 1) {
  EpipolarSamplingOptions o;
  o.slices = 128;
  o.samples = 64;
  o.initialStep = 8;
  o.downscale = downscale;
  return o;
}

/// The CPU twin of the test evaluator.
glm::dvec4 evaluateCpu(const Camera& camera, double x, double y, double d) {
  return {0.01 * x, 0.01 * y, 0.05 * camera.surfaceViewDepth(d), 1.0};
}

/// Runs the test evaluator on a list (indirect dispatch).
void evaluateGpu(const gpu::SampleList& list) {
  // Built once, never deleted (the shared context outlives the tests).
  static const gl::Handle* program =
      new gl::Handle(buildProgram({{ShaderStage::Compute, "test/epipolar_sampling_eval.comp", {}}}));
  glUseProgram(program->get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, list.buffer);
  glBindImageTexture(0, list.coordinates, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
  glBindImageTexture(1, list.output, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  gpu::dispatchSampleList(list.buffer);
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                  GL_TEXTURE_UPDATE_BARRIER_BIT);
  gl::unbindPassState(3);
  gl::checkError("epipolar sampling test evaluator");
}

/// The entries of a list, sorted, as (x, y).
std::vector<std::pair<int, int>> listEntries(const gpu::SampleList& list) {
  const int count = gpu::sampleListCount(list.buffer);
  std::vector<std::uint32_t> raw(static_cast<std::size_t>(count));
  if (count > 0)
    glGetNamedBufferSubData(list.buffer, gpu::kSampleListHeaderBytes, static_cast<GLsizeiptr>(count) * 4,
                            raw.data());
  std::vector<std::pair<int, int>> out;
  for (std::uint32_t e : raw)
    out.emplace_back(static_cast<int>(e & 0xFFFFu), static_cast<int>(e >> 16));
  std::sort(out.begin(), out.end());
  return out;
}

Image readRgba(std::uint32_t texture, int w, int h) {
  return gl::readTexture(texture, w, h, gl::TexelData::Rgba);
}

std::vector<glm::ivec2> readSources(std::uint32_t texture, int w, int h) {
  std::vector<glm::ivec2> s(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  glGetTextureImage(texture, 0, GL_RG_INTEGER, GL_INT, static_cast<GLsizei>(s.size() * sizeof(glm::ivec2)),
                    s.data());
  return s;
}

EpipolarSamples readSamples(const EpipolarSamplingPass& pass) {
  const int Ns = pass.info().options.samples, N = pass.info().options.slices;
  return {readRgba(pass.coordinatesTexture(), Ns, N),
          gl::readTexture(pass.unshadowedTexture(), Ns, N, gl::TexelData::Red)};
}

std::string sci(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2e", v);
  return text;
}

int pixelOf(double v, int size) {
  return std::clamp(static_cast<int>(std::floor(v)), 0, size - 1);
}

/// Max abs difference over the RGBA pixels not in `skip` (pixel indices), and the number of pixels beyond
/// `tolerance`.
struct ImageDiff {
  double maxAbs = 0.0;
  int beyond = 0;
};
ImageDiff compareImages(const Image& gpu, const Image& cpu, const std::vector<int>& skip, double tolerance) {
  ImageDiff r;
  const std::set<int> s(skip.begin(), skip.end());
  for (int y = 0; y < cpu.height(); ++y)
    for (int x = 0; x < cpu.width(); ++x) {
      if (s.count(y * cpu.width() + x)) continue;
      double m = 0.0;
      for (int c = 0; c < 4; ++c) {
        const double d = std::abs(static_cast<double>(gpu.at(x, y, c)) - cpu.at(x, y, c));
        m = std::isnan(d) ? std::numeric_limits<double>::infinity() : std::max(m, d);
      }
      r.maxAbs = std::max(r.maxAbs, m);
      if (m > tolerance) ++r.beyond;
    }
  return r;
}

std::vector<int> pixelIndices(const std::vector<std::pair<int, int>>& entries, int width) {
  std::vector<int> out;
  for (const auto& [x, y] : entries)
    out.push_back(y * width + x);
  std::sort(out.begin(), out.end());
  return out;
}

/// Fills an RGBA32F texture with NaN.
void fillNaN(std::uint32_t texture) {
  const float nan[4] = {std::nanf(""), std::nanf(""), std::nanf(""), std::nanf("")};
  glClearTexImage(texture, 0, GL_RGBA, GL_FLOAT, nan);
}

constexpr int kLights = 3;
const char* lightName(int which) {
  return which == 0   ? "front light (epipole on screen)"
         : which == 1 ? "side light (epipole off screen)"
                      : "light parallel to the image plane (epipole 1e5 px away)";
}

DirectionalLight lightOf(int which) {
  if (which == 2) { // perpendicular to the camera's forward (0, -0.5, -10): clip w = 0
    const Camera camera = groundCamera(kWidth, kHeight);
    const glm::dvec3 d = glm::normalize(glm::cross(camera.forward(), glm::dvec3(0.3, 1.0, 0.0)));
    return DirectionalLight(d, glm::dvec3(2.0, 1.8, 1.5));
  }
  return which == 0 ? frontLight() : sideLight();
}

} // namespace

TEST_CASE("EpipolarSampling GL: the blocks match their C++ structs") {
  CREP_REQUIRE_GL();
  const gl::Handle program = buildProgram({{ShaderStage::Compute, "passes/epipolar/unwarp.comp", {}}});
  const GLuint p = program.get();
  const auto uniformOffset = [p](const char* name) {
    const GLuint index = glGetProgramResourceIndex(p, GL_UNIFORM, name);
    if (index == GL_INVALID_INDEX) return -1;
    const GLenum property = GL_OFFSET;
    GLint value = -1;
    glGetProgramResourceiv(p, GL_UNIFORM, index, 1, &property, 1, nullptr, &value);
    return value;
  };
  const auto bufferVariable = [p](const char* name, GLenum property) {
    const GLuint index = glGetProgramResourceIndex(p, GL_BUFFER_VARIABLE, name);
    if (index == GL_INVALID_INDEX) return -1;
    GLint value = -1;
    glGetProgramResourceiv(p, GL_BUFFER_VARIABLE, index, 1, &property, 1, nullptr, &value);
    return value;
  };
  using gpu::EpipolarSamplingLine;
  using gpu::EpipolarSamplingParams;
  const GLuint block = glGetProgramResourceIndex(p, GL_UNIFORM_BLOCK, "CrepEpipolarSamplingBlock");
  REQUIRE(block != GL_INVALID_INDEX);
  const GLenum sizeProperty = GL_BUFFER_DATA_SIZE;
  GLint size = -1;
  glGetProgramResourceiv(p, GL_UNIFORM_BLOCK, block, 1, &sizeProperty, 1, nullptr, &size);
  CHECK(size == static_cast<GLint>(sizeof(EpipolarSamplingParams)));
  CHECK(uniformOffset("crep_sampling.epipole") ==
        static_cast<GLint>(offsetof(EpipolarSamplingParams, epipole)));
  CHECK(uniformOffset("crep_sampling.border") ==
        static_cast<GLint>(offsetof(EpipolarSamplingParams, border)));
  CHECK(uniformOffset("crep_sampling.counts") ==
        static_cast<GLint>(offsetof(EpipolarSamplingParams, counts)));
  CHECK(uniformOffset("crep_sampling.target") ==
        static_cast<GLint>(offsetof(EpipolarSamplingParams, target)));
  CHECK(uniformOffset("crep_sampling.thresholds") ==
        static_cast<GLint>(offsetof(EpipolarSamplingParams, thresholds)));
  CHECK(bufferVariable("crep_lines[0].ends", GL_OFFSET) ==
        static_cast<GLint>(offsetof(EpipolarSamplingLine, ends)));
  CHECK(bufferVariable("crep_lines[0].info", GL_OFFSET) ==
        static_cast<GLint>(offsetof(EpipolarSamplingLine, info)));
  CHECK(bufferVariable("crep_lines[0].ends", GL_TOP_LEVEL_ARRAY_STRIDE) ==
        static_cast<GLint>(sizeof(EpipolarSamplingLine)));
}

TEST_CASE("EpipolarSampling GL: coordinates and refinement equal the CPU stages") {
  CREP_REQUIRE_GL();
  for (int which = 0; which < kLights; ++which) {
    const std::string name = lightName(which);
    CAPTURE(name);
    Scene scene(lightOf(which));
    const EpipolarSamplingOptions options = smallOptions();
    EpipolarSamplingPass pass({kWidth, kHeight, options});
    pass.placeSamples(scene.frame());
    CHECK(pass.lines().epipoleOnScreen == (which == 0));
    if (which == 2)
      CHECK(glm::length(pass.lines().epipole - glm::dvec2(kWidth, kHeight) / 2.0) == doctest::Approx(1e5));
    const int Ns = options.samples, N = options.slices;

    // Stage 2: coordinates and U against epipolarSamples (double).
    const EpipolarSamples gpu = readSamples(pass);
    const EpipolarSamples cpu =
        epipolarSamples(pass.lines(), scene.depth, scene.camera, scene.light, scene.medium);
    int validityMismatch = 0, valid = 0, pixelDiffers = 0, depthMismatch = 0;
    double maxXy = 0.0, maxZ = 0.0, maxU = 0.0;
    for (int i = 0; i < N; ++i)
      for (int k = 0; k < Ns; ++k) {
        const bool gv = gpu.coordinates.at(k, i, 0) >= 0.0f, cv = cpu.coordinates.at(k, i, 0) >= 0.0f;
        if (gv != cv) ++validityMismatch;
        if (!gv || !cv) {
          if (!gv) CHECK(gpu.unshadowed.at(k, i) == 0.0f);
          continue;
        }
        ++valid;
        const double gx = gpu.coordinates.at(k, i, 0), gy = gpu.coordinates.at(k, i, 1);
        const double cx = cpu.coordinates.at(k, i, 0), cy = cpu.coordinates.at(k, i, 1);
        maxXy = std::max({maxXy, std::abs(gx - cx), std::abs(gy - cy)});
        if (pixelOf(gx, kWidth) != pixelOf(cx, kWidth) || pixelOf(gy, kHeight) != pixelOf(cy, kHeight)) {
          ++pixelDiffers;
          continue;
        }
        if (gpu.coordinates.at(k, i, 2) != cpu.coordinates.at(k, i, 2)) ++depthMismatch;
        const double cz = cpu.coordinates.at(k, i, 3);
        maxZ = std::max(maxZ, std::abs(gpu.coordinates.at(k, i, 3) - cz) / cz);
        const double cu = cpu.unshadowed.at(k, i);
        maxU = std::max(maxU, std::abs(gpu.unshadowed.at(k, i) - cu) / std::max(cu, 1e-30));
      }
    MESSAGE(std::string(std::string(lightName(which)) + ": " + std::to_string(valid) +
                        " valid samples, validity mismatches " + std::to_string(validityMismatch) +
                        ", max |xy| diff " + sci(maxXy) + " px, other containing pixel " +
                        std::to_string(pixelDiffers) + ", max z rel " + sci(maxZ) + ", max U rel " +
                        sci(maxU)));
    CHECK(valid > 0);
    CHECK(validityMismatch == 0);
    CHECK(maxXy <= 1e-3);
    CHECK(pixelDiffers <= valid / 1000 + 2);
    CHECK(depthMismatch == 0);
    CHECK(maxZ <= 1e-5);
    CHECK(maxU <= 1e-5);

    // Stage 3: sources and the marched list against refineSamples on the GPU's own coordinates.
    pass.refine();
    const std::vector<glm::ivec2> sources = readSources(pass.sourcesTexture(), Ns, N);
    const std::vector<glm::ivec2> expected = refineSamples(gpu, pass.lines(), options);
    REQUIRE(sources.size() == expected.size());
    int sourceMismatch = 0;
    std::vector<std::pair<int, int>> marched;
    for (std::size_t j = 0; j < expected.size(); ++j) {
      if (sources[j] != expected[j]) ++sourceMismatch;
      const int k = static_cast<int>(j) % Ns, i = static_cast<int>(j) / Ns;
      if (expected[j] == glm::ivec2(k, k)) marched.emplace_back(k, i);
    }
    std::sort(marched.begin(), marched.end());
    const std::vector<std::pair<int, int>> entries = listEntries(pass.sampleList());
    MESSAGE(std::string(std::string(lightName(which)) + ": sources differing " +
                        std::to_string(sourceMismatch) + " of " + std::to_string(expected.size()) +
                        ", marched GPU " + std::to_string(entries.size()) + " CPU " +
                        std::to_string(marched.size())));
    CHECK(sourceMismatch == 0);
    CHECK(pass.statistics().marchedSamples == static_cast<int>(marched.size()));
    CHECK(entries == marched);                               // both sorted by (k, i)
    CHECK(marched.size() < static_cast<std::size_t>(valid)); // the refinement skips samples
  }
}

TEST_CASE("EpipolarSampling GL: refinement options") {
  CREP_REQUIRE_GL();
  Scene scene(sideLight());
  struct Variant {
    const char* name;
    int step;
    bool depth, scattering;
    int samples = 64;
  };
  for (const Variant& v : {Variant{"S = 1", 1, true, true}, Variant{"S = Ns", 64, true, true},
                           Variant{"no criteria", 8, false, false}, Variant{"depth only", 16, true, false},
                           Variant{"scattering only", 16, false, true}, Variant{"Ns = 32", 4, true, true, 32},
                           Variant{"Ns = 1024", 32, true, true, 1024}}) {
    CAPTURE(std::string(v.name));
    EpipolarSamplingOptions options = smallOptions();
    options.initialStep = v.step;
    options.samples = v.samples;
    options.depthCriterion = v.depth;
    options.scatteringCriterion = v.scattering;
    EpipolarSamplingPass pass({kWidth, kHeight, options});
    pass.placeSamples(scene.frame());
    pass.refine();
    const int Ns = options.samples, N = options.slices;
    const std::vector<glm::ivec2> sources = readSources(pass.sourcesTexture(), Ns, N);
    CHECK(sources == refineSamples(readSamples(pass), pass.lines(), options));
    // Without criteria exactly the initial samples are marched: k % S == 0 and lastValid.
    int initial = 0;
    for (const EpipolarLines::Line& l : pass.lines().lines)
      if (l.lastValid >= 0) initial += l.lastValid / v.step + 1 + (l.lastValid % v.step != 0 ? 1 : 0);
    const EpipolarSamplingPass::Statistics s = pass.statistics();
    MESSAGE(std::string(std::string(v.name) + ": marched " + std::to_string(s.marchedSamples) + " of " +
                        std::to_string(s.validSamples) + " valid, initial " + std::to_string(initial)));
    if (v.step == 1) CHECK(s.marchedSamples == s.validSamples);
    if (!v.depth && !v.scattering) CHECK(s.marchedSamples == initial);
    if ((v.depth || v.scattering) && v.step > 1) CHECK(s.marchedSamples > initial);
  }
}

TEST_CASE("EpipolarSampling GL: interpolation, unwarp and upscale equal the CPU stages") {
  CREP_REQUIRE_GL();
  for (int which = 0; which < kLights; ++which)
    for (int F : {1, 2, 4}) {
      const std::string name = lightName(which);
      CAPTURE(name);
      CAPTURE(F);
      Scene scene(lightOf(which));
      const EpipolarSamplingOptions options = smallOptions(F);
      EpipolarSamplingPass pass({kWidth, kHeight, options});
      const EpipolarSamplingPass::FrameAttribs frame = scene.frame();
      const int Ns = options.samples, N = options.slices, w = kWidth / F, h = kHeight / F;
      fillNaN(scene.output.get());
      pass.placeSamples(frame);
      pass.refine();
      evaluateGpu(pass.sampleList());
      const EpipolarSamples samples = readSamples(pass);
      const std::vector<glm::ivec2> sources = readSources(pass.sourcesTexture(), Ns, N);
      const Image marched = readRgba(pass.sampleTexture(), Ns, N);

      // Stage 4.
      pass.interpolate();
      const Image interpolated = readRgba(pass.sampleTexture(), Ns, N);
      const Image expectedInterpolation = interpolateSamples(sources, marched);
      double maxRel = 0.0;
      for (int i = 0; i < N; ++i)
        for (int k = 0; k < Ns; ++k)
          for (int c = 0; c < 4; ++c) {
            const double e = expectedInterpolation.at(k, i, c);
            maxRel = std::max(maxRel, std::abs(interpolated.at(k, i, c) - e) / std::max(std::abs(e), 1e-6));
          }
      // The marched samples hold the evaluator's value of their own coordinates.
      const std::vector<std::pair<int, int>> marchedEntries = listEntries(pass.sampleList());
      double maxEval = 0.0;
      for (const auto& [k, i] : marchedEntries) {
        const glm::dvec4 v = evaluateCpu(scene.camera, samples.coordinates.at(k, i, 0),
                                         samples.coordinates.at(k, i, 1), samples.coordinates.at(k, i, 2));
        for (int c = 0; c < 4; ++c)
          maxEval = std::max(maxEval, std::abs(marched.at(k, i, c) - v[c]) / std::max(std::abs(v[c]), 1e-6));
      }

      // Stage 5.
      pass.unwarp(frame);
      const std::uint32_t targetTexture = F == 1 ? scene.output.get() : pass.targetTexture();
      CHECK(pass.correctionList().output == targetTexture);
      const Image target = readRgba(targetTexture, w, h);
      const Image targetCoordinates = readRgba(pass.targetCoordinatesTexture(), w, h);
      const std::vector<int> corrections = pixelIndices(listEntries(pass.correctionList()), w);
      const UnwarpResult expected =
          unwarpSamples(pass.lines(), samples, interpolated, scene.depth, scene.camera, options);
      const ImageDiff unwarpDiff = compareImages(target, expected.image, expected.corrections, 1e-4);
      std::vector<int> symmetric;
      std::set_symmetric_difference(corrections.begin(), corrections.end(), expected.corrections.begin(),
                                    expected.corrections.end(), std::back_inserter(symmetric));
      double maxCoord = 0.0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          for (int c = 0; c < 4; ++c) {
            const double e = expected.coordinates.at(x, y, c);
            maxCoord =
                std::max(maxCoord, std::abs(targetCoordinates.at(x, y, c) - e) / std::max(std::abs(e), 1.0));
          }
      MESSAGE(std::string(
          std::string(lightName(which)) + ", F = " + std::to_string(F) + ": interpolation max rel " +
          sci(maxRel) + " (evaluator " + sci(maxEval) + "); unwarp max abs " + sci(unwarpDiff.maxAbs) +
          ", pixels beyond 1e-4: " + std::to_string(unwarpDiff.beyond) + ", corrections GPU " +
          std::to_string(corrections.size()) + " CPU " + std::to_string(expected.corrections.size()) +
          " (differing " + std::to_string(symmetric.size()) + "), target coordinates max rel " +
          sci(maxCoord)));
      CHECK(maxRel <= 1e-6);
      CHECK(maxEval <= 1e-6);
      CHECK(unwarpDiff.beyond == 0);
      CHECK(unwarpDiff.maxAbs <= 1e-4);
      CHECK(symmetric.empty());
      CHECK(maxCoord <= 1e-6);

      // The corrections, then stage 6.
      evaluateGpu(pass.correctionList());
      const Image corrected = readRgba(targetTexture, w, h);
      for (int p : corrections) {
        const glm::dvec4 v =
            evaluateCpu(scene.camera, targetCoordinates.at(p % w, p / w, 0),
                        targetCoordinates.at(p % w, p / w, 1), targetCoordinates.at(p % w, p / w, 2));
        CHECK(corrected.at(p % w, p / w, 0) == doctest::Approx(v.x).epsilon(1e-6));
      }
      pass.upscale(frame);
      if (F == 1) {
        CHECK(pass.statistics().correctedFullPixels == 0);
        continue;
      }
      const UnwarpResult complete{corrected, targetCoordinates, corrections};
      const UnwarpResult expectedFull = upscaleSamples(complete, scene.depth, scene.camera, options);
      const Image full = readRgba(scene.output.get(), kWidth, kHeight);
      const std::vector<std::pair<int, int>> fullEntries = listEntries(pass.upscaleCorrectionList());
      const std::vector<int> fullCorrections = pixelIndices(fullEntries, kWidth);
      const ImageDiff upscaleDiff = compareImages(full, expectedFull.image, expectedFull.corrections, 1e-4);
      std::vector<int> fullSymmetric;
      std::set_symmetric_difference(fullCorrections.begin(), fullCorrections.end(),
                                    expectedFull.corrections.begin(), expectedFull.corrections.end(),
                                    std::back_inserter(fullSymmetric));
      // The full-resolution coordinates of the pixels to correct: centre, own depth.
      const Image fullCoordinates = readRgba(pass.fullCoordinatesTexture(), kWidth, kHeight);
      int fullCoordinateMismatch = 0;
      for (const auto& [x, y] : fullEntries)
        if (fullCoordinates.at(x, y, 0) != x + 0.5f || fullCoordinates.at(x, y, 1) != y + 0.5f ||
            fullCoordinates.at(x, y, 2) != scene.depth.at(x, y))
          ++fullCoordinateMismatch;
      MESSAGE(std::string(std::string(lightName(which)) + ", F = " + std::to_string(F) +
                          ": upscale max abs " + sci(upscaleDiff.maxAbs) +
                          ", pixels beyond 1e-4: " + std::to_string(upscaleDiff.beyond) +
                          ", full corrections GPU " + std::to_string(fullCorrections.size()) + " CPU " +
                          std::to_string(expectedFull.corrections.size()) + " (differing " +
                          std::to_string(fullSymmetric.size()) + ")"));
      CHECK(upscaleDiff.beyond == 0);
      CHECK(upscaleDiff.maxAbs <= 1e-4);
      CHECK(fullSymmetric.empty());
      CHECK(fullCoordinateMismatch == 0);
    }
}

TEST_CASE("EpipolarSampling GL: run leaves no pixel unwritten and counts like the CPU pipeline") {
  CREP_REQUIRE_GL();
  for (int F : {1, 2, 4}) {
    const EpipolarSamplingOptions options = smallOptions(F);
    EpipolarSamplingPass pass({kWidth, kHeight, options}); // one pass for the frames of every light
    for (int which = 0; which < kLights; ++which) {
      const std::string name = lightName(which);
      CAPTURE(name);
      CAPTURE(F);
      Scene scene(lightOf(which), GL_DEPTH_COMPONENT32F);
      fillNaN(scene.output.get());
      int calls = 0;
      pass.run(scene.frame(), [&](const gpu::SampleList& list) {
        ++calls;
        evaluateGpu(list);
      });
      CHECK(calls == (F == 1 ? 2 : 3));
      GLint program = -1, image = -1, storage = -1;
      glGetIntegerv(GL_CURRENT_PROGRAM, &program);
      glGetIntegeri_v(GL_IMAGE_BINDING_NAME, 2, &image);
      glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, 2, &storage);
      CHECK(program == 0);
      CHECK(image == 0);
      CHECK(storage == 0);
      const Image out = readRgba(scene.output.get(), kWidth, kHeight);
      int nonFinite = 0;
      for (float v : out.data())
        if (!std::isfinite(v)) ++nonFinite;
      const EpipolarSamplingPass::Statistics s = pass.statistics();
      const Camera& camera = scene.camera;
      const EpipolarSamplingResult cpu =
          epipolarSampling(scene.camera, scene.light, scene.medium, scene.depth, options,
                           [&camera](double x, double y, double d) { return evaluateCpu(camera, x, y, d); });
      const ImageDiff diff = compareImages(out, cpu.image, {}, 1e-3);
      MESSAGE(std::string(std::string(lightName(which)) + ", F = " + std::to_string(F) + ": non-finite " +
                          std::to_string(nonFinite) + "; GPU valid / marched / corrected / full " +
                          std::to_string(s.validSamples) + " / " + std::to_string(s.marchedSamples) + " / " +
                          std::to_string(s.correctedPixels) + " / " + std::to_string(s.correctedFullPixels) +
                          ", CPU " + std::to_string(cpu.validSamples) + " / " +
                          std::to_string(cpu.marchedSamples) + " / " + std::to_string(cpu.correctedPixels) +
                          " / " + std::to_string(cpu.correctedFullPixels) +
                          "; image vs CPU pipeline max abs " + sci(diff.maxAbs) + ", pixels beyond 1e-3 " +
                          std::to_string(diff.beyond)));
      CHECK(nonFinite == 0);
      CHECK(s.validSamples == cpu.validSamples);
      // The CPU pipeline places and refines its samples in double: a sample next to a threshold may
      // refine differently; the counts agree to 1 %.
      CHECK(std::abs(s.marchedSamples - cpu.marchedSamples) <= cpu.marchedSamples / 100 + 1);
      CHECK(std::abs(s.correctedPixels - cpu.correctedPixels) <= cpu.correctedPixels / 100 + 1);
      CHECK(std::abs(s.correctedFullPixels - cpu.correctedFullPixels) <= cpu.correctedFullPixels / 100 + 1);
      CHECK(diff.beyond <= kWidth * kHeight / 200);
    }
  }
}

TEST_CASE("EpipolarSampling GL: validation names the field") {
  CREP_REQUIRE_GL();
  EpipolarSamplingOptions o = smallOptions();
  CHECK(invalidParameter([&] {
          EpipolarSamplingPass({0, kHeight, o});
        }) == "EpipolarSamplingPass::CreateInfo.width");
  o.samples = 48;
  CHECK(invalidParameter([&] {
          EpipolarSamplingPass({kWidth, kHeight, o});
        }) == "EpipolarSamplingPass::CreateInfo.options.samples");
  o = smallOptions(4);
  CHECK(invalidParameter([&] {
          EpipolarSamplingPass({kWidth, 90, o});
        }) == "EpipolarSamplingPass::CreateInfo.height");
  CHECK(invalidParameter([&] {
          EpipolarSamplingPass({162, 88, o});
        }) == "EpipolarSamplingPass::CreateInfo.width");
  for (const double offset : {-0.1, 0.75}) {
    CAPTURE(offset);
    CHECK(invalidParameter([&] {
            EpipolarSamplingPass({kWidth, kHeight, smallOptions(), nullptr, offset});
          }) == "EpipolarSamplingPass::CreateInfo.lineOffset");
  }

  Scene scene(sideLight());
  EpipolarSamplingPass pass({kWidth, kHeight, smallOptions()});
  EpipolarSamplingPass::FrameAttribs f = scene.frame();
  f.camera = nullptr;
  CHECK(invalidParameter([&] { pass.placeSamples(f); }) == "EpipolarSamplingPass::FrameAttribs.camera");
  f = scene.frame();
  f.light = nullptr;
  CHECK(invalidParameter([&] { pass.placeSamples(f); }) == "EpipolarSamplingPass::FrameAttribs.light");
  f = scene.frame();
  f.medium = nullptr;
  CHECK(invalidParameter([&] { pass.unwarp(f); }) == "EpipolarSamplingPass::FrameAttribs.medium");
  f = scene.frame();
  f.cameraDepth = 0;
  CHECK(invalidParameter([&] { pass.placeSamples(f); }) == "EpipolarSamplingPass::FrameAttribs.cameraDepth");
  const gl::Handle small = gl::createTexture2D(GL_RGBA32F, 80, 45);
  const gl::Handle rgba8 = gl::createTexture2D(GL_RGBA8, kWidth, kHeight);
  f = scene.frame();
  f.cameraDepth = small.get();
  CHECK(invalidParameter([&] { pass.placeSamples(f); }) == "EpipolarSamplingPass::FrameAttribs.cameraDepth");
  f = scene.frame();
  f.cameraDepth = rgba8.get();
  CHECK(invalidParameter([&] { pass.placeSamples(f); }) == "EpipolarSamplingPass::FrameAttribs.cameraDepth");
  f = scene.frame();
  f.output = rgba8.get();
  CHECK(invalidParameter([&] { pass.placeSamples(f); }) == "EpipolarSamplingPass::FrameAttribs.output");
  f.output = small.get();
  CHECK(invalidParameter([&] { pass.unwarp(f); }) == "EpipolarSamplingPass::FrameAttribs.output");
  f = scene.frame();
  CHECK(invalidParameter([&] { pass.run(f, {}); }) == "EpipolarSamplingPass::run.evaluate");
  CHECK(pass.memoryBytes() > static_cast<std::size_t>(64 * 128 * 44));
  gl::checkError("validation");
}
