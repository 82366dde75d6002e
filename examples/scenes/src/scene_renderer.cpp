#include <crep/core/error.h>
#include <crep/gpu/gl_state.h>
#include <crep/gpu/shader_library.h>
#include <crep/pipeline/rectified_shadow_pass.h>
#include <crep/scenes/scene_renderer.h>
#include <crep/scenes/shaders.h>

#include <epoxy/gl.h>

namespace crep::scenes {

namespace {
void setMatrix(GLuint program, GLint location, const glm::dmat4& m) {
  const glm::mat4 f(m);
  glProgramUniformMatrix4fv(program, location, 1, GL_FALSE, &f[0][0]);
}
void setVec3(GLuint program, GLint location, const glm::dvec3& v) {
  glProgramUniform3f(program, location, static_cast<float>(v.x), static_cast<float>(v.y),
                     static_cast<float>(v.z));
}
} // namespace

struct SceneRenderer::Impl {
  gl::Handle vao, positions, normals, indices, depthProgram, shadeProgram, framebuffer;
  GLsizei indexCount = 0;
};

SceneRenderer::SceneRenderer(const Mesh& mesh) : impl_(std::make_unique<Impl>()) {
  if (mesh.positions.size() != mesh.normals.size())
    throw InvalidArgument("Mesh.normals", std::to_string(mesh.normals.size()) + " normals",
                          "must match the " + std::to_string(mesh.positions.size()) + " positions");
  Impl& d = *impl_;
  d.positions = gl::createBuffer();
  d.normals = gl::createBuffer();
  d.indices = gl::createBuffer();
  glNamedBufferStorage(d.positions.get(), static_cast<GLsizeiptr>(mesh.positions.size() * sizeof(glm::vec3)),
                       mesh.positions.data(), 0);
  glNamedBufferStorage(d.normals.get(), static_cast<GLsizeiptr>(mesh.normals.size() * sizeof(glm::vec3)),
                       mesh.normals.data(), 0);
  glNamedBufferStorage(d.indices.get(), static_cast<GLsizeiptr>(mesh.indices.size() * sizeof(std::uint32_t)),
                       mesh.indices.data(), 0);
  d.indexCount = static_cast<GLsizei>(mesh.indices.size());
  d.vao = gl::createVertexArray();
  const GLuint vao = d.vao.get();
  glVertexArrayVertexBuffer(vao, 0, d.positions.get(), 0, sizeof(glm::vec3));
  glVertexArrayVertexBuffer(vao, 1, d.normals.get(), 0, sizeof(glm::vec3));
  glVertexArrayElementBuffer(vao, d.indices.get());
  for (GLuint a = 0; a < 2; ++a) {
    glEnableVertexArrayAttrib(vao, a);
    glVertexArrayAttribFormat(vao, a, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, a, a);
  }
  registerShaders();
  d.depthProgram = buildProgram({{ShaderStage::Vertex, "passes/scene.vert", {}},
                                 {ShaderStage::Fragment, "passes/scene_depth.frag", {}}});
  d.shadeProgram = buildProgram({{ShaderStage::Vertex, "passes/scene.vert", {}},
                                 {ShaderStage::Fragment, "passes/scene_shade.frag", {}}});
  d.framebuffer = gl::createFramebuffer();
  gl::checkError("SceneRenderer: mesh upload");
}

SceneRenderer::~SceneRenderer() = default;

void SceneRenderer::drawDepth(const glm::dmat4& clipFromWorld) {
  Impl& d = *impl_;
  glUseProgram(d.depthProgram.get());
  setMatrix(d.depthProgram.get(), 0, clipFromWorld);
  glBindVertexArray(d.vao.get());
  glDrawElements(GL_TRIANGLES, d.indexCount, GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
  glUseProgram(0);
}

void SceneRenderer::renderDepth(const glm::dmat4& clipFromWorld, std::uint32_t depthTexture, int layer, int x,
                                int y, int width, int height, const DepthRenderOptions& options) {
  Impl& d = *impl_;
  const GLuint fb = d.framebuffer.get();
  GLint target = 0;
  glGetTextureParameteriv(depthTexture, GL_TEXTURE_TARGET, &target);
  if (target == GL_TEXTURE_2D_ARRAY)
    glNamedFramebufferTextureLayer(fb, GL_DEPTH_ATTACHMENT, depthTexture, 0, layer);
  else
    glNamedFramebufferTexture(fb, GL_DEPTH_ATTACHMENT, depthTexture, 0);
  glNamedFramebufferDrawBuffer(fb, GL_NONE);
  glNamedFramebufferReadBuffer(fb, GL_NONE);
  if (glCheckNamedFramebufferStatus(fb, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw GlError("SceneRenderer::renderDepth: depth texture " + std::to_string(depthTexture) +
                  " is not a complete depth attachment (expected GL_DEPTH_COMPONENT32F)");
  {
    // The library's depth-pass contract (docs/GL_STATE.md): every raster state set here, the caller's
    // restored after.
    gl::DepthPassScope scope(fb, width, height, {options.depthClamp, options.cullBackFaces});
    scope.setViewport(x, y, width, height); // and the scissor box: the clear stays inside the viewport
    const float one = 1.0f;
    glClearNamedFramebufferfv(fb, GL_DEPTH, 0, &one);
    drawDepth(clipFromWorld);
  }
  glNamedFramebufferTexture(fb, GL_DEPTH_ATTACHMENT, 0, 0);
  gl::checkError("SceneRenderer::renderDepth");
}

void SceneRenderer::renderRectified(const Rectification& r, std::uint32_t depthTexture, int width,
                                    int height) {
  if (!r.projective())
    throw InvalidArgument("Rectification.status", statusToken(r.status),
                          "must be projective to render a rectified map");
  // The library's split pass (what the README shows an engine): clear once, viewport + scissor per split,
  // depth clamp, GL_LESS, no culling.
  RectifiedShadowPass pass({width, height});
  pass.run({&r, [&](int, const glm::dmat4& clipFromWorld) { drawDepth(clipFromWorld); }, depthTexture});
}

void SceneRenderer::renderShaded(const ShadeInputs& in, std::uint32_t colorTexture,
                                 std::uint32_t depthTexture, int width, int height) {
  Impl& d = *impl_;
  const GLuint fb = d.framebuffer.get();
  glNamedFramebufferTexture(fb, GL_COLOR_ATTACHMENT0, colorTexture, 0);
  glNamedFramebufferTexture(fb, GL_DEPTH_ATTACHMENT, depthTexture, 0);
  glNamedFramebufferDrawBuffer(fb, GL_COLOR_ATTACHMENT0);
  if (glCheckNamedFramebufferStatus(fb, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw GlError("SceneRenderer::renderShaded: colour/depth textures do not form a complete framebuffer");
  glBindFramebuffer(GL_FRAMEBUFFER, fb);
  glViewport(0, 0, width, height);
  const float zero[4] = {0, 0, 0, 0}, one = 1.0f;
  glClearNamedFramebufferfv(fb, GL_COLOR, 0, zero);
  glClearNamedFramebufferfv(fb, GL_DEPTH, 0, &one);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  const GLuint p = d.shadeProgram.get();
  glUseProgram(p);
  setMatrix(p, 0, in.clipFromWorld);
  setMatrix(p, 1, in.shadowClipFromWorld);
  setVec3(p, 2, in.lightDirection);
  setVec3(p, 3, in.lightIrradiance);
  setVec3(p, 4, in.ambient);
  setVec3(p, 5, in.albedo);
  // Hardware depth comparison on a sampler object so the caller's texture state is untouched.
  gl::Handle sampler = gl::createSampler();
  glSamplerParameteri(sampler.get(), GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glSamplerParameteri(sampler.get(), GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  glSamplerParameteri(sampler.get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glSamplerParameteri(sampler.get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glSamplerParameteri(sampler.get(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(sampler.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glBindTextureUnit(0, in.shadowMap);
  glBindSampler(0, sampler.get());
  if (in.spots.size() > static_cast<std::size_t>(kMaxShadeSpots))
    throw InvalidArgument("SceneRenderer::ShadeInputs.spots", std::to_string(in.spots.size()),
                          "at most " + std::to_string(kMaxShadeSpots) + " spot lights");
  const int spotCount = static_cast<int>(in.spots.size());
  glProgramUniform1i(p, 6, spotCount);
  for (int i = 0; i < spotCount; ++i) {
    const ShadeInputs::Spot& spot = in.spots[static_cast<std::size_t>(i)];
    setVec3(p, 7 + i, spot.light->position());
    setVec3(p, 11 + i, spot.light->direction());
    glProgramUniform2f(p, 15 + i, static_cast<float>(spot.light->cosInner()),
                       static_cast<float>(spot.light->cosOuter()));
    setVec3(p, 19 + i, spot.light->intensity());
    setMatrix(p, 23 + i, spot.shadowClipFromWorld);
  }
  // Every sampler of the array bound (unused ones to the sun's map) so no unit is left incomplete.
  for (int i = 0; i < kMaxShadeSpots; ++i) {
    glBindTextureUnit(static_cast<GLuint>(1 + i),
                      i < spotCount ? in.spots[static_cast<std::size_t>(i)].shadowMap : in.shadowMap);
    glBindSampler(static_cast<GLuint>(1 + i), sampler.get());
  }
  // The sun's light texture at unit 5 (linear filtering, clamp to edge).
  glProgramUniform1i(p, 27, in.sunTexture != 0 ? 1 : 0);
  setMatrix(p, 28, in.sunTextureClipFromWorld);
  gl::Handle linear = gl::createSampler();
  glSamplerParameteri(linear.get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glSamplerParameteri(linear.get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glSamplerParameteri(linear.get(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glSamplerParameteri(linear.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glBindTextureUnit(5, in.sunTexture);
  glBindSampler(5, linear.get());
  glBindVertexArray(d.vao.get());
  glDrawElements(GL_TRIANGLES, d.indexCount, GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
  for (GLuint unit = 0; unit <= static_cast<GLuint>(kMaxShadeSpots) + 1; ++unit) {
    glBindSampler(unit, 0);
    glBindTextureUnit(unit, 0);
  }
  glUseProgram(0);
  glDisable(GL_DEPTH_TEST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glNamedFramebufferTexture(fb, GL_COLOR_ATTACHMENT0, 0, 0);
  glNamedFramebufferTexture(fb, GL_DEPTH_ATTACHMENT, 0, 0);
  gl::checkError("SceneRenderer::renderShaded");
}

Image SceneRenderer::renderDepthImage(const glm::dmat4& clipFromWorld, int width, int height,
                                      const DepthRenderOptions& options) {
  gl::Handle tex = createDepthTexture(width, height);
  renderDepth(clipFromWorld, tex.get(), 0, 0, 0, width, height, options);
  return readDepthTexture(tex.get(), width, height);
}

gl::Handle createDepthTexture(int width, int height, const char* parameter) {
  return gl::createTexture2D(GL_DEPTH_COMPONENT32F, width, height, parameter);
}

Image readDepthTexture(std::uint32_t texture, int width, int height, int layer) {
  return gl::readTexture(texture, width, height, gl::TexelData::Depth, layer);
}

} // namespace crep::scenes
