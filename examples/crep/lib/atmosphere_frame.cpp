#include "atmosphere_frame.h"

#include "gl_session.h"
#include "methods.h"

#include <crep/atmosphere/gpu_pass.h>
#include <crep/core/error.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/gpu/shader_library.h>

#include <epoxy/gl.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <optional>
#include <string>

namespace crep::tool {

const std::set<std::string> kAtmosphereOptions = {
    "sun-elevation",     "sun-azimuth",     "camera-elevation",    "shafts",
    "meters-per-unit",   "origin-altitude", "atmosphere-table",    "orders",
    "atmosphere-cache",  "sun-irradiance",  "multiple-scattering", "ground-albedo",
    "integration-steps", "sky-steps",       "single-scattering",   "half-float-tables"};

const char* const kAtmosphereOptionsHelp =
    R"(          atmosphere (--method atmosphere; Bruneton and Neyret 2008 tables, Yusov 2013):
            --sun-elevation DEG  sun above the horizon, in [-90, 90] (default 30; < 0 twilight)
            --sun-azimuth DEG    from -Z (straight ahead of the built-in cameras) towards +X (default:
                                 the scene's sun)
            --camera-elevation DEG  pitch the scene's camera to DEG, in [-89, 89]
            --shafts S           integrated (default; (a) single scattering integrated over the lit
                                 sections of the min/max march + unoccluded higher orders) | lut ((b) lit
                                 length and first lit distance, two table look-ups) | prefiltered ((c)
                                 the prefiltered visibility times the table) | none (no shadows)
            --meters-per-unit X  metres per world unit (default 50)
            --origin-altitude M  metres above sea level of world y = 0 (default 0)
            --atmosphere-table HxAxPxT  4D table size (default 32x32x32x8; 32x128x64x16: the
                                 reference)
            --multiple-scattering M  orders (default: orders 2..N by sphere and ray integrals) | lut
                                 (Hillaire 2020's table of every order >= 2: seconds, not minutes, and
                                 darker; docs/MEASUREMENTS.md, Atmosphere)
            --orders N           orders: scattering orders 1..N (default 4); 1: single scattering only
            --ground-albedo A    the ground's albedo in lut's multiple scattering, in [0, 1]
                                 (default 0.1)
            --single-scattering S  none, lut, prefiltered: view-tables (default; Hillaire 2020's
                                 per-frame aerial perspective volume and sky-view table) | table (Eq. 8
                                 on the 4D table, the reference of earlier versions)
            --integration-steps N  (a): trapezoid steps over the scene's part of a ray, in [1, 4096]
                                 (default 64)
            --sky-steps N        (a): steps of a sky ray beyond the far plane, in [1, 4096] (default 16)
            --half-float-tables on|off  the 4D tables as RGBA16F on the GPU (default off)
            --atmosphere-cache DIR  table cache (default $XDG_CACHE_HOME/crepuscular or
                                 ~/.cache/crepuscular; `none`: always compute)
            --sun-irradiance E   extraterrestrial sun irradiance, white (default 10)
)";

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

AtmosphereTableSize parseTableSize(const std::string& text) {
  AtmosphereTableSize size;
  int* fields[] = {&size.height, &size.viewZenith, &size.sunZenith, &size.sunView};
  std::size_t pos = 0;
  for (int i = 0; i < 4; ++i) {
    std::size_t end = i < 3 ? text.find('x', pos) : text.size();
    if (end == std::string::npos || end == pos)
      throw UsageError("option --atmosphere-table: '" + text + "' is not HxAxPxT (e.g. 32x128x64x16)");
    const std::string part = text.substr(pos, end - pos);
    if (part.size() > 5 || part.find_first_not_of("0123456789") != std::string::npos)
      throw UsageError("option --atmosphere-table: '" + text + "' is not HxAxPxT (e.g. 32x128x64x16)");
    *fields[i] = std::stoi(part);
    pos = end + 1;
  }
  return size;
}

std::string defaultCacheDirectory() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::string(xdg) + "/crepuscular";
  if (const char* home = std::getenv("HOME"); home && *home) return std::string(home) + "/.cache/crepuscular";
  return {};
}

