// The per-frame GL pass of the atmosphere (crep/atmosphere/gpu_pass.h): crep::atmosphereImage's
// rays in float (Yusov 2013, Eq. 8 and Listings 1-2; shafts (a) and (b) over the min/max trees of Yusov
// 2012, Algorithm 2). Shader: passes/atmosphere/atmosphere.comp (with crep/atmosphere.glsl,
// crep/minmax_walk.glsl).
#include <crep/atmosphere/gpu_pass.h>
#include <crep/core/error.h>
#include <crep/core/shader_library.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_layout.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/scatter/gpu_world_march.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <string>
#include <utility>

namespace crep {

namespace {

// Texture units, uniform and storage bindings of passes/atmosphere/atmosphere.comp: CREP_ATMOSPHERE_* of
// crep/bindings.h.
constexpr int kUnits = CREP_ATMOSPHERE_SKY_MIE_UNIT + 1; ///< units and bindings unbound afterwards
                                                         ///< (gl::unbindPassState)

bool walksTrees(AtmosphereShafts shafts) {
  return shafts == AtmosphereShafts::Integrated || shafts == AtmosphereShafts::LitLengthTable;
}

void checkSteps(const char* parameter, int steps) {
  if (steps < 1 || steps > 4096)
    throw InvalidArgument(parameter, std::to_string(steps), "must be in [1, 4096]");
}

/// A GL_TEXTURE_3D (the aerial perspective volume) or GL_TEXTURE_2D (the sky-view table, size.z 0) RGBA32F;
/// read through the pass's linear clamp-to-edge sampler.
gl::Handle createViewTable(const glm::ivec3& size) {
  gl::Handle t = gl::createTexture(size.z > 0 ? GL_TEXTURE_3D : GL_TEXTURE_2D);
  if (size.z > 0)
    glTextureStorage3D(t.get(), 1, GL_RGBA32F, size.x, size.y, size.z);
  else
    glTextureStorage2D(t.get(), 1, GL_RGBA32F, size.x, size.y);
  return t;
}

} // namespace

AtmospherePass::AtmospherePass(const CreateInfo& info) : info_(info) {
  info_.options.shafts = info.shafts;
  checkSteps("AtmospherePass::CreateInfo.options.integrationSteps", info.options.integrationSteps);
  checkSteps("AtmospherePass::CreateInfo.options.skySteps", info.options.skySteps);
  const int mode = static_cast<int>(info.shafts);
  if (mode < 0 || mode > 3)
    throw InvalidArgument("AtmospherePass::CreateInfo.shafts", std::to_string(mode),
                          "must be an AtmosphereShafts");
  if (walksTrees(info.shafts)) {
    gl::checkTextureSize("AtmospherePass::CreateInfo.mapWidth/mapHeight", info.mapWidth, info.mapHeight);
    requireTreeLevels("AtmospherePass::CreateInfo.mapWidth", info.mapWidth);
  }
  validateViewTables(info.options, "AtmospherePass::CreateInfo.options");
  view_ = info.options.single == AtmosphereSingleScattering::ViewTables &&
          info.shafts != AtmosphereShafts::Integrated;
  if (view_) {
    const AtmosphereRayOptions& o = info.options;
    gl::checkTextureSize("AtmospherePass::CreateInfo.options.skyViewSize", o.skyViewSize.x, o.skyViewSize.y);
    volumeRayleigh_ = createViewTable(o.volumeSize);
    volumeMie_ = createViewTable(o.volumeSize);
    skyRayleigh_ = createViewTable(glm::ivec3(o.skyViewSize, 0));
    skyMie_ = createViewTable(glm::ivec3(o.skyViewSize, 0));
    volumeProgram_ = buildProgram({{ShaderStage::Compute,
                                    "passes/atmosphere/atmosphere.comp",
                                    {{"CREP_ATMOSPHERE_VOLUME_PASS", "1"}}}});
    skyViewProgram_ = buildProgram({{ShaderStage::Compute,
                                     "passes/atmosphere/atmosphere.comp",
                                     {{"CREP_ATMOSPHERE_VOLUME_PASS", "2"}}}});
  }
  marchParams_ = gl::createDynamicBuffer(sizeof(gpu::MarchParams));
  atmosphereParams_ = gl::createDynamicBuffer(sizeof(gpu::AtmosphereParams));
  nearest_ = gl::createClampSampler(GL_NEAREST);
  linear_ = gl::createClampSampler(GL_LINEAR);
  if (!walksTrees(info.shafts)) // the one program of None and (c): compile errors surface here
    programs_[0][0] = buildProgram({{ShaderStage::Compute,
                                     "passes/atmosphere/atmosphere.comp",
                                     {{"CREP_ATMOSPHERE_SHAFTS", std::to_string(mode)},
                                      {"CREP_ATMOSPHERE_VOLUME", view_ ? "1" : "0"}}}});
  gl::checkError("AtmospherePass");
}

/// A validated frame of the pass (AtmospherePass::validate) and what run() derives from it.
struct AtmospherePass::Plan {
  bool walk = false;         ///< shafts (a), (b): the map's min/max trees walked
  bool prefiltered = false;  ///< shafts (c)
  int width = 0, height = 0; ///< the camera image's size
  GpuLayoutData layoutData;  ///< walk: the map's layout block
};

void AtmospherePass::validate(const FrameAttribs& f, std::string_view owner) const {
  plan(f, owner);
}

AtmospherePass::Plan AtmospherePass::plan(const FrameAttribs& f, std::string_view owner) const {
  const std::string p = std::string(owner) + ".";
  Plan plan;
  plan.walk = walksTrees(info_.shafts);
  if (!f.tables) invalid(p + "tables", "null", "must be set");
  if (!f.placement) invalid(p + "placement", "null", "must be set");
  if (!f.camera) invalid(p + "camera", "null", "must be set");
  if (!f.sun) invalid(p + "sun", "null", "must be set");
  try {
    crep::validate(*f.placement, f.tables->info().parameters);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(p + "placement", e.what(), "must be valid");
  }
  const gl::TextureLevel image = gl::requireTexture2D((p + "cameraDepth").c_str(), f.cameraDepth);
  gl::requireDepthFormat((p + "cameraDepth").c_str(), f.cameraDepth);
  plan.width = image.width;
  plan.height = image.height;
  gl::requireTexture2D((p + "output").c_str(), f.output, plan.width, plan.height, GL_RGBA32F);
  if (f.transmittanceOutput != 0)
    gl::requireTexture2D((p + "transmittanceOutput").c_str(), f.transmittanceOutput, plan.width, plan.height,
                         GL_RGBA32F);
  const int W = info_.mapWidth, H = info_.mapHeight;
  if (plan.walk) {
    if (!f.layout) invalid(p + "layout", "null", "must be set (shafts (a), (b))");
    plan.layoutData = gpu::requireGpuLayout(*f.layout, (p + "layout").c_str());
    gpu::requireMapSize(*f.layout, W, H, "AtmospherePass::CreateInfo.mapWidth/mapHeight");
    gl::requireTexture2D((p + "rectifiedDepth").c_str(), f.rectifiedDepth, W, H);
    gl::requireDepthFormat((p + "rectifiedDepth").c_str(), f.rectifiedDepth);
    requireMinMaxBuffer((p + "minMaxBuffer").c_str(), f.minMaxBuffer, W, H, "shafts (a), (b)");
    gpu::LayoutBuffers::requireUploadable(plan.layoutData, H);
  }
  plan.prefiltered = info_.shafts == AtmosphereShafts::PrefilteredVisibility;
  if (plan.prefiltered) {
    gl::requireTexture2D((p + "prefiltered").c_str(), f.prefiltered, plan.width, plan.height);
    if (!f.proxyMedium) invalid(p + "proxyMedium", "null", "must be set (shafts (c))");
  }
  return plan;
}

void AtmospherePass::run(const FrameAttribs& f) {
  const Plan p = plan(f, "AtmospherePass::FrameAttribs");
  const bool combined = f.tables->info().options.combinedMie;
  gl::Handle& program = programs_[combined ? 1 : 0][p.walk ? static_cast<int>(p.layoutData.kind) : 0];
  if (!program)
    program = buildProgram({{ShaderStage::Compute,
                             "passes/atmosphere/atmosphere.comp",
                             {{"CREP_ATMOSPHERE_SHAFTS", std::to_string(static_cast<int>(info_.shafts))},
                              {"CREP_LAYOUT", std::to_string(static_cast<int>(p.layoutData.kind))},
                              {"CREP_ATMOSPHERE_COMBINED_MIE", combined ? "1" : "0"},
                              {"CREP_ATMOSPHERE_VOLUME", view_ ? "1" : "0"}}}});
  uploadBlocks(f, p);
  if (view_) computeViewTables(*f.tables);
  dispatchImage(f, p, program.get());
}

void AtmospherePass::uploadBlocks(const FrameAttribs& f, const Plan& p) {
  const int W = info_.mapWidth;
  // The march block carries the camera and the sun (and (c)'s proxy medium: the closed form of
  // prefilteredVisibility); a placeholder medium otherwise (its members are not read).
  const Medium placeholder({.absorption = glm::dvec3(1.0)});
  gpu::MarchParams params =
      gpu::makeMarchParams(*f.camera, *f.sun, p.prefiltered ? *f.proxyMedium : placeholder, p.width, p.height,
                           p.walk ? W : 0, p.walk ? info_.mapHeight : 0);
  params.info = glm::ivec4(p.walk ? MinMaxTrees::levelCount(W) : 0, p.walk ? MinMaxTrees::rowStrideFor(W) : 0,
                           info_.options.integrationSteps, info_.options.skySteps);
  if (view_) {
    params.region = glm::ivec4(info_.options.volumeSize, info_.options.volumeSteps);
    params.block =
        glm::vec4(glm::vec2(info_.options.skyViewSize), static_cast<float>(info_.options.skyViewSteps), 0.0f);
  }
  glNamedBufferSubData(marchParams_.get(), 0, sizeof(params), &params);
  const AtmosphereTablesPass::CreateInfo& tables = f.tables->info();
  const gpu::AtmosphereParams atmosphere =
      gpu::atmosphereParams(tables.parameters, tables.options, *f.placement);
  glNamedBufferSubData(atmosphereParams_.get(), 0, sizeof(atmosphere), &atmosphere);
}

// Hillaire 2020, Sec. 5.2-5.3: the camera's view tables, one ray per invocation.
void AtmospherePass::computeViewTables(const AtmosphereTablesPass& tables) {
  const glm::ivec3 vs = info_.options.volumeSize;
  const glm::ivec2 ss = info_.options.skyViewSize;
  glBindBufferBase(GL_UNIFORM_BUFFER, CREP_ATMOSPHERE_MARCH_BINDING, marchParams_.get());
  glBindBufferBase(GL_UNIFORM_BUFFER, CREP_ATMOSPHERE_PARAMS_BINDING, atmosphereParams_.get());
  glBindTextureUnit(CREP_ATMOSPHERE_OPTICAL_DEPTH_TABLE_UNIT, tables.opticalDepthTexture());
  glUseProgram(volumeProgram_.get());
  glBindImageTexture(CREP_ATMOSPHERE_VOLUME_RAYLEIGH_OUT_IMAGE, volumeRayleigh_.get(), 0, GL_TRUE, 0,
                     GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(CREP_ATMOSPHERE_VOLUME_MIE_OUT_IMAGE, volumeMie_.get(), 0, GL_TRUE, 0, GL_WRITE_ONLY,
                     GL_RGBA32F);
  glDispatchCompute(static_cast<GLuint>((vs.x + 7) / 8), static_cast<GLuint>((vs.y + 7) / 8), 1);
  glUseProgram(skyViewProgram_.get());
  glBindImageTexture(CREP_ATMOSPHERE_SKY_RAYLEIGH_OUT_IMAGE, skyRayleigh_.get(), 0, GL_FALSE, 0,
                     GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(CREP_ATMOSPHERE_SKY_MIE_OUT_IMAGE, skyMie_.get(), 0, GL_FALSE, 0, GL_WRITE_ONLY,
                     GL_RGBA32F);
  glDispatchCompute(static_cast<GLuint>((ss.x + 7) / 8), static_cast<GLuint>((ss.y + 7) / 8), 1);
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
}

void AtmospherePass::dispatchImage(const FrameAttribs& f, const Plan& p, std::uint32_t program) {
  const GLuint transmittance = f.transmittanceOutput != 0
                                   ? f.transmittanceOutput
                                   : gl::scratchTexture2D(dummyTransmittance_, dummyWidth_, dummyHeight_,
                                                          GL_RGBA32F, p.width, p.height);
  glUseProgram(program);
  glBindBufferBase(GL_UNIFORM_BUFFER, CREP_ATMOSPHERE_MARCH_BINDING, marchParams_.get());
  glBindBufferBase(GL_UNIFORM_BUFFER, CREP_ATMOSPHERE_PARAMS_BINDING, atmosphereParams_.get());
  glBindTextureUnit(CREP_ATMOSPHERE_CAMERA_DEPTH_UNIT, f.cameraDepth);
  glBindSampler(CREP_ATMOSPHERE_CAMERA_DEPTH_UNIT, nearest_.get());
  // The tables keep their own sampling state (linear, clamp to edge: AtmosphereTablesPass).
  glBindTextureUnit(CREP_ATMOSPHERE_OPTICAL_DEPTH_TABLE_UNIT, f.tables->opticalDepthTexture());
  glBindTextureUnit(CREP_ATMOSPHERE_SINGLE_TABLE_UNIT, f.tables->singleTexture());
  glBindTextureUnit(CREP_ATMOSPHERE_HIGHER_ORDERS_TABLE_UNIT, f.tables->higherOrdersTexture());
  glBindTextureUnit(CREP_ATMOSPHERE_AMBIENT_TABLE_UNIT, f.tables->ambientTexture());
  // With combinedMie there is no single Mie table (the shader does not read the unit).
  const bool combined = f.tables->info().options.combinedMie;
  glBindTextureUnit(CREP_ATMOSPHERE_SINGLE_MIE_TABLE_UNIT,
                    combined ? f.tables->singleTexture() : f.tables->singleMieTexture());
  if (p.walk) { // Yusov 2012, Algorithm 2: the rows' min/max trees
    layoutBuffers_.upload(p.layoutData, info_.mapHeight);
    layoutBuffers_.bind(CREP_LAYOUT_DEFAULT_BINDING, CREP_SLICES_DEFAULT_BINDING);
    glBindTextureUnit(CREP_ATMOSPHERE_RECTIFIED_DEPTH_UNIT, f.rectifiedDepth);
    glBindSampler(CREP_ATMOSPHERE_RECTIFIED_DEPTH_UNIT, nearest_.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, CREP_ATMOSPHERE_MIN_MAX_BINDING, f.minMaxBuffer);
  }
  if (p.prefiltered) {
    glBindTextureUnit(CREP_ATMOSPHERE_PREFILTERED_UNIT, f.prefiltered);
    glBindSampler(CREP_ATMOSPHERE_PREFILTERED_UNIT, nearest_.get());
  }
  if (view_) {
    const std::pair<GLuint, GLuint> views[] = {{CREP_ATMOSPHERE_VOLUME_RAYLEIGH_UNIT, volumeRayleigh_.get()},
                                               {CREP_ATMOSPHERE_VOLUME_MIE_UNIT, volumeMie_.get()},
                                               {CREP_ATMOSPHERE_SKY_RAYLEIGH_UNIT, skyRayleigh_.get()},
                                               {CREP_ATMOSPHERE_SKY_MIE_UNIT, skyMie_.get()}};
    for (const auto& [unit, texture] : views) {
      glBindTextureUnit(unit, texture);
      glBindSampler(unit, linear_.get());
    }
  }
  glBindImageTexture(CREP_ATMOSPHERE_INSCATTERING_OUT_IMAGE, f.output, 0, GL_FALSE, 0, GL_WRITE_ONLY,
                     GL_RGBA32F);
  glBindImageTexture(CREP_ATMOSPHERE_TRANSMITTANCE_OUT_IMAGE, transmittance, 0, GL_FALSE, 0, GL_WRITE_ONLY,
                     GL_RGBA32F);
  glDispatchCompute(static_cast<GLuint>((p.width + 7) / 8), static_cast<GLuint>((p.height + 7) / 8), 1);
  gl::passOutputBarrier();
  gl::unbindPassState(kUnits);
  gl::checkError("AtmospherePass::run");
}

} // namespace crep
