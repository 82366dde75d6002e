// The atmosphere's tables on the GPU (crep/atmosphere/gpu_tables.h: gpu::atmosphereParams and
// AtmosphereTablesPass; the CPU reference and the algorithm are crep/atmosphere/atmosphere.h's). Stages, one
// compute shader each (one texel per invocation): passes/atmosphere/optical_depth.comp,
// passes/atmosphere/single.comp (L1), passes/atmosphere/scattered.comp (J_n), passes/atmosphere/order.comp
// (L_n), passes/atmosphere/sum.comp (L_H) and passes/atmosphere/ambient.comp (E_sky); look-ups of
// glsl/crep/atmosphere.glsl.
#include <crep/atmosphere/gpu_tables.h>
#include <crep/core/error.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/shader_library.h>

#include "crep/bindings.h"

#include <algorithm>
#include <chrono>
#include <new>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace crep {

namespace gpu {

AtmosphereParams atmosphereParams(const AtmosphereParameters& p, const AtmospherePrecomputeOptions& o,
                                  const AtmospherePlacement& placement) {
  AtmosphereParams a;
  a.radii =
      glm::vec4(static_cast<float>(p.earthRadius), static_cast<float>(p.earthRadius + p.atmosphereHeight),
                static_cast<float>(p.atmosphereHeight), static_cast<float>(kOccludedDensity));
  a.rayleighScattering =
      glm::vec4(glm::vec3(p.rayleighScattering), static_cast<float>(p.rayleighScaleHeight));
  a.mieScattering = glm::vec4(glm::vec3(p.mieScattering), static_cast<float>(p.mieScaleHeight));
  a.mieExtinction = glm::vec4(glm::vec3(p.mieScattering + p.mieAbsorption), static_cast<float>(p.mieG));
  a.tableSize = glm::ivec4(o.size.height, o.size.viewZenith, o.size.sunZenith, o.size.sunView);
  a.auxSizes = glm::ivec4(o.opticalDepthHeight, o.opticalDepthZenith, o.ambientSize, o.orders);
  a.placement = glm::vec4(static_cast<float>(placement.metersPerUnit),
                          static_cast<float>(placement.originAltitude), 0.0f, 0.0f);
  a.multipleScattering =
      glm::vec4(static_cast<float>(p.groundAlbedo), static_cast<float>(o.multipleScatteringSize),
                static_cast<float>(o.multipleScatteringSteps), 0.0f);
  return a;
}

} // namespace gpu

namespace {

constexpr const char* kOptions = "AtmospherePrecomputeOptions";

void requireAtMost(const std::string& parameter, int value, int limit, const char* limitName) {
  if (value > limit)
    throw InvalidArgument(parameter, std::to_string(value),
                          "must be <= " + std::string(limitName) + " (" + std::to_string(limit) + ")");
}

// A 3D texture of the packed 4D table, read with linear filtering, clamped to the edge (the look-ups').
// RGBA32F so that imageStore and the float look-ups match the CPU's float tables; on a real GPU an engine
// that is short of memory could store RGBA16F (Yusov 2013 does: 32 MB at the default size) at ~1e-3
// relative precision. Filtering is the hardware's (float weights on llvmpipe; 8-bit fractions on many
// GPUs, which blur the comparison with the CPU reference, not the image). GPU: linear filtering of RGBA32F
// is optional in Vulkan (sampledImageFilterLinear); desktop GPUs have it.
gpu::Texture createTable3D(gpu::Backend& b, const AtmosphereTableSize& s, gpu::Format format,
                           const char* label) {
  return gpu::Texture(
      b, {gpu::TextureType::Texture3D, format, s.height, s.viewZenith, s.sunZenith * s.sunView, label});
}

gpu::Texture createTexture2D(gpu::Backend& b, gpu::Format format, int width, int height, const char* label) {
  return gpu::Texture(b, {gpu::TextureType::Texture2D, format, width, height, 1, label});
}

unsigned groups(int n, int local) {
  return static_cast<unsigned>((n + local - 1) / local);
}

const char* kTableNames[3] = {"AtmosphereTablesPass: single", "AtmosphereTablesPass: single Mie",
                              "AtmosphereTablesPass: higher orders"};

} // namespace

