// AtmosphereTablesPass and gpu::atmosphereParams (crep/atmosphere/gpu_tables.h) against the CPU reference
// (crep/atmosphere/atmosphere.h, precomputeAtmosphere): every table of a small atmosphere computed on the GPU
// vs the CPU, upload/download round trip, the public GLSL look-ups (glsl/crep/atmosphere.glsl) vs the CPU
// look-ups on the same tables, the block's layout, and bad create-infos named.
#include "common/gl_fixture.h"

#include <crep/atmosphere/atmosphere.h>
#include <crep/atmosphere/gpu_tables.h>
#include <crep/core/error.h>
#include <crep/gpu/gl.h>
#include <crep/gpu/shader_library.h>

#include <doctest/doctest.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

using namespace crep;

namespace {

/// The small atmosphere of the tests (llvmpipe: seconds on the GPU and the CPU).
AtmospherePrecomputeOptions smallOptions() {
  AtmospherePrecomputeOptions o;
  o.size = {8, 16, 8, 4};
  o.orders = 3;
  o.singleSteps = 32;
  o.orderSteps = 32;
  o.sphereSamples = 32;
  o.opticalDepthHeight = 16;
  o.opticalDepthZenith = 32;
  o.opticalDepthSteps = 32;
  o.ambientSize = 16;
  return o;
}

/// The CPU tables of smallOptions(), computed once per process.
const AtmosphereTables& cpuTables() {
  static const AtmosphereTables tables = precomputeAtmosphere(AtmosphereParameters{}, smallOptions());
  return tables;
}

/// max over texels and channels of |gpu - cpu| / max |cpu| (the table's relative error).
double tableError(const std::vector<float>& gpu, const std::vector<float>& cpu, int channels, int used) {
  REQUIRE(gpu.size() == cpu.size());
  double scale = 0.0, worst = 0.0;
  for (std::size_t i = 0; i < cpu.size(); ++i)
    if (static_cast<int>(i % channels) < used) scale = std::max(scale, std::abs(double(cpu[i])));
  REQUIRE(scale > 0.0);
  for (std::size_t i = 0; i < cpu.size(); ++i)
    if (static_cast<int>(i % channels) < used)
      worst = std::max(worst, std::abs(double(gpu[i]) - double(cpu[i])));
  return worst / scale;
}

std::vector<float> toVector(const Image& image) {
  return {image.data().begin(), image.data().end()};
}

// Float (GPU) vs double (CPU) on the small atmosphere, measured on llvmpipe (see the MESSAGEs): optical
// depth 1.1e-6, ambient 3.6e-6, L1 5.1e-5, L_H 1.2e-4, L_M 4.2e-5. The 4D tables' largest errors are at
// texels whose rays meet the sun near the horizon: the optical depth table blends kOccludedDensity (1e9)
// into its texels next to the ground-hit ones, which multiplies a float rounding of the look-up coordinate
// (~1e-7) by ~1e4 in the sun's optical depth. Bounds: 2.5x above the largest measured value.
constexpr double kOpticalDepthTolerance = 1e-5;
constexpr double kAmbientTolerance = 2e-5;
constexpr double kTableTolerance = 3e-4;

} // namespace

