// Every shader of the library compiles and links on the driver (Mesa llvmpipe here); compile errors
// point at the real file and line; define variants work; the public includes agree with the CPU.
#include "common/gl_fixture.h"

#include <crep/core/error.h>
#include <crep/core/medium.h>
#include <crep/gpu/gl.h>
#include <crep/gpu/shader_library.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <string_view>
#include <vector>

using crep::ShaderDefine;
using crep::ShaderLibrary;
using crep::ShaderStage;
using crep::ShaderStageSource;

namespace {

bool contains(std::string_view haystack, std::string_view needle) {
  return haystack.find(needle) != std::string_view::npos;
}

/// Shaders of the library (glsl/) and of examples/ (examples/glsl/, registered by test_main.cpp);
/// the "test/" files are the fixtures of tests/glsl/.
bool isLibraryFile(std::string_view path) {
  return !path.starts_with("test/");
}

std::vector<std::string> libraryFiles(std::string_view extension) {
  std::vector<std::string> out;
  for (const auto& f : ShaderLibrary::files())
    if (isLibraryFile(f.path) && f.path.ends_with(extension)) out.emplace_back(f.path);
  return out;
}

/// The vertex shader a fragment shader is drawn with, by naming convention: the .vert in the same
/// folder whose name is the longest "_"-separated prefix of the .frag's name (scene_shade.frag ->
/// scene.vert, fullscreen_copy.frag -> fullscreen.vert), else passes/fullscreen.vert.
std::string vertexShaderFor(const std::string& fragment, const std::set<std::string>& vertexShaders) {
  const std::size_t slash = fragment.rfind('/');
  const std::string folder = fragment.substr(0, slash + 1);
  std::string stem = fragment.substr(slash + 1, fragment.rfind('.') - slash - 1);
  for (;;) {
    if (vertexShaders.count(folder + stem + ".vert") != 0) return folder + stem + ".vert";
    const std::size_t underscore = stem.rfind('_');
    if (underscore == std::string::npos) return "passes/fullscreen.vert";
    stem.resize(underscore);
  }
}

/// Compiles GLSL text that is not an embedded file; returns the info log when it fails.
std::string compileError(GLenum type, const crep::ExpandedShader& expanded) {
  const crep::gl::Handle shader(crep::gl::ObjectType::Shader, glCreateShader(type));
  const GLchar* text = expanded.text.c_str();
  glShaderSource(shader.get(), 1, &text, nullptr);
  glCompileShader(shader.get());
  GLint ok = GL_FALSE;
  glGetShaderiv(shader.get(), GL_COMPILE_STATUS, &ok);
  if (ok == GL_TRUE) return "";
  std::string log(4096, '\0');
  GLsizei length = 0;
  glGetShaderInfoLog(shader.get(), static_cast<GLsizei>(log.size()), &length, log.data());
  log.resize(static_cast<std::size_t>(length));
  return expanded.translateLog(log) + " ";
}

std::vector<float> readTexture(GLuint texture, GLenum format, int width, int height, int channels) {
  std::vector<float> pixels(static_cast<std::size_t>(width * height * channels));
  glGetTextureImage(texture, 0, format, GL_FLOAT, static_cast<GLsizei>(pixels.size() * sizeof(float)),
                    pixels.data());
  return pixels;
}

} // namespace

TEST_CASE("Every compute shader of the library compiles and links") {
  CREP_REQUIRE_GL();
  const std::vector<std::string> shaders = libraryFiles(".comp");
  CHECK(!shaders.empty());
  for (const std::string& path : shaders) {
    CAPTURE(path);
    // Every shader compiles without defines: variants have #ifndef defaults.
    const std::vector<ShaderStageSource> stages = {{ShaderStage::Compute, path, {}}};
    try {
      const crep::gl::Handle program = crep::buildProgram(stages);
      CHECK(glIsProgram(program.get()) == GL_TRUE);
    } catch (const crep::ShaderError& e) {
      FAIL_CHECK(e.what());
    }
  }
}

