// The per-frame pass of the atmosphere on a gpu::Backend (crep/atmosphere/gpu_pass.h):
// crep::atmosphereImage's rays in float (Yusov 2013, Eq. 8 and Listings 1-2; shafts (a) and (b) over the
// min/max trees of Yusov 2012, Algorithm 2). Shader: passes/atmosphere/atmosphere.comp (with
// crep/atmosphere.glsl, crep/minmax_walk.glsl).
#include <crep/atmosphere/gpu_pass.h>
#include <crep/core/error.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_layout.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/shader_library.h>
#include <crep/scatter/gpu_world_march.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <new>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace crep {

namespace {

bool walksTrees(AtmosphereShafts shafts) {
  return shafts == AtmosphereShafts::Integrated || shafts == AtmosphereShafts::LitLengthTable;
}

void checkSteps(const char* parameter, int steps) {
  if (steps < 1 || steps > 4096)
    throw InvalidArgument(parameter, std::to_string(steps), "must be in [1, 4096]");
}

/// The aerial perspective volume (3D) or the sky-view table (2D, size.z 0), RGBA32F, read linearly.
gpu::Texture createViewTable(gpu::Backend& b, const glm::ivec3& size, const char* label) {
  return gpu::Texture(b, {size.z > 0 ? gpu::TextureType::Texture3D : gpu::TextureType::Texture2D,
                          gpu::Format::RGBA32F, size.x, size.y, std::max(size.z, 1), label});
}

constexpr const char* kProgram = "passes/atmosphere/atmosphere.comp";

} // namespace

AtmospherePass::AtmospherePass(const CreateInfo& info) : info_(info) {
  info_.options.shafts = info.shafts;
  checkSteps("AtmospherePass::CreateInfo.options.integrationSteps", info.options.integrationSteps);
  checkSteps("AtmospherePass::CreateInfo.options.skySteps", info.options.skySteps);
  const int mode = static_cast<int>(info.shafts);
  if (mode < 0 || mode > 3)
    throw InvalidArgument("AtmospherePass::CreateInfo.shafts", std::to_string(mode),
                          "must be an AtmosphereShafts");
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  gpu::Backend& b = *backend_;
  if (walksTrees(info.shafts)) {
    gpu::checkTextureSize(b, "AtmospherePass::CreateInfo.mapWidth/mapHeight", info.mapWidth, info.mapHeight);
    requireTreeLevels("AtmospherePass::CreateInfo.mapWidth", info.mapWidth);
  }
  validateViewTables(info.options, "AtmospherePass::CreateInfo.options");
  view_ = info.options.single == AtmosphereSingleScattering::ViewTables &&
          info.shafts != AtmosphereShafts::Integrated;
  if (view_) {
    const AtmosphereRayOptions& o = info.options;
    gpu::checkTextureSize(b, "AtmospherePass::CreateInfo.options.skyViewSize", o.skyViewSize.x,
                          o.skyViewSize.y);
    volumeRayleigh_ = createViewTable(b, o.volumeSize, "AtmospherePass: volume (Rayleigh)");
    volumeMie_ = createViewTable(b, o.volumeSize, "AtmospherePass: volume (Mie)");
    skyRayleigh_ = createViewTable(b, glm::ivec3(o.skyViewSize, 0), "AtmospherePass: sky view (Rayleigh)");
    skyMie_ = createViewTable(b, glm::ivec3(o.skyViewSize, 0), "AtmospherePass: sky view (Mie)");
    for (const char* pass : {"1", "2"})
      b.prepareProgram(kProgram, std::vector<ShaderDefine>{{"CREP_ATMOSPHERE_VOLUME_PASS", pass}});
  }
  marchParams_ = gpu::Buffer(b, sizeof(gpu::MarchParams), "AtmospherePass: march block");
  atmosphereParams_ = gpu::Buffer(b, sizeof(gpu::AtmosphereParams), "AtmospherePass: atmosphere block");
  layoutBuffers_ = gpu::LayoutBuffers(backend_);
  if (!walksTrees(info.shafts)) { // the one program of None and (c): compile errors surface here
    const std::vector<ShaderDefine> defines = imageDefines(false, 0);
    b.prepareProgram(kProgram, defines);
  }
}