TEST_CASE("gpu::atmosphereParams: the block's fields and std140 offsets") {
  CREP_REQUIRE_GL();
  AtmosphereParameters p;
  AtmospherePlacement placement{2.5, 100.0};
  const gpu::AtmosphereParams a = gpu::atmosphereParams(p, smallOptions(), placement);
  CHECK(a.radii == glm::vec4(6360.0e3f, 6440.0e3f, 80.0e3f, 1.0e9f));
  CHECK(a.rayleighScattering == glm::vec4(glm::vec3(p.rayleighScattering), 7994.0f));
  CHECK(a.mieScattering == glm::vec4(glm::vec3(p.mieScattering), 1200.0f));
  CHECK(a.mieExtinction == glm::vec4(glm::vec3(p.mieScattering + p.mieAbsorption), 0.76f));
  CHECK(a.tableSize == glm::ivec4(8, 16, 8, 4));
  CHECK(a.auxSizes == glm::ivec4(16, 32, 16, 3));
  CHECK(a.placement == glm::vec4(2.5f, 100.0f, 0.0f, 0.0f));

  // The block as a shader sees it: offsets of every member.
  static const char* kSource = R"(#version 450 core
#include "crep/atmosphere.glsl"
layout(local_size_x = 1) in;
layout(std140, binding = 0) uniform CrepAtmosphereBlock { CrepAtmosphereParams crep_atmosphere; };
layout(std430, binding = 0) buffer Out { vec4 values[7]; };
void main() {
  values[0] = crep_atmosphere.radii;
  values[1] = crep_atmosphere.rayleighScattering;
  values[2] = crep_atmosphere.mieScattering;
  values[3] = crep_atmosphere.mieExtinction;
  values[4] = vec4(crep_atmosphere.tableSize);
  values[5] = vec4(crep_atmosphere.auxSizes);
  values[6] = crep_atmosphere.placement;
}
)";
  static const ShaderLibrary::File files[] = {{"tests/atmosphere/atmosphere_block.comp", kSource}};
  ShaderLibrary::addFiles(files);
  gl::Handle program = buildProgram({{ShaderStage::Compute, "tests/atmosphere/atmosphere_block.comp", {}}});
  gl::Handle block = gl::createDynamicBuffer(sizeof a);
  glNamedBufferSubData(block.get(), 0, sizeof a, &a);
  gl::Handle out = gl::createDynamicBuffer(7 * sizeof(glm::vec4));
  glUseProgram(program.get());
  glBindBufferBase(GL_UNIFORM_BUFFER, 0, block.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, out.get());
  glDispatchCompute(1, 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glm::vec4 v[7];
  glGetNamedBufferSubData(out.get(), 0, sizeof v, v);
  gl::unbindPassState(1);
  CHECK(v[0] == a.radii);
  CHECK(v[1] == a.rayleighScattering);
  CHECK(v[2] == a.mieScattering);
  CHECK(v[3] == a.mieExtinction);
  CHECK(v[4] == glm::vec4(a.tableSize));
  CHECK(v[5] == glm::vec4(a.auxSizes));
  CHECK(v[6] == a.placement);
}

TEST_CASE("AtmosphereTablesPass: every GPU table equals precomputeAtmosphere's") {
  CREP_REQUIRE_GL();
  const AtmosphereTables& cpu = cpuTables();
  AtmosphereTablesPass pass({AtmosphereParameters{}, smallOptions()});
  pass.compute();
  const AtmosphereTables gpu = pass.download();

  std::string stages;
  for (const auto& [name, ms] : pass.stageTimes())
    stages += name + " " + std::to_string(ms) + " ms; ";
  MESSAGE("stage times (8x16x8x4, llvmpipe): " << stages);
  REQUIRE(pass.stageTimes().size() == 2 + 2 * 2 + 1);
  CHECK(pass.stageTimes()[0].first == "optical depth");
  CHECK(pass.stageTimes()[1].first == "single scattering");
  CHECK(pass.stageTimes()[2].first == "order 2: J");
  CHECK(pass.stageTimes()[5].first == "order 3: L");
  CHECK(pass.stageTimes()[6].first == "ambient");

  // Optical depth: the same occluded texels (kOccludedDensity exactly), the others relative to the largest.
  const Image& odCpu = cpu.opticalDepth;
  const Image& odGpu = gpu.opticalDepth;
  REQUIRE(odGpu.sameShape(odCpu));
  int occluded = 0, mismatched = 0;
  double odScale = 0.0, odWorst = 0.0;
  for (int j = 0; j < odCpu.height(); ++j)
    for (int i = 0; i < odCpu.width(); ++i)
      for (int c = 0; c < 2; ++c) {
        const bool occCpu = odCpu.at(i, j, c) == static_cast<float>(kOccludedDensity);
        const bool occGpu = odGpu.at(i, j, c) == static_cast<float>(kOccludedDensity);
        occluded += occCpu ? 1 : 0;
        mismatched += occCpu != occGpu ? 1 : 0;
        if (!occCpu) {
          odScale = std::max(odScale, double(odCpu.at(i, j, c)));
          odWorst = std::max(odWorst, std::abs(double(odGpu.at(i, j, c)) - double(odCpu.at(i, j, c))));
        }
      }
  CHECK(occluded > 0);
  CHECK(mismatched == 0);
  const double odError = odWorst / odScale;
  // The single table's four channels (RGB S_R, A S_M's red), the single Mie table's RGB.
  const double singleError = tableError(gpu.single.rgba, cpu.single.rgba, 4, 4);
  const double mieError = tableError(gpu.singleMie.rgba, cpu.singleMie.rgba, 4, 3);
  const double higherError = tableError(gpu.higherOrders.rgba, cpu.higherOrders.rgba, 4, 3);
  const double ambientError = tableError(toVector(gpu.ambient), toVector(cpu.ambient), 3, 3);
  MESSAGE("relative errors GPU vs CPU: optical depth " << odError << ", S_R and S_M.r " << singleError
                                                       << ", S_M " << mieError << ", L_H " << higherError
                                                       << ", ambient " << ambientError);
  CHECK(odError < kOpticalDepthTolerance);
  CHECK(singleError < kTableTolerance);
  CHECK(mieError < kTableTolerance);
  CHECK(higherError < kTableTolerance);
  CHECK(ambientError < kAmbientTolerance);
  // The single table's A is the single Mie table's R; the other A channels are 0.
  for (std::size_t i = 3; i < gpu.singleMie.rgba.size(); i += 4) {
    REQUIRE(gpu.singleMie.rgba[i] == 0.0f);
    REQUIRE(gpu.higherOrders.rgba[i] == 0.0f);
    REQUIRE(gpu.single.rgba[i] == gpu.singleMie.rgba[i - 3]);
  }
}