TEST_CASE("Every vertex and fragment shader of the library compiles and links") {
  CREP_REQUIRE_GL();
  const std::vector<std::string> vertexList = libraryFiles(".vert");
  const std::set<std::string> vertexShaders(vertexList.begin(), vertexList.end());
  REQUIRE(vertexShaders.count("passes/fullscreen.vert") == 1);
  std::set<std::string> unpaired = vertexShaders;
  for (const std::string& fragment : libraryFiles(".frag")) {
    const std::string vertex = vertexShaderFor(fragment, vertexShaders);
    unpaired.erase(vertex);
    CAPTURE(vertex);
    CAPTURE(fragment);
    const std::vector<ShaderStageSource> stages = {{ShaderStage::Vertex, vertex, {}},
                                                   {ShaderStage::Fragment, fragment, {}}};
    try {
      crep::buildProgram(stages);
    } catch (const crep::ShaderError& e) {
      FAIL_CHECK(e.what());
    }
  }
  for (const std::string& vertex : unpaired) {
    CAPTURE(vertex);
    const std::vector<ShaderStageSource> stages = {{ShaderStage::Vertex, vertex, {}}};
    try {
      crep::buildProgram(stages);
    } catch (const crep::ShaderError& e) {
      FAIL_CHECK(e.what());
    }
  }
}

TEST_CASE("Every public include compiles on its own") {
  CREP_REQUIRE_GL();
  for (const std::string& path : libraryFiles(".glsl")) {
    CAPTURE(path);
    crep::ExpandedShader e = ShaderLibrary::expand(path);
    e.text += "layout(local_size_x = 1) in;\nvoid main() {}\n";
    CHECK(compileError(GL_COMPUTE_SHADER, e) == "");
  }
}

TEST_CASE("buildProgram: errors name the file, the included file and the line") {
  CREP_REQUIRE_GL();
  SUBCASE("compile error in an included file") {
    try {
      crep::buildProgram({{ShaderStage::Compute, "test/compile_error.comp", {{"CREP_X", "1"}}}});
      FAIL("no ShaderError");
    } catch (const crep::ShaderError& e) {
      const std::string message = e.what();
      MESSAGE(message);
      // Mesa reports this error with source-string number 0: the line number identifies the file.
      CHECK(contains(message, "compute shader \"test/compile_error.comp\" with CREP_X=1"));
      CHECK(contains(message, "test/compile_error_inc.glsl:4"));
      CHECK(!contains(message, "test/compile_error.comp:4"));
      CHECK(contains(message, "crep_test_undefined_symbol"));
    }
  }
  SUBCASE("link error") {
    try {
      crep::buildProgram({{ShaderStage::Compute, "test/test_fill.comp", {}},
                          {ShaderStage::Vertex, "passes/fullscreen.vert", {}}});
      FAIL("no ShaderError");
    } catch (const crep::ShaderError& e) {
      MESSAGE(std::string(e.what()));
      CHECK(contains(e.what(), "cannot link"));
      CHECK(contains(e.what(), "\"test/test_fill.comp\", \"passes/fullscreen.vert\""));
    }
  }
  SUBCASE("missing file, no stages") {
    CHECK_THROWS_AS(crep::buildProgram({{ShaderStage::Compute, "passes/no_such_file.comp", {}}}),
                    crep::ShaderError);
    CHECK_THROWS_AS(crep::buildProgram(std::span<const ShaderStageSource>()), crep::ShaderError);
  }
}