AtmospherePass::~AtmospherePass() = default;

AtmospherePass::AtmospherePass(AtmospherePass&& o) noexcept
    : info_(o.info_), ownBackend_(std::move(o.ownBackend_)), backend_(std::exchange(o.backend_, nullptr)),
      view_(o.view_), volumeRayleigh_(std::move(o.volumeRayleigh_)), volumeMie_(std::move(o.volumeMie_)),
      skyRayleigh_(std::move(o.skyRayleigh_)), skyMie_(std::move(o.skyMie_)),
      layoutBuffers_(std::move(o.layoutBuffers_)), marchParams_(std::move(o.marchParams_)),
      atmosphereParams_(std::move(o.atmosphereParams_)),
      dummyTransmittance_(std::move(o.dummyTransmittance_)), dummyWidth_(o.dummyWidth_),
      dummyHeight_(o.dummyHeight_) {}

AtmospherePass& AtmospherePass::operator=(AtmospherePass&& o) noexcept {
  if (this != &o) {
    this->~AtmospherePass(); // the textures and buffers go before the backend that made them
    new (this) AtmospherePass(std::move(o));
  }
  return *this;
}

/// The image program's variant: shafts, layout kind (walks), combined Mie, view tables.
std::vector<ShaderDefine> AtmospherePass::imageDefines(bool combinedMie, int layoutKind) const {
  std::vector<ShaderDefine> d = {{"CREP_ATMOSPHERE_SHAFTS", std::to_string(static_cast<int>(info_.shafts))},
                                 {"CREP_ATMOSPHERE_VOLUME", view_ ? "1" : "0"}};
  if (walksTrees(info_.shafts) || combinedMie) {
    d.push_back({"CREP_LAYOUT", std::to_string(layoutKind)});
    d.push_back({"CREP_ATMOSPHERE_COMBINED_MIE", combinedMie ? "1" : "0"});
  }
  return d;
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
  gpu::requireNotMovedFrom(backend_, "AtmospherePass");
  const std::string p = std::string(owner) + ".";
  const gpu::Backend& b = *backend_;
  Plan plan;
  plan.walk = walksTrees(info_.shafts);
  if (!f.tables) invalid(p + "tables", "null", "must be set");
  if (f.tables->backend() == nullptr)
    invalid(p + "tables", "a moved-from AtmosphereTablesPass", "must hold tables");
  // Tables of another backend: their ids mean nothing here (two GL backends share the context's names).
  if (f.tables->backend() != backend_ &&
      (b.kind() != gpu::BackendKind::OpenGL || f.tables->backend()->kind() != gpu::BackendKind::OpenGL))
    invalid(p + "tables", std::string("tables on ") + std::string(f.tables->backend()->name()),
            "must be on the pass's backend (" + std::string(b.name()) + ")");
  if (!f.placement) invalid(p + "placement", "null", "must be set");
  if (!f.camera) invalid(p + "camera", "null", "must be set");
  if (!f.sun) invalid(p + "sun", "null", "must be set");
  try {
    crep::validate(*f.placement, f.tables->info().parameters);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(p + "placement", e.what(), "must be valid");
  }
  const gpu::TextureLevel image = gpu::requireTexture2DOf(b, (p + "cameraDepth").c_str(), f.cameraDepth);
  gpu::requireDepthFormatOf(b, (p + "cameraDepth").c_str(), f.cameraDepth);
  plan.width = image.width;
  plan.height = image.height;
  gpu::requireTexture2DOf(b, (p + "output").c_str(), f.output, plan.width, plan.height, gpu::Format::RGBA32F);
  if (f.transmittanceOutput != 0)
    gpu::requireTexture2DOf(b, (p + "transmittanceOutput").c_str(), f.transmittanceOutput, plan.width,
                            plan.height, gpu::Format::RGBA32F);
  const int W = info_.mapWidth, H = info_.mapHeight;
  if (plan.walk) {
    if (!f.layout) invalid(p + "layout", "null", "must be set (shafts (a), (b))");
    plan.layoutData = gpu::requireGpuLayout(*f.layout, (p + "layout").c_str());
    gpu::requireMapSize(*f.layout, W, H, "AtmospherePass::CreateInfo.mapWidth/mapHeight");
    gpu::requireTexture2DOf(b, (p + "rectifiedDepth").c_str(), f.rectifiedDepth, W, H);
    gpu::requireDepthFormatOf(b, (p + "rectifiedDepth").c_str(), f.rectifiedDepth);
    requireMinMaxBuffer(b, (p + "minMaxBuffer").c_str(), f.minMaxBuffer, W, H, "shafts (a), (b)");
    gpu::LayoutBuffers::requireUploadable(plan.layoutData, H);
  }
  plan.prefiltered = info_.shafts == AtmosphereShafts::PrefilteredVisibility;
  if (plan.prefiltered) {
    gpu::requireTexture2DOf(b, (p + "prefiltered").c_str(), f.prefiltered, plan.width, plan.height);
    if (!f.proxyMedium) invalid(p + "proxyMedium", "null", "must be set (shafts (c))");
  }
  return plan;
}

