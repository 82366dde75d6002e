// An engine-side consumer of the installed runtime library (crep::crepuscular only). Like an engine, it
// owns the GL context (a headless EGL context on Mesa's surfaceless platform, created with libEGL in
// engine_context.cpp) and its GL loader (libepoxy); the library's passes run on that context. It rectifies a
// camera and a sun, fills a rectified depth map and a camera depth buffer with ramps, runs
// crep::PrefilterPass and crep::EvaluatePass and checks the scattering image; then one frame through the
// frame-level API (crep::Scattering) with the engine's own reversed-Z, [0, 1], infinite-far camera matrices
// and its own standard shadow map, its casters drawn through drawCasters by its own depth-only program, and
// its reversed-Z clip control (glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE)) set globally, as such engines
// set it once at start-up; checked against the same frame through a GL-convention camera under GL's default
// clip control (docs/GL_STATE.md: the library sets the clip control of its own depth passes).
//
// Exit status: 0 success, 1 failure, 77 no GL context (the install test treats that as a failure too:
// llvmpipe is expected wherever the tests run).
#include <crep/core/camera.h>
#include <crep/core/error.h>
#include <crep/core/light.h>
#include <crep/core/medium.h>
#include <crep/core/version.h>
#include <crep/gpu/shader_library.h>
#include <crep/pipeline/scattering.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/rectify/rectified_map.h>
#include <crep/rectify/rectify.h>

#include "engine_context.h"

#include <epoxy/gl.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string_view>
#include <utility>
#include <vector>

namespace {

constexpr int kNoGl = 77;

/// A depth texture as an engine's depth pass would leave it, filled from `values` (row 0 at the bottom).
GLuint depthTexture(int width, int height, const std::vector<float>& values) {
  GLuint texture = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &texture);
  glTextureStorage2D(texture, 1, GL_DEPTH_COMPONENT32F, width, height);
  glTextureSubImage2D(texture, 0, 0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, values.data());
  return texture;
}

/// The engine's depth-only caster program and mesh: a roof (two triangles at y = 3 over x in [-4, 0],
/// z in [-2, 6]) that shadows part of the air in front of the wall.
struct Casters {
  GLuint program = 0, vao = 0, buffer = 0;
  int draws = 0;
  Casters() {
    const char* vs = "#version 450 core\nlayout(location = 0) in vec3 position;\n"
                     "layout(location = 0) uniform mat4 clipFromWorld;\n"
                     "void main() { gl_Position = clipFromWorld * vec4(position, 1.0); }\n";
    const char* fs = "#version 450 core\nvoid main() {}\n";
    program = glCreateProgram();
    for (const auto& [type, source] : {std::pair{GL_VERTEX_SHADER, vs}, std::pair{GL_FRAGMENT_SHADER, fs}}) {
      const GLuint shader = glCreateShader(type);
      glShaderSource(shader, 1, &source, nullptr);
      glCompileShader(shader);
      glAttachShader(program, shader);
      glDeleteShader(shader);
    }
    glLinkProgram(program);
    const float roof[] = {-4, 3, -2, 0, 3, -2, 0, 3, 6, -4, 3, -2, 0, 3, 6, -4, 3, 6};
    glCreateBuffers(1, &buffer);
    glNamedBufferStorage(buffer, sizeof roof, roof, 0);
    glCreateVertexArrays(1, &vao);
    glVertexArrayVertexBuffer(vao, 0, buffer, 0, 3 * sizeof(float));
    glEnableVertexArrayAttrib(vao, 0);
    glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, 0, 0);
  }
  ~Casters() {
    glDeleteVertexArrays(1, &vao);
    glDeleteBuffers(1, &buffer);
    glDeleteProgram(program);
  }
  void draw(const glm::dmat4& clipFromWorld) {
    const glm::mat4 m(clipFromWorld);
    glUseProgram(program);
    glProgramUniformMatrix4fv(program, 0, 1, GL_FALSE, &m[0][0]);
    glBindVertexArray(vao);
    glDrawArrays(GL_TRIANGLES, 0, 6);
    glBindVertexArray(0);
    glUseProgram(0);
    ++draws;
  }
};