TEST_CASE("test_fill.comp: define variants, a dispatch that is not a multiple of the work group size") {
  CREP_REQUIRE_GL();
  // The image is larger than the filled extent, and the last work groups reach past the extent but
  // stay inside the image: every texel outside the extent must keep its clear value.
  const int width = 45, height = 29, extentX = 37, extentY = 23;
  for (const auto& [defines, expected] :
       {std::pair{std::vector<ShaderDefine>{{"CREP_FILL_VALUE", "2.5"}}, 2.5f},
        std::pair{std::vector<ShaderDefine>{}, 1.0f}}) {
    CAPTURE(expected);
    const crep::gl::Handle texture = crep::gl::createTexture(GL_TEXTURE_2D);
    glTextureStorage2D(texture.get(), 1, GL_R32F, width, height);
    const float clear = -1.0f;
    glClearTexImage(texture.get(), 0, GL_RED, GL_FLOAT, &clear);
    const crep::gl::Handle program =
        crep::buildProgram({{ShaderStage::Compute, "test/test_fill.comp", defines}});
    glUseProgram(program.get());
    glUniform2i(0, extentX, extentY);
    glBindImageTexture(0, texture.get(), 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    glDispatchCompute((extentX + 7) / 8, (extentY + 7) / 8, 1);
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
    glBindImageTexture(0, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    glUseProgram(0);
    crep::gl::checkError("test_fill dispatch");

    const std::vector<float> pixels = readTexture(texture.get(), GL_RED, width, height, 1);
    int wrong = 0;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const float want = x < extentX && y < extentY ? expected : clear;
        if (pixels[static_cast<std::size_t>(y * width + x)] != want && wrong++ < 5)
          FAIL_CHECK("texel (" << x << ", " << y << ") = " << pixels[static_cast<std::size_t>(y * width + x)]
                               << ", expected " << want);
      }
    CHECK(wrong == 0);
  }
}

TEST_CASE("fullscreen.vert covers every pixel: fullscreen_copy.frag and fullscreen_linear_depth.frag") {
  CREP_REQUIRE_GL();
  const int width = 37, height = 23;
  const crep::gl::Handle vao = crep::gl::createVertexArray();
  const crep::gl::Handle framebuffer = crep::gl::createFramebuffer();

  SUBCASE("copy") {
    std::vector<float> source(static_cast<std::size_t>(width * height * 4));
    for (std::size_t i = 0; i < source.size(); ++i)
      source[i] = static_cast<float>(i) * 0.25f - 100.0f;
    const crep::gl::Handle input = crep::gl::createTexture(GL_TEXTURE_2D);
    glTextureStorage2D(input.get(), 1, GL_RGBA32F, width, height);
    glTextureSubImage2D(input.get(), 0, 0, 0, width, height, GL_RGBA, GL_FLOAT, source.data());
    const crep::gl::Handle output = crep::gl::createTexture(GL_TEXTURE_2D);
    glTextureStorage2D(output.get(), 1, GL_RGBA32F, width, height);
    glNamedFramebufferTexture(framebuffer.get(), GL_COLOR_ATTACHMENT0, output.get(), 0);
    REQUIRE(glCheckNamedFramebufferStatus(framebuffer.get(), GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);

    const crep::gl::Handle program =
        crep::buildProgram({{ShaderStage::Vertex, "passes/fullscreen.vert", {}},
                            {ShaderStage::Fragment, "passes/fullscreen_copy.frag", {}}});
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.get());
    glViewport(0, 0, width, height);
    glUseProgram(program.get());
    glBindTextureUnit(0, input.get());
    glBindVertexArray(vao.get());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glBindTextureUnit(0, 0);
    glUseProgram(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    CHECK(readTexture(output.get(), GL_RGBA, width, height, 4) == source);
  }
  SUBCASE("linear depth") {
    const float zNear = 0.1f, zFar = 100.0f;
    std::vector<float> depth(static_cast<std::size_t>(width * height));
    for (std::size_t i = 0; i < depth.size(); ++i)
      depth[i] = static_cast<float>(i) / static_cast<float>(depth.size());
    const crep::gl::Handle input = crep::gl::createTexture(GL_TEXTURE_2D);
    glTextureStorage2D(input.get(), 1, GL_DEPTH_COMPONENT32F, width, height);
    glTextureSubImage2D(input.get(), 0, 0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, depth.data());
    glTextureParameteri(input.get(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(input.get(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    const crep::gl::Handle output = crep::gl::createTexture(GL_TEXTURE_2D);
    glTextureStorage2D(output.get(), 1, GL_R32F, width, height);
    glNamedFramebufferTexture(framebuffer.get(), GL_COLOR_ATTACHMENT0, output.get(), 0);
    REQUIRE(glCheckNamedFramebufferStatus(framebuffer.get(), GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);

    const crep::gl::Handle program =
        crep::buildProgram({{ShaderStage::Vertex, "passes/fullscreen.vert", {}},
                            {ShaderStage::Fragment, "passes/fullscreen_linear_depth.frag", {}}});
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer.get());
    glViewport(0, 0, width, height);
    glUseProgram(program.get());
    glUniform1f(0, zNear);
    glUniform1f(1, zFar);
    glBindTextureUnit(0, input.get());
    glBindVertexArray(vao.get());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glBindTextureUnit(0, 0);
    glUseProgram(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    const std::vector<float> distance = readTexture(output.get(), GL_RED, width, height, 1);
    double maxRelative = 0.0;
    for (std::size_t i = 0; i < depth.size(); ++i) {
      // Depth-buffer value of a point at view distance t: the inverse of the standard GL projection.
      const double n = zNear, f = zFar, ndcZ = 2.0 * depth[i] - 1.0;
      const double want = 2.0 * n * f / (f + n - ndcZ * (f - n));
      maxRelative = std::max(maxRelative, std::abs(distance[i] - want) / want);
    }
    // float evaluation; the worst conditioning is near depth = 1 (distance ~ far).
    CHECK(maxRelative < 1e-4);
  }
}

TEST_CASE("crep/phase.glsl and crep/common.glsl agree with the CPU functions") {
  CREP_REQUIRE_GL();
  // 1000 samples: not a multiple of the work group size (64).
  const int count = 1000;
  const float zNear = 0.1f, zFar = 100.0f;
  std::vector<float> inputs(static_cast<std::size_t>(count) * 4);
  for (int i = 0; i < count; ++i) {
    const float t = static_cast<float>(i) / static_cast<float>(count - 1);
    inputs[static_cast<std::size_t>(4 * i + 0)] =
        -0.9f + 1.8f * std::fmod(t * 7.0f, 1.0f);                                    // g in [-0.9, 0.9]
    inputs[static_cast<std::size_t>(4 * i + 1)] = -1.0f + 2.0f * t;                  // cosTheta
    inputs[static_cast<std::size_t>(4 * i + 2)] = 0.99f * std::fmod(t * 3.0f, 1.0f); // depth
    inputs[static_cast<std::size_t>(4 * i + 3)] = t;                                 // linear colour
  }
  const crep::gl::Handle inputBuffer = crep::gl::createBuffer();
  glNamedBufferStorage(inputBuffer.get(), static_cast<GLsizeiptr>(inputs.size() * sizeof(float)),
                       inputs.data(), 0);
  const crep::gl::Handle outputBuffer = crep::gl::createBuffer();
  glNamedBufferStorage(outputBuffer.get(), static_cast<GLsizeiptr>(inputs.size() * sizeof(float)), nullptr,
                       GL_DYNAMIC_STORAGE_BIT);
  const crep::gl::Handle program = crep::buildProgram({{ShaderStage::Compute, "test/include_eval.comp", {}}});
  glUseProgram(program.get());
  glUniform1ui(0, count);
  glUniform2f(1, zNear, zFar);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, inputBuffer.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, outputBuffer.get());
  glDispatchCompute((count + 63) / 64, 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, 0);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, 0);
  glUseProgram(0);
  std::vector<float> outputs(inputs.size());
  glGetNamedBufferSubData(outputBuffer.get(), 0, static_cast<GLsizeiptr>(outputs.size() * sizeof(float)),
                          outputs.data());

  double hgError = 0.0, rayleighError = 0.0, depthError = 0.0, srgbError = 0.0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(count); ++i) {
    const double g = inputs[4 * i], c = inputs[4 * i + 1], d = inputs[4 * i + 2], l = inputs[4 * i + 3];
    const double hg = crep::henyeyGreenstein(g, c);
    const double rayleigh = crep::rayleighPhase(c);
    const double ndcZ = 2.0 * d - 1.0;
    const double distance = 2.0 * zNear * zFar / (zFar + zNear - ndcZ * (zFar - zNear));
    const double srgb = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
    hgError = std::max(hgError, std::abs(outputs[4 * i] - hg) / hg);
    rayleighError = std::max(rayleighError, std::abs(outputs[4 * i + 1] - rayleigh) / rayleigh);
    depthError = std::max(depthError, std::abs(outputs[4 * i + 2] - distance) / distance);
    srgbError = std::max(srgbError, std::abs(outputs[4 * i + 3] - srgb));
  }
  MESSAGE("max relative error: HG " << hgError << ", Rayleigh " << rayleighError << ", linear depth "
                                    << depthError << "; max abs sRGB error " << srgbError);
  // float evaluation: 1 + g^2 - 2 g cos cancels down to (1 - |g|)^2 = 0.01, which costs ~2 digits.
  CHECK(hgError < 1e-4);
  CHECK(rayleighError < 1e-6);
  CHECK(depthError < 1e-4);
  CHECK(srgbError < 1e-5);
}