TEST_CASE("AtmosphereTablesPass: combinedMie keeps no single Mie table, its look-ups agree with the CPU") {
  CREP_REQUIRE_GL();
  AtmospherePrecomputeOptions o = smallOptions();
  o.combinedMie = true;
  AtmosphereTablesPass pass({AtmosphereParameters{}, o});
  CHECK(pass.singleMieTexture() == 0u);
  pass.compute();
  const AtmosphereTables gpu = pass.download();
  CHECK(gpu.singleMie.rgba.empty());
  // Against the CPU reference of the same option, as the separate form's tables.
  const AtmosphereTables cpu = precomputeAtmosphere(AtmosphereParameters{}, o);
  CHECK(cpu.singleMie.rgba.empty());
  const double singleError = tableError(gpu.single.rgba, cpu.single.rgba, 4, 4);
  const double higherError = tableError(gpu.higherOrders.rgba, cpu.higherOrders.rgba, 4, 3);
  const double ambientError = tableError(toVector(gpu.ambient), toVector(cpu.ambient), 3, 3);
  // What the combined form costs: its L_H (J_2 reads the rebuilt Mie) and E_sky against the separate form's.
  const double higherVsSeparate = tableError(cpu.higherOrders.rgba, cpuTables().higherOrders.rgba, 4, 3);
  const double ambientVsSeparate = tableError(toVector(cpu.ambient), toVector(cpuTables().ambient), 3, 3);
  MESSAGE("combinedMie, GPU vs CPU: single " << singleError << ", L_H " << higherError << ", ambient "
                                             << ambientError << "; CPU combined vs separate: L_H "
                                             << higherVsSeparate << ", ambient " << ambientVsSeparate
                                             << " of each table's peak");
  CHECK(gpu.single.rgba == pass.download().single.rgba);
  CHECK(singleError < kTableTolerance);
  CHECK(higherError < kTableTolerance);
  CHECK(ambientError < kAmbientTolerance);
  CHECK(tableError(gpu.single.rgba, cpuTables().single.rgba, 4, 4) < kTableTolerance); // the same S_R
  // Parameters whose combined form cannot be formed are refused, naming the option.
  AtmosphereParameters noRed;
  noRed.rayleighScattering.x = 0.0;
  try {
    AtmosphereTablesPass bad({noRed, o});
    FAIL("no exception");
  } catch (const InvalidArgument& e) {
    CHECK(e.parameter() == "AtmospherePrecomputeOptions.combinedMie");
  }
}