int checks() {
  // The installed version header agrees with the package version find_package reported.
  if (std::string_view(CREP_VERSION_STRING) != CREP_PACKAGE_VERSION ||
      crep::kVersion != CREP_VERSION_MAJOR * 10000 + CREP_VERSION_MINOR * 100 + CREP_VERSION_PATCH) {
    std::fprintf(stderr, "consumer: crep/core/version.h says %s, the package %s\n", CREP_VERSION_STRING,
                 CREP_PACKAGE_VERSION);
    return 1;
  }
  // Only the library's shaders are shipped: no tool, scene or test shader.
  for (const crep::ShaderLibrary::File& f : crep::ShaderLibrary::files()) {
    const std::string_view p = f.path;
    if (!p.starts_with("crep/") && !p.starts_with("passes/")) {
      std::fprintf(stderr, "consumer: unexpected embedded shader %.*s\n", int(p.size()), p.data());
      return 1;
    }
    for (const std::string_view tool :
         {"passes/fullscreen", "passes/scene", "passes/composite", "passes/march_world", "passes/test_fill"})
      if (p.starts_with(tool)) {
        std::fprintf(stderr, "consumer: tool or test shader %.*s in the runtime library\n", int(p.size()),
                     p.data());
        return 1;
      }
  }
  if (!std::filesystem::is_regular_file(std::filesystem::path(CREP_GLSL_DIR) / "crep" / "scattering.glsl")) {
    std::fprintf(stderr, "consumer: no crep/scattering.glsl in %s\n", CREP_GLSL_DIR);
    return 1;
  }
  try {
    crep::Camera::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 1.0, 1.0, 1.0, 0.5);
    std::fprintf(stderr, "consumer: near >= far must throw\n");
    return 1;
  } catch (const crep::InvalidArgument& e) {
    std::printf("expected error: %s\n", e.what());
  }
  return 0;
}

/// An RGBA32F texture the size of the camera image.
GLuint outputTexture(int width, int height) {
  GLuint texture = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &texture);
  glTextureStorage2D(texture, 1, GL_RGBA32F, width, height);
  return texture;
}