AtmosphereTablesPass::AtmosphereTablesPass(const CreateInfo& info) : info_(info) {
  validate(info.parameters, info.options);
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  gpu::Backend& b = *backend_;
  const bool gl = b.kind() == gpu::BackendKind::OpenGL;
  const AtmospherePrecomputeOptions& o = info.options;
  const std::string size = std::string(kOptions) + ".size.";
  const int max3D = b.max3DTextureSize();
  const char* limit3D = gl ? "GL_MAX_3D_TEXTURE_SIZE" : "the backend's 3D texture size";
  requireAtMost(size + "height", o.size.height, max3D, limit3D);
  requireAtMost(size + "viewZenith", o.size.viewZenith, max3D, limit3D);
  requireAtMost(size + "sunView", o.size.sunZenith * o.size.sunView, max3D, limit3D);
  const int max2D = b.maxTextureSize();
  const char* limit2D = gl ? "GL_MAX_TEXTURE_SIZE" : "the backend's texture size";
  requireAtMost(std::string(kOptions) + ".opticalDepthHeight", o.opticalDepthHeight, max2D, limit2D);
  requireAtMost(std::string(kOptions) + ".opticalDepthZenith", o.opticalDepthZenith, max2D, limit2D);
  requireAtMost(std::string(kOptions) + ".ambientSize", o.ambientSize, max2D, limit2D);
  if (usesMultipleScatteringLut(o))
    requireAtMost(std::string(kOptions) + ".multipleScatteringSize", o.multipleScatteringSize, max2D,
                  limit2D);
  opticalDepth_ = createTexture2D(b, gpu::Format::RG32F, o.opticalDepthHeight, o.opticalDepthZenith,
                                  "AtmosphereTablesPass: optical depth");
  const gpu::Format format = info.halfFloatTables ? gpu::Format::RGBA16F : gpu::Format::RGBA32F;
  single_ = createTable3D(b, o.size, format, kTableNames[0]);
  if (!o.combinedMie) singleMie_ = createTable3D(b, o.size, format, kTableNames[1]);
  higher_ = createTable3D(b, o.size, format, kTableNames[2]);
  ambient_ = createTexture2D(b, gpu::Format::RGBA32F, o.ambientSize, 1, "AtmosphereTablesPass: ambient");
  if (usesMultipleScatteringLut(o))
    msLut_ = createTexture2D(b, gpu::Format::RGBA32F, o.multipleScatteringSize, o.multipleScatteringSize,
                             "AtmosphereTablesPass: multiple scattering LUT");
}

AtmosphereTablesPass::~AtmosphereTablesPass() = default;

AtmosphereTablesPass::AtmosphereTablesPass(AtmosphereTablesPass&& o) noexcept
    : info_(o.info_), ownBackend_(std::move(o.ownBackend_)), backend_(std::exchange(o.backend_, nullptr)),
      opticalDepth_(std::move(o.opticalDepth_)), single_(std::move(o.single_)),
      singleMie_(std::move(o.singleMie_)), higher_(std::move(o.higher_)), ambient_(std::move(o.ambient_)),
      msLut_(std::move(o.msLut_)), times_(std::move(o.times_)) {}

AtmosphereTablesPass& AtmosphereTablesPass::operator=(AtmosphereTablesPass&& o) noexcept {
  if (this != &o) {
    this->~AtmosphereTablesPass(); // the tables go before the backend that made them
    new (this) AtmosphereTablesPass(std::move(o));
  }
  return *this;
}