void AtmospherePass::run(const FrameAttribs& f) {
  const Plan p = plan(f, "AtmospherePass::FrameAttribs");
  uploadBlocks(f, p);
  if (view_) computeViewTables(*f.tables);
  dispatchImage(f, p);
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
  backend_->writeBuffer(marchParams_.id(), 0, std::as_bytes(std::span(&params, 1)));
  const AtmosphereTablesPass::CreateInfo& tables = f.tables->info();
  const gpu::AtmosphereParams atmosphere =
      gpu::atmosphereParams(tables.parameters, tables.options, *f.placement);
  backend_->writeBuffer(atmosphereParams_.id(), 0, std::as_bytes(std::span(&atmosphere, 1)));
}

// Hillaire 2020, Sec. 5.2-5.3: the camera's view tables, one ray per invocation.
void AtmospherePass::computeViewTables(const AtmosphereTablesPass& tables) {
  const glm::ivec3 vs = info_.options.volumeSize;
  const glm::ivec2 ss = info_.options.skyViewSize;
  const auto dispatch = [&](const char* pass, gpu::TextureId rayleigh, gpu::TextureId mie,
                            std::uint32_t rayleighImage, std::uint32_t mieImage, glm::ivec2 size) {
    gpu::Dispatch d;
    d.label = std::string("AtmospherePass (view tables ") + pass + ")";
    d.program = kProgram;
    d.defines = {{"CREP_ATMOSPHERE_VOLUME_PASS", pass}};
    d.resources = {gpu::Resource::uniform(CREP_ATMOSPHERE_MARCH_BINDING, marchParams_.id()),
                   gpu::Resource::uniform(CREP_ATMOSPHERE_PARAMS_BINDING, atmosphereParams_.id()),
                   gpu::Resource::sampled(CREP_ATMOSPHERE_OPTICAL_DEPTH_TABLE_UNIT,
                                          tables.opticalDepthTexture(), gpu::Filter::Linear),
                   gpu::Resource::image(rayleighImage, rayleigh, gpu::Access::WriteOnly),
                   gpu::Resource::image(mieImage, mie, gpu::Access::WriteOnly)};
    d.groups =
        glm::uvec3(static_cast<unsigned>((size.x + 7) / 8), static_cast<unsigned>((size.y + 7) / 8), 1u);
    backend_->dispatch(d);
  };
  dispatch("1", volumeRayleigh_.id(), volumeMie_.id(), CREP_ATMOSPHERE_VOLUME_RAYLEIGH_OUT_IMAGE,
           CREP_ATMOSPHERE_VOLUME_MIE_OUT_IMAGE, glm::ivec2(vs));
  dispatch("2", skyRayleigh_.id(), skyMie_.id(), CREP_ATMOSPHERE_SKY_RAYLEIGH_OUT_IMAGE,
           CREP_ATMOSPHERE_SKY_MIE_OUT_IMAGE, ss);
}

