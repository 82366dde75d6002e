// The blocks shared between C++ (crep/prefilter/gpu_structs.h) and GLSL (crep/scattering_structs.glsl):
// every member offset, array stride and block size the driver reports for the linked programs equals the
// C++ offsetof / sizeof (std140 / std430 rules). And the public include crep/scattering.glsl used the way
// an engine uses it: its files registered with GL_ARB_shading_language_include, #included by a
// fragment shader that is not part of the library, drawn, and compared with the EvaluatePass image.
#include "common/gl_fixture.h"
#include "common/gl_util.h"

#include "common/prefilter_gpu.h"

#include <crep/core/error.h>
#include <crep/gpu/shader_library.h>
#include <crep/prefilter/gpu_pass.h>
#include <crep/prefilter/gpu_structs.h>
#include <crep/support/image_compare.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <cstddef>
#include <string>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

/// Compiles and links one shader of each given type from complete sources; FAILs with the log. Sources
/// using GL_ARB_shading_language_include are compiled with the include search path "/crep" (Mesa
/// resolves a relative #include against the search paths, not against the including file).
gl::Handle linkProgram(const std::vector<std::pair<GLenum, std::string>>& sources) {
  gl::Handle program(gl::ObjectType::Program, glCreateProgram());
  std::vector<gl::Handle> shaders;
  for (const auto& [type, text] : sources) {
    gl::Handle shader(gl::ObjectType::Shader, glCreateShader(type));
    const GLchar* src = text.c_str();
    glShaderSource(shader.get(), 1, &src, nullptr);
    if (text.find("GL_ARB_shading_language_include") != std::string::npos) {
      const GLchar* searchPath = "/crep";
      glCompileShaderIncludeARB(shader.get(), 1, &searchPath, nullptr);
    } else {
      glCompileShader(shader.get());
    }
    GLint ok = GL_FALSE;
    glGetShaderiv(shader.get(), GL_COMPILE_STATUS, &ok);
    if (ok != GL_TRUE) {
      std::string log(8192, '\0');
      GLsizei length = 0;
      glGetShaderInfoLog(shader.get(), static_cast<GLsizei>(log.size()), &length, log.data());
      log.resize(static_cast<std::size_t>(length));
      FAIL("compile error: " << log);
    }
    glAttachShader(program.get(), shader.get());
    shaders.push_back(std::move(shader));
  }
  glLinkProgram(program.get());
  GLint ok = GL_FALSE;
  glGetProgramiv(program.get(), GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    std::string log(8192, '\0');
    GLsizei length = 0;
    glGetProgramInfoLog(program.get(), static_cast<GLsizei>(log.size()), &length, log.data());
    log.resize(static_cast<std::size_t>(length));
    FAIL("link error: " << log);
  }
  return program;
}

struct Member {
  std::string name;
  std::size_t offset;
};

#define CREP_MEMBER(Struct, member)                                                                          \
  Member {                                                                                                   \
#member, offsetof(Struct, member)                                                                        \
  }

const std::vector<Member> kScatteringMembers = {
    CREP_MEMBER(gpu::ScatteringParams, frameOrigin),
    CREP_MEMBER(gpu::ScatteringParams, frameAxisX),
    CREP_MEMBER(gpu::ScatteringParams, frameAxisY),
    CREP_MEMBER(gpu::ScatteringParams, frameAxisZ),
    CREP_MEMBER(gpu::ScatteringParams, slopes),
    CREP_MEMBER(gpu::ScatteringParams, extinction),
    CREP_MEMBER(gpu::ScatteringParams, mieScattering),
    CREP_MEMBER(gpu::ScatteringParams, rayleighScattering),
    CREP_MEMBER(gpu::ScatteringParams, lightIrradiance),
    CREP_MEMBER(gpu::ScatteringParams, lightDirection),
    CREP_MEMBER(gpu::ScatteringParams, mapSize),
    CREP_MEMBER(gpu::ScatteringParams, basisInfo),
    CREP_MEMBER(gpu::ScatteringParams, depthMargin),
    {"splitZeta[0]", offsetof(gpu::ScatteringParams, splitZeta)},
};
const std::vector<Member> kPrefilterMembers = {CREP_MEMBER(gpu::PrefilterParams, mapSize),
                                               CREP_MEMBER(gpu::PrefilterParams, basisInfo),
                                               CREP_MEMBER(gpu::PrefilterParams, weights)};