TEST_CASE("AtmosphereTablesPass: orders = 1 gives L_H = 0") {
  CREP_REQUIRE_GL();
  AtmospherePrecomputeOptions o = smallOptions();
  o.orders = 1;
  AtmosphereTablesPass pass({AtmosphereParameters{}, o});
  pass.compute();
  const AtmosphereTables gpu = pass.download();
  CHECK(pass.stageTimes().size() == 3);
  CHECK(std::all_of(gpu.higherOrders.rgba.begin(), gpu.higherOrders.rgba.end(),
                    [](float v) { return v == 0.0f; }));
  // The same L1 as with three orders (identical programs and inputs).
  CHECK(tableError(gpu.single.rgba, cpuTables().single.rgba, 4, 4) < kTableTolerance);
  CHECK(tableError(gpu.singleMie.rgba, cpuTables().singleMie.rgba, 4, 3) < kTableTolerance);
}

TEST_CASE("AtmosphereTablesPass: halfFloatTables holds the RGBA32F tables rounded to half precision") {
  CREP_REQUIRE_GL();
  const AtmospherePrecomputeOptions o = smallOptions();
  AtmosphereTablesPass full({AtmosphereParameters{}, o});
  full.compute();
  const AtmosphereTables reference = full.download();
  AtmosphereTablesPass::CreateInfo info{AtmosphereParameters{}, o};
  info.halfFloatTables = true;
  AtmosphereTablesPass half(info);
  GLint format = 0;
  glGetTextureLevelParameteriv(half.singleTexture(), 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
  CHECK(format == GL_RGBA16F);
  // Half precision keeps 11 significant bits and the backends round to the nearest (gpu::halfBits):
  // |h - f| <= 2^-11 |f|, plus 2^-25 for values below half's normal range. (Mesa's own GL upload truncates,
  // up to 2^-10 |f|: the GL backend rounds before it uploads.)
  const auto rounded = [](const std::vector<float>& h, const std::vector<float>& f) {
    REQUIRE(h.size() == f.size());
    double worst = 0.0;
    int outside = 0;
    for (std::size_t i = 0; i < f.size(); ++i) {
      const double error = std::abs(double(h[i]) - double(f[i]));
      if (error > std::ldexp(std::abs(double(f[i])), -11) + std::ldexp(1.0, -25)) ++outside;
      if (std::abs(f[i]) > 1e-4f) worst = std::max(worst, error / std::abs(double(f[i])));
    }
    CHECK(outside == 0);
    return worst;
  };
  half.compute();
  CHECK(half.stageTimes().back().first == "RGBA16F rounding");
  const AtmosphereTables computed = half.download();
  const double single = rounded(computed.single.rgba, reference.single.rgba);
  const double mie = rounded(computed.singleMie.rgba, reference.singleMie.rgba);
  const double higher = rounded(computed.higherOrders.rgba, reference.higherOrders.rgba);
  MESSAGE("RGBA16F tables vs RGBA32F, largest relative difference: S_R + S_M.r " << single << ", S_M " << mie
                                                                                 << ", L_H " << higher);
  // The rest is computed as before.
  CHECK(toVector(computed.ambient) == toVector(reference.ambient));
  // Upload rounds the same way.
  AtmosphereTablesPass uploaded(info);
  uploaded.upload(reference);
  const AtmosphereTables back = uploaded.download();
  CHECK(back.single.rgba == computed.single.rgba);
  CHECK(back.higherOrders.rgba == computed.higherOrders.rgba);
}

TEST_CASE("AtmosphereTablesPass: upload then download is bit-identical") {
  CREP_REQUIRE_GL();
  const AtmosphereTables& cpu = cpuTables();
  AtmosphereTablesPass pass({cpu.parameters, cpu.options});
  pass.upload(cpu);
  const AtmosphereTables back = pass.download();
  const auto bits = [](const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
  };
  CHECK(bits(toVector(back.opticalDepth), toVector(cpu.opticalDepth)));
  CHECK(bits(back.single.rgba, cpu.single.rgba));
  CHECK(bits(back.higherOrders.rgba, cpu.higherOrders.rgba));
  CHECK(bits(back.singleMie.rgba, cpu.singleMie.rgba));
  CHECK(bits(toVector(back.ambient), toVector(cpu.ambient)));
  CHECK(back.orders.empty());

  // Mismatching tables are refused, naming the argument.
  AtmosphereTables other = cpu;
  other.parameters.mieG = 0.8;
  try {
    pass.upload(other);
    FAIL("no exception");
  } catch (const InvalidArgument& e) {
    CHECK(e.parameter() == "AtmosphereTablesPass::upload.tables");
  }
  other = cpu;
  other.ambient = Image(3, 1, 3);
  CHECK_THROWS_AS(pass.upload(other), InvalidArgument);
}

namespace {

struct LookUpCase {
  glm::vec4 position; ///< xyz metres, w: the ambient look-up's cos sun zenith
  glm::vec4 view;     ///< xyz unit
  glm::vec4 sun;      ///< xyz unit
  glm::vec4 end;      ///< xyz a second point on the view ray (transmittance)
};
struct LookUpResult {
  glm::vec4 multiple; ///< L_M: crep_lookUpAtmosphere on L_H plus crep_sampleSingleScattering there, rgb
  glm::vec4 coords;   ///< its coordinates
  glm::vec4 single;   ///< a second look-up, L1 with those coordinates as previous, rgb
  glm::vec4 density;  ///< xy crep_densityToTop(h, cos view zenith)
  glm::vec4 sunT;     ///< crep_sunTransmittance
  glm::vec4 segment;  ///< crep_atmosphereTransmittance(position, end)
  glm::vec4 ambient;  ///< crep_ambientSkyLight(position.w)
};

const char* kLookUpSource = R"(#version 450 core
#include "crep/atmosphere.glsl"
layout(local_size_x = 64) in;
layout(std140, binding = 0) uniform CrepAtmosphereBlock { CrepAtmosphereParams crep_atmosphere; };
struct Case { vec4 position; vec4 view; vec4 sun; vec4 end; };
struct Result { vec4 multiple; vec4 coords; vec4 single; vec4 density; vec4 sunT; vec4 segment; vec4 ambient; };
layout(std430, binding = 0) readonly buffer Cases { Case cases[]; };
layout(std430, binding = 1) writeonly buffer Results { Result results[]; };
layout(binding = 0) uniform sampler3D higherTable;
layout(binding = 1) uniform sampler3D singleTable;
layout(binding = 2) uniform sampler2D opticalDepth;
layout(binding = 3) uniform sampler2D ambient;
layout(binding = 4) uniform sampler3D singleMieTable;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= uint(cases.length())) return;
  Case c = cases[i];
  Result r;
  vec4 coords = vec4(-1.0);
  float cosSunView = dot(c.view.xyz, c.sun.xyz);
  vec3 higher = crep_lookUpAtmosphere(higherTable, crep_atmosphere, c.position.xyz, c.view.xyz, c.sun.xyz, coords);
  r.multiple = vec4(higher + crep_sampleSingleScattering(singleTable, singleMieTable, crep_atmosphere, coords, cosSunView), 0.0);
  r.coords = coords;
  crep_lookUpAtmosphere(singleTable, crep_atmosphere, c.end.xyz, c.view.xyz, c.sun.xyz, coords);
  r.single = vec4(crep_sampleSingleScattering(singleTable, singleMieTable, crep_atmosphere, coords, cosSunView), 0.0);
  float rr = length(c.position.xyz);
  r.density = vec4(crep_densityToTop(opticalDepth, crep_atmosphere, rr - crep_atmosphere.radii.x,
                                     dot(c.position.xyz / rr, c.view.xyz)), 0.0, 0.0);
  r.sunT = vec4(crep_sunTransmittance(opticalDepth, crep_atmosphere, c.position.xyz, c.sun.xyz), 0.0);
  r.segment = vec4(crep_atmosphereTransmittance(opticalDepth, crep_atmosphere, c.position.xyz, c.end.xyz), 0.0);
  r.ambient = vec4(crep_ambientSkyLight(ambient, crep_atmosphere, c.position.w), 0.0);
  results[i] = r;
}
)";

} // namespace