namespace {

/// The programs of the table stages (one compute shader each, one texel per invocation) for `o`: the J_n /
/// L_n ones with more than one order by Orders, the Psi_ms one with the Lut method.
struct TableStages {
  ShaderStageSource optical, single, sum, copy, clear, ambient, firstScattered, scattered, order, ms;
};

TableStages tableStages(const AtmospherePrecomputeOptions& o) {
  const auto stage = [](const char* path, std::vector<ShaderDefine> defines) {
    return ShaderStageSource{ShaderStage::Compute, path, std::move(defines)};
  };
  const auto steps = [](int n) {
    return std::vector<ShaderDefine>{{"CREP_ATMOSPHERE_STEPS", std::to_string(n)}};
  };
  const ShaderDefine combined{"CREP_ATMOSPHERE_COMBINED_MIE", o.combinedMie ? "1" : "0"};
  const std::vector<ShaderDefine> samples{{"CREP_ATMOSPHERE_SAMPLES", std::to_string(o.sphereSamples)},
                                          combined};
  const bool lut = usesMultipleScatteringLut(o);
  std::vector<ShaderDefine> singleDefines = steps(o.singleSteps);
  singleDefines.push_back(combined);
  singleDefines.push_back({"CREP_ATMOSPHERE_MS_LUT", lut ? "1" : "0"});
  std::vector<ShaderDefine> firstOrder = samples;
  firstOrder.push_back({"CREP_ATMOSPHERE_FIRST_ORDER", "1"});
  std::vector<ShaderDefine> msDefines = steps(o.multipleScatteringSteps);
  msDefines.push_back({"CREP_ATMOSPHERE_SAMPLES", std::to_string(o.sphereSamples)});
  TableStages t;
  t.optical = stage("passes/atmosphere/optical_depth.comp", steps(o.opticalDepthSteps));
  t.single = stage("passes/atmosphere/single.comp", singleDefines);
  t.sum = stage("passes/atmosphere/sum.comp", {});
  t.copy = stage("passes/atmosphere/sum.comp", {{"CREP_ATMOSPHERE_SUM_MODE", "1"}});
  t.clear = stage("passes/atmosphere/sum.comp", {{"CREP_ATMOSPHERE_SUM_MODE", "2"}});
  t.ambient =
      stage("passes/atmosphere/ambient.comp",
            {{"CREP_ATMOSPHERE_SAMPLES", std::to_string(kAmbientSampleFactor * o.sphereSamples)}, combined});
  t.ms = stage("passes/atmosphere/ms.comp", msDefines);
  t.firstScattered = stage("passes/atmosphere/scattered.comp", firstOrder);
  t.scattered = stage("passes/atmosphere/scattered.comp", samples);
  t.order = stage("passes/atmosphere/order.comp", steps(o.orderSteps));
  return t;
}

/// The stages a computation of `o` runs.
std::vector<const ShaderStageSource*> usedStages(const AtmospherePrecomputeOptions& o, const TableStages& t) {
  std::vector<const ShaderStageSource*> used = {&t.optical, &t.single, &t.ambient};
  const bool lut = usesMultipleScatteringLut(o);
  if (lut) used.push_back(&t.ms);
  if (o.orders == 1) used.push_back(&t.clear);
  if (o.orders > 1 && !lut)
    for (const ShaderStageSource* s : {&t.firstScattered, &t.scattered, &t.order, &t.copy, &t.sum})
      used.push_back(s);
  return used;
}

/// Each stage ends with the backend's finish() and is timed on the wall clock (GL_TIME_ELAPSED reads ~0 on
/// llvmpipe).
class StageClock {
public:
  StageClock(gpu::Backend& backend, std::vector<std::pair<std::string, double>>& times)
      : backend_(backend), times_(times) {
    backend_.finish();
    start_ = std::chrono::steady_clock::now();
  }
  void end(std::string name) {
    backend_.finish();
    const auto now = std::chrono::steady_clock::now();
    times_.emplace_back(std::move(name), std::chrono::duration<double, std::milli>(now - start_).count());
    start_ = now;
  }

private:
  gpu::Backend& backend_;
  std::vector<std::pair<std::string, double>>& times_;
  std::chrono::steady_clock::time_point start_;
};

/// The pass's tables as the stages read and write them, and the dispatches over them.
struct TableRun {
  gpu::Backend& b;
  const AtmospherePrecomputeOptions& o;
  const TableStages& stages;
  gpu::BufferId params;
  gpu::TextureId opticalDepth, msLut, single, singleMie, higher;