const std::vector<Member> kEvaluateMembers = {
    CREP_MEMBER(gpu::EvaluateParams, cameraPosition), CREP_MEMBER(gpu::EvaluateParams, cameraForward),
    CREP_MEMBER(gpu::EvaluateParams, cameraRight),    CREP_MEMBER(gpu::EvaluateParams, cameraUp),
    CREP_MEMBER(gpu::EvaluateParams, imageSize),      CREP_MEMBER(gpu::EvaluateParams, cameraCenter),
    CREP_MEMBER(gpu::EvaluateParams, cameraDepth)};
const std::vector<Member> kLocalLightMembers = {CREP_MEMBER(gpu::LocalLightParams, origin),
                                                CREP_MEMBER(gpu::LocalLightParams, position),
                                                CREP_MEMBER(gpu::LocalLightParams, axis),
                                                CREP_MEMBER(gpu::LocalLightParams, cone),
                                                CREP_MEMBER(gpu::LocalLightParams, intensity),
                                                CREP_MEMBER(gpu::LocalLightParams, mieScattering),
                                                CREP_MEMBER(gpu::LocalLightParams, rayleighScattering)};
const std::vector<Member> kRegionWeightsMembers = {
    CREP_MEMBER(gpu::RegionWeights, scale), CREP_MEMBER(gpu::RegionWeights, c),
    CREP_MEMBER(gpu::RegionWeights, d), CREP_MEMBER(gpu::RegionWeights, valid)};

#undef CREP_MEMBER

/// Checks a uniform block `block { Struct instance; }`: block size and every active member's offset.
/// Returns the number of members found active.
int checkUniformBlock(GLuint program, const std::string& block, const std::string& instance,
                      const std::vector<Member>& members, std::size_t size, bool requireAll) {
  CAPTURE(block);
  const GLint dataSize = resourceProperty(program, GL_UNIFORM_BLOCK, block, GL_BUFFER_DATA_SIZE);
  REQUIRE(dataSize >= 0);
  CHECK(static_cast<std::size_t>(dataSize) == size);
  int active = 0;
  for (const Member& m : members) {
    const std::string name = instance + "." + m.name;
    CAPTURE(name);
    const GLint offset = resourceProperty(program, GL_UNIFORM, name, GL_OFFSET);
    if (offset < 0) {
      CHECK_FALSE(requireAll);
      continue;
    }
    ++active;
    CHECK(static_cast<std::size_t>(offset) == m.offset);
  }
  return active;
}

/// The same for the storage buffer of gpu::RegionWeights (an unsized array of structs).
void checkRegionWeightsBlock(GLuint program) {
  for (const Member& m : kRegionWeightsMembers) {
    const std::string name = "crep_regionWeights[0]." + m.name;
    CAPTURE(name);
    const GLint offset = resourceProperty(program, GL_BUFFER_VARIABLE, name, GL_OFFSET);
    REQUIRE(offset >= 0);
    CHECK(static_cast<std::size_t>(offset) == m.offset);
    CHECK(resourceProperty(program, GL_BUFFER_VARIABLE, name, GL_TOP_LEVEL_ARRAY_STRIDE) ==
          static_cast<GLint>(sizeof(gpu::RegionWeights)));
  }
}

/// The text of an embedded file with its #includes resolved, without a #version line.
std::string expandedWithoutVersion(const std::string& path) {
  std::string text = ShaderLibrary::expand(path).text;
  const std::size_t version = text.find("#version");
  if (version != std::string::npos) text.erase(version, text.find('\n', version) + 1 - version);
  return text;
}

} // namespace

