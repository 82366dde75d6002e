// The atmosphere's tables on the GPU (crep/atmosphere/gpu_tables.h: gpu::atmosphereParams and
// AtmosphereTablesPass; the CPU reference and the algorithm are crep/atmosphere/atmosphere.h's). Stages, one
// compute shader each (one texel per invocation): passes/atmosphere/optical_depth.comp,
// passes/atmosphere/single.comp (L1), passes/atmosphere/scattered.comp (J_n), passes/atmosphere/order.comp
// (L_n), passes/atmosphere/sum.comp (L_H) and passes/atmosphere/ambient.comp (E_sky); look-ups of
// glsl/crep/atmosphere.glsl.
#include <crep/atmosphere/gpu_tables.h>
#include <crep/core/error.h>
#include <crep/core/gl_state.h>
#include <crep/core/shader_library.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <chrono>
#include <cstring>
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

int max3DTextureSize() {
  GLint v = 0;
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &v);
  return v;
}

void requireAtMost(const std::string& parameter, int value, int limit, const char* limitName) {
  if (value > limit)
    throw InvalidArgument(parameter, std::to_string(value),
                          "must be <= " + std::string(limitName) + " (" + std::to_string(limit) + ")");
}

// A GL_TEXTURE_3D RGBA32F of the packed 4D table, linear filtering and clamp to edge (the look-ups').
// RGBA32F so that imageStore and the float look-ups match the CPU's float tables; on a real GPU an engine
// that is short of memory could store RGBA16F (Yusov 2013 does: 32 MB at the default size) at ~1e-3
// relative precision. Filtering is the hardware's (float weights on llvmpipe; 8-bit fractions on many
// GPUs, which blur the comparison with the CPU reference, not the image).
gl::Handle createTable3D(const AtmosphereTableSize& s, GLenum format = GL_RGBA32F) {
  gl::Handle t = gl::createTexture(GL_TEXTURE_3D);
  glTextureStorage3D(t.get(), 1, format, s.height, s.viewZenith, s.sunZenith * s.sunView);
  glTextureParameteri(t.get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(t.get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(t.get(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(t.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTextureParameteri(t.get(), GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
  return t;
}

gl::Handle createLinearTexture2D(std::uint32_t format, int width, int height) {
  gl::Handle t = gl::createTexture2D(format, width, height);
  glTextureParameteri(t.get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(t.get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  return t;
}

GLuint groups(int n, int local) {
  return static_cast<GLuint>((n + local - 1) / local);
}

} // namespace

AtmosphereTablesPass::AtmosphereTablesPass(const CreateInfo& info) : info_(info) {
  validate(info.parameters, info.options);
  const AtmospherePrecomputeOptions& o = info.options;
  const std::string size = std::string(kOptions) + ".size.";
  const int max3D = max3DTextureSize();
  requireAtMost(size + "height", o.size.height, max3D, "GL_MAX_3D_TEXTURE_SIZE");
  requireAtMost(size + "viewZenith", o.size.viewZenith, max3D, "GL_MAX_3D_TEXTURE_SIZE");
  requireAtMost(size + "sunView", o.size.sunZenith * o.size.sunView, max3D, "GL_MAX_3D_TEXTURE_SIZE");
  const int max2D = gl::maxTextureSize();
  requireAtMost(std::string(kOptions) + ".opticalDepthHeight", o.opticalDepthHeight, max2D,
                "GL_MAX_TEXTURE_SIZE");
  requireAtMost(std::string(kOptions) + ".opticalDepthZenith", o.opticalDepthZenith, max2D,
                "GL_MAX_TEXTURE_SIZE");
  requireAtMost(std::string(kOptions) + ".ambientSize", o.ambientSize, max2D, "GL_MAX_TEXTURE_SIZE");
  gl::checkError("AtmosphereTablesPass (before allocation)");
  opticalDepth_ = createLinearTexture2D(GL_RG32F, o.opticalDepthHeight, o.opticalDepthZenith);
  const GLenum format = info.halfFloatTables ? GL_RGBA16F : GL_RGBA32F;
  single_ = createTable3D(o.size, format);
  if (!o.combinedMie) singleMie_ = createTable3D(o.size, format);
  higher_ = createTable3D(o.size, format);
  ambient_ = createLinearTexture2D(GL_RGBA32F, o.ambientSize, 1);
  if (usesMultipleScatteringLut(o)) {
    requireAtMost(std::string(kOptions) + ".multipleScatteringSize", o.multipleScatteringSize, max2D,
                  "GL_MAX_TEXTURE_SIZE");
    msLut_ = createLinearTexture2D(GL_RGBA32F, o.multipleScatteringSize, o.multipleScatteringSize);
  }
  gl::checkError("AtmosphereTablesPass: allocating the tables");
}

namespace {

/// The programs of the table stages (one compute shader each, one texel per invocation) for `o`: the J_n /
/// L_n ones with more than one order by Orders, the Psi_ms one with the Lut method.
struct TablePrograms {
  gl::Handle optical, single, sum, ambient, firstScattered, scattered, order, ms;
};

TablePrograms buildTablePrograms(const AtmospherePrecomputeOptions& o) {
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
  TablePrograms p;
  p.optical = buildProgram(
      {{ShaderStage::Compute, "passes/atmosphere/optical_depth.comp", steps(o.opticalDepthSteps)}});
  p.single = buildProgram({{ShaderStage::Compute, "passes/atmosphere/single.comp", singleDefines}});
  p.sum = buildProgram({{ShaderStage::Compute, "passes/atmosphere/sum.comp", {}}});
  const std::vector<ShaderDefine> ambientSamples{
      {"CREP_ATMOSPHERE_SAMPLES", std::to_string(kAmbientSampleFactor * o.sphereSamples)}, combined};
  p.ambient = buildProgram({{ShaderStage::Compute, "passes/atmosphere/ambient.comp", ambientSamples}});
  if (lut) {
    std::vector<ShaderDefine> msDefines = steps(o.multipleScatteringSteps);
    msDefines.push_back({"CREP_ATMOSPHERE_SAMPLES", std::to_string(o.sphereSamples)});
    p.ms = buildProgram({{ShaderStage::Compute, "passes/atmosphere/ms.comp", msDefines}});
  }
  if (o.orders > 1 && !lut) {
    p.firstScattered = buildProgram({{ShaderStage::Compute, "passes/atmosphere/scattered.comp", firstOrder}});
    p.scattered = buildProgram({{ShaderStage::Compute, "passes/atmosphere/scattered.comp", samples}});
    p.order = buildProgram({{ShaderStage::Compute, "passes/atmosphere/order.comp", steps(o.orderSteps)}});
  }
  return p;
}

/// Each stage ends with glFinish and is timed on the wall clock (GL_TIME_ELAPSED reads ~0 on llvmpipe).
class StageClock {
public:
  explicit StageClock(std::vector<std::pair<std::string, double>>& times) : times_(times) {
    glFinish();
    start_ = std::chrono::steady_clock::now();
  }
  void end(std::string name) {
    glFinish();
    const auto now = std::chrono::steady_clock::now();
    times_.emplace_back(std::move(name), std::chrono::duration<double, std::milli>(now - start_).count());
    start_ = now;
  }

private:
  std::vector<std::pair<std::string, double>>& times_;
  std::chrono::steady_clock::time_point start_;
};

/// Dispatches over a whole packed 4D table of size `s`. One dispatch covers a whole table (32 x 128 x 1024
/// texels at the default size). On a real GPU with a watchdog (Windows TDR, ~2 s) a J_n dispatch of many
/// sphere samples at a large size may have to be split into slabs of z; llvmpipe has no watchdog.
struct TableDispatch {
  const AtmosphereTableSize& s;
  int depth() const { return s.sunZenith * s.sunView; }
  void dispatch() const {
    glDispatchCompute(groups(s.height, 4), groups(s.viewZenith, 4), groups(depth(), 4));
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT |
                    GL_TEXTURE_UPDATE_BARRIER_BIT);
  }
  /// accumulator += addend with the sum program.
  void sum(GLuint program, GLuint accumulator, GLuint addend) const {
    glUseProgram(program);
    glBindImageTexture(CREP_ATMOSPHERE_TABLES_SUM_ACCUMULATOR_IMAGE, accumulator, 0, GL_TRUE, 0,
                       GL_READ_WRITE, GL_RGBA32F);
    glBindImageTexture(CREP_ATMOSPHERE_TABLES_SUM_ADDEND_IMAGE, addend, 0, GL_TRUE, 0, GL_READ_ONLY,
                       GL_RGBA32F);
    dispatch();
  }
  void copy(GLuint from, GLuint to) const {
    glCopyImageSubData(from, GL_TEXTURE_3D, 0, 0, 0, 0, to, GL_TEXTURE_3D, 0, 0, 0, 0, s.height, s.viewZenith,
                       depth());
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  }
};

/// The pass's tables, as the stages read and write them.
struct TableTextures {
  GLuint opticalDepth, msLut, single, singleMie, higher;
};

// The optical depth, Psi_ms (Hillaire 2020, the Lut method), L1 without its phase functions (S_R, S_M) and,
// with the Lut method, L_H in the same march.
void computeSingle(const AtmospherePrecomputeOptions& o, const TableTextures& t,
                   const TablePrograms& programs, StageClock& clock) {
  const bool lut = usesMultipleScatteringLut(o);
  // Optical depth.
  glUseProgram(programs.optical.get());
  glBindImageTexture(CREP_ATMOSPHERE_TABLES_OPTICAL_DEPTH_OUTPUT_IMAGE, t.opticalDepth, 0, GL_FALSE, 0,
                     GL_WRITE_ONLY, GL_RG32F);
  glDispatchCompute(groups(o.opticalDepthHeight, 8), groups(o.opticalDepthZenith, 8), 1);
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  clock.end("optical depth");

  // Psi_ms (Hillaire 2020, the Lut method).
  if (lut) {
    glUseProgram(programs.ms.get());
    glBindTextureUnit(CREP_ATMOSPHERE_TABLES_MS_OPTICAL_DEPTH_UNIT, t.opticalDepth);
    glBindImageTexture(CREP_ATMOSPHERE_TABLES_MS_OUTPUT_IMAGE, t.msLut, 0, GL_FALSE, 0, GL_WRITE_ONLY,
                       GL_RGBA32F);
    glDispatchCompute(groups(o.multipleScatteringSize, 8), groups(o.multipleScatteringSize, 8), 1);
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    clock.end("multiple scattering LUT");
  }

  // L1 without its phase functions (S_R, S_M); Lut: L_H in the same march.
  glUseProgram(programs.single.get());
  glBindTextureUnit(CREP_ATMOSPHERE_TABLES_SINGLE_OPTICAL_DEPTH_UNIT, t.opticalDepth);
  glBindImageTexture(CREP_ATMOSPHERE_TABLES_SINGLE_OUTPUT_IMAGE, t.single, 0, GL_TRUE, 0, GL_WRITE_ONLY,
                     GL_RGBA32F);
  if (!o.combinedMie)
    glBindImageTexture(CREP_ATMOSPHERE_TABLES_SINGLE_OUTPUT_MIE_IMAGE, t.singleMie, 0, GL_TRUE, 0,
                       GL_WRITE_ONLY, GL_RGBA32F);
  if (lut) {
    glBindTextureUnit(CREP_ATMOSPHERE_TABLES_SINGLE_MS_LUT_UNIT, t.msLut);
    glBindImageTexture(CREP_ATMOSPHERE_TABLES_SINGLE_OUTPUT_HIGHER_IMAGE, t.higher, 0, GL_TRUE, 0,
                       GL_WRITE_ONLY, GL_RGBA32F);
  }
  TableDispatch{o.size}.dispatch();
  if (o.orders == 1) {
    // L_H = 0 (timed with single scattering).
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    glClearTexImage(t.higher, 0, GL_RGBA, GL_FLOAT, zero);
  }
  clock.end(lut ? "single scattering and L_H" : "single scattering");
}

// J_n and L_n ping-pong through two scratch tables: J_n reads L_(n-1) (L1 or the previous L_n), L_n reads J_n
// and overwrites the previous L_n, already added to L_H.
void computeOrders(const AtmospherePrecomputeOptions& o, const TableTextures& t,
                   const TablePrograms& programs, StageClock& clock) {
  const TableDispatch table{o.size};
  // The single Mie unit of the passes that read L1 (the single table itself with combinedMie: not read).
  const GLuint mieTable = o.combinedMie ? t.single : t.singleMie;
  gl::Handle scattered = createTable3D(o.size);
  gl::Handle order = createTable3D(o.size);
  gl::checkError("AtmosphereTablesPass::compute: allocating the scratch tables");
  for (int n = 2; n <= o.orders; ++n) {
    const std::string name = "order " + std::to_string(n) + ": ";
    glUseProgram(n == 2 ? programs.firstScattered.get() : programs.scattered.get());
    glBindTextureUnit(CREP_ATMOSPHERE_TABLES_SCATTERED_PREVIOUS_ORDER_UNIT, n == 2 ? t.single : order.get());
    if (n == 2) { // L1's Mie part and, for the ground's bounce, the optical depth table
      glBindTextureUnit(CREP_ATMOSPHERE_TABLES_SCATTERED_SINGLE_MIE_UNIT, mieTable);
      glBindTextureUnit(CREP_ATMOSPHERE_TABLES_SCATTERED_OPTICAL_DEPTH_UNIT, t.opticalDepth);
    }
    glBindImageTexture(CREP_ATMOSPHERE_TABLES_SCATTERED_OUTPUT_IMAGE, scattered.get(), 0, GL_TRUE, 0,
                       GL_WRITE_ONLY, GL_RGBA32F);
    table.dispatch();
    clock.end(name + "J");
    glUseProgram(programs.order.get());
    glBindTextureUnit(CREP_ATMOSPHERE_TABLES_ORDER_SCATTERED_UNIT, scattered.get());
    glBindImageTexture(CREP_ATMOSPHERE_TABLES_ORDER_OUTPUT_IMAGE, order.get(), 0, GL_TRUE, 0, GL_WRITE_ONLY,
                       GL_RGBA32F);
    table.dispatch();
    // L_H += L_n (timed with this L stage).
    if (n == 2)
      table.copy(order.get(), t.higher);
    else
      table.sum(programs.sum.get(), t.higher, order.get());
    clock.end(name + "L");
  }
}

// halfFloatTables: the RGBA32F tables rounded to the RGBA16F ones through the host (GL converts float to half
// on upload), which then replace them.
void roundToHalf(const AtmosphereTableSize& s, gl::Handle* const (&tables)[3],
                 std::vector<gl::Handle>& halves) {
  const int depth = s.sunZenith * s.sunView;
  std::vector<float> texels(static_cast<std::size_t>(s.height) * s.viewZenith * depth * 4);
  const GLsizei bytes = static_cast<GLsizei>(texels.size() * sizeof(float));
  for (int i = 0; i < 3; ++i) {
    if (!halves[static_cast<std::size_t>(i)]) continue;
    glGetTextureImage(tables[i]->get(), 0, GL_RGBA, GL_FLOAT, bytes, texels.data());
    glTextureSubImage3D(halves[static_cast<std::size_t>(i)].get(), 0, 0, 0, 0, s.height, s.viewZenith, depth,
                        GL_RGBA, GL_FLOAT, texels.data());
    *tables[i] = std::move(halves[static_cast<std::size_t>(i)]);
  }
}
} // namespace

void AtmosphereTablesPass::compute() {
  const AtmospherePrecomputeOptions& o = info_.options;
  times_.clear();
  // halfFloatTables: compute into RGBA32F tables, then round them once into the RGBA16F ones (the stages
  // store to rgba32f images and the orders read the tables they wrote).
  std::vector<gl::Handle> halves;
  if (info_.halfFloatTables) {
    for (gl::Handle* table : {&single_, &singleMie_, &higher_}) {
      halves.push_back(std::move(*table));
      if (halves.back()) *table = createTable3D(o.size);
    }
  }
  const gpu::AtmosphereParams params = gpu::atmosphereParams(info_.parameters, o);
  gl::Handle block = gl::createDynamicBuffer(sizeof params);
  glNamedBufferSubData(block.get(), 0, sizeof params, &params);
  const TablePrograms programs = buildTablePrograms(o);

  StageClock clock(times_);
  glBindBufferBase(GL_UNIFORM_BUFFER, CREP_ATMOSPHERE_TABLES_PARAMS_BINDING, block.get());
  // Samplers of the texture units the stages read (CREP_ATMOSPHERE_TABLES_*_UNIT, 0-2): none, whatever the
  // engine left there (each texture's own linear, clamp-to-edge state).
  glBindSamplers(0, 3, nullptr);
  const TableTextures t{opticalDepth_.get(), msLut_.get(), single_.get(), singleMie_.get(), higher_.get()};
  computeSingle(o, t, programs, clock);
  if (o.orders > 1 && !usesMultipleScatteringLut(o)) computeOrders(o, t, programs, clock);

  // E_sky.
  glUseProgram(programs.ambient.get());
  glBindTextureUnit(CREP_ATMOSPHERE_TABLES_AMBIENT_SINGLE_UNIT, single_.get());
  glBindTextureUnit(CREP_ATMOSPHERE_TABLES_AMBIENT_SINGLE_MIE_UNIT,
                    o.combinedMie ? single_.get() : singleMie_.get());
  glBindTextureUnit(CREP_ATMOSPHERE_TABLES_AMBIENT_HIGHER_ORDERS_UNIT, higher_.get());
  glBindImageTexture(CREP_ATMOSPHERE_TABLES_AMBIENT_OUTPUT_IMAGE, ambient_.get(), 0, GL_FALSE, 0,
                     GL_WRITE_ONLY, GL_RGBA32F);
  glDispatchCompute(groups(o.ambientSize, 64), 1, 1);
  gl::passOutputBarrier();
  clock.end("ambient");

  gl::unbindPassState(3);
  if (info_.halfFloatTables) {
    roundToHalf(o.size, {&single_, &singleMie_, &higher_}, halves);
    clock.end("RGBA16F rounding");
  }
  gl::checkError("AtmosphereTablesPass::compute");
}

namespace {

bool sameSize(const AtmosphereTableSize& a, const AtmosphereTableSize& b) {
  return a.height == b.height && a.viewZenith == b.viewZenith && a.sunZenith == b.sunZenith &&
         a.sunView == b.sunView;
}

} // namespace

void AtmosphereTablesPass::upload(const AtmosphereTables& tables) {
  const AtmospherePrecomputeOptions& o = info_.options;
  const auto fail = [](const std::string& why) {
    throw InvalidArgument("AtmosphereTablesPass::upload.tables", "(tables)", why);
  };
  if (atmosphereCacheKey(tables.parameters, tables.options) != atmosphereCacheKey(info_.parameters, o))
    fail("must have the parameters and options of the pass's CreateInfo");
  std::vector<std::pair<GLuint, const AtmosphereTable4D*>> targets = {{single_.get(), &tables.single},
                                                                      {higher_.get(), &tables.higherOrders}};
  if (!o.combinedMie) targets.emplace_back(singleMie_.get(), &tables.singleMie);
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

  const gl::PixelStoreScope
      pixelStore; // tightly packed floats, no pixel unpack buffer: whatever the caller left
  glTextureSubImage2D(opticalDepth_.get(), 0, 0, 0, o.opticalDepthHeight, o.opticalDepthZenith, GL_RG,
                      GL_FLOAT, tables.opticalDepth.data().data());
  const int depth = o.size.sunZenith * o.size.sunView;
  for (const auto& [texture, table] : targets)
    glTextureSubImage3D(texture, 0, 0, 0, 0, o.size.height, o.size.viewZenith, depth, GL_RGBA, GL_FLOAT,
                        table->rgba.data());
  glTextureSubImage2D(ambient_.get(), 0, 0, 0, o.ambientSize, 1, GL_RGB, GL_FLOAT,
                      tables.ambient.data().data());
  if (lut)
    glTextureSubImage2D(msLut_.get(), 0, 0, 0, o.multipleScatteringSize, o.multipleScatteringSize, GL_RGB,
                        GL_FLOAT, tables.multipleScatteringLut.data().data());
  gl::passOutputBarrier();
  gl::checkError("AtmosphereTablesPass::upload");
}

AtmosphereTables AtmosphereTablesPass::download() const {
  const AtmospherePrecomputeOptions& o = info_.options;
  AtmosphereTables t;
  t.parameters = info_.parameters;
  t.options = o;
  t.options.keepOrders = false;
  const gl::PixelStoreScope
      pixelStore; // tightly packed floats, no pixel pack buffer: whatever the caller left
  t.opticalDepth = Image(o.opticalDepthHeight, o.opticalDepthZenith, 2);
  glGetTextureImage(opticalDepth_.get(), 0, GL_RG, GL_FLOAT, static_cast<GLsizei>(t.opticalDepth.byteSize()),
                    t.opticalDepth.data().data());
  std::vector<std::pair<GLuint, AtmosphereTable4D*>> sources = {{single_.get(), &t.single},
                                                                {higher_.get(), &t.higherOrders}};
  if (!o.combinedMie) sources.emplace_back(singleMie_.get(), &t.singleMie);
  for (const auto& [texture, table] : sources) {
    table->size = o.size;
    table->rgba.assign(table->texels() * 4, 0.0f);
    glGetTextureImage(texture, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(table->rgba.size() * sizeof(float)),
                      table->rgba.data());
  }
  t.ambient = Image(o.ambientSize, 1, 3);
  glGetTextureImage(ambient_.get(), 0, GL_RGB, GL_FLOAT, static_cast<GLsizei>(t.ambient.byteSize()),
                    t.ambient.data().data());
  if (usesMultipleScatteringLut(o)) {
    t.multipleScatteringLut = Image(o.multipleScatteringSize, o.multipleScatteringSize, 3);
    glGetTextureImage(msLut_.get(), 0, GL_RGB, GL_FLOAT,
                      static_cast<GLsizei>(t.multipleScatteringLut.byteSize()),
                      t.multipleScatteringLut.data().data());
  }
  gl::checkError("AtmosphereTablesPass::download");
  return t;
}

} // namespace crep