/// One frame through crep::Scattering, as an engine with reversed-Z and its own shadow map runs it: the
/// camera from the engine's matrices, its depth buffer in its convention (near / Z, sky 0), its standard
/// shadow map. The same frame through `camera` (OpenGL conventions, standard depth) must agree.
int engineFrame(const crep::Camera& camera, const crep::DirectionalLight& sun, const crep::Medium& medium,
                int width, int height) {
  // The engine's projection: reversed-Z, [0, 1] clip depth (glClipControl), infinite far plane.
  glm::dmat4 clipFromView(0.0);
  const double ty = std::tan(0.5 * camera.fovY());
  clipFromView[0][0] = 1.0 / (ty * camera.aspect());
  clipFromView[1][1] = 1.0 / ty;
  clipFromView[2][3] = -1.0;
  clipFromView[3][2] = camera.near();
  const crep::Camera engineCamera = crep::Camera::fromMatrices(camera.viewFromWorld(), clipFromView,
                                                               crep::ClipDepth::ZeroToOne, camera.far());
  // Depth buffers of a wall at view depth 4 + 2 v (v = row / height), sky in the top rows.
  std::vector<float> standardDepth(std::size_t(width) * height), reversedDepth(standardDepth.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const bool sky = y >= height - 4;
      const double z = 4.0 + 2.0 * y / height;
      standardDepth[std::size_t(y) * width + x] = sky ? 1.0f : float(camera.depthBufferValue(z));
      reversedDepth[std::size_t(y) * width + x] = sky ? 0.0f : float(engineCamera.depthBufferValue(z));
    }
  // The engine's standard shadow map: orthographic along the sun over the frustum, an occluder over half
  // of it.
  const crep::FrustumCorners corners = camera.frustumCorners();
  const crep::Scattering::ShadowMap shadowMap{
      .texture = 0, .lightClipFromWorld = crep::orthographicLightClipFromWorld(sun, corners), .bias = 1e-4};
  constexpr int kShadowSize = 128;
  std::vector<float> shadow(std::size_t(kShadowSize) * kShadowSize);
  for (int y = 0; y < kShadowSize; ++y)
    for (int x = 0; x < kShadowSize; ++x)
      shadow[std::size_t(y) * kShadowSize + x] = x < kShadowSize / 2 ? 0.3f : 1.0f;

  crep::Scattering scattering({.width = width, .height = height, .mapSize = 64});
  Casters casters;
  std::vector<float> images[2];
  for (int pass = 0; pass < 2; ++pass) {
    const bool engine = pass == 1;
    // The engine's reversed-Z clip control, set once for all its passes; GL's default for the reference.
    glClipControl(GL_LOWER_LEFT, engine ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
    const GLuint depth = depthTexture(width, height, engine ? reversedDepth : standardDepth);
    const GLuint shadowTexture = depthTexture(kShadowSize, kShadowSize, shadow);
    const GLuint output = outputTexture(width, height);
    crep::Scattering::ShadowMap map = shadowMap;
    map.texture = shadowTexture;
    crep::Scattering::FrameAttribs f;
    f.camera = engine ? &engineCamera : &camera;
    f.light = &sun;
    f.medium = &medium;
    f.cameraDepth = depth;
    f.output = output;
    f.shadowMap = &map;
    f.drawCasters = [&](const glm::dmat4& clipFromWorld) { casters.draw(clipFromWorld); };
    const int drawsBefore = casters.draws;
    const crep::Scattering::FrameResult r = scattering.run(f);
    GLint origin = 0, depthMode = 0;
    glGetIntegerv(GL_CLIP_ORIGIN, &origin);
    glGetIntegerv(GL_CLIP_DEPTH_MODE, &depthMode);
    if (casters.draws == drawsBefore || origin != GL_LOWER_LEFT ||
        depthMode != (engine ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE)) {
      std::fprintf(stderr,
                   "consumer: drawCasters not called (%d draws) or the engine's clip control not "
                   "restored (0x%x, 0x%x)\n",
                   casters.draws - drawsBefore, origin, depthMode);
      return 1;
    }
    std::printf("crep::Scattering, %s camera: %s layout, %zu stages\n", engine ? "reversed-Z" : "GL",
                r.layout == crep::Scattering::Layout::Projective ? "projective" : "epipolar",
                r.stages.size());
    images[pass].resize(std::size_t(width) * height * 4);
    glGetTextureImage(output, 0, GL_RGBA, GL_FLOAT, GLsizei(images[pass].size() * sizeof(float)),
                      images[pass].data());
    glDeleteTextures(1, &output);
    glDeleteTextures(1, &shadowTexture);
    glDeleteTextures(1, &depth);
  }
  double peak = 0.0, worst = 0.0;
  for (std::size_t i = 0; i < images[0].size(); ++i) {
    if (!std::isfinite(images[1][i])) {
      std::fprintf(stderr, "consumer: crep::Scattering value %g at %zu\n", double(images[1][i]), i);
      return 1;
    }
    if (i % 4 != 3) peak = std::fmax(peak, images[0][i]);
    worst = std::fmax(worst, std::fabs(double(images[1][i]) - images[0][i]));
  }
  glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
  std::printf("crep::Scattering: reversed-Z engine (GL_ZERO_TO_ONE clip control, casters drawn through "
              "drawCasters) vs GL camera: max |difference| %.3g, peak %.4g\n",
              worst, peak);
  if (!(peak > 0.0) || !(worst <= 1e-4 * peak)) {
    std::fprintf(stderr, "consumer: the engine camera's frame differs from the GL camera's\n");
    return 1;
  }
  return 0;
}

} // namespace

