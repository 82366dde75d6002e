// `crep render`: the main job. Renders a built-in scene (standard shadow pass and lit camera pass),
// computes single scattering with the chosen method and writes the scattering and composited images
// to EXR plus a tone-mapped PNG, with a table of per-stage timings.
#include "args.h"
#include "commands.h"
#include "timings.h"

#include <crep/core/error.h>
#include <crep/core/exr.h>
#include <crep/core/gl.h>
#include <crep/core/gl_context.h>
#include <crep/core/png.h>
#include <crep/core/shader_library.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <epoxy/gl.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

namespace crep::tool {

namespace {

gl::Handle createColorTexture(int width, int height, GLenum format) {
  return gl::createTexture2D(format, width, height, "--size");
}

Image readRgba(GLuint texture, int width, int height) {
  return gl::readTexture(texture, width, height, gl::TexelData::Rgba);
}

void setVec3(GLuint program, GLint location, const glm::dvec3& v) {
  glProgramUniform3f(program, location, static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z));
}

void setMat4(GLuint program, GLint location, const glm::dmat4& m) {
  const glm::mat4 f(m);
  glProgramUniformMatrix4fv(program, location, 1, GL_FALSE, &f[0][0]);
}

void dispatch2D(int width, int height) {
  glDispatchCompute(static_cast<GLuint>((width + 7) / 8), static_cast<GLuint>((height + 7) / 8), 1);
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
}

StorageFormat parseFormat(const std::string& text) {
  if (text == "rgba8") return StorageFormat::RGBA8;
  if (text == "rgba16f") return StorageFormat::RGBA16F;
  if (text == "rgba32f") return StorageFormat::RGBA32F;
  throw UsageError("option --format: '" + text + "' is not rgba8, rgba16f or rgba32f");
}

} // namespace