/// The atmosphere at the camera's altitude as a homogeneous medium in 1 / world unit: the proxy of (c).
Medium proxyMedium(const AtmosphereSettings& s, const Camera& camera) {
  const AtmosphereParameters& p = s.parameters;
  const glm::dvec3 c = atmospherePosition(s.placement, p, camera.position());
  const double h = std::clamp(glm::length(c) - p.earthRadius, 0.0, p.atmosphereHeight);
  const double k = s.placement.metersPerUnit;
  const double dr = std::exp(-h / p.rayleighScaleHeight), dm = std::exp(-h / p.mieScaleHeight);
  return Medium({.mieScattering = p.mieScattering * dm * k,
                 .hgG = p.mieG,
                 .rayleighScattering = p.rayleighScattering * dr * k,
                 .absorption = p.mieAbsorption * dm * k + glm::dvec3(1e-12)});
}

} // namespace

const char* atmosphereShaftsName(AtmosphereShafts shafts) {
  switch (shafts) {
  case AtmosphereShafts::None:
    return "none";
  case AtmosphereShafts::Integrated:
    return "integrated";
  case AtmosphereShafts::LitLengthTable:
    return "lut";
  case AtmosphereShafts::PrefilteredVisibility:
    return "prefiltered";
  }
  return "?";
}

bool hasAtmosphereOptions(const Args& args) {
  for (const std::string& name : kAtmosphereOptions)
    if (args.has(name)) return true;
  return false;
}

AtmosphereSettings atmosphereSettings(const Args& args) {
  AtmosphereSettings s;
  s.sunElevation = args.number("sun-elevation", s.sunElevation, -90.0, 90.0);
  if (args.has("sun-azimuth")) s.sunAzimuth = args.number("sun-azimuth", 0.0, -360.0, 360.0);
  if (args.has("camera-elevation")) s.cameraElevation = args.number("camera-elevation", 0.0, -89.0, 89.0);
  const std::string shafts = args.string("shafts", "integrated");
  if (shafts == "none")
    s.shafts = AtmosphereShafts::None;
  else if (shafts == "integrated")
    s.shafts = AtmosphereShafts::Integrated;
  else if (shafts == "lut")
    s.shafts = AtmosphereShafts::LitLengthTable;
  else if (shafts == "prefiltered")
    s.shafts = AtmosphereShafts::PrefilteredVisibility;
  else
    throw UsageError("option --shafts: '" + shafts + "' is not one of integrated, lut, prefiltered, none");
  s.placement.metersPerUnit = args.number("meters-per-unit", s.placement.metersPerUnit, 1e-3, 1e5);
  s.placement.originAltitude =
      args.number("origin-altitude", s.placement.originAltitude, 0.0, s.parameters.atmosphereHeight * 0.5);
  if (args.has("atmosphere-table")) s.tables.size = parseTableSize(args.string("atmosphere-table", ""));
  s.tables.orders = args.integer("orders", s.tables.orders, 1, 16);
  const std::string multiple = args.string("multiple-scattering", "orders");
  if (multiple == "lut")
    s.tables.multipleScattering = AtmosphereMultipleScattering::Lut;
  else if (multiple == "orders")
    s.tables.multipleScattering = AtmosphereMultipleScattering::Orders;
  else
    throw UsageError("option --multiple-scattering: '" + multiple + "' is not lut or orders");
  s.parameters.groundAlbedo = args.number("ground-albedo", s.parameters.groundAlbedo, 0.0, 1.0);
  s.sunIrradiance = args.number("sun-irradiance", s.sunIrradiance, 1e-6, 1e6);
  const std::string half = args.string("half-float-tables", "off");
  if (half != "on" && half != "off")
    throw UsageError("option --half-float-tables: '" + half + "' is not on or off");
  s.halfFloatTables = half == "on";
  const std::string single = args.string("single-scattering", "view-tables");
  if (single == "view-tables")
    s.ray.single = AtmosphereSingleScattering::ViewTables;
  else if (single == "table")
    s.ray.single = AtmosphereSingleScattering::Table4D;
  else
    throw UsageError("option --single-scattering: '" + single + "' is not view-tables or table");
  s.ray.integrationSteps = args.integer("integration-steps", s.ray.integrationSteps, 1, 4096);
  s.ray.skySteps = args.integer("sky-steps", s.ray.skySteps, 1, 4096);
  try {
    validate(s.tables);
  } catch (const InvalidArgument& e) {
    throw UsageError(std::string("options --atmosphere-table/--orders: ") + e.what());
  }
  const std::string cache = args.string("atmosphere-cache", "");
  s.cacheDirectory = !args.has("atmosphere-cache") ? defaultCacheDirectory() : cache == "none" ? "" : cache;
  if (args.has("atmosphere-cache") && cache.empty())
    throw UsageError("option --atmosphere-cache: empty (use `none` to disable the cache)");
  return s;
}