  /// One stage: the atmosphere block (unless `withParams` is false), `resources`, `groupCounts`.
  void dispatch(const ShaderStageSource& stage, std::vector<gpu::Resource> resources, glm::uvec3 groupCounts,
                bool withParams = true) const {
    gpu::Dispatch d;
    d.label = "AtmosphereTablesPass (" + stage.path + ")";
    d.program = stage.path;
    d.defines = stage.defines;
    if (withParams)
      d.resources.push_back(gpu::Resource::uniform(CREP_ATMOSPHERE_TABLES_PARAMS_BINDING, params));
    d.resources.insert(d.resources.end(), resources.begin(), resources.end());
    d.groups = groupCounts;
    b.dispatch(d);
  }
  /// Dispatches over a whole packed 4D table. One dispatch covers a whole table (32 x 128 x 1024 texels at
  /// the default size). On a real GPU with a watchdog (Windows TDR, ~2 s) a J_n dispatch of many sphere
  /// samples at a large size may have to be split into slabs of z; llvmpipe has no watchdog.
  glm::uvec3 tableGroups() const {
    return {groups(o.size.height, 4), groups(o.size.viewZenith, 4),
            groups(o.size.sunZenith * o.size.sunView, 4)};
  }
  static gpu::Resource linear(std::uint32_t unit, gpu::TextureId t) {
    return gpu::Resource::sampled(unit, t, gpu::Filter::Linear);
  }
  static gpu::Resource out(std::uint32_t image, gpu::TextureId t) {
    return gpu::Resource::image(image, t, gpu::Access::WriteOnly);
  }
  /// accumulator += addend (sum), = addend (copy) or = 0 (clear: addend 0).
  void accumulate(const ShaderStageSource& stage, gpu::TextureId accumulator, gpu::TextureId addend) const {
    std::vector<gpu::Resource> r = {
        gpu::Resource::image(CREP_ATMOSPHERE_TABLES_SUM_ACCUMULATOR_IMAGE, accumulator,
                             &stage == &stages.sum ? gpu::Access::ReadWrite : gpu::Access::WriteOnly)};
    if (addend != 0)
      r.push_back(
          gpu::Resource::image(CREP_ATMOSPHERE_TABLES_SUM_ADDEND_IMAGE, addend, gpu::Access::ReadOnly));
    dispatch(stage, r, tableGroups(), false);
  }
};

// The optical depth, Psi_ms (Hillaire 2020, the Lut method), L1 without its phase functions (S_R, S_M) and,
// with the Lut method, L_H in the same march.
void computeSingle(const TableRun& t, StageClock& clock) {
  const AtmospherePrecomputeOptions& o = t.o;
  const bool lut = usesMultipleScatteringLut(o);
  t.dispatch(t.stages.optical,
             {TableRun::out(CREP_ATMOSPHERE_TABLES_OPTICAL_DEPTH_OUTPUT_IMAGE, t.opticalDepth)},
             {groups(o.opticalDepthHeight, 8), groups(o.opticalDepthZenith, 8), 1u});
  clock.end("optical depth");

  if (lut) { // Psi_ms (Hillaire 2020, the Lut method)
    t.dispatch(t.stages.ms,
               {TableRun::linear(CREP_ATMOSPHERE_TABLES_MS_OPTICAL_DEPTH_UNIT, t.opticalDepth),
                TableRun::out(CREP_ATMOSPHERE_TABLES_MS_OUTPUT_IMAGE, t.msLut)},
               {groups(o.multipleScatteringSize, 8), groups(o.multipleScatteringSize, 8), 1u});
    clock.end("multiple scattering LUT");
  }

  // L1 without its phase functions (S_R, S_M); Lut: L_H in the same march.
  std::vector<gpu::Resource> r = {
      TableRun::linear(CREP_ATMOSPHERE_TABLES_SINGLE_OPTICAL_DEPTH_UNIT, t.opticalDepth),
      TableRun::out(CREP_ATMOSPHERE_TABLES_SINGLE_OUTPUT_IMAGE, t.single)};
  if (!o.combinedMie) r.push_back(TableRun::out(CREP_ATMOSPHERE_TABLES_SINGLE_OUTPUT_MIE_IMAGE, t.singleMie));
  if (lut) {
    r.push_back(TableRun::linear(CREP_ATMOSPHERE_TABLES_SINGLE_MS_LUT_UNIT, t.msLut));
    r.push_back(TableRun::out(CREP_ATMOSPHERE_TABLES_SINGLE_OUTPUT_HIGHER_IMAGE, t.higher));
  }
  t.dispatch(t.stages.single, r, t.tableGroups());
  if (o.orders == 1) t.accumulate(t.stages.clear, t.higher, 0); // L_H = 0 (timed with single scattering)
  clock.end(lut ? "single scattering and L_H" : "single scattering");
}

// J_n and L_n ping-pong through two scratch tables: J_n reads L_(n-1) (L1 or the previous L_n), L_n reads J_n
// and overwrites the previous L_n, already added to L_H.
void computeOrders(const TableRun& t, StageClock& clock) {
  const AtmospherePrecomputeOptions& o = t.o;
  // The single Mie unit of the passes that read L1 (the single table itself with combinedMie: not read).
  const gpu::TextureId mieTable = o.combinedMie ? t.single : t.singleMie;
  const gpu::Texture scattered =
      createTable3D(t.b, o.size, gpu::Format::RGBA32F, "AtmosphereTablesPass: J_n");
  const gpu::Texture order = createTable3D(t.b, o.size, gpu::Format::RGBA32F, "AtmosphereTablesPass: L_n");
  for (int n = 2; n <= o.orders; ++n) {
    const std::string name = "order " + std::to_string(n) + ": ";
    std::vector<gpu::Resource> r = {
        TableRun::linear(CREP_ATMOSPHERE_TABLES_SCATTERED_PREVIOUS_ORDER_UNIT,
                         n == 2 ? t.single : order.id()),
        TableRun::out(CREP_ATMOSPHERE_TABLES_SCATTERED_OUTPUT_IMAGE, scattered.id())};
    if (n == 2) { // L1's Mie part and, for the ground's bounce, the optical depth table
      r.push_back(TableRun::linear(CREP_ATMOSPHERE_TABLES_SCATTERED_SINGLE_MIE_UNIT, mieTable));
      r.push_back(TableRun::linear(CREP_ATMOSPHERE_TABLES_SCATTERED_OPTICAL_DEPTH_UNIT, t.opticalDepth));
    }
    t.dispatch(n == 2 ? t.stages.firstScattered : t.stages.scattered, r, t.tableGroups());
    clock.end(name + "J");
    t.dispatch(t.stages.order,
               {TableRun::linear(CREP_ATMOSPHERE_TABLES_ORDER_SCATTERED_UNIT, scattered.id()),
                TableRun::out(CREP_ATMOSPHERE_TABLES_ORDER_OUTPUT_IMAGE, order.id())},
               t.tableGroups());
    // L_H += L_n (timed with this L stage).
    t.accumulate(n == 2 ? t.stages.copy : t.stages.sum, t.higher, order.id());
    clock.end(name + "L");
  }
}

} // namespace

