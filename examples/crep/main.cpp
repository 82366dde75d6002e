// crep: the command-line tool of crepuscular. See `crep help`.
#include "args.h"
#include "atmosphere_frame.h"
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

#ifndef CREP_VERSION
#error "CREP_VERSION (the project version) must be defined by the build"
#endif

namespace {

const char* const kIntro = R"(crep - single scattering from rectified shadow maps

usage: crep <command> [options]
       crep <command> --help     that command's options
       crep --version

commands:
)";

const char* const kRender =
    R"(  render    render a built-in scene with volumetric scattering to EXR + PNG, print per-stage timings
            --scene NAME        colonnade (default) | forest | terrain | boxes | sunset (sun in view) |
                                colonnade-night (three spot lamps, no sun) | stained-glass (the sun
                                through a window, a light texture)
            --size WxH          image size (default 1280x720)
            --method M          prefilter (default: Klehm et al., GPU) | reference (world-space march
                                against a standard shadow map) | atmosphere (the Earth's sky,
                                aerial perspective and shafts; options below) | the other methods listed
                                below
@METHOD_OPTIONS@@ATMOSPHERE_OPTIONS@            --exposure X        PNG exposure in [1e-30, 1e30] (default 1)
@TONEMAP_OPTIONS@            --out PREFIX        output path prefix (default crep-<scene>): writes PREFIX.exr, PREFIX.png
            --export-frame DIR  also write the frame as input for `crep scatter`: DIR/depth.exr,
                                DIR/shadow.exr (float depth-buffer values), DIR/frame.json, and
                                DIR/lightN.exr for a scene's local lights
            --backend B         opengl (default) | vulkan: crep::Scattering (--method prefilter, minmax,
                                epipolar-sampling or epipolar-prefilter) on a Vulkan device, given
                                the scene's maps rendered by GL
            --debug-gl          debug GL context; GL errors abort the command
)";

const char* const kScatter =
    R"(  scatter   single scattering for your own data; writes a scattering EXR (RGB in-scattered radiance,
            A transmittance)
            --depth FILE.exr    camera depth: OpenGL depth-buffer values in [0, 1] (1 = sky)
            --shadow FILE.exr   the main light's map: depth-buffer values of shadowMap.lightClipFromWorld
                                (a point light: its six faces stacked, +X at the top;
                                docs/FORMATS.md)
            --frame FILE.json   camera, light (directional, spot or point; optional additional spot /
                                point lights with their own maps), shadow matrix and medium (schema:
                                docs/FORMATS.md, example: examples/data/frame.json)
            --method M          prefilter (default: the standard map is resampled into the projective
                                rectification on the CPU) | reference | the other methods below
@METHOD_OPTIONS@            --out FILE.exr      output (default scattering.exr); never one of the inputs
            --png FILE.png      also a tone-mapped preview of the in-scattered radiance
            --exposure X        PNG exposure in [1e-30, 1e30] (default 1)
            --debug-gl          debug GL context; GL errors abort the command
)";

const char* const kCompare =
    R"(  compare   every method plus the reference on one built-in scene and camera: a contact sheet PNG
            (images, amplified error heat maps, metrics and timings) and a CSV
            --scene NAME --size WxH (default 640x360) as for render
@METHOD_OPTIONS@            (--steps: reference march samples per pixel, default 512 here)
            --methods A,B       methods to run besides the reference (default: every method)
            --exposure X        exposure of the images on the sheet in [1e-30, 1e30] (default 1)
            --amplify X         error heat map: |error| / peak of the reference * X, in (0, 1e6]
                                (default 20)
            --tile-width N      width of each image on the sheet in [16, 4096] (default: the image
                                width within [16, 400])
            --out PREFIX        writes PREFIX.png and PREFIX.csv (default crep-compare-<scene>)
            --backend B         opengl (default) | vulkan: crep::Scattering's methods (prefilter,
                                minmax, epipolar-sampling, epipolar-prefilter) on a Vulkan device
                                (the reference and the other methods on OpenGL)
            --debug-gl          debug GL context; GL errors abort the command
)";

