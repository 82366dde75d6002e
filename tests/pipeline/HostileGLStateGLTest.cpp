// The GL state contract (docs/GL_STATE.md) under a hostile engine: a frame on a clean context, then the
// same frame after the test leaves every raster, multisample, pixel-store and binding state an engine might
// leave (reversed-Z clip control, an upper-left origin, depth range (0.1, 0.9), GL_GREATER, depth writes off,
// polygon offset and GL_LINE mode, front-face culling with GL_CW, a 16x16 scissor box, colour writes off, a
// failing stencil test, sample coverage 0, clip distances, rasterizer discard, sRGB, odd pixel-store values,
// bound pixel buffers, its own framebuffer, program and bindings). The outputs must be identical bit for bit
// (the library sets every state its results depend on) and every state the test set must read back unchanged
// (the library restores it), except the documented "left unbound" units 0-7 and program 0. Frames: sun
// projective and in view (its own standard map drawn with drawCasters), spot lights off screen (rectified
// map) and in view (perspective map), a point light's faces, a light texture; and RectifiedShadowPass alone.
// The negative control forgets one state at a time inside the pass (the callback sets it for its own draw)
// and shows the map changes for each state the contract sets: the comparison above would catch a pass that
// forgot it. States the contract leaves alone because a depth-only, single-sampled target ignores them
// (colour, stencil, blend, multisample) change nothing.
#include "common/gl_fixture.h"
#include "pipeline/scattering_frame.h"

#include <crep/core/error.h>
#include <crep/gpu/gl_state.h>
#include <crep/pipeline/rectified_shadow_pass.h>
#include <crep/rectify/rectify.h>
#include <crep/scatter/gpu_light_texture.h>
#include <crep/scenes/scene.h>
#include <crep/scenes/scene_renderer.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>

#include <cstring>
#include <functional>
#include <string>
#include <utility>
#include <vector>

using namespace crep;
using namespace crep::test;