void AtmosphereTablesPass::compute() {
  gpu::requireNotMovedFrom(backend_, "AtmosphereTablesPass");
  const AtmospherePrecomputeOptions& o = info_.options;
  gpu::Backend& b = *backend_;
  times_.clear();
  const TableStages stages = tableStages(o);
  const std::vector<const ShaderStageSource*> used = usedStages(o, stages);
  for (const ShaderStageSource* s : used)
    b.prepareProgram(s->path, s->defines);
  // halfFloatTables: compute into RGBA32F tables, then round them once into the RGBA16F ones (the stages
  // store to rgba32f images and the orders read the tables they wrote).
  gpu::Texture* const tables[3] = {&single_, &singleMie_, &higher_};
  gpu::Texture halves[3];
  if (info_.halfFloatTables)
    for (int i = 0; i < 3; ++i) {
      if (tables[i]->id() == 0) continue;
      halves[i] = std::move(*tables[i]);
      *tables[i] = createTable3D(b, o.size, gpu::Format::RGBA32F, kTableNames[i]);
    }
  const gpu::AtmosphereParams params = gpu::atmosphereParams(info_.parameters, o);
  const gpu::Buffer block(b, sizeof params, "AtmosphereTablesPass: atmosphere block");
  b.writeBuffer(block.id(), 0, std::as_bytes(std::span(&params, 1)));

  StageClock clock(b, times_);
  const TableRun run{
      b, o, stages, block.id(), opticalDepth_.id(), msLut_.id(), single_.id(), singleMie_.id(), higher_.id()};
  computeSingle(run, clock);
  if (o.orders > 1 && !usesMultipleScatteringLut(o)) computeOrders(run, clock);

  // E_sky.
  run.dispatch(stages.ambient,
               {TableRun::linear(CREP_ATMOSPHERE_TABLES_AMBIENT_SINGLE_UNIT, single_.id()),
                TableRun::linear(CREP_ATMOSPHERE_TABLES_AMBIENT_SINGLE_MIE_UNIT,
                                 o.combinedMie ? single_.id() : singleMie_.id()),
                TableRun::linear(CREP_ATMOSPHERE_TABLES_AMBIENT_HIGHER_ORDERS_UNIT, higher_.id()),
                TableRun::out(CREP_ATMOSPHERE_TABLES_AMBIENT_OUTPUT_IMAGE, ambient_.id())},
               {groups(o.ambientSize, 64), 1u, 1u});
  clock.end("ambient");

  if (info_.halfFloatTables) {
    // Through the host: the backend converts float to half on upload.
    for (int i = 0; i < 3; ++i) {
      if (halves[i].id() == 0) continue;
      b.writeTexture(halves[i].id(), b.readTexture(tables[i]->id()));
      *tables[i] = std::move(halves[i]);
    }
    clock.end("RGBA16F rounding");
  }
}