void AtmospherePass::dispatchImage(const FrameAttribs& f, const Plan& p) {
  gpu::Backend& b = *backend_;
  std::uint32_t transmittance = f.transmittanceOutput;
  if (transmittance == 0) { // not asked for: a scratch target of the image's size
    if (dummyWidth_ != p.width || dummyHeight_ != p.height) {
      dummyTransmittance_ = gpu::Texture(b, {gpu::TextureType::Texture2D, gpu::Format::RGBA32F, p.width,
                                             p.height, 1, "AtmospherePass: transmittance (not asked for)"});
      dummyWidth_ = p.width;
      dummyHeight_ = p.height;
    }
    transmittance = dummyTransmittance_.id();
  }
  const bool combined = f.tables->info().options.combinedMie;
  const AtmosphereTablesPass& t = *f.tables;
  const auto linear = [](std::uint32_t unit, gpu::TextureId texture) {
    return gpu::Resource::sampled(unit, texture, gpu::Filter::Linear);
  };
  gpu::Dispatch d;
  d.label = "AtmospherePass::run";
  d.program = kProgram;
  d.defines = imageDefines(combined, p.walk ? static_cast<int>(p.layoutData.kind) : 0);
  // The tables read linearly, clamped to the edge; with combinedMie there is no single Mie table (the shader
  // does not read the unit: the single table stands in).
  d.resources = {
      gpu::Resource::uniform(CREP_ATMOSPHERE_MARCH_BINDING, marchParams_.id()),
      gpu::Resource::uniform(CREP_ATMOSPHERE_PARAMS_BINDING, atmosphereParams_.id()),
      gpu::Resource::sampled(CREP_ATMOSPHERE_CAMERA_DEPTH_UNIT, f.cameraDepth),
      linear(CREP_ATMOSPHERE_OPTICAL_DEPTH_TABLE_UNIT, t.opticalDepthTexture()),
      linear(CREP_ATMOSPHERE_SINGLE_TABLE_UNIT, t.singleTexture()),
      linear(CREP_ATMOSPHERE_HIGHER_ORDERS_TABLE_UNIT, t.higherOrdersTexture()),
      linear(CREP_ATMOSPHERE_AMBIENT_TABLE_UNIT, t.ambientTexture()),
      linear(CREP_ATMOSPHERE_SINGLE_MIE_TABLE_UNIT, combined ? t.singleTexture() : t.singleMieTexture()),
      gpu::Resource::image(CREP_ATMOSPHERE_INSCATTERING_OUT_IMAGE, f.output, gpu::Access::WriteOnly),
      gpu::Resource::image(CREP_ATMOSPHERE_TRANSMITTANCE_OUT_IMAGE, transmittance, gpu::Access::WriteOnly)};
  if (p.walk) { // Yusov 2012, Algorithm 2: the rows' min/max trees
    layoutBuffers_.upload(p.layoutData, info_.mapHeight);
    layoutBuffers_.appendResources(d.resources, CREP_LAYOUT_DEFAULT_BINDING, CREP_SLICES_DEFAULT_BINDING);
    d.resources.push_back(gpu::Resource::sampled(CREP_ATMOSPHERE_RECTIFIED_DEPTH_UNIT, f.rectifiedDepth));
    d.resources.push_back(gpu::Resource::storage(CREP_ATMOSPHERE_MIN_MAX_BINDING, f.minMaxBuffer));
  }
  if (p.prefiltered)
    d.resources.push_back(gpu::Resource::sampled(CREP_ATMOSPHERE_PREFILTERED_UNIT, f.prefiltered));
  if (view_) {
    d.resources.push_back(linear(CREP_ATMOSPHERE_VOLUME_RAYLEIGH_UNIT, volumeRayleigh_.id()));
    d.resources.push_back(linear(CREP_ATMOSPHERE_VOLUME_MIE_UNIT, volumeMie_.id()));
    d.resources.push_back(linear(CREP_ATMOSPHERE_SKY_RAYLEIGH_UNIT, skyRayleigh_.id()));
    d.resources.push_back(linear(CREP_ATMOSPHERE_SKY_MIE_UNIT, skyMie_.id()));
  }
  d.groups =
      glm::uvec3(static_cast<unsigned>((p.width + 7) / 8), static_cast<unsigned>((p.height + 7) / 8), 1u);
  b.dispatch(d);
}

} // namespace crep