TEST_CASE("prefilter GPU: shared structs have the std140 / std430 offsets of their GLSL twins") {
  CREP_REQUIRE_GL();
  // A shader that declares every block and reads every member, so that all are active.
  const std::string source =
      "#version 450 core\n" + expandedWithoutVersion("crep/scattering_structs.glsl") + R"(
layout(local_size_x = 1) in;
layout(std140, binding = 0) uniform CrepScatteringBlock { CrepScatteringParams crep_scattering; };
layout(std140, binding = 1) uniform CrepPrefilterBlock { CrepPrefilterParams crep_prefilter; };
layout(std140, binding = 2) uniform CrepEvaluateBlock { CrepEvaluateParams crep_evaluate; };
layout(std140, binding = 3) uniform CrepLocalLightBlock { CrepLocalLightParams crep_localLight; };
layout(std430, binding = 0) readonly buffer CrepRegionWeightsBlock { CrepRegionWeights crep_regionWeights[]; };
layout(std430, binding = 1) writeonly buffer Out { vec4 result; };
void main() {
  CrepScatteringParams s = crep_scattering;
  vec4 v = s.frameOrigin + s.frameAxisX + s.frameAxisY + s.frameAxisZ + s.slopes + s.extinction + s.mieScattering +
           s.rayleighScattering + s.lightIrradiance + s.lightDirection + vec4(s.mapSize + s.basisInfo) + s.depthMargin;
  for (int k = 0; k < CREP_MAX_SPLITS; ++k) v += s.splitZeta[k];
  v += vec4(crep_prefilter.mapSize + crep_prefilter.basisInfo) + crep_prefilter.weights;
  v += crep_evaluate.cameraPosition + crep_evaluate.cameraForward + crep_evaluate.cameraRight + crep_evaluate.cameraUp +
       vec4(crep_evaluate.imageSize) + crep_evaluate.cameraCenter + crep_evaluate.cameraDepth;
  v += crep_localLight.origin + crep_localLight.position + crep_localLight.axis + crep_localLight.cone +
       crep_localLight.intensity + crep_localLight.mieScattering + crep_localLight.rayleighScattering;
  CrepRegionWeights w = crep_regionWeights[gl_WorkGroupID.x];
  v += vec4(w.scale, w.c, w.d, float(w.valid));
  result = v;
}
)";
  const gl::Handle program = linkProgram({{GL_COMPUTE_SHADER, source}});
  const GLuint p = program.get();
  checkUniformBlock(p, "CrepScatteringBlock", "crep_scattering", kScatteringMembers,
                    sizeof(gpu::ScatteringParams), true);
  CHECK(resourceProperty(p, GL_UNIFORM, "crep_scattering.splitZeta[0]", GL_ARRAY_STRIDE) == 16);
  CHECK(resourceProperty(p, GL_UNIFORM, "crep_scattering.splitZeta[0]", GL_ARRAY_SIZE) == gpu::kMaxSplits);
  checkUniformBlock(p, "CrepPrefilterBlock", "crep_prefilter", kPrefilterMembers,
                    sizeof(gpu::PrefilterParams), true);
  checkUniformBlock(p, "CrepEvaluateBlock", "crep_evaluate", kEvaluateMembers, sizeof(gpu::EvaluateParams),
                    true);
  checkUniformBlock(p, "CrepLocalLightBlock", "crep_localLight", kLocalLightMembers,
                    sizeof(gpu::LocalLightParams), true);
  checkRegionWeightsBlock(p);

  // The passes' own programs declare the same blocks (with their own binding defines): same layout
  // for the members they use.
  const gl::Handle prefilter = buildProgram({{ShaderStage::Compute, "passes/prefilter/prefilter.comp", {}}});
  CHECK(checkUniformBlock(prefilter.get(), "CrepPrefilterBlock", "crep_prefilter", kPrefilterMembers,
                          sizeof(gpu::PrefilterParams), false) >= 3);
  checkRegionWeightsBlock(prefilter.get());
  const gl::Handle prefilterLocal =
      buildProgram({{ShaderStage::Compute, "passes/prefilter/prefilter.comp", {{"CREP_LOCAL_LIGHT", "1"}}}});
  CHECK(checkUniformBlock(prefilterLocal.get(), "CrepLocalLightBlock", "crep_localParams", kLocalLightMembers,
                          sizeof(gpu::LocalLightParams), false) == 7);
  const gl::Handle evaluate = buildProgram(
      {{ShaderStage::Compute, "passes/prefilter/evaluate.comp", {{"CREP_NEAR_PLANE_CORRECTION", "1"}}}});
  CHECK(checkUniformBlock(evaluate.get(), "CrepScatteringBlock", "crep_scattering", kScatteringMembers,
                          sizeof(gpu::ScatteringParams), false) >= 12);
  CHECK(checkUniformBlock(evaluate.get(), "CrepEvaluateBlock", "crep_evaluate", kEvaluateMembers,
                          sizeof(gpu::EvaluateParams), false) == 7);
  checkRegionWeightsBlock(evaluate.get());
}