TEST_CASE("atmosphere.glsl: the GLSL look-ups equal the CPU look-ups on the same tables") {
  CREP_REQUIRE_GL();
  const AtmosphereTables& cpu = cpuTables();
  const AtmosphereParameters& p = cpu.parameters;
  AtmosphereTablesPass pass({p, cpu.options});
  pass.upload(cpu);

  // Random points (altitude 0 .. H_Atm, squared for more low ones), view and sun directions; positions are
  // floats, and the CPU gets the same float values.
  const int count = 512;
  std::vector<LookUpCase> cases(count);
  std::uint32_t state = 7;
  const auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / double(1u << 24);
  };
  const auto unitVector = [&] {
    const double y = 2.0 * next() - 1.0, a = 2.0 * 3.14159265358979 * next(), r = std::sqrt(1.0 - y * y);
    return glm::vec3(glm::normalize(glm::dvec3(r * std::cos(a), y, r * std::sin(a))));
  };
  // Even cases sit on the +y axis (|position| and so the altitude are exact in float), odd ones anywhere
  // (the altitude from a float position is good to ~0.5 m, atmosphere.glsl's stated resolution).
  for (std::size_t i = 0; i < cases.size(); ++i) {
    LookUpCase& c = cases[i];
    const double u = next();
    const double h = p.atmosphereHeight * u * u;
    const glm::vec3 up = i % 2 == 0 ? glm::vec3(0.0f, 1.0f, 0.0f) : unitVector();
    c.position =
        glm::vec4(up * static_cast<float>(p.earthRadius + h), static_cast<float>(2.0 * next() - 1.0));
    c.view = glm::vec4(unitVector(), 0.0f);
    c.sun = glm::vec4(unitVector(), 0.0f);
    c.end = glm::vec4(glm::vec3(c.position) + glm::vec3(c.view) * static_cast<float>(20.0e3 * next()), 0.0f);
  }

  static const ShaderLibrary::File files[] = {{"tests/atmosphere/atmosphere_look_ups.comp", kLookUpSource}};
  ShaderLibrary::addFiles(files);
  gl::Handle program =
      buildProgram({{ShaderStage::Compute, "tests/atmosphere/atmosphere_look_ups.comp", {}}});
  const gpu::AtmosphereParams params = gpu::atmosphereParams(p, cpu.options);
  gl::Handle block = gl::createDynamicBuffer(sizeof params);
  glNamedBufferSubData(block.get(), 0, sizeof params, &params);
  gl::Handle in = gl::createDynamicBuffer(cases.size() * sizeof(LookUpCase));
  glNamedBufferSubData(in.get(), 0, static_cast<GLsizeiptr>(cases.size() * sizeof(LookUpCase)), cases.data());
  gl::Handle out = gl::createDynamicBuffer(cases.size() * sizeof(LookUpResult));
  glUseProgram(program.get());
  glBindBufferBase(GL_UNIFORM_BUFFER, 0, block.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out.get());
  glBindTextureUnit(0, pass.higherOrdersTexture());
  glBindTextureUnit(1, pass.singleTexture());
  glBindTextureUnit(2, pass.opticalDepthTexture());
  glBindTextureUnit(3, pass.ambientTexture());
  glBindTextureUnit(4, pass.singleMieTexture());
  glDispatchCompute((count + 63) / 64, 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<LookUpResult> results(count);
  glGetNamedBufferSubData(out.get(), 0, static_cast<GLsizeiptr>(results.size() * sizeof(LookUpResult)),
                          results.data());
  gl::unbindPassState(5);

  // Scales: the largest value of each quantity (relative errors as in the tables' test).
  const auto tableMax = [](const std::vector<float>& v) {
    double m = 0.0;
    for (float x : v)
      m = std::max(m, std::abs(double(x)));
    return m;
  };
  const double ambientMax = tableMax(toVector(cpu.ambient));
  std::vector<glm::dvec3> cpuMultiple(count), cpuSingle(count);
  double multipleMax = 0.0, singleMax = 0.0;
  for (int i = 0; i < count; ++i) {
    const LookUpCase& c = cases[i];
    glm::dvec4 coords(-1.0);
    const glm::dvec3 view(c.view), sun(c.sun);
    cpuMultiple[i] = lookUpMultipleScattering(cpu, glm::dvec3(c.position), view, sun, coords);
    cpuSingle[i] = lookUpSingleScattering(cpu, glm::dvec3(c.end), view, sun, coords);
    for (int k = 0; k < 3; ++k) {
      multipleMax = std::max(multipleMax, std::abs(cpuMultiple[i][k]));
      singleMax = std::max(singleMax, std::abs(cpuSingle[i][k]));
    }
  }
  // [0]: points on the axis, [1]: anywhere.
  double multipleErr[2] = {}, singleErr[2] = {}, coordsErr[2] = {}, densityErr[2] = {}, sunErr[2] = {};
  double segmentErr[2] = {};
  double ambientErr = 0.0;
  int segmentCases = 0;
  for (int i = 0; i < count; ++i) {
    const int set = i % 2;
    const LookUpCase& c = cases[i];
    const LookUpResult& r = results[i];
    const glm::dvec3 position(c.position), view(c.view), sun(c.sun), end(c.end);
    const glm::dvec3 m = cpuMultiple[i], s = cpuSingle[i];
    glm::dvec4 firstCoords(-1.0);
    lookUpAtmosphere(cpu, cpu.higherOrders, position, view, sun, firstCoords);
    const double rr = glm::length(position);
    const glm::dvec2 d = lookUpDensityToTop(cpu, rr - p.earthRadius, glm::dot(position / rr, view));
    const glm::dvec3 t = sunTransmittance(cpu, position, sun);
    const glm::dvec3 seg = atmosphereTransmittance(cpu, position, end);
    const glm::dvec3 amb = lookUpAmbientSkyLight(cpu, c.position.w);
    for (int k = 0; k < 3; ++k) {
      multipleErr[set] = std::max(multipleErr[set], std::abs(r.multiple[k] - m[k]) / multipleMax);
      singleErr[set] = std::max(singleErr[set], std::abs(r.single[k] - s[k]) / singleMax);
      sunErr[set] = std::max(sunErr[set], std::abs(r.sunT[k] - t[k]));
      ambientErr = std::max(ambientErr, std::abs(r.ambient[k] - amb[k]) / ambientMax);
    }
    for (int k = 0; k < 4; ++k)
      coordsErr[set] = std::max(coordsErr[set], std::abs(r.coords[k] - firstCoords[k]));
    // Density integrals: relative to the value (occluded rays: both kOccludedDensity-sized).
    for (int k = 0; k < 2; ++k)
      densityErr[set] =
          std::max(densityErr[set], std::abs(r.density[k] - d[k]) / std::max(1.0, std::abs(d[k])));
    // Segments: transmittance (absolute, in [0, 1]) where the ray does not graze the ground.
    if (glm::length(end - position) > 1.0) {
      ++segmentCases;
      for (int k = 0; k < 3; ++k)
        segmentErr[set] = std::max(segmentErr[set], std::abs(r.segment[k] - seg[k]));
    }
  }
  for (int set = 0; set < 2; ++set) {
    const std::string which = set == 0 ? "points on the axis" : "points anywhere";
    MESSAGE("GLSL vs CPU look-ups, " << count / 2 << " " << which << ": L_M " << multipleErr[set]
                                     << ", L1 (second look-up) " << singleErr[set] << ", coordinates "
                                     << coordsErr[set] << ", density to top " << densityErr[set]
                                     << ", sun transmittance " << sunErr[set] << ", segment transmittance "
                                     << segmentErr[set]);
  }
  MESSAGE("ambient " << ambientErr << " (" << segmentCases << " segments)");
  // Exact altitudes: float rounding of the look-ups' arithmetic only (measured: see the MESSAGE; bound 1e-4).
  CHECK(multipleErr[0] < 1e-4);
  CHECK(singleErr[0] < 1e-4);
  CHECK(coordsErr[0] < 1e-4);
  CHECK(densityErr[0] < 1e-4);
  CHECK(sunErr[0] < 1e-4);
  CHECK(ambientErr < 1e-4);
  // Float positions: a 0.5 m altitude error changes a Mie density integral by up to 0.5 m / H_M = 4.2e-4
  // relative (measured 5.2e-4 for the density, 1.0e-3 for segment transmittances); bound 2e-3.
  CHECK(multipleErr[1] < 2e-3);
  CHECK(singleErr[1] < 2e-3);
  CHECK(densityErr[1] < 2e-3);
  CHECK(sunErr[1] < 2e-3);
  CHECK(segmentErr[1] < 2e-3);
  // A segment's end point is off the axis in both sets (its altitude good to ~0.5 m): the same bound.
  CHECK(segmentErr[0] < 2e-3);
}