namespace {

// ---------------------------------------------------------------------------------------------------------
// The test's own read-back of every state it sets (independent of the library's gl::RasterState).

using StateList = std::vector<std::pair<std::string, std::vector<double>>>;

/// `firstUnit`: the engine's bindings read from that unit on (Scattering::run leaves 0-7 unbound).
StateList readEngineState(GLuint firstUnit) {
  StateList s;
  const auto ints = [&](const std::string& name, GLenum pname, int n) {
    GLint v[4] = {0, 0, 0, 0};
    glGetIntegerv(pname, v);
    s.emplace_back(name, std::vector<double>(v, v + n));
  };
  const auto intsAt = [&](const std::string& name, GLenum pname, GLuint index, int n) {
    GLint v[4] = {0, 0, 0, 0};
    glGetIntegeri_v(pname, index, v);
    s.emplace_back(name + "[" + std::to_string(index) + "]", std::vector<double>(v, v + n));
  };
  const auto floats = [&](const std::string& name, GLenum pname, int n) {
    GLfloat v[4] = {0, 0, 0, 0};
    glGetFloatv(pname, v);
    s.emplace_back(name, std::vector<double>(v, v + n));
  };
  const auto on = [&](const std::string& name, GLenum cap) {
    s.emplace_back(name, std::vector<double>{double(glIsEnabled(cap))});
  };
  ints("GL_DRAW_FRAMEBUFFER_BINDING", GL_DRAW_FRAMEBUFFER_BINDING, 1);
  ints("GL_READ_FRAMEBUFFER_BINDING", GL_READ_FRAMEBUFFER_BINDING, 1);
  ints("GL_CLIP_ORIGIN", GL_CLIP_ORIGIN, 1);
  ints("GL_CLIP_DEPTH_MODE", GL_CLIP_DEPTH_MODE, 1);
  for (GLuint i = 0; i < 2; ++i) {
    GLdouble range[2] = {0, 0};
    glGetDoublei_v(GL_DEPTH_RANGE, i, range);
    s.emplace_back("GL_DEPTH_RANGE[" + std::to_string(i) + "]", std::vector<double>(range, range + 2));
    GLfloat viewport[4] = {0, 0, 0, 0};
    glGetFloati_v(GL_VIEWPORT, i, viewport);
    s.emplace_back("GL_VIEWPORT[" + std::to_string(i) + "]", std::vector<double>(viewport, viewport + 4));
    intsAt("GL_SCISSOR_BOX", GL_SCISSOR_BOX, i, 4);
    s.emplace_back("GL_SCISSOR_TEST[" + std::to_string(i) + "]",
                   std::vector<double>{double(glIsEnabledi(GL_SCISSOR_TEST, i))});
  }
  ints("GL_DEPTH_FUNC", GL_DEPTH_FUNC, 1);
  ints("GL_DEPTH_WRITEMASK", GL_DEPTH_WRITEMASK, 1);
  on("GL_DEPTH_TEST", GL_DEPTH_TEST);
  on("GL_DEPTH_CLAMP", GL_DEPTH_CLAMP);
  ints("GL_POLYGON_MODE", GL_POLYGON_MODE, 2);
  on("GL_POLYGON_OFFSET_FILL", GL_POLYGON_OFFSET_FILL);
  on("GL_POLYGON_OFFSET_LINE", GL_POLYGON_OFFSET_LINE);
  on("GL_POLYGON_OFFSET_POINT", GL_POLYGON_OFFSET_POINT);
  floats("GL_POLYGON_OFFSET_FACTOR", GL_POLYGON_OFFSET_FACTOR, 1);
  floats("GL_POLYGON_OFFSET_UNITS", GL_POLYGON_OFFSET_UNITS, 1);
  on("GL_POLYGON_SMOOTH", GL_POLYGON_SMOOTH);
  on("GL_CULL_FACE", GL_CULL_FACE);
  ints("GL_CULL_FACE_MODE", GL_CULL_FACE_MODE, 1);
  ints("GL_FRONT_FACE", GL_FRONT_FACE, 1);
  ints("GL_COLOR_WRITEMASK", GL_COLOR_WRITEMASK, 4);
  on("GL_STENCIL_TEST", GL_STENCIL_TEST);
  ints("GL_STENCIL_FUNC", GL_STENCIL_FUNC, 1);
  ints("GL_STENCIL_WRITEMASK", GL_STENCIL_WRITEMASK, 1);
  on("GL_RASTERIZER_DISCARD", GL_RASTERIZER_DISCARD);
  on("GL_MULTISAMPLE", GL_MULTISAMPLE);
  on("GL_SAMPLE_COVERAGE", GL_SAMPLE_COVERAGE);
  floats("GL_SAMPLE_COVERAGE_VALUE", GL_SAMPLE_COVERAGE_VALUE, 1);
  on("GL_SAMPLE_ALPHA_TO_COVERAGE", GL_SAMPLE_ALPHA_TO_COVERAGE);
  on("GL_SAMPLE_MASK", GL_SAMPLE_MASK);
  intsAt("GL_SAMPLE_MASK_VALUE", GL_SAMPLE_MASK_VALUE, 0, 1);
  on("GL_SAMPLE_SHADING", GL_SAMPLE_SHADING);
  on("GL_PRIMITIVE_RESTART", GL_PRIMITIVE_RESTART);
  on("GL_PRIMITIVE_RESTART_FIXED_INDEX", GL_PRIMITIVE_RESTART_FIXED_INDEX);
  ints("GL_PRIMITIVE_RESTART_INDEX", GL_PRIMITIVE_RESTART_INDEX, 1);
  for (GLenum i = 0; i < 8; ++i)
    on("GL_CLIP_DISTANCE" + std::to_string(i), GL_CLIP_DISTANCE0 + i);
  on("GL_FRAMEBUFFER_SRGB", GL_FRAMEBUFFER_SRGB);
  on("GL_BLEND", GL_BLEND);
  on("GL_DITHER", GL_DITHER);
  on("GL_COLOR_LOGIC_OP", GL_COLOR_LOGIC_OP);
  on("GL_PROGRAM_POINT_SIZE", GL_PROGRAM_POINT_SIZE);
  for (const auto& [name, pname] : std::vector<std::pair<const char*, GLenum>>{
           {"GL_PACK_ALIGNMENT", GL_PACK_ALIGNMENT},
           {"GL_PACK_ROW_LENGTH", GL_PACK_ROW_LENGTH},
           {"GL_PACK_SKIP_ROWS", GL_PACK_SKIP_ROWS},
           {"GL_UNPACK_ALIGNMENT", GL_UNPACK_ALIGNMENT},
           {"GL_UNPACK_ROW_LENGTH", GL_UNPACK_ROW_LENGTH},
           {"GL_UNPACK_SKIP_PIXELS", GL_UNPACK_SKIP_PIXELS},
           {"GL_PIXEL_PACK_BUFFER_BINDING", GL_PIXEL_PACK_BUFFER_BINDING},
           {"GL_PIXEL_UNPACK_BUFFER_BINDING", GL_PIXEL_UNPACK_BUFFER_BINDING}})
    ints(name, pname, 1);
  // The engine's bindings (beyond the units a frame leaves unbound, docs/GL_STATE.md).
  for (GLuint unit = firstUnit; unit < 16; ++unit) {
    GLint texture = 0, sampler = 0;
    glActiveTexture(GL_TEXTURE0 + unit);
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &texture);
    glGetIntegerv(GL_SAMPLER_BINDING, &sampler);
    s.emplace_back("texture unit " + std::to_string(unit),
                   std::vector<double>{double(texture), double(sampler)});
    intsAt("GL_UNIFORM_BUFFER_BINDING", GL_UNIFORM_BUFFER_BINDING, unit, 1);
    intsAt("GL_SHADER_STORAGE_BUFFER_BINDING", GL_SHADER_STORAGE_BUFFER_BINDING, unit, 1);
    intsAt("GL_IMAGE_BINDING_NAME", GL_IMAGE_BINDING_NAME, unit, 1);
  }
  glActiveTexture(GL_TEXTURE0);
  return s;
}