TEST_CASE("prefilter GPU: crep/scattering.glsl works in an engine's own fragment shader") {
  CREP_REQUIRE_GL();
  REQUIRE_MESSAGE(epoxy_has_gl_extension("GL_ARB_shading_language_include"),
                  "the engine-style include test uses GL_ARB_shading_language_include");
  // Register the public includes as an engine with its own include mechanism would: the raw files.
  for (const auto& f : ShaderLibrary::files()) {
    if (!f.path.starts_with("crep/")) continue;
    const std::string name = "/" + std::string(f.path);
    glNamedStringARB(GL_SHADER_INCLUDE_ARB, static_cast<GLint>(name.size()), name.c_str(),
                     static_cast<GLint>(f.source.size()), f.source.data());
  }
  constexpr int W = 250, H = 37, w = 161, h = 93;
  const GpuScene s = renderGpuScene("boxes", W, H, 2, w, h);
  const std::string vertex = std::string(ShaderLibrary::source("passes/fullscreen.vert"));
  // A deferred-lighting style pass: world position from the depth buffer, then the library call. Its
  // own bindings and uniform names; the include's resources moved away from the defaults.
  const auto fragment = [](const std::string& defines) {
    return "#version 450 core\n#extension GL_ARB_shading_language_include : require\n" + defines +
           R"(#define CREP_SCATTERING_BINDING 3
#define CREP_FILTERED_BASIS_UNIT 5
#include "/crep/scattering.glsl"
layout(location = 0) in vec2 texCoord;
layout(location = 0) out vec4 fragColor;
layout(binding = 2) uniform sampler2D gbufferDepth;
layout(location = 0) uniform mat4 worldFromClip;
layout(location = 1) uniform vec3 eye;
layout(location = 2) uniform vec3 forward;
layout(location = 3) uniform vec2 nearFar;
void main() {
  float d = texelFetch(gbufferDepth, ivec2(gl_FragCoord.xy), 0).r;
  vec4 p = worldFromClip * vec4(texCoord * 2.0 - 1.0, 2.0 * min(d, 1.0) - 1.0, 1.0);
  vec3 ray = p.xyz / p.w - eye;
  vec3 dir = normalize(ray);
  // Sky: the far-plane distance along the ray (crep_inScattering's rule for sky pixels).
  float surface = d < 1.0 ? length(ray) : nearFar.y / dot(dir, forward);
  fragColor = crep_inScattering(eye, dir, surface);
}
)";
  };

  // The library's pass on the same basis, the reference for the engine shader.
  PrefilterPass::CreateInfo info;
  info.mapWidth = W;
  info.mapHeight = H;
  PrefilterPass prefilterPass(info);
  PrefilterPass::FrameAttribs pf;
  pf.rectifiedDepth = s.mapTexture.get();
  pf.layout = s.layout.get();
  pf.medium = &s.scene.medium;
  prefilterPass.run(pf);
  EvaluatePass evaluatePass({});
  const gl::Handle reference = createTexture2D(GL_RGBA32F, w, h);
  evaluatePass.run(sunEvaluation(s, prefilterPass.filteredBasis(), reference.get()));
  const Image expected = readRgbaTexture(reference.get(), w, h);

  const gpu::ScatteringParams params =
      makeScatteringParams(prefilterPass.filteredBasis(), *s.layout, s.scene.sun, s.scene.medium);
  gl::Handle ubo = gl::createBuffer();
  glNamedBufferStorage(ubo.get(), sizeof params, &params, 0);
  const gl::Handle target = createTexture2D(GL_RGBA32F, w, h);
  const gl::Handle fbo = gl::createFramebuffer();
  glNamedFramebufferTexture(fbo.get(), GL_COLOR_ATTACHMENT0, target.get(), 0);
  REQUIRE(glCheckNamedFramebufferStatus(fbo.get(), GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE);
  const gl::Handle vao = gl::createVertexArray();

  // Variants: M from the block or compiled in; Fourier angles reduced in double or in float. The first
  // is compared with the pass: the engine reconstructs its rays from worldFromClip in float, so the
  // surface distance differs from the pass's (camera basis + linear depth) by float rounding, which is
  // amplified where the 2d - 1 form loses digits near the far plane (measured: relative RMSE 2.7e-6,
  // max 1.1e-4 of the peak at one sky pixel). The others are compared with the first.
  struct Variant {
    std::string defines;
    double maxRelative; ///< max |d| / peak
    double relativeRmse;
  };
  const Variant variants[] = {
      {"", 1e-3, 2e-5}, {"#define CREP_BASES 32\n", 1e-6, 1e-6}, {"#define CREP_FP64 1\n", 1e-4, 1e-5}};
  Image first;
  for (const Variant& v : variants) {
    CAPTURE(v.defines);
    const gl::Handle program =
        linkProgram({{GL_VERTEX_SHADER, vertex}, {GL_FRAGMENT_SHADER, fragment(v.defines)}});
    const GLuint p = program.get();
    const glm::mat4 worldFromClip(glm::inverse(s.scene.camera.clipFromWorld()));
    glProgramUniformMatrix4fv(p, 0, 1, GL_FALSE, &worldFromClip[0][0]);
    const glm::vec3 eye(s.scene.camera.position()), forward(s.scene.camera.forward());
    glProgramUniform3fv(p, 1, 1, &eye[0]);
    glProgramUniform3fv(p, 2, 1, &forward[0]);
    glProgramUniform2f(p, 3, static_cast<float>(s.scene.camera.near()),
                       static_cast<float>(s.scene.camera.far()));
    glBindFramebuffer(GL_FRAMEBUFFER, fbo.get());
    glViewport(0, 0, w, h);
    glDisable(GL_DEPTH_TEST);
    glUseProgram(p);
    glBindVertexArray(vao.get());
    glBindBufferBase(GL_UNIFORM_BUFFER, 3, ubo.get());
    glBindTextureUnit(5, prefilterPass.filteredBasisTexture());
    glBindTextureUnit(2, s.depthTexture.get());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindTextureUnit(2, 0);
    glBindTextureUnit(5, 0);
    glBindBufferBase(GL_UNIFORM_BUFFER, 3, 0);
    glBindVertexArray(0);
    glUseProgram(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    const Image actual = readRgbaTexture(target.get(), w, h);
    const ImageMetrics m = compareImages(actual, first.empty() ? expected : first);
    MESSAGE("engine shader " << (v.defines.empty() ? std::string("(no defines)\n") : v.defines)
                             << std::string(first.empty() ? "  vs EvaluatePass: "
                                                          : "  vs the engine shader without defines: ")
                             << describe(m));
    CHECK(m.nanCount == 0);
    CHECK(m.maxAbsError <= v.maxRelative * m.peak);
    CHECK(m.relativeRmse <= v.relativeRmse);
    if (first.empty()) first = actual;
  }
  for (const auto& f : ShaderLibrary::files())
    if (f.path.starts_with("crep/")) {
      const std::string name = "/" + std::string(f.path);
      glDeleteNamedStringARB(static_cast<GLint>(name.size()), name.c_str());
    }
}