TEST_CASE("AtmosphereTablesPass: a bad create-info names the field") {
  CREP_REQUIRE_GL();
  const auto parameterOf = [](const AtmosphereTablesPass::CreateInfo& info) -> std::string {
    try {
      AtmosphereTablesPass pass(info);
    } catch (const InvalidArgument& e) {
      return e.parameter();
    }
    return "(no exception)";
  };
  AtmosphereTablesPass::CreateInfo info{AtmosphereParameters{}, smallOptions()};
  info.parameters.earthRadius = -1.0;
  CHECK(parameterOf(info) == "AtmosphereParameters.earthRadius");
  info = {AtmosphereParameters{}, smallOptions()};
  info.parameters.mieG = 1.0;
  CHECK(parameterOf(info) == "AtmosphereParameters.mieG");
  info = {AtmosphereParameters{}, smallOptions()};
  info.options.size.viewZenith = 15;
  CHECK(parameterOf(info) == "AtmospherePrecomputeOptions.size.viewZenith");
  info = {AtmosphereParameters{}, smallOptions()};
  info.options.orders = 0;
  CHECK(parameterOf(info) == "AtmospherePrecomputeOptions.orders");

  // Sizes beyond GL_MAX_3D_TEXTURE_SIZE (and the 2048 the library allows) name the size field.
  GLint max3D = 0;
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3D);
  MESSAGE("GL_MAX_3D_TEXTURE_SIZE " << max3D);
  info = {AtmosphereParameters{}, smallOptions()};
  info.options.size.height = std::max(max3D, 2048) + 1;
  CHECK(parameterOf(info) == "AtmospherePrecomputeOptions.size.height");
  info = {AtmosphereParameters{}, smallOptions()};
  info.options.size.viewZenith = std::max(max3D, 2048) + 2;
  CHECK(parameterOf(info) == "AtmospherePrecomputeOptions.size.viewZenith");
  info = {AtmosphereParameters{}, smallOptions()};
  info.options.size.sunZenith = 64;
  info.options.size.sunView = 64; // packed depth 4096
  const std::string packed = parameterOf(info);
  CHECK(packed == "AtmospherePrecomputeOptions.size.sunView");
}