/// The names whose values differ, "" when none.
std::string differences(const StateList& expected, const StateList& actual) {
  std::string out;
  for (std::size_t i = 0; i < expected.size() && i < actual.size(); ++i)
    if (expected[i].second != actual[i].second) {
      out += expected[i].first + ": set";
      for (double v : expected[i].second)
        out += " " + std::to_string(v);
      out += ", read back";
      for (double v : actual[i].second)
        out += " " + std::to_string(v);
      out += "; ";
    }
  return out;
}

// ---------------------------------------------------------------------------------------------------------
// The engine: its own objects, the hostile state, and GL's defaults.

struct Engine {
  gl::Handle colour = gl::createTexture2D(GL_RGBA8, 64, 64),
             depth = gl::createTexture2D(GL_DEPTH24_STENCIL8, 64, 64);
  gl::Handle framebuffer = gl::createFramebuffer(), packBuffer = gl::createDynamicBuffer(256),
             unpackBuffer = gl::createDynamicBuffer(256), uniform = gl::createDynamicBuffer(256),
             storage = gl::createDynamicBuffer(256), sampler = gl::createClampSampler(GL_LINEAR),
             image = gl::createTexture2D(GL_RGBA32F, 4, 4);
  Engine() {
    glNamedFramebufferTexture(framebuffer.get(), GL_COLOR_ATTACHMENT0, colour.get(), 0);
    glNamedFramebufferTexture(framebuffer.get(), GL_DEPTH_STENCIL_ATTACHMENT, depth.get(), 0);
  }
};