DirectionalLight atmosphereSun(const AtmosphereSettings& s, const DirectionalLight& sceneSun) {
  double azimuth = 0.0;
  if (s.sunAzimuth) {
    azimuth = *s.sunAzimuth * kDegree;
  } else {
    const glm::dvec3 toSun = -sceneSun.direction();
    azimuth = std::atan2(toSun.x, -toSun.z);
  }
  const double e = s.sunElevation * kDegree;
  const glm::dvec3 toSun(std::sin(azimuth) * std::cos(e), std::sin(e), -std::cos(azimuth) * std::cos(e));
  return DirectionalLight(-toSun, glm::dvec3(s.sunIrradiance));
}

Camera atmosphereCamera(const AtmosphereSettings& s, const Camera& c) {
  if (!s.cameraElevation) return c;
  const glm::dvec3 f = c.forward();
  const double yaw = std::atan2(f.x, -f.z), e = *s.cameraElevation * kDegree;
  const glm::dvec3 dir(std::sin(yaw) * std::cos(e), std::sin(e), -std::cos(yaw) * std::cos(e));
  return Camera::lookAt(c.position(), c.position() + dir, {0.0, 1.0, 0.0}, c.fovY(), c.aspect(), c.near(),
                        c.far());
}

AtmosphereTableSet atmosphereTables(const AtmosphereSettings& s, StageTimings& timings) {
  AtmosphereTableSet set;
  set.pass = timings.time("atmosphere tables setup", [&] {
    return std::make_unique<AtmosphereTablesPass>(
        AtmosphereTablesPass::CreateInfo{s.parameters, s.tables, s.halfFloatTables});
  });
  AtmosphereTablesPass& pass = *set.pass;
  bool computed = false;
  const auto compute = [&] {
    computed = true;
    // RGBA16F: compute in an RGBA32F pass so that the cache keeps the unrounded tables, then upload.
    std::optional<AtmosphereTablesPass> full;
    if (s.halfFloatTables) full.emplace(AtmosphereTablesPass::CreateInfo{s.parameters, s.tables});
    AtmosphereTablesPass& target = full ? *full : pass;
    target.compute();
    for (const auto& [name, ms] : target.stageTimes())
      timings.add("atmosphere: " + name, ms);
    AtmosphereTables tables = timings.time("atmosphere tables download", [&] { return target.download(); });
    if (full) timings.time("atmosphere tables upload (RGBA16F)", [&] { pass.upload(tables); });
    return tables;
  };
  if (s.cacheDirectory.empty()) {
    set.cpu = compute();
    return set;
  }
  set.cpu = cachedAtmosphereTables(
      s.cacheDirectory, s.parameters, s.tables, compute,
      [](const std::string& message) { std::fprintf(stderr, "crep: warning: %s\n", message.c_str()); });
  if (!computed) {
    set.loaded = true;
    timings.time("atmosphere tables upload (cache)", [&] {
      pass.upload(set.cpu);
      glFinish();
    });
  }
  return set;
}