TEST_CASE("AtmosphereTablesPass: the multiple scattering LUT (Hillaire 2020) and its L_H equal the CPU's") {
  CREP_REQUIRE_GL();
  AtmosphereParameters p;
  p.groundAlbedo = 0.3;
  AtmospherePrecomputeOptions o = smallOptions();
  o.multipleScattering = AtmosphereMultipleScattering::Lut;
  o.multipleScatteringSize = 16;
  AtmosphereTablesPass pass({p, o});
  REQUIRE(pass.multipleScatteringLutTexture() != 0u);
  pass.compute();
  const AtmosphereTables gpu = pass.download();
  const AtmosphereTables cpu = precomputeAtmosphere(p, o);
  const double lutError =
      tableError(toVector(gpu.multipleScatteringLut), toVector(cpu.multipleScatteringLut), 3, 3);
  const double singleError = tableError(gpu.single.rgba, cpu.single.rgba, 4, 4);
  const double higherError = tableError(gpu.higherOrders.rgba, cpu.higherOrders.rgba, 4, 3);
  const double ambientError = tableError(toVector(gpu.ambient), toVector(cpu.ambient), 3, 3);
  MESSAGE("LUT method, GPU vs CPU: Psi_ms " << lutError << ", single " << singleError << ", L_H "
                                            << higherError << ", ambient " << ambientError
                                            << " of each table's peak");
  CHECK(pass.stageTimes().size() == 4); // optical depth, LUT, single scattering and L_H, ambient
  CHECK(lutError < kTableTolerance);
  CHECK(singleError < kTableTolerance);
  CHECK(higherError < kTableTolerance);
  CHECK(ambientError < kAmbientTolerance);
  // Upload then download: the LUT too, bit for bit.
  AtmosphereTablesPass other({p, o});
  other.upload(cpu);
  const AtmosphereTables back = other.download();
  CHECK(std::memcmp(back.multipleScatteringLut.data().data(), cpu.multipleScatteringLut.data().data(),
                    cpu.multipleScatteringLut.byteSize()) == 0);
}