/// Two hostile engines: `variant` 0 an engine with reversed-Z (GL_LOWER_LEFT, GL_ZERO_TO_ONE) whose
/// depth test is on with GL_GREATER, 1 one with a Direct3D-style upper-left origin whose depth test and
/// clamp are in the opposite positions and which left rasterizer discard on.
void setHostileState(const Engine& e, int variant) {
  glBindFramebuffer(GL_FRAMEBUFFER, e.framebuffer.get());
  glClipControl(variant == 0 ? GL_LOWER_LEFT : GL_UPPER_LEFT, GL_ZERO_TO_ONE);
  glDepthRange(0.1, 0.9);
  glDepthRangeIndexed(1, 0.25, 0.5);
  glViewport(7, 9, 33, 21);
  glViewportIndexedf(1, 2.0f, 3.0f, 40.0f, 30.0f);
  glScissor(3, 5, 16, 16);
  glScissorIndexed(1, 1, 1, 8, 8);
  glEnable(GL_SCISSOR_TEST);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_FALSE);
  (variant == 0 ? glEnable : glDisable)(GL_DEPTH_TEST);
  (variant == 0 ? glDisable : glEnable)(GL_DEPTH_CLAMP);
  glPolygonMode(GL_FRONT_AND_BACK, variant == 0 ? GL_LINE : GL_POINT);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glEnable(GL_POLYGON_OFFSET_LINE);
  glEnable(GL_POLYGON_OFFSET_POINT);
  glPolygonOffset(4.0f, 1000.0f);
  glEnable(GL_POLYGON_SMOOTH);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_FRONT);
  glFrontFace(GL_CW);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glEnable(GL_STENCIL_TEST);
  glStencilFunc(GL_NEVER, 1, 0xFF);
  glStencilMask(0x0F);
  (variant == 1 ? glEnable : glDisable)(GL_RASTERIZER_DISCARD);
  glDisable(GL_MULTISAMPLE);
  glEnable(GL_SAMPLE_COVERAGE);
  glSampleCoverage(0.0f, GL_FALSE);
  glEnable(GL_SAMPLE_ALPHA_TO_COVERAGE);
  glEnable(GL_SAMPLE_MASK);
  glSampleMaski(0, 0u);
  glEnable(GL_SAMPLE_SHADING);
  glEnable(GL_PRIMITIVE_RESTART);
  glPrimitiveRestartIndex(0xFFFFFFFEu); // an index the casters do not use: restart is the callback's state
  glEnable(GL_PRIMITIVE_RESTART_FIXED_INDEX);
  glEnable(GL_CLIP_DISTANCE0);
  glEnable(GL_CLIP_DISTANCE3);
  glEnable(GL_FRAMEBUFFER_SRGB);
  glEnable(GL_BLEND);
  glDisable(GL_DITHER);
  glEnable(GL_COLOR_LOGIC_OP);
  glEnable(GL_PROGRAM_POINT_SIZE);
  glPixelStorei(GL_PACK_ALIGNMENT, 8);
  glPixelStorei(GL_PACK_ROW_LENGTH, 7);
  glPixelStorei(GL_PACK_SKIP_ROWS, 2);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 8);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 5);
  glPixelStorei(GL_UNPACK_SKIP_PIXELS, 3);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, e.packBuffer.get());
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, e.unpackBuffer.get());
  for (GLuint unit = 0; unit < 16; ++unit) {
    glBindTextureUnit(unit, e.colour.get());
    glBindSampler(unit, e.sampler.get());
    glBindBufferBase(GL_UNIFORM_BUFFER, unit, e.uniform.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, unit, e.storage.get());
    glBindImageTexture(unit, e.image.get(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  }
}

/// GL's initial values of what setHostileState() changes (viewport: the test's choice).
void setDefaultState() {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
  glDepthRange(0.0, 1.0);
  glViewport(0, 0, 1, 1);
  glScissor(0, 0, 1, 1);
  glDisable(GL_SCISSOR_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_DEPTH_CLAMP);
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glDisable(GL_POLYGON_OFFSET_FILL);
  glDisable(GL_POLYGON_OFFSET_LINE);
  glDisable(GL_POLYGON_OFFSET_POINT);
  glPolygonOffset(0.0f, 0.0f);
  glDisable(GL_POLYGON_SMOOTH);
  glDisable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glFrontFace(GL_CCW);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDisable(GL_STENCIL_TEST);
  glStencilFunc(GL_ALWAYS, 0, 0xFF);
  glStencilMask(0xFF);
  glDisable(GL_RASTERIZER_DISCARD);
  glEnable(GL_MULTISAMPLE);
  glDisable(GL_SAMPLE_COVERAGE);
  glSampleCoverage(1.0f, GL_FALSE);
  glDisable(GL_SAMPLE_ALPHA_TO_COVERAGE);
  glDisable(GL_SAMPLE_MASK);
  glSampleMaski(0, ~0u);
  glDisable(GL_SAMPLE_SHADING);
  glDisable(GL_PRIMITIVE_RESTART);
  glDisable(GL_PRIMITIVE_RESTART_FIXED_INDEX);
  for (GLenum i = 0; i < 8; ++i)
    glDisable(GL_CLIP_DISTANCE0 + i);
  glDisable(GL_FRAMEBUFFER_SRGB);
  glDisable(GL_BLEND);
  glEnable(GL_DITHER);
  glDisable(GL_COLOR_LOGIC_OP);
  glDisable(GL_PROGRAM_POINT_SIZE);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  glPixelStorei(GL_PACK_SKIP_ROWS, 0);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  gl::unbindPassState(16);
}

/// After a run: program 0 and units 0-7 unbound (the documented "left unbound" contract).
void checkUnitsUnbound() {
  GLint program = -1;
  glGetIntegerv(GL_CURRENT_PROGRAM, &program);
  CHECK(program == 0);
  for (GLuint unit = 0; unit < 8; ++unit) {
    CAPTURE(unit);
    GLint texture = -1, sampler = -1, uniform = -1, storage = -1, image = -1;
    glActiveTexture(GL_TEXTURE0 + unit);
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &texture);
    glGetIntegerv(GL_SAMPLER_BINDING, &sampler);
    glGetIntegeri_v(GL_UNIFORM_BUFFER_BINDING, unit, &uniform);
    glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, unit, &storage);
    glGetIntegeri_v(GL_IMAGE_BINDING_NAME, unit, &image);
    CHECK(texture == 0);
    CHECK(sampler == 0);
    CHECK(uniform == 0);
    CHECK(storage == 0);
    CHECK(image == 0);
  }
  glActiveTexture(GL_TEXTURE0);
}