int main() {
  if (const int status = checks(); status != 0) return status;

  EngineContext engine;
  if (!engine.create()) return kNoGl;
  std::printf("engine context: %s, %s\n", reinterpret_cast<const char*>(glGetString(GL_VERSION)),
              reinterpret_cast<const char*>(glGetString(GL_RENDERER)));
  try {
    // The frame: a camera and a sun from the side, so the rectification is projective.
    constexpr int kCameraWidth = 48, kCameraHeight = 32, kMapSize = 64;
    const crep::Camera camera = crep::Camera::lookAt({0, 2, 8}, {0, 1, 0}, {0, 1, 0}, glm::radians(60.0),
                                                     double(kCameraWidth) / kCameraHeight, 0.1, 50.0);
    const crep::DirectionalLight sun({1.0, -0.6, -0.3}, glm::dvec3(3.0));
    const crep::Medium medium(
        {.mieScattering = {0.05, 0.05, 0.05}, .hgG = 0.5, .absorption = {0.01, 0.01, 0.01}});
    const crep::Rectification rect = crep::rectify(camera, sun);
    if (!rect.projective()) {
      std::fprintf(stderr, "consumer: the rectification is not projective: %s\n", rect.message.c_str());
      return 1;
    }
    const crep::ProjectiveLayout layout(rect);
    std::printf("rectification: %d splits, span %.1f degrees\n", rect.splitCount(), rect.span);

    // The rectified shadow map (an occluder ramp: nearer the light toward the top rows and to the
    // right, nothing in the bottom quarter) and the camera depth buffer (a ramp, sky in the top rows).
    std::vector<float> map(std::size_t(kMapSize) * kMapSize);
    for (int y = 0; y < kMapSize; ++y)
      for (int x = 0; x < kMapSize; ++x)
        map[std::size_t(y) * kMapSize + x] =
            y < kMapSize / 4 ? 1.0f : 0.2f + 0.6f * float(x + y) / float(2 * (kMapSize - 1));
    std::vector<float> depth(std::size_t(kCameraWidth) * kCameraHeight);
    for (int y = 0; y < kCameraHeight; ++y)
      for (int x = 0; x < kCameraWidth; ++x)
        depth[std::size_t(y) * kCameraWidth + x] =
            y >= kCameraHeight - 4 ? 1.0f : 0.9f + 0.099f * float(x) / float(kCameraWidth - 1);
    const GLuint rectifiedDepth = depthTexture(kMapSize, kMapSize, map);
    const GLuint cameraDepth = depthTexture(kCameraWidth, kCameraHeight, depth);
    GLuint output = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &output);
    glTextureStorage2D(output, 1, GL_RGBA32F, kCameraWidth, kCameraHeight);

    // The library's passes on the engine's context.
    crep::PrefilterPass prefilter({.mapWidth = kMapSize, .mapHeight = kMapSize});
    crep::EvaluatePass evaluate({});
    prefilter.run({.rectifiedDepth = rectifiedDepth, .layout = &layout, .medium = &medium});
    evaluate.run({.cameraDepth = cameraDepth,
                  .output = output,
                  .camera = &camera,
                  .light = &sun,
                  .medium = &medium,
                  .layout = &layout,
                  .basis = prefilter.filteredBasis()});

    std::vector<float> pixels(std::size_t(kCameraWidth) * kCameraHeight * 4);
    glGetTextureImage(output, 0, GL_RGBA, GL_FLOAT, GLsizei(pixels.size() * sizeof(float)), pixels.data());
    if (const GLenum error = glGetError(); error != GL_NO_ERROR) {
      std::fprintf(stderr, "consumer: GL error 0x%x\n", error);
      return 1;
    }
    double maxRadiance = 0.0, minTransmittance = 1.0;
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      if (!std::isfinite(pixels[i]) || pixels[i] < 0.0f) {
        std::fprintf(stderr, "consumer: scattering value %g at pixel %zu channel %zu\n", double(pixels[i]),
                     i / 4, i % 4);
        return 1;
      }
      if (i % 4 == 3)
        minTransmittance = std::fmin(minTransmittance, pixels[i]);
      else
        maxRadiance = std::fmax(maxRadiance, pixels[i]);
    }
    if (!(maxRadiance > 0.0) || !(minTransmittance < 1.0)) {
      std::fprintf(stderr, "consumer: no scattering (max radiance %g, min transmittance %g)\n", maxRadiance,
                   minTransmittance);
      return 1;
    }
    glDeleteTextures(1, &output);
    glDeleteTextures(1, &cameraDepth);
    glDeleteTextures(1, &rectifiedDepth);
    if (const int status = engineFrame(camera, sun, medium, kCameraWidth, kCameraHeight); status != 0)
      return status;
    std::printf("consumer ok: %zu embedded shader files; %dx%d scattering image, max in-scattered %.4g, "
                "min transmittance %.4g\n",
                crep::ShaderLibrary::files().size(), kCameraWidth, kCameraHeight, maxRadiance,
                minTransmittance);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 1;
  }
  return 0;
}
