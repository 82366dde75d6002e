// The tool's registry of scattering methods: each a function that runs on one FrameInputs and reports its
// stages. Adding a method is one entry in methodRegistry() (methods.cpp): a name, a one-line summary and
// a function FrameInputs -> MethodOutput built from the library's passes.
#pragma once

#include "frame.h"
#include "timings.h"

#include <crep/epipolar/epipolar.h>
#include <crep/gpu/gl.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace crep::tool {

/// What one method produced.
struct MethodOutput {
  gl::Handle scattering; ///< GL_RGBA32F width x height: RGB in-scattered radiance, A grey transmittance
  std::string used;      ///< the method actually run (a fallback may differ from the one asked)
  std::string detail;    ///< its parameters, for the report
  StageTimings timings;  ///< its stages (wall clock, each ends with glFinish)
};

/// One registry entry.
struct Method {
  std::string name;
  std::string summary;
  bool reference = false; ///< the reference of `crep compare`
  std::function<MethodOutput(FrameInputs&, const MethodSettings&)> run;
};

/// Every method available in this build, the reference first.
const std::vector<Method>& methodRegistry();
/// The entry called `name`; throws UsageError naming `option` and listing the names otherwise.
const Method& findMethod(const std::string& name, const std::string& option = "--method");
/// "prefilter | reference | ..." for help texts and errors.
std::string methodNames();

/// The epipolar fallback map of a frame: the layout of Klehm et al. 2014, Sec. 4.1 for the frame's
/// camera, light and screen, and the standard shadow map resampled into it on the GPU.
struct EpipolarMap {
  std::shared_ptr<EpipolarLayout> layout;
  gl::Handle texture; ///< R32F, width x sliceCount
  int width = 0, height = 0;
};
EpipolarMap makeEpipolarMap(const FrameInputs& frame, const MethodSettings& settings, StageTimings& timings);

/// Runs `name` and, when the rectification is not projective and the method needs it, the fallback
/// (announced on stderr by the method).
MethodOutput runMethod(const std::string& name, FrameInputs& frame, const MethodSettings& settings);
/// The front door's CreateInfo of the tool's settings for `frame` (the prefilter, minmax and epipolar
/// methods; `crep render --backend` adds its backend).
Scattering::CreateInfo frontDoorCreateInfo(const FrameInputs& frame, const MethodSettings& settings,
                                           Scattering::Method method,
                                           Scattering::Sampling sampling = Scattering::Sampling::PerPixel);

} // namespace crep::tool