std::size_t differingValues(const Image& a, const Image& b) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.data().size(); ++i)
    if (std::memcmp(&a.data()[i], &b.data()[i], sizeof(float)) != 0) ++n;
  return n;
}

/// Runs `frame` on the clean context, then under both hostile variants: identical bits, restored state.
/// `unbindsUnits`: a crep::Scattering frame (program 0 and units 0-7 unbound after it); otherwise every
/// unit must be as the engine left it.
void checkUnderHostileState(const std::string& name, const std::function<Image()>& frame,
                            bool unbindsUnits = true) {
  const GLuint firstUnit = unbindsUnits ? 8 : 0;
  CAPTURE(name);
  const Engine engine;
  setDefaultState();
  const Image clean = frame();
  for (int variant = 0; variant < 2; ++variant) {
    CAPTURE(variant);
    setHostileState(engine, variant);
    const StateList before = readEngineState(firstUnit);
    const Image hostile = frame();
    const StateList after = readEngineState(firstUnit);
    const std::size_t differing = differingValues(clean, hostile);
    MESSAGE(name << ", hostile engine " << variant << ": " << differing << " of " << clean.data().size()
                 << " values differ from the clean frame");
    CHECK(differing == 0);
    const std::string changed = differences(before, after);
    CHECK_MESSAGE(changed.empty(), changed);
    if (unbindsUnits) checkUnitsUnbound();
    setDefaultState();
  }
}

Scattering::CreateInfo hostileInfo() {
  Scattering::CreateInfo info = smallInfo();
  info.ownShadowMapSize = 512;
  return info;
}

} // namespace

TEST_CASE("GL state contract: crep::Scattering gives the clean context's frame bit for bit under a hostile "
          "engine's state, and restores it") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  Scattering scattering(hostileInfo());
  const auto run = [&](const Scattering::FrameAttribs& a) {
    scattering.run(a);
    return f.read();
  };
  checkUnderHostileState("sun, projective (rectified map drawn with drawCasters)", [&] {
    const Scattering::FrameResult r = scattering.run(f.attribs(true, false));
    CHECK(r.layout == Scattering::Layout::Projective);
    return f.read();
  });

  const SunWindow window = sunWindowTexture(f);
  const GpuLightTexture& sunTexture = window.light;
  checkUnderHostileState("sun with a light texture, projective", [&] {
    Scattering::FrameAttribs a = f.attribs(true, false);
    a.lightTexture = &sunTexture;
    return run(a);
  });

  f.lightToward(1.0, 0.25, 0.2);
  checkUnderHostileState("sun in view (epipolar; its standard map drawn with drawCasters)", [&] {
    const Scattering::FrameResult r = scattering.run(f.attribs(true, false));
    CHECK(r.layout == Scattering::Layout::Epipolar);
    return f.read();
  });
}