int renderCommand(const std::vector<std::string>& argv) {
  const Args args(argv,
                  {"scene", "size", "map-size", "steps", "exposure", "out", "method", "bases", "format", "splits"},
                  {"debug-gl"});
  const std::string sceneName = args.string("scene", "colonnade");
  const glm::ivec2 size = args.size("size", {1280, 720}, Image::kMaxDimension);
  const int mapSize = args.integer("map-size", 1024, 1, Image::kMaxDimension);
  const int steps = args.integer("steps", 256, 1, 65536);
  const double exposure = args.number("exposure", 1.0);
  if (!(exposure > 0.0)) throw UsageError("option --exposure: must be > 0");
  const std::string method = args.string("method", "prefilter");
  if (method != "prefilter" && method != "reference")
    throw UsageError("option --method: '" + method + "' is not prefilter or reference");
  const int bases = args.integer("bases", kDefaultBases, kMinBases, kMaxBases);
  if (bases % 4 != 0) throw UsageError("option --bases: must be a multiple of 4");
  const StorageFormat format = parseFormat(args.string("format", "rgba8"));
  RectifyOptions rectifyOptions;
  rectifyOptions.splits = args.integer("splits", rectifyOptions.splits, 1, RectifyOptions::kMaxSplits);
  if (mapSize % rectifyOptions.splits != 0)
    throw UsageError("option --map-size: " + std::to_string(mapSize) + " must be a multiple of --splits " +
                     std::to_string(rectifyOptions.splits));
  const std::string out = args.string("out", "crep-" + sceneName);
  if (out.empty()) throw UsageError("option --out: must not be empty");

  StageTimings timings;
  GlContextOptions contextOptions;
  contextOptions.debug = args.has("debug-gl");
  bool glFailed = false;
  std::string glMessage;
  if (contextOptions.debug)
    contextOptions.debugCallback = [&](const GlDebugMessage& m) {
      if (m.isError() && !glFailed) {
        glFailed = true;
        glMessage = m.text;
      }
    };
  // The context lives for the whole process, like an application's: destroying the last context
  // unloads Mesa's driver, after which LeakSanitizer cannot attribute the driver's own allocations.
  static GlContext* context = nullptr; // reachable until exit, never destroyed
  context = timings.time("gl context", [&] { return new GlContext(contextOptions); });
  std::fprintf(stderr, "crep render: %s, %s\n", context->renderer().c_str(), context->version().c_str());

  const scenes::Scene scene =
      timings.time("scene build", [&] { return scenes::makeScene(sceneName, double(size.x) / double(size.y)); });
  gl::checkTextureSize("--map-size", mapSize, mapSize);
  gl::checkTextureSize("--size", size.x, size.y);

  // The method actually used: the projective prefilter needs a projective rectification (the
  // epipolar fallback is not implemented yet; until then a non-projective frame uses the reference).
  const Rectification rect = timings.time("rectify", [&] { return rectify(scene.camera, scene.sun, rectifyOptions); });
  std::string used = method;
  if (method == "prefilter" && !rect.projective()) {
    std::fprintf(stderr, "crep render: rectification is %s (%s); using the reference march\n",
                 statusToken(rect.status), rect.message.c_str());
    used = "reference";
  }

  auto renderer = timings.time("scene upload + shaders", [&] {
    auto r = std::make_unique<scenes::SceneRenderer>(scene.mesh);
    glFinish();
    return r;
  });
  gl::Handle compositeProgram = buildProgram({{ShaderStage::Compute, "passes/composite.comp", {}}});

  // Standard shadow map: lit surfaces (and the reference march).
  const glm::dmat4 shadowClipFromWorld = scenes::standardLightClipFromWorld(scene.sun, scene.boundsMin, scene.boundsMax);
  gl::Handle shadowMap = scenes::createDepthTexture(mapSize, mapSize, "--map-size");
  timings.time("shadow pass (standard)", [&] {
    renderer->renderDepth(shadowClipFromWorld, shadowMap.get(), 0, 0, 0, mapSize, mapSize, {.depthClamp = true});
    glFinish();
  });

  gl::Handle color = createColorTexture(size.x, size.y, GL_RGBA32F);
  gl::Handle depth = scenes::createDepthTexture(size.x, size.y, "--size");
  timings.time("camera pass", [&] {
    scenes::SceneRenderer::ShadeInputs in;
    in.clipFromWorld = scene.camera.clipFromWorld();
    in.shadowClipFromWorld = shadowClipFromWorld;
    in.shadowMap = shadowMap.get();
    in.lightDirection = scene.sun.direction();
    in.lightIrradiance = scene.sun.irradiance();
    renderer->renderShaded(in, color.get(), depth.get(), size.x, size.y);
    glFinish();
  });

  gl::Handle scattering = createColorTexture(size.x, size.y, GL_RGBA32F);
  if (used == "prefilter") {
    const auto layout = std::make_shared<ProjectiveLayout>(rect);
    gl::Handle rectified = scenes::createDepthTexture(mapSize, mapSize, "--map-size");
    timings.time("shadow pass (rectified)", [&] {
      renderer->renderRectified(rect, rectified.get(), mapSize, mapSize);
      glFinish();
    });
    PrefilterPass::CreateInfo prefilterInfo;
    prefilterInfo.width = mapSize;
    prefilterInfo.height = mapSize;
    prefilterInfo.bases = bases;
    prefilterInfo.format = format;
    auto prefilterPass = timings.time("prefilter setup", [&] { return std::make_unique<PrefilterPass>(prefilterInfo); });
    EvaluatePass::CreateInfo evaluateInfo;
    evaluateInfo.bases = bases;
    auto evaluatePass = timings.time("evaluate setup", [&] { return std::make_unique<EvaluatePass>(evaluateInfo); });
    timings.time("prefilter", [&] {
      PrefilterPass::Frame frame;
      frame.rectifiedDepth = rectified.get();
      frame.layout = layout.get();
      frame.medium = &scene.medium;
      prefilterPass->run(frame);
      glFinish();
    });
    timings.time("evaluate", [&] {
      EvaluatePass::Frame frame;
      frame.cameraDepth = depth.get();
      frame.output = scattering.get();
      frame.camera = &scene.camera;
      frame.light = &scene.sun;
      frame.medium = &scene.medium;
      frame.layout = layout.get();
      frame.basis = prefilterPass->filteredBasis();
      evaluatePass->run(frame);
      glFinish();
    });
  } else {
    gl::Handle marchProgram = timings.time("march shader", [&] {
      return buildProgram(
          {{ShaderStage::Compute, "passes/march_world.comp", {{"CREP_MARCH_STEPS", std::to_string(steps)}}}});
    });
    timings.time("reference march", [&] {
      const GLuint p = marchProgram.get();
      glUseProgram(p);
      setMat4(p, 0, glm::inverse(scene.camera.clipFromWorld()));
      setMat4(p, 1, shadowClipFromWorld);
      setVec3(p, 2, scene.camera.position());
      setVec3(p, 3, scene.sun.direction());
      setVec3(p, 4, scene.sun.irradiance());
      setVec3(p, 5, scene.medium.mieScattering());
      setVec3(p, 6, scene.medium.rayleighScattering());
      setVec3(p, 7, scene.medium.extinction());
      glProgramUniform1f(p, 8, static_cast<float>(scene.medium.hgG()));
      glProgramUniform2i(p, 9, size.x, size.y);
      glProgramUniform1f(p, 10, 2e-4f);
      glBindTextureUnit(0, depth.get());
      glBindTextureUnit(1, shadowMap.get());
      glBindImageTexture(0, scattering.get(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
      dispatch2D(size.x, size.y);
      glUseProgram(0);
      glBindTextureUnit(0, 0);
      glBindTextureUnit(1, 0);
      glFinish();
      gl::checkError("reference march");
    });
  }

  gl::Handle composite = createColorTexture(size.x, size.y, GL_RGBA32F);
  timings.time("composite", [&] {
    const GLuint p = compositeProgram.get();
    glUseProgram(p);
    setMat4(p, 0, glm::inverse(scene.camera.clipFromWorld()));
    setVec3(p, 1, scene.camera.position());
    setVec3(p, 2, scene.medium.extinction());
    glProgramUniform2i(p, 3, size.x, size.y);
    glBindTextureUnit(0, depth.get());
    glBindTextureUnit(1, color.get());
    glBindTextureUnit(2, scattering.get());
    glBindImageTexture(0, composite.get(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    dispatch2D(size.x, size.y);
    glUseProgram(0);
    for (GLuint unit = 0; unit < 3; ++unit) glBindTextureUnit(unit, 0);
    glFinish();
    gl::checkError("composite");
  });

  Image scatteringImage, compositeImage;
  timings.time("readback", [&] {
    scatteringImage = readRgba(scattering.get(), size.x, size.y);
    compositeImage = readRgba(composite.get(), size.x, size.y);
  });
  if (glFailed) throw GlError("GL error during rendering: " + glMessage);

  // Refuse to write a silently wrong image.
  long long nonFinite = 0;
  for (float v : compositeImage.data()) nonFinite += std::isfinite(v) ? 0 : 1;
  for (float v : scatteringImage.data()) nonFinite += std::isfinite(v) ? 0 : 1;
  if (nonFinite > 0) throw Error("render produced " + std::to_string(nonFinite) + " non-finite samples");

  const std::string exrPath = out + ".exr", pngPath = out + ".png";
  timings.time("write exr", [&] {
    const ExrLayer layers[] = {{"composite", &compositeImage}, {"scattering", &scatteringImage}};
    writeExrLayers(exrPath, layers);
  });
  timings.time("write png", [&] { writePng(pngPath, compositeImage, ToneMap{static_cast<float>(exposure)}); });

  std::printf("crep render: scene %s, %dx%d, method %s, map %d^2", scene.name.c_str(), size.x, size.y, used.c_str(),
              mapSize);
  if (used == "prefilter")
    std::printf(", M = %d, %d splits\n", bases, rect.splitCount());
  else
    std::printf(", %d march steps\n", steps);
  timings.print(stdout);
  std::printf("wrote %s (layers composite.RGBA, scattering.RGBA) and %s\n", exrPath.c_str(), pngPath.c_str());
  return 0;
}

} // namespace crep::tool