const char* const kRectify =
    R"(  rectify   print the projective rectification for a camera and a directional light as JSON:
            {"status": "projective"|"fallback"|"empty", "reason", "measure", "threshold",
             "splits": [{"rectClipFromWorld": [16 numbers, column-major], "range": [a, b]}]}
            ("empty": the lit part of the camera frustum is empty or flat, nothing is lit)
            --camera-pos x,y,z --camera-target x,y,z --camera-up x,y,z (default 0,1,0)
            --fovy-deg F (60, in [0.001, 180)) --aspect A (16/9) --near N (0.1) --far F (120)
            --light-dir x,y,z   direction the light travels
            --splits K (4) --scheme uniform|logarithmic|blend (logarithmic) --blend L (0.5)
            (camera and light default to the colonnade scene's)
)";

const char* const kHelp = R"(  help      this text (crep help <command>: that command's section)
)";

const char* const kFooter = R"(
Numbers: decimal only, no spaces or '+' (12, -0.5, 2e-3); sizes WIDTHxHEIGHT in digits (640x360).
Exit status: 0 success, 1 runtime error (GL, I/O, invalid input data or parameter; the message names
the file or field), 2 usage error (the message names the option; nothing has been written).
)";

/// `text` with its "@METHOD_OPTIONS@" replaced by the help lines of the method options.
std::string withMethodOptions(std::string text) {
  const std::string marker = "@METHOD_OPTIONS@";
  if (const auto at = text.find(marker); at != std::string::npos)
    text.replace(at, marker.size(), crep::tool::kMethodOptionsHelp);
  const std::string toneMapMarker = "@TONEMAP_OPTIONS@";
  if (const auto at = text.find(toneMapMarker); at != std::string::npos)
    text.replace(at, toneMapMarker.size(), crep::tool::kToneMapOptionsHelp);
  const std::string atmosphereMarker = "@ATMOSPHERE_OPTIONS@";
  if (const auto at = text.find(atmosphereMarker); at != std::string::npos)
    text.replace(at, atmosphereMarker.size(), crep::tool::kAtmosphereOptionsHelp);
  return text;
}

std::string paddedName(std::string name) {
  name.resize(std::max<std::size_t>(name.size(), 10), ' ');
  return name;
}

/// The `crep help` section of each command, in the order of `crep help`: the built-in commands, the
/// registered ones (bench/ adds `crep bench`) after compare.
struct Section {
  std::string name, text;
  bool methods = false; ///< takes --method / --methods: help lists the methods of this build
};

std::vector<Section> sections() {
  std::vector<Section> s = {{"render", withMethodOptions(kRender), true},
                            {"scatter", withMethodOptions(kScatter), true},
                            {"compare", withMethodOptions(kCompare), true}};
  for (const crep::tool::Command& c : crep::tool::registeredCommands())
    s.push_back({c.name, "  " + paddedName(c.name) + c.help, false});
  s.push_back({"rectify", kRectify, false});
  s.push_back({"help", kHelp, false});
  return s;
}

std::string methodList() {
  std::string methods = "\nmethods (this build):\n";
  for (const crep::tool::Method& m : crep::tool::methodRegistry())
    methods += "  " + paddedName(m.name) + "  " + m.summary + "\n";
  return methods;
}

void printUsage(std::FILE* out) {
  std::string text = kIntro;
  for (const Section& s : sections())
    text += s.text;
  text += methodList() + kFooter;
  std::fputs(text.c_str(), out);
}

/// `crep <command> --help`: that command's section (stdout). False if there is no such command.
bool printCommandHelp(const std::string& command) {
  for (const Section& s : sections())
    if (s.name == command) {
      std::string text = "usage: crep " + command + " [options]\n\n" + s.text;
      if (s.methods) text += methodList();
      text += kFooter;
      std::fputs(text.c_str(), stdout);
      return true;
    }
  return false;
}

bool isHelp(const std::string& arg) {
  return arg == "--help" || arg == "-h";
}

} // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    printUsage(stderr);
    return 2;
  }
  if (args[0] == "--version") {
    std::printf("crep %s\n", CREP_VERSION);
    return 0;
  }
  if (args[0] == "help" || isHelp(args[0])) {
    if (args.size() == 1) {
      printUsage(stdout);
      return 0;
    }
    if (args.size() == 2 && printCommandHelp(args[1])) return 0;
    std::fprintf(stderr, "crep help: unknown command '%s' (see crep help)\n", args[1].c_str());
    return 2;
  }
  const std::string command = args[0];
  args.erase(args.begin());
  // Every command answers --help (anywhere among its options) with its section of the usage text.
  if (std::any_of(args.begin(), args.end(), isHelp) && printCommandHelp(command)) return 0;
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