TEST_CASE("GL state contract: local lights (spot off screen and in view, point light) under a hostile "
          "engine's state") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  f.setLight(DirectionalLight(f.scene.sun.direction(), glm::dvec3(0.0)));
  Scattering scattering(hostileInfo());
  const Camera& c = f.scene.camera;
  const SpotLight offScreen = spotToward(c, c.position() - 4.0 * c.forward() + 7.0 * c.up());
  const SpotLight inView = spotToward(c, c.position() + 9.0 * c.forward() + 1.5 * c.up() - 1.0 * c.right());
  const PointLight point({.position = c.position() - 8.0 * c.right() + 4.0 * c.up() - 6.0 * c.forward(),
                          .color = {1.0, 0.8, 0.6},
                          .intensity = 60.0,
                          .range = 80.0});
  for (const auto& [name, spot, status] :
       {std::tuple{"spot off screen (its rectified map drawn with drawCasters)", &offScreen,
                   RectifyStatus::Projective},
        std::tuple{"spot in view (its perspective map drawn with drawCasters)", &inView,
                   RectifyStatus::Fallback}})
    checkUnderHostileState(name, [&, spot = spot, status = status] {
      Scattering::FrameAttribs a = f.attribs(true, false);
      a.light = nullptr;
      a.spotLights = std::span<const SpotLight>(spot, 1);
      const Scattering::FrameResult r = scattering.run(a);
      REQUIRE(r.localLights.size() == 1);
      CHECK(r.localLights[0].status == status);
      return f.read();
    });
  checkUnderHostileState("point light (six faces drawn with drawCasters)", [&] {
    Scattering::FrameAttribs a = f.attribs(true, false);
    a.light = nullptr;
    a.pointLights = std::span<const PointLight>(&point, 1);
    scattering.run(a);
    return f.read();
  });
}

TEST_CASE(
    "GL state contract: RectifiedShadowPass under a hostile engine's state, and a callback that changes the "
    "pass's state is named") {
  CREP_REQUIRE_GL();
  const scenes::Scene scene = scenes::makeScene("boxes", 16.0 / 9.0);
  const Rectification r = rectify(scene.camera, scene.sun);
  REQUIRE(r.projective());
  scenes::SceneRenderer renderer(scene.mesh);
  RectifiedShadowPass pass({256, 128});
  const auto draw = [&](int, const glm::dmat4& m) { renderer.drawDepth(m); };
  checkUnderHostileState(
      "RectifiedShadowPass",
      [&] {
        pass.run({&r, draw});
        return gl::readTexture(pass.depthTexture(), 256, 128, gl::TexelData::Depth);
      },
      false);

  // A callback that leaves a state of the pass changed: named, and the caller's state still restored.
  const Engine engine;
  setHostileState(engine, 0);
  const StateList before = readEngineState(0);
  std::string message, parameter;
  try {
    pass.run({&r, [&](int, const glm::dmat4& m) {
                renderer.drawDepth(m);
                glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
              }});
  } catch (const InvalidArgument& e) {
    message = e.what();
    parameter = e.parameter();
  }
  MESSAGE(message);
  CHECK(parameter == "RectifiedShadowPass::FrameAttribs.drawCasters");
  CHECK(message.find("GL_CLIP_DEPTH_MODE = GL_ZERO_TO_ONE") != std::string::npos);
  const std::string changed = differences(before, readEngineState(0));
  CHECK_MESSAGE(changed.empty(), changed);
  setDefaultState();
}

