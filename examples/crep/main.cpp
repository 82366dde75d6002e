// crep: the command-line tool of crepuscular. See `crep help`.
#include "args.h"
#include "commands.h"

#include <crep/core/error.h>

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
                                against a standard shadow map)
            --map-size N        shadow map and rectified map size (default 1024)
            --bases M           Fourier bases, a multiple of 4 in [4, 128] (default 32)
            --format F          filtered-basis storage rgba8 (default) | rgba16f | rgba32f
            --splits K          rectification splits (default 4; --map-size must be a multiple)
            --steps N           reference march samples per pixel (default 256)
            --exposure X        PNG exposure (default 1)
            --out PREFIX        output path prefix (default crep-<scene>): writes PREFIX.exr, PREFIX.png
            --debug-gl          debug GL context; GL errors abort the command
  rectify   print the projective rectification for a camera and a directional light as JSON:
            {"status": "projective"|"fallback", "reason", "measure", "threshold",
             "splits": [{"rectClipFromWorld": [16 numbers, column-major], "range": [a, b]}]}
            --camera-pos x,y,z --camera-target x,y,z --camera-up x,y,z (default 0,1,0)
            --fovy-deg F (60) --aspect A (16/9) --near N (0.1) --far F (120)
            --light-dir x,y,z   direction the light travels
            --splits K (4) --scheme uniform|logarithmic|blend (logarithmic) --blend L (0.5)
            (camera and light default to the colonnade scene's)
  help      this text

Exit status: 0 success, 1 runtime error (GL, I/O, invalid parameter), 2 usage error.
)";

} // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "help" || args[0] == "--help" || args[0] == "-h") {
    std::fputs(kUsage, args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  const std::string command = args[0];
  args.erase(args.begin());
  try {
    if (command == "render") return crep::tool::renderCommand(args);
    if (command == "rectify") return crep::tool::rectifyCommand(args);
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
