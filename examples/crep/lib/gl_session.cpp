#include "gl_session.h"

#include "frame.h"

#include <crep/core/error.h>
#include <crep/gpu/gl_state.h>
#include <crep/gpu/shader_library.h>
#include <crep/support/gl_context.h>

#include <epoxy/gl.h>

#include <cmath>
#include <cstdio>
#include <vector>

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

bool gGlFailed = false;
std::string gGlMessage;
std::string gRenderer;
} // namespace

void ensureGlContext(const std::string& command, bool debug, StageTimings& timings) {
  static GlContext* context = nullptr; // reachable until exit, never destroyed (gl_session.h)
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
  const gl::PixelStoreScope pixelStore;
  glTextureSubImage2D(t.get(), 0, 0, 0, image.width(), image.height(), GL_RED, GL_FLOAT, channel0.data());
  gl::checkError("upload");
  return t;
}

Image readRgba(std::uint32_t texture, int width, int height) {
  return gl::readTexture(texture, width, height, gl::TexelData::Rgba);
}

gl::Handle runImageProgram(std::uint32_t program, int width, int height,
                           std::initializer_list<std::uint32_t> textures, const char* what) {
  gl::Handle out = gl::createTexture2D(GL_RGBA32F, width, height, "--size");
  glUseProgram(program);
  GLuint unit = 0;
  for (const std::uint32_t texture : textures)
    glBindTextureUnit(unit++, texture);
  glBindImageTexture(0, out.get(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glDispatchCompute(static_cast<GLuint>((width + 7) / 8), static_cast<GLuint>((height + 7) / 8), 1);
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT |
                  GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  glUseProgram(0);
  for (GLuint u = 0; u < unit; ++u)
    glBindTextureUnit(u, 0);
  glFinish();
  gl::checkError(what);
  return out;
}

gl::Handle compositeImage(const FrameInputs& frame, std::uint32_t surfaceColor, std::uint32_t scattering) {
  static gl::Handle* program = nullptr; // built once per process, lives with the context
  if (!program) program = new gl::Handle(buildProgram({{ShaderStage::Compute, "passes/composite.comp", {}}}));
  const GLuint p = program->get();
  setMat4(p, 0, glm::inverse(frame.camera.clipFromWorld()));
  setVec3(p, 1, frame.camera.position());
  setVec3(p, 2, frame.medium.extinction());
  glProgramUniform2i(p, 3, frame.width, frame.height);
  return runImageProgram(p, frame.width, frame.height, {frame.cameraDepth.get(), surfaceColor, scattering},
                         "composite");
}

void addScattering(const FrameInputs& frame, std::uint32_t sum, std::uint32_t addend) {
  static gl::Handle* program = nullptr; // built once per process, lives with the context
  if (!program)
    program = new gl::Handle(buildProgram({{ShaderStage::Compute, "passes/add_scattering.comp", {}}}));
  glUseProgram(program->get());
  glBindImageTexture(0, sum, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glBindImageTexture(1, addend, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
  glDispatchCompute(static_cast<GLuint>((frame.width + 7) / 8), static_cast<GLuint>((frame.height + 7) / 8),
                    1);
  glMemoryBarrier(GL_ALL_BARRIER_BITS);
  glBindImageTexture(0, 0, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glBindImageTexture(1, 0, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
  glUseProgram(0);
  gl::checkError("add scattering");
}

void requireFinite(const Image& image, const std::string& what) {
  long long nonFinite = 0;
  for (float v : image.data())
    nonFinite += std::isfinite(v) ? 0 : 1;
  if (nonFinite > 0) throw Error(what + " has " + std::to_string(nonFinite) + " non-finite samples");
}

} // namespace crep::tool