TEST_CASE("GL state contract, negative control: a pass that forgets one state gives another map") {
  CREP_REQUIRE_GL();
  const scenes::Scene scene = scenes::makeScene("boxes", 16.0 / 9.0);
  const Rectification r = rectify(scene.camera, scene.sun);
  REQUIRE(r.projective());
  scenes::SceneRenderer renderer(scene.mesh);
  constexpr int kW = 256, kH = 128;
  RectifiedShadowPass pass({kW, kH});
  setDefaultState();
  pass.run({&r, [&](int, const glm::dmat4& m) { renderer.drawDepth(m); }});
  const Image clean = gl::readTexture(pass.depthTexture(), kW, kH, gl::TexelData::Depth);

  // Each case: what a pass that forgot the state would draw with (the engine's value, set inside the
  // callback), and the contract's value the pass set (restored before the callback returns).
  struct Case {
    const char* state;
    std::function<void()> forget, set;
    int changesMap; ///< 1 changes it; 0 irrelevant to a single-sampled depth-only target (not set by the
                    ///< contract); -1 undefined by the spec (reported: the contract sets it for other
                    ///< drivers)
  };
  const std::vector<Case> cases = {
      {"clip depth mode GL_ZERO_TO_ONE", [] { glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE); },
       [] { glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE); }, 1},
      {"clip origin GL_UPPER_LEFT", [] { glClipControl(GL_UPPER_LEFT, GL_NEGATIVE_ONE_TO_ONE); },
       [] { glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE); }, 1},
      {"depth range (0.1, 0.9)", [] { glDepthRangeIndexed(0, 0.1, 0.9); },
       [] { glDepthRangeIndexed(0, 0.0, 1.0); }, 1},
      {"depth function GL_GREATER", [] { glDepthFunc(GL_GREATER); }, [] { glDepthFunc(GL_LESS); }, 1},
      {"depth mask off", [] { glDepthMask(GL_FALSE); }, [] { glDepthMask(GL_TRUE); }, 1},
      {"depth test off", [] { glDisable(GL_DEPTH_TEST); }, [] { glEnable(GL_DEPTH_TEST); }, 1},
      {"depth clamp off", [] { glDisable(GL_DEPTH_CLAMP); }, [] { glEnable(GL_DEPTH_CLAMP); }, 1},
      {"polygon mode GL_LINE", [] { glPolygonMode(GL_FRONT_AND_BACK, GL_LINE); },
       [] { glPolygonMode(GL_FRONT_AND_BACK, GL_FILL); }, 1},
      {"polygon offset fill (4, 1000)",
       [] {
         glEnable(GL_POLYGON_OFFSET_FILL);
         glPolygonOffset(4.0f, 1000.0f);
       },
       [] { glDisable(GL_POLYGON_OFFSET_FILL); }, 1},
      {"polygon offset line with GL_LINE",
       [] {
         glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
         glEnable(GL_POLYGON_OFFSET_LINE);
         glPolygonOffset(4.0f, 1000.0f);
       },
       [] {
         glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
         glDisable(GL_POLYGON_OFFSET_LINE);
       },
       1},
      {"back faces culled", [] { glEnable(GL_CULL_FACE); }, [] { glDisable(GL_CULL_FACE); }, 1},
      // (The rectification mirrors this scene's winding: its visible faces are back faces, which is why the
      // pass culls nothing.)
      {"scissor box 16x16", [] { glScissorIndexed(0, 0, 0, 16, 16); }, [] {}, 1},
      {"viewport of the whole map", [] { glViewportIndexedf(0, 0.0f, 0.0f, float(kW), float(kH)); }, [] {},
       1},
      {"rasterizer discard", [] { glEnable(GL_RASTERIZER_DISCARD); },
       [] { glDisable(GL_RASTERIZER_DISCARD); }, 1},
      {"colour mask off", [] { glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE); },
       [] { glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE); }, 0},
      {"stencil test GL_NEVER",
       [] {
         glEnable(GL_STENCIL_TEST);
         glStencilFunc(GL_NEVER, 1, 0xFF);
       },
       [] {
         glDisable(GL_STENCIL_TEST);
         glStencilFunc(GL_ALWAYS, 0, 0xFF);
       },
       0},
      {"sample coverage 0",
       [] {
         glEnable(GL_SAMPLE_COVERAGE);
         glSampleCoverage(0.0f, GL_FALSE);
       },
       [] {
         glDisable(GL_SAMPLE_COVERAGE);
         glSampleCoverage(1.0f, GL_FALSE);
       },
       0},
      {"sample mask 0",
       [] {
         glEnable(GL_SAMPLE_MASK);
         glSampleMaski(0, 0u);
       },
       [] {
         glDisable(GL_SAMPLE_MASK);
         glSampleMaski(0, ~0u);
       },
       0},
      {"alpha to coverage", [] { glEnable(GL_SAMPLE_ALPHA_TO_COVERAGE); },
       [] { glDisable(GL_SAMPLE_ALPHA_TO_COVERAGE); }, 0},
      {"framebuffer sRGB", [] { glEnable(GL_FRAMEBUFFER_SRGB); }, [] { glDisable(GL_FRAMEBUFFER_SRGB); }, 0},
      {"blend", [] { glEnable(GL_BLEND); }, [] { glDisable(GL_BLEND); }, 0},
      {"clip distance 0 (not written by the casters' program)", [] { glEnable(GL_CLIP_DISTANCE0); },
       [] { glDisable(GL_CLIP_DISTANCE0); }, -1},
      {"polygon smooth", [] { glEnable(GL_POLYGON_SMOOTH); }, [] { glDisable(GL_POLYGON_SMOOTH); }, -1},
  };
  for (const Case& k : cases) {
    CAPTURE(std::string(k.state));
    pass.run({&r, [&](int, const glm::dmat4& m) {
                GLfloat viewport[4];
                GLint scissor[4];
                glGetFloati_v(GL_VIEWPORT, 0, viewport);
                glGetIntegeri_v(GL_SCISSOR_BOX, 0, scissor);
                k.forget();
                renderer.drawDepth(m);
                k.set();
                glViewportIndexedfv(0, viewport); // the split's viewport and scissor, as the pass set them
                glScissorIndexedv(0, scissor);
              }});
    const Image forgot = gl::readTexture(pass.depthTexture(), kW, kH, gl::TexelData::Depth);
    const std::size_t differing = differingValues(clean, forgot);
    MESSAGE("forgetting " << std::string(k.state) << ": " << differing << " of " << clean.data().size()
                          << " texels differ");
    if (k.changesMap >= 0) CHECK(int(differing > 0) == k.changesMap);
  }
  glPolygonOffset(0.0f, 0.0f);
  setDefaultState();
}

