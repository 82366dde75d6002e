// crep: the command-line tool of crepuscular. See `crep help`.
#include "args.h"
#include "command_registry.h"
#include "commands.h"
#include "methods.h"
#include "options.h"

#include <crep/core/error.h>
#include <crep/scenes/shaders.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

namespace {

const char* kUsage = R"(crep - single scattering from rectified shadow maps

usage: crep <command> [options]

commands:
  render    render a built-in scene with volumetric scattering to EXR + PNG, print per-stage timings
            --scene NAME        colonnade (default) | forest | terrain | boxes
            --size WxH          image size (default 1280x720)
            --method M          prefilter (default: Klehm et al., GPU) | reference (world-space march
                                against a standard shadow map) | the other methods listed below
%s            --exposure X        PNG exposure (default 1)
            --out PREFIX        output path prefix (default crep-<scene>): writes PREFIX.exr, PREFIX.png
            --export-frame DIR  also write the frame as input for `crep scatter`: DIR/depth.exr,
                                DIR/shadow.exr (float depth-buffer values), DIR/frame.json
            --debug-gl          debug GL context; GL errors abort the command
  scatter   single scattering for your own data; writes a scattering EXR (RGB in-scattered radiance,
            A transmittance)
            --depth FILE.exr    camera depth: OpenGL depth-buffer values in [0, 1] (1 = sky)
            --shadow FILE.exr   standard shadow map: depth-buffer values of shadowMap.lightClipFromWorld
            --frame FILE.json   camera, light, shadow matrix and medium (schema: README, example:
                                examples/data/frame.json)
            --method M          prefilter (default: the standard map is resampled into the projective
                                rectification on the CPU) | reference | the other methods below
            (and --map-size --bases --format --splits --steps as for render)
            --out FILE.exr      output (default scattering.exr)
            --png FILE.png      also a tone-mapped preview of the in-scattered radiance
            --exposure X        PNG exposure (default 1)
  compare   every method plus the reference on one built-in scene and camera: a contact sheet PNG
            (images, amplified error heat maps, metrics and timings) and a CSV
            --scene NAME --size WxH (default 640x360) and the method options of render
            --steps N           reference march samples per pixel (default 512)
            --methods A,B       methods to run besides the reference (default: every method)
            --amplify X         error heat map: |error| / peak of the reference * X (default 20)
            --tile-width N      width of each image on the sheet (default: min(image width, 400))
            --out PREFIX        writes PREFIX.png and PREFIX.csv (default crep-compare-<scene>)
%s  rectify   print the projective rectification for a camera and a directional light as JSON:
            {"status": "projective"|"fallback", "reason", "measure", "threshold",
             "splits": [{"rectClipFromWorld": [16 numbers, column-major], "range": [a, b]}]}
            --camera-pos x,y,z --camera-target x,y,z --camera-up x,y,z (default 0,1,0)
            --fovy-deg F (60) --aspect A (16/9) --near N (0.1) --far F (120)
            --light-dir x,y,z   direction the light travels
            --splits K (4) --scheme uniform|logarithmic|blend (logarithmic) --blend L (0.5)
            (camera and light default to the colonnade scene's)
  help      this text

methods (this build):
%s
Exit status: 0 success, 1 runtime error (GL, I/O, invalid input data or parameter; the message names
the file or field), 2 usage error (the message names the option).
)";

std::string paddedName(std::string name) {
  name.resize(std::max<std::size_t>(name.size(), 10), ' ');
  return name;
}

void printUsage(std::FILE* out) {
  // Commands registered by other parts of the build (bench/ adds `crep bench`), after compare.
  std::string registered;
  for (const crep::tool::Command& c : crep::tool::registeredCommands())
    registered += "  " + paddedName(c.name) + c.help;
  std::string methods;
  for (const crep::tool::Method& m : crep::tool::methodRegistry())
    methods += "  " + paddedName(m.name) + "  " + m.summary + "\n";
  std::fprintf(out, kUsage, crep::tool::kMethodOptionsHelp, registered.c_str(), methods.c_str());
}

} // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "help" || args[0] == "--help" || args[0] == "-h") {
    printUsage(args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  const std::string command = args[0];
  args.erase(args.begin());
  try {
    // The tool's own shaders (reference march, compositing, scene rasterization) next to the library's.
    crep::scenes::registerShaders();
    if (command == "render") return crep::tool::renderCommand(args);
    if (command == "scatter") return crep::tool::scatterCommand(args);
    if (command == "compare") return crep::tool::compareCommand(args);
    if (command == "rectify") return crep::tool::rectifyCommand(args);
    if (const crep::tool::Command* registered = crep::tool::findCommand(command))
      return registered->run(args);
    std::fprintf(stderr, "crep: unknown command '%s' (see crep help)\n", command.c_str());
    return 2;
  } catch (const crep::tool::UsageError& e) {
    std::fprintf(stderr, "crep %s: %s\n", command.c_str(), e.what());
    return 2;
  } catch (const crep::Error& e) {
    std::fprintf(stderr, "crep %s: %s\n", command.c_str(), e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crep %s: unexpected error: %s\n", command.c_str(), e.what());
    return 1;
  }
}