AtmosphereOutput runAtmosphere(FrameInputs& frame, const MethodSettings& settings,
                               const AtmosphereSettings& s, const AtmosphereTablesPass& tables,
                               StageTimings& timings) {
  AtmosphereOutput out;
  out.detail = std::string("shafts ") + atmosphereShaftsName(s.shafts);
  AtmospherePass::FrameAttribs a;
  a.tables = &tables;
  a.placement = &s.placement;
  a.camera = &frame.camera;
  a.sun = &frame.light;
  a.cameraDepth = frame.cameraDepth.get();
  int mapWidth = 0, mapHeight = 0;
  std::optional<EpipolarMap> epipolar;
  std::unique_ptr<MinMaxTreePass> trees;
  MethodOutput prefiltered;
  Medium proxy = proxyMedium(s, frame.camera);
  if (s.shafts == AtmosphereShafts::Integrated || s.shafts == AtmosphereShafts::LitLengthTable) {
    Rectification rect;
    const RectifiedGpuMap* map = frame.rectified(settings, timings, &rect);
    if (map) {
      a.layout = map->layout.get();
      a.rectifiedDepth = map->texture.get();
      mapWidth = mapHeight = map->size;
      out.detail +=
          ", " + std::to_string(map->rect.splitCount()) + " splits, map " + std::to_string(map->size) + "^2";
    } else {
      std::fprintf(stderr, "crep: atmosphere: rectification is not projective (%s); epipolar fallback map\n",
                   rect.message.c_str());
      epipolar = makeEpipolarMap(frame, settings, timings);
      a.layout = epipolar->layout.get();
      a.rectifiedDepth = epipolar->texture.get();
      mapWidth = epipolar->width;
      mapHeight = epipolar->height;
      out.detail += ", epipolar fallback map " + std::to_string(mapWidth) + "x" + std::to_string(mapHeight);
    }
    trees = timings.time("min/max setup", [&] {
      return std::make_unique<MinMaxTreePass>(MinMaxTreePass::CreateInfo{mapWidth, mapHeight});
    });
    timings.time("min/max trees", [&] {
      trees->run(a.rectifiedDepth);
      glFinish();
    });
    a.minMaxBuffer = trees->treeBuffer();
  } else if (s.shafts == AtmosphereShafts::PrefilteredVisibility) {
    // (c): the prefiltered method on the homogeneous proxy of the air at the camera.
    const Medium saved = frame.medium;
    frame.medium = proxy;
    prefiltered = runMethod("prefilter", frame, settings);
    frame.medium = saved;
    for (const auto& row : prefiltered.timings.rows())
      timings.add("prefilter: " + row.stage, row.ms);
    a.prefiltered = prefiltered.scattering.get();
    a.proxyMedium = &proxy;
    out.detail += ", proxy medium at the camera (" + prefiltered.used + ")";
  }
  AtmospherePass::CreateInfo info;
  info.shafts = s.shafts;
  info.options = s.ray;
  info.mapWidth = mapWidth;
  info.mapHeight = mapHeight;
  auto pass = timings.time("atmosphere setup", [&] { return std::make_unique<AtmospherePass>(info); });
  out.inscattering = gl::createTexture2D(GL_RGBA32F, frame.width, frame.height, "--size");
  out.transmittance = gl::createTexture2D(GL_RGBA32F, frame.width, frame.height, "--size");
  a.output = out.inscattering.get();
  a.transmittanceOutput = out.transmittance.get();
  timings.time(std::string("atmosphere (") + atmosphereShaftsName(s.shafts) + ")", [&] {
    pass->run(a);
    glFinish();
  });
  return out;
}

gl::Handle compositeAtmosphere(const FrameInputs& frame, std::uint32_t surfaceColor,
                               const AtmosphereOutput& a) {
  static gl::Handle* program = nullptr; // built once per process, lives with the context
  if (!program)
    program = new gl::Handle(buildProgram({{ShaderStage::Compute, "passes/atmosphere_composite.comp", {}}}));
  const GLuint p = program->get();
  glProgramUniform2i(p, 0, frame.width, frame.height);
  return runImageProgram(p, frame.width, frame.height,
                         {surfaceColor, a.inscattering.get(), a.transmittance.get()}, "atmosphere composite");
}

} // namespace crep::tool
