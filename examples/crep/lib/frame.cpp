#include "frame.h"

#include "args.h"
#include "epipolar_methods.h"
#include "resample.h"

#include <crep/core/error.h>
#include <crep/core/shader_library.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>
#include <crep/support/gl_context.h>

#include <epoxy/gl.h>

#include <cmath>
#include <cstdio>

namespace crep::tool {

namespace {

void setVec3(GLuint program, GLint location, const glm::dvec3& v) {
  glProgramUniform3f(program, location, static_cast<float>(v.x), static_cast<float>(v.y),
                     static_cast<float>(v.z));
}

void setMat4(GLuint program, GLint location, const glm::dmat4& m) {
  const glm::mat4 f(m);
  glProgramUniformMatrix4fv(program, location, 1, GL_FALSE, &f[0][0]);
}

void dispatch2D(int width, int height) {
  glDispatchCompute(static_cast<GLuint>((width + 7) / 8), static_cast<GLuint>((height + 7) / 8), 1);
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT |
                  GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
}

gl::Handle newScatteringTexture(const Frame& frame) {
  return gl::createTexture2D(GL_RGBA32F, frame.width, frame.height, "--size");
}

// --- methods ----------------------------------------------------------------------------------------

/// The world-space reference: every pixel's view ray marched against the standard shadow map
/// (glsl/passes/march_world.comp), independent of any rectification.
MethodOutput runReference(Frame& frame, const MethodSettings& settings) {
  MethodOutput out;
  out.used = "reference";
  out.detail = std::to_string(settings.steps) + " march steps, standard map " +
               std::to_string(frame.shadowWidth) + "x" + std::to_string(frame.shadowHeight);
  gl::Handle program = out.timings.time("march shader", [&] {
    return buildProgram({{ShaderStage::Compute,
                          "passes/march_world.comp",
                          {{"CREP_MARCH_STEPS", std::to_string(settings.steps)}}}});
  });
  out.scattering = newScatteringTexture(frame);
  out.timings.time("reference march", [&] {
    const GLuint p = program.get();
    glUseProgram(p);
    setMat4(p, 0, glm::inverse(frame.camera.clipFromWorld()));
    setMat4(p, 1, frame.lightClipFromWorld);
    setVec3(p, 2, frame.camera.position());
    setVec3(p, 3, frame.light.direction());
    setVec3(p, 4, frame.light.irradiance());
    setVec3(p, 5, frame.medium.mieScattering());
    setVec3(p, 6, frame.medium.rayleighScattering());
    setVec3(p, 7, frame.medium.extinction());
    glProgramUniform1f(p, 8, static_cast<float>(frame.medium.hgG()));
    glProgramUniform2i(p, 9, frame.width, frame.height);
    glProgramUniform1f(p, 10, static_cast<float>(frame.shadowBias));
    glBindTextureUnit(0, frame.cameraDepth.get());
    glBindTextureUnit(1, frame.shadowMap.get());
    glBindImageTexture(0, out.scattering.get(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    dispatch2D(frame.width, frame.height);
    glUseProgram(0);
    glBindTextureUnit(0, 0);
    glBindTextureUnit(1, 0);
    glFinish();
    gl::checkError("reference march");
  });
  return out;
}

/// The rectified map of a projective frame, or the fallback announced on stderr (nullptr).
const RectifiedGpuMap* rectifiedOrFallback(Frame& frame, const MethodSettings& settings,
                                           StageTimings& timings, const char* method) {
  Rectification rect;
  const RectifiedGpuMap* map = frame.rectified(settings, timings, &rect);
  if (!map && !epipolarAvailable())
    std::fprintf(stderr, "crep: %s: rectification is %s (%s); using the reference march\n", method,
                 statusToken(rect.status), rect.message.c_str());
  return map;
}

/// Klehm et al.: GPU prefilter of the rectified map (Fourier basis, transmittance-weighted prefix
/// filter per row) and the constant-time evaluation per pixel.
MethodOutput runPrefilter(Frame& frame, const MethodSettings& settings) {
  StageTimings timings;
  const RectifiedGpuMap* map = rectifiedOrFallback(frame, settings, timings, "prefilter");
  if (!map) {
    // The epipolar resampling fallback (epipolar_methods.cpp) when the epipolar module is built.
    if (std::optional<MethodOutput> fallback = prefilterFallback(frame, settings, Rectification{})) {
      timings.append(fallback->timings.rows());
      fallback->timings = timings;
      return std::move(*fallback);
    }
    MethodOutput out = runReference(frame, settings);
    timings.append(out.timings.rows());
    out.timings = timings;
    return out;
  }
  MethodOutput out;
  out.used = "prefilter";
  out.detail = "M = " + std::to_string(settings.bases) + ", " + storageFormatToken(settings.format) + ", " +
               std::to_string(map->rect.splitCount()) + " splits, map " + std::to_string(map->size) + "^2 " +
               map->source;
  out.timings = timings;
  PrefilterPass::CreateInfo prefilterInfo;
  prefilterInfo.width = map->size;
  prefilterInfo.height = map->size;
  prefilterInfo.bases = settings.bases;
  prefilterInfo.format = settings.format;
  auto prefilter =
      out.timings.time("prefilter setup", [&] { return std::make_unique<PrefilterPass>(prefilterInfo); });
  EvaluatePass::CreateInfo evaluateInfo;
  evaluateInfo.bases = settings.bases;
  auto evaluate =
      out.timings.time("evaluate setup", [&] { return std::make_unique<EvaluatePass>(evaluateInfo); });
  out.timings.time("prefilter", [&] {
    PrefilterPass::Frame f;
    f.rectifiedDepth = map->texture.get();
    f.layout = map->layout.get();
    f.medium = &frame.medium;
    prefilter->run(f);
    glFinish();
  });
  out.scattering = newScatteringTexture(frame);
  out.timings.time("evaluate", [&] {
    EvaluatePass::Frame f;
    f.cameraDepth = frame.cameraDepth.get();
    f.output = out.scattering.get();
    f.camera = &frame.camera;
    f.light = &frame.light;
    f.medium = &frame.medium;
    f.layout = map->layout.get();
    f.basis = prefilter->filteredBasis();
    evaluate->run(f);
    glFinish();
  });
  return out;
}

} // namespace

// --- registry ---------------------------------------------------------------------------------------

const std::vector<Method>& methodRegistry() {
  static const std::vector<Method> registry = [] {
    std::vector<Method> r = {
        {"reference", "world-space march of every view ray against the standard shadow map", true,
         runReference},
        {"prefilter", "Klehm et al. 2014: prefiltered Fourier basis on the rectified map (GPU)", false,
         runPrefilter},
    };
    appendEpipolarMethods(r); // "minmax", "brute" when epipolar/ is built (epipolar_methods.cpp)
    return r;
  }();
  return registry;
}

std::string methodNames() {
  std::string names;
  for (const Method& m : methodRegistry())
    names += (names.empty() ? "" : " | ") + m.name;
  return names;
}

const Method& findMethod(const std::string& name, const std::string& option) {
  for (const Method& m : methodRegistry())
    if (m.name == name) return m;
  throw UsageError("option " + option + ": '" + name + "' is not a method (" + methodNames() + ")");
}

MethodOutput runMethod(const std::string& name, Frame& frame, const MethodSettings& settings) {
  return findMethod(name).run(frame, settings);
}

// --- frame ------------------------------------------------------------------------------------------

const RectifiedGpuMap* Frame::rectified(const MethodSettings& settings, StageTimings& timings,
                                        Rectification* rectOut) {
  if (rect_ && rectifiedSize_ == settings.mapSize && rectifiedSplits_ == settings.rectify.splits) {
    if (rectOut) *rectOut = *rect_;
    if (!rectified_) return nullptr;
    timings.append(rectified_->cost);
    return &*rectified_;
  }
  rectified_.reset();
  StageTimings cost;
  rect_ = cost.time("rectify", [&] { return rectify(camera, light, settings.rectify); });
  rectifiedSize_ = settings.mapSize;
  rectifiedSplits_ = settings.rectify.splits;
  if (rectOut) *rectOut = *rect_;
  if (!rect_->projective()) {
    timings.append(cost.rows());
    return nullptr;
  }
  RectifiedGpuMap map;
  map.rect = *rect_;
  map.layout = std::make_shared<ProjectiveLayout>(*rect_);
  map.size = settings.mapSize;
  if (renderer) {
    map.source = "rasterized";
    map.texture = scenes::createDepthTexture(map.size, map.size, "--map-size");
    cost.time("shadow pass (rectified)", [&] {
      renderer->renderRectified(map.rect, map.texture.get(), map.size, map.size);
      glFinish();
    });
  } else {
    // crep::ShadowResamplePass (crep/epipolar/resample.h) does the same on the GPU; the CPU rule here is
    // kept because it is tested (CrepScatterGLTest) independently of the epipolar module.
    map.source = "resampled from the standard map (CPU)";
    const Image resampled = cost.time("resample (CPU)", [&] {
      return pointResampleShadowMap(*map.layout, map.size, map.size, shadowImage, lightClipFromWorld);
    });
    map.texture = cost.time("upload rectified map", [&] {
      gl::Handle t = uploadR32F(resampled, "--map-size");
      glFinish();
      return t;
    });
  }
  map.cost = cost.rows();
  timings.append(map.cost);
  rectified_ = std::move(map);
  return &*rectified_;
}

// --- GL helpers -------------------------------------------------------------------------------------

namespace {
bool gGlFailed = false;
std::string gGlMessage;
std::string gRenderer;
} // namespace

void ensureGlContext(const std::string& command, bool debug, StageTimings& timings) {
  // The context lives for the whole process, like an application's: destroying the last context
  // unloads Mesa's driver, after which LeakSanitizer cannot attribute the driver's own allocations.
  static GlContext* context = nullptr; // reachable until exit, never destroyed
  if (context) return;
  GlContextOptions options;
  options.debug = debug;
  if (debug)
    options.debugCallback = [](const GlDebugMessage& m) {
      if (m.isError() && !gGlFailed) {
        gGlFailed = true;
        gGlMessage = m.text;
      }
    };
  context = timings.time("gl context", [&] { return new GlContext(options); });
  gRenderer = context->renderer();
  std::fprintf(stderr, "crep %s: %s, %s\n", command.c_str(), context->renderer().c_str(),
               context->version().c_str());
}

std::string glRenderer() {
  return gRenderer;
}

void checkGlErrors(const char* what) {
  if (gGlFailed) {
    gGlFailed = false;
    throw GlError(std::string("GL error during ") + what + ": " + gGlMessage);
  }
}

gl::Handle uploadR32F(const Image& image, const char* parameter) {
  gl::Handle t = gl::createTexture2D(GL_R32F, image.width(), image.height(), parameter);
  std::vector<float> channel0(image.pixelCount());
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      channel0[static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width()) +
               static_cast<std::size_t>(x)] = image.at(x, y, 0);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(t.get(), 0, 0, 0, image.width(), image.height(), GL_RED, GL_FLOAT, channel0.data());
  gl::checkError("upload");
  return t;
}

Image readRgba(std::uint32_t texture, int width, int height) {
  return gl::readTexture(texture, width, height, gl::TexelData::Rgba);
}

gl::Handle compositeImage(const Frame& frame, std::uint32_t surfaceColor, std::uint32_t scattering) {
  static gl::Handle* program = nullptr; // built once per process, lives with the context
  if (!program) program = new gl::Handle(buildProgram({{ShaderStage::Compute, "passes/composite.comp", {}}}));
  gl::Handle out = gl::createTexture2D(GL_RGBA32F, frame.width, frame.height, "--size");
  const GLuint p = program->get();
  glUseProgram(p);
  setMat4(p, 0, glm::inverse(frame.camera.clipFromWorld()));
  setVec3(p, 1, frame.camera.position());
  setVec3(p, 2, frame.medium.extinction());
  glProgramUniform2i(p, 3, frame.width, frame.height);
  glBindTextureUnit(0, frame.cameraDepth.get());
  glBindTextureUnit(1, surfaceColor);
  glBindTextureUnit(2, scattering);
  glBindImageTexture(0, out.get(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  dispatch2D(frame.width, frame.height);
  glUseProgram(0);
  for (GLuint unit = 0; unit < 3; ++unit)
    glBindTextureUnit(unit, 0);
  glFinish();
  gl::checkError("composite");
  return out;
}

void requireFinite(const Image& image, const std::string& what) {
  long long nonFinite = 0;
  for (float v : image.data())
    nonFinite += std::isfinite(v) ? 0 : 1;
  if (nonFinite > 0) throw Error(what + " has " + std::to_string(nonFinite) + " non-finite samples");
}

// --- built-in scenes --------------------------------------------------------------------------------

SceneFrame::SceneFrame() = default;
SceneFrame::~SceneFrame() = default;
SceneFrame::SceneFrame(SceneFrame&&) noexcept = default;
SceneFrame& SceneFrame::operator=(SceneFrame&&) noexcept = default;

SceneFrame makeSceneFrame(const std::string& name, int width, int height, int shadowMapSize,
                          StageTimings& timings) {
  SceneFrame s;
  s.scene = timings.time("scene build", [&] {
    return std::make_unique<scenes::Scene>(scenes::makeScene(name, double(width) / double(height)));
  });
  gl::checkTextureSize("--map-size", shadowMapSize, shadowMapSize);
  gl::checkTextureSize("--size", width, height);
  const scenes::Scene& scene = *s.scene;
  s.renderer = timings.time("scene upload + shaders", [&] {
    auto r = std::make_unique<scenes::SceneRenderer>(scene.mesh);
    glFinish();
    return r;
  });
  s.frame = std::make_unique<Frame>(scene.camera, scene.sun, scene.medium);
  Frame& f = *s.frame;
  f.width = width;
  f.height = height;
  f.renderer = s.renderer.get();
  // Standard shadow map: lit surfaces and the reference march.
  f.lightClipFromWorld = scenes::standardLightClipFromWorld(scene.sun, scene.boundsMin, scene.boundsMax);
  f.shadowWidth = f.shadowHeight = shadowMapSize;
  f.shadowMap = scenes::createDepthTexture(shadowMapSize, shadowMapSize, "--map-size");
  timings.time("shadow pass (standard)", [&] {
    s.renderer->renderDepth(f.lightClipFromWorld, f.shadowMap.get(), 0, 0, 0, shadowMapSize, shadowMapSize,
                            {.depthClamp = true});
    glFinish();
  });
  s.color = gl::createTexture2D(GL_RGBA32F, width, height, "--size");
  f.cameraDepth = scenes::createDepthTexture(width, height, "--size");
  timings.time("camera pass", [&] {
    scenes::SceneRenderer::ShadeInputs in;
    in.clipFromWorld = scene.camera.clipFromWorld();
    in.shadowClipFromWorld = f.lightClipFromWorld;
    in.shadowMap = f.shadowMap.get();
    in.lightDirection = scene.sun.direction();
    in.lightIrradiance = scene.sun.irradiance();
    s.renderer->renderShaded(in, s.color.get(), f.cameraDepth.get(), width, height);
    glFinish();
  });
  return s;
}

} // namespace crep::tool