namespace {

bool sameSize(const AtmosphereTableSize& a, const AtmosphereTableSize& b) {
  return a.height == b.height && a.viewZenith == b.viewZenith && a.sunZenith == b.sunZenith &&
         a.sunView == b.sunView;
}

/// RGB texels as RGBA (alpha 0), and back.
std::vector<float> rgba(const Image& rgb) {
  std::vector<float> out(static_cast<std::size_t>(rgb.width()) * static_cast<std::size_t>(rgb.height()) * 4,
                         0.0f);
  for (int y = 0; y < rgb.height(); ++y)
    for (int x = 0; x < rgb.width(); ++x)
      for (int c = 0; c < 3; ++c)
        out[(static_cast<std::size_t>(y) * rgb.width() + x) * 4 + c] = rgb.at(x, y, c);
  return out;
}

Image rgb(const std::vector<float>& rgba, int width, int height) {
  Image out(width, height, 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c)
        out.at(x, y, c) = rgba[(static_cast<std::size_t>(y) * width + x) * 4 + c];
  return out;
}

} // namespace

void AtmosphereTablesPass::upload(const AtmosphereTables& tables) {
  gpu::requireNotMovedFrom(backend_, "AtmosphereTablesPass");
  const AtmospherePrecomputeOptions& o = info_.options;
  const auto fail = [](const std::string& why) {
    throw InvalidArgument("AtmosphereTablesPass::upload.tables", "(tables)", why);
  };
  if (atmosphereCacheKey(tables.parameters, tables.options) != atmosphereCacheKey(info_.parameters, o))
    fail("must have the parameters and options of the pass's CreateInfo");
  std::vector<std::pair<gpu::TextureId, const AtmosphereTable4D*>> targets = {
      {single_.id(), &tables.single}, {higher_.id(), &tables.higherOrders}};
  if (!o.combinedMie) targets.emplace_back(singleMie_.id(), &tables.singleMie);
  for (const auto& [texture, t] : targets)
    if (!sameSize(t->size, o.size) || t->rgba.size() != t->texels() * 4)
      fail("4D tables must be of the CreateInfo's size");
  if (tables.opticalDepth.width() != o.opticalDepthHeight ||
      tables.opticalDepth.height() != o.opticalDepthZenith || tables.opticalDepth.channels() != 2)
    fail("opticalDepth must be opticalDepthHeight x opticalDepthZenith with 2 channels");
  if (tables.ambient.width() != o.ambientSize || tables.ambient.height() != 1 ||
      tables.ambient.channels() != 3)
    fail("ambient must be ambientSize x 1 with 3 channels");
  const bool lut = usesMultipleScatteringLut(o);
  if (lut && (tables.multipleScatteringLut.width() != o.multipleScatteringSize ||
              tables.multipleScatteringLut.height() != o.multipleScatteringSize ||
              tables.multipleScatteringLut.channels() != 3))
    fail("multipleScatteringLut must be multipleScatteringSize^2 with 3 channels");

  gpu::Backend& b = *backend_;
  b.writeTexture(opticalDepth_.id(), tables.opticalDepth.data());
  for (const auto& [texture, table] : targets)
    b.writeTexture(texture, table->rgba);
  b.writeTexture(ambient_.id(), rgba(tables.ambient));
  if (lut) b.writeTexture(msLut_.id(), rgba(tables.multipleScatteringLut));
}

AtmosphereTables AtmosphereTablesPass::download() const {
  gpu::requireNotMovedFrom(backend_, "AtmosphereTablesPass");
  const AtmospherePrecomputeOptions& o = info_.options;
  gpu::Backend& b = *backend_;
  AtmosphereTables t;
  t.parameters = info_.parameters;
  t.options = o;
  t.options.keepOrders = false;
  t.opticalDepth = Image(o.opticalDepthHeight, o.opticalDepthZenith, 2);
  const std::vector<float> optical = b.readTexture(opticalDepth_.id());
  std::copy(optical.begin(), optical.end(), t.opticalDepth.data().begin());
  std::vector<std::pair<gpu::TextureId, AtmosphereTable4D*>> sources = {{single_.id(), &t.single},
                                                                        {higher_.id(), &t.higherOrders}};
  if (!o.combinedMie) sources.emplace_back(singleMie_.id(), &t.singleMie);
  for (const auto& [texture, table] : sources) {
    table->size = o.size;
    table->rgba = b.readTexture(texture);
  }
  t.ambient = rgb(b.readTexture(ambient_.id()), o.ambientSize, 1);
  if (usesMultipleScatteringLut(o))
    t.multipleScatteringLut =
        rgb(b.readTexture(msLut_.id()), o.multipleScatteringSize, o.multipleScatteringSize);
  return t;
}

} // namespace crep
