// The portable shaders beside the GL programs: resources.json's work-group sizes are the GL programs',
// and every program variant crep::Scattering builds for its frames (sun projective and in view, a light
// texture, froxels, spot and point lights) compiles for Vulkan and validates, so a Vulkan backend or an
// engine precompiling for D3D12 or Metal (crep::programVariantsBuilt) can take each of them; and each is
// shipped (resources.json's "passes" or "variants", declared in glsl/portable_variants.txt), so the list
// cannot fall behind the frames.
#include "common/frame_extras.h"
#include "common/gl_fixture.h"
#include "common/shader_tools.h"
#include "pipeline/scattering_frame.h"

#include <crep/gpu/shader_library.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <set>
#include <span>
#include <string>

using namespace crep;
using namespace crep::test;

TEST_CASE("portable shaders: resources.json's work-group sizes are those of the GL programs") {
  CREP_REQUIRE_GL();
  const nlohmann::json resources = portableShaderResources();
  int checked = 0;
  for (const nlohmann::json& pass : resources.at("passes")) {
    const std::string name = pass.at("name");
    CAPTURE(name);
    const gl::Handle program = buildProgram({{ShaderStage::Compute, name, {}}});
    GLint size[3] = {0, 0, 0};
    glGetProgramiv(program.get(), GL_COMPUTE_WORK_GROUP_SIZE, size);
    for (int i = 0; i < 3; ++i)
      CHECK(pass.at("workgroup_size")[static_cast<std::size_t>(i)].get<int>() == size[i]);
    ++checked;
  }
  CHECK(checked >= 30);
}

TEST_CASE("portable shaders: every program variant of the front door's frames compiles for Vulkan") {
  CREP_REQUIRE_GL();
  ScatteringFixture f("colonnade");
  Scattering scattering(smallInfo());
  std::set<std::string> frames;
  const auto run = [&](const char* what, const Scattering::FrameAttribs& a) {
    scattering.run(a);
    frames.insert(what);
  };
  run("sun, projective", f.attribs(true, false));
  {
    const SunWindow window = sunWindowTexture(f);
    Scattering::FrameAttribs a = f.attribs(true, false);
    a.lightTexture = &window.light;
    run("sun with a light texture", a);
  }
  {
    const gl::Handle volume = gl::createTexture(GL_TEXTURE_3D);
    glTextureStorage3D(volume.get(), 1, GL_RGBA16F, 32, 18, 16);
    Scattering::FroxelTarget froxels{volume.get(), {.width = 32, .height = 18, .depth = 16}, glm::dvec3(0.0)};
    Scattering::FrameAttribs a = f.attribs(true, false);
    a.froxels = &froxels;
    run("sun into froxels", a);
  }
  f.lightToward(1.0, 0.25, 0.2);
  run("sun in view (epipolar)", f.attribs(true, false));
  const Camera& c = f.scene.camera;
  const SpotLight spots[] = {
      spotToward(c, c.position() - 4.0 * c.forward() + 7.0 * c.up()),
      spotToward(c, c.position() + 9.0 * c.forward() + 1.5 * c.up() - 1.0 * c.right())};
  const PointLight point = crep::test::pointBehindLeft(c);
  Scattering::FrameAttribs local = f.attribs(true, false);
  local.light = nullptr;
  local.spotLights = std::span<const SpotLight>(spots);
  local.pointLights = std::span<const PointLight>(&point, 1);
  run("spot lights (off screen and in view) and a point light", local);

  const nlohmann::json resources = portableShaderResources();
  std::set<std::string> passes;
  int compiled = 0, shipped = 0;
  for (const ShaderStageSource& v : programVariantsBuilt()) {
    if (!isLibraryPass(v.path)) continue;
    std::string defines;
    for (const ShaderDefine& d : v.defines)
      defines += " " + d.name + "=" + d.value;
    CAPTURE(v.path);
    CAPTURE(defines);
    const ExpandedShader e = ShaderLibrary::expand(v.path, v.defines);
    const RunResult r = compileComputeForVulkan(v.path + "." + std::to_string(compiled), e.text);
    CHECK_MESSAGE(r.exitCode == 0, "not valid for Vulkan:\n" << e.translateLog(r.output));
    // Shipped: the default variant in resources.json's "passes", any other in its "variants", declared
    // in glsl/portable_variants.txt (the line to add is the message).
    const bool listed = shippedVariant(resources, v.path, v.defines) != nullptr;
    std::string stem = v.path.substr(std::string_view("passes/").size()); // <module>/<pass>.comp
    stem.resize(stem.size() - std::string_view(".comp").size());
    CHECK_MESSAGE(listed, "not shipped; glsl/portable_variants.txt needs the line\n" << stem << defines);
    shipped += listed ? 1 : 0;
    passes.insert(v.path);
    ++compiled;
  }
  MESSAGE(compiled << " variants of " << passes.size() << " passes from " << frames.size() << " frames, "
                   << shipped << " of them shipped");
  CHECK(compiled >= 15);
  CHECK(passes.count("passes/prefilter/evaluate.comp") == 1);
  CHECK(passes.count("passes/prefilter/prefilter.comp") == 1);
  CHECK(passes.count("passes/epipolar/resample.comp") == 1);
}
