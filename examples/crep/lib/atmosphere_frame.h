// The tool's atmosphere (crep/atmosphere/atmosphere.h, gpu_tables.h, gpu_pass.h): `crep render
// --method atmosphere` places a built-in scene on the Earth, sets the sun by its elevation and azimuth,
// precomputes (or loads from the disk cache) the scattering tables and evaluates the sky, the aerial
// perspective and the light shafts of the scene's shadow map with one of the shaft methods (a), (b), (c).
//
// Conventions of the options: world +Y is up, the sun's azimuth is measured from -Z (the direction the
// built-in cameras face) towards +X, so azimuth 0 puts the sun straight ahead of a built-in camera and 90 to
// its right; the direction towards the sun is (sin az cos el, sin el, -cos az cos el).
#pragma once

#include "args.h"
#include "frame.h"
#include "timings.h"

#include <crep/atmosphere/atmosphere.h>
#include <crep/atmosphere/gpu_tables.h>
#include <crep/core/camera.h>
#include <crep/core/light.h>
#include <crep/gpu/gl.h>

#include <memory>
#include <optional>
#include <set>
#include <string>

namespace crep::tool {

/// --sun-elevation --sun-azimuth --camera-elevation --shafts --meters-per-unit --origin-altitude
/// --atmosphere-table --orders --atmosphere-cache --sun-irradiance --multiple-scattering --ground-albedo
/// --integration-steps --sky-steps --single-scattering --half-float-tables
extern const std::set<std::string> kAtmosphereOptions;
extern const char* const kAtmosphereOptionsHelp;

struct AtmosphereSettings {
  double sunElevation = 30.0;            ///< degrees above the horizon, in [-90, 90]
  std::optional<double> sunAzimuth;      ///< degrees; unset: the scene's own sun azimuth
  std::optional<double> cameraElevation; ///< degrees, in [-89, 89]; unset: the scene's camera
  AtmosphereShafts shafts = AtmosphereShafts::Integrated;
  AtmospherePlacement placement{50.0, 0.0};
  AtmosphereParameters parameters;
  AtmospherePrecomputeOptions tables;
  AtmosphereRayOptions ray;     ///< (a)'s steps, None/(b)/(c)'s single scattering (shafts: `shafts` above)
  bool halfFloatTables = false; ///< AtmosphereTablesPass::CreateInfo::halfFloatTables
  std::string cacheDirectory;   ///< empty: no cache
  double sunIrradiance = 10.0;  ///< extraterrestrial sun irradiance (white)
};

/// The settings of those options (UsageError naming the option for bad values). The cache directory
/// defaults to $XDG_CACHE_HOME/crepuscular, else $HOME/.cache/crepuscular, else none; "none" disables it.
AtmosphereSettings atmosphereSettings(const Args& args);
/// Whether any of those options is given (they need --method atmosphere).
bool hasAtmosphereOptions(const Args& args);

/// "none" | "integrated" | "lut" | "prefiltered" (the values of --shafts).
const char* atmosphereShaftsName(AtmosphereShafts shafts);

/// The sun of these settings (azimuth default: `sceneSun`'s).
DirectionalLight atmosphereSun(const AtmosphereSettings& s, const DirectionalLight& sceneSun);
/// The camera of these settings: `sceneCamera` pitched to cameraElevation (yaw and position kept).
Camera atmosphereCamera(const AtmosphereSettings& s, const Camera& sceneCamera);

/// The tables on the GPU and their CPU copy: loaded from the cache when valid (a corrupt file is reported
/// on stderr and recomputed), else computed on the GPU (and saved). Stages to `timings`.
struct AtmosphereTableSet {
  std::unique_ptr<AtmosphereTablesPass> pass;
  AtmosphereTables cpu;
  bool loaded = false; ///< from the cache
};
AtmosphereTableSet atmosphereTables(const AtmosphereSettings& s, StageTimings& timings);

/// The sky, aerial perspective and shafts of a frame whose light is atmosphereSun(s, ...).
struct AtmosphereOutput {
  gl::Handle inscattering;  ///< GL_RGBA32F: RGB in-scattered radiance, A mean transmittance
  gl::Handle transmittance; ///< GL_RGBA32F: RGB transmittance to the surface (0 for the sky beyond it)
  std::string detail;
};
AtmosphereOutput runAtmosphere(FrameInputs& frame, const MethodSettings& settings,
                               const AtmosphereSettings& s, const AtmosphereTablesPass& tables,
                               StageTimings& timings);

/// surface * transmittance + in-scattering (GL_RGBA32F).
gl::Handle compositeAtmosphere(const FrameInputs& frame, std::uint32_t surfaceColor,
                               const AtmosphereOutput& a);

} // namespace crep::tool