TEST_CASE("GL state contract: what cannot be set aside is named (an active GL_TIME_ELAPSED query, an active "
          "transform feedback)") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  Scattering scattering(hostileInfo());
  setDefaultState();
  const gl::Handle query = gl::createQuery(GL_TIME_ELAPSED);
  glBeginQuery(GL_TIME_ELAPSED, query.get());
  std::string message;
  try {
    scattering.run(f.attribs(true, false));
  } catch (const GlError& e) {
    message = e.what();
  }
  glEndQuery(GL_TIME_ELAPSED);
  MESSAGE(message);
  CHECK(message.find("GL_TIME_ELAPSED") != std::string::npos);
  CHECK(message.find("stageTimings") != std::string::npos);
  // The same frame with the timings off runs inside the caller's query.
  Scattering::CreateInfo untimed = hostileInfo();
  untimed.stageTimings = false;
  Scattering quiet(untimed);
  glBeginQuery(GL_TIME_ELAPSED, query.get());
  CHECK_NOTHROW(quiet.run(f.attribs(true, false)));
  glEndQuery(GL_TIME_ELAPSED);

  // Transform feedback active (a program with a captured output, begun and not paused).
  const char* vs =
      "#version 450 core\nout float captured;\nvoid main() { captured = 1.0; gl_Position = vec4(0.0); }\n";
  const GLuint shader = glCreateShader(GL_VERTEX_SHADER);
  glShaderSource(shader, 1, &vs, nullptr);
  glCompileShader(shader);
  const GLuint program = glCreateProgram();
  glAttachShader(program, shader);
  const char* varyings[] = {"captured"};
  glTransformFeedbackVaryings(program, 1, varyings, GL_INTERLEAVED_ATTRIBS);
  glLinkProgram(program);
  GLint linked = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &linked);
  REQUIRE(linked == GL_TRUE);
  const gl::Handle captureBuffer = gl::createDynamicBuffer(1024);
  glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, captureBuffer.get());
  glUseProgram(program);
  glBeginTransformFeedback(GL_POINTS);
  message.clear();
  try {
    scattering.run(f.attribs(true, false));
  } catch (const GlError& e) {
    message = e.what();
  }
  glEndTransformFeedback();
  glUseProgram(0);
  glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, 0);
  glDeleteProgram(program);
  glDeleteShader(shader);
  MESSAGE(message);
  CHECK(message.find("GL_TRANSFORM_FEEDBACK_ACTIVE") != std::string::npos);
  setDefaultState();
}
