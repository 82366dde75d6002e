// `crep compare`: one built-in scene and camera, every method of the registry plus the reference.
// Writes a contact sheet PNG (each method's composited image, an amplified error heat map against the
// reference, metrics and timings printed on the sheet) and a CSV (relative RMSE, PSNR, max and mean
// absolute error of the in-scattered radiance against the reference, milliseconds per stage).
#include "args.h"
#include "backend_method.h"
#include "commands.h"
#include "contact_sheet.h"
#include "gl_session.h"
#include "methods.h"
#include "options.h"
#include "paths.h"
#include "scene_frame.h"
#include "timings.h"

#include <crep/core/error.h>
#include <crep/scenes/scene.h>
#include <crep/support/image_compare.h>
#include <crep/support/output_file.h>
#include <crep/support/png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <unistd.h>

namespace crep::tool {

namespace {

struct Result {
  std::string name, used, detail;
  Image scattering, composite;
  ImageMetrics metrics;
  StageTimings timings;
};

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s)
    q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::vector<std::string> selectedMethods(const Args& args) {
  std::vector<std::string> names;
  for (const Method& m : methodRegistry())
    if (m.reference) names.push_back(m.name);
  if (!args.has("methods")) {
    for (const Method& m : methodRegistry())
      if (!m.reference) names.push_back(m.name);
    return names;
  }
  // Names separated by single commas: an empty list or an empty name ("prefilter,", "a,,b") is an error,
  // not a silently shorter list.
  const std::string list = args.string("methods", "");
  if (list.empty())
    throw UsageError("option --methods: empty; give methods separated by commas (" + methodNames() + ")");
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = list.find(',', start);
    const std::string name =
        list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (name.empty())
      throw UsageError("option --methods: '" + list +
                       "' has an empty method name (names separated by single "
                       "commas: " +
                       methodNames() + ")");
    const Method& m = findMethod(name, "--methods");
    if (std::find(names.begin(), names.end(), m.name) == names.end()) names.push_back(m.name);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return names;
}

/// The command line of `crep compare`, checked.
struct CompareArgs {
  std::string sceneName;
  glm::ivec2 size{0};
  MethodSettings settings;
  double exposure = 0.0, amplify = 0.0;
  int tileWidth = 0;
  std::vector<std::string> names; ///< the methods, the reference first
  std::string out, csvPath, pngPath;
  std::string backend = "opengl"; ///< --backend: crep::Scattering's methods on Vulkan (backend_method.h)
  bool debugGl = false;
};

/// Parses and checks the command line: the scene, the sizes (the contact sheet within the image limits),
/// the methods and the output prefix.
CompareArgs parseCompareArgs(const std::vector<std::string>& argv) {
  std::set<std::string> valued = {"scene",   "size",    "out",     "exposure",
                                  "amplify", "methods", "backend", "tile-width"};
  valued.insert(kMethodOptions.begin(), kMethodOptions.end());
  valued.erase("method");
  const Args args(argv, valued, {"debug-gl"});
  CompareArgs o;
  o.sceneName = args.string("scene", "colonnade");
  requireSceneName(o.sceneName); // before the default --out (crep-compare-<scene>) is derived from it
  o.size = args.size("size", {640, 360}, Image::kMaxDimension, Image::kMaxPixels);
  o.settings = methodSettings(args);
  if (!args.has("steps")) o.settings.steps = 512;
  o.exposure = exposureOption(args);
  o.amplify = args.number("amplify", 20.0);
  // Bounded so that the legend prints a plain number; at 1e6 float rounding of the images (relative
  // 6e-8) already fills 6% of the heat map's scale.
  if (!(o.amplify > 0.0 && o.amplify <= 1e6)) throw UsageError("option --amplify: must be in (0, 1e6]");
  // Default: the image width within the accepted tile widths (a 1-pixel wide image is shown 16 wide).
  o.tileWidth =
      args.integer("tile-width", std::clamp(o.size.x, kMinTileWidth, 400), kMinTileWidth, kMaxTileWidth);
  o.names = selectedMethods(args);
  o.backend = args.string("backend", "opengl");
  if (o.backend != "opengl") {
    requireBackend(o.backend);
    if (std::none_of(o.names.begin(), o.names.end(), runsOnBackend))
      throw UsageError(
          "option --backend " + o.backend +
          ": runs prefilter, minmax, epipolar-sampling and epipolar-prefilter; --methods has none");
  }
  const glm::ivec2 size = o.size;
  requireMethodImageSize(o.settings, o.names, size,
                         "--size " + std::to_string(size.x) + "x" + std::to_string(size.y), false);
  const glm::ivec2 sheetBound = sheetSizeBound(o.tileWidth, size, static_cast<int>(o.names.size()));
  if (sheetBound.y > Image::kMaxDimension ||
      static_cast<long long>(sheetBound.x) * sheetBound.y > Image::kMaxPixels)
    throw UsageError(
        "option --tile-width: tiles " + std::to_string(o.tileWidth) + " wide for --size " +
        std::to_string(size.x) + "x" + std::to_string(size.y) + " make a contact sheet of up to " +
        std::to_string(sheetBound.x) + "x" + std::to_string(sheetBound.y) +
        " pixels, beyond the image limits (" + std::to_string(Image::kMaxDimension) + " per side, " +
        std::to_string(Image::kMaxPixels) + " pixels): use a smaller --tile-width or a wider --size");
  o.out = args.string("out", "crep-compare-" + o.sceneName);
  requireOutputPrefix({"--out", o.out});
  o.csvPath = o.out + ".csv";
  o.pngPath = o.out + ".png";
  o.debugGl = args.has("debug-gl");
  return o;
}

/// Every method on the frame: its scattering and composited images and timings, and its metrics against
/// the first method's image (the reference).
std::vector<Result> runMethods(const CompareArgs& o, SceneFrame& s) {
  FrameInputs& frame = *s.frame;
  std::vector<Result> results;
  for (const std::string& name : o.names) {
    if (isatty(2)) std::fprintf(stderr, "crep compare: method %s ...\n", name.c_str());
    MethodOutput m = o.backend == "vulkan" && runsOnBackend(name) ? runOnVulkan(s, name, o.settings)
                                                                  : runMethod(name, frame, o.settings);
    gl::Handle composite = compositeImage(frame, s.color.get(), m.scattering.get());
    Result r{name,
             m.used,
             m.detail,
             readRgba(m.scattering.get(), o.size.x, o.size.y),
             readRgba(composite.get(), o.size.x, o.size.y),
             {},
             m.timings};
    checkGlErrors(name.c_str());
    requireFinite(r.scattering, "the scattering image of " + name);
    results.push_back(std::move(r));
  }
  const Image& reference = results.front().scattering;
  crep::CompareOptions compareOptions;
  compareOptions.channels = 3;
  for (Result& r : results)
    r.metrics = compareImages(r.scattering, reference, compareOptions);
  return results;
}

/// The CSV: one row per method; a column per stage any method has (empty where it has none).
std::string compareCsv(const CompareArgs& o, const std::vector<Result>& results) {
  std::vector<std::string> stages;
  for (const Result& r : results)
    for (const auto& row : r.timings.rows())
      if (std::find(stages.begin(), stages.end(), row.stage) == stages.end()) stages.push_back(row.stage);
  std::ostringstream csv;
  csv << "scene,width,height,method,ran,relative_rmse,psnr_db,max_abs_error,mean_abs_error";
  for (const std::string& st : stages)
    csv << "," << csvField("ms " + st);
  csv << ",ms total\n";
  for (const Result& r : results) {
    csv << o.sceneName << "," << o.size.x << "," << o.size.y << "," << r.name << "," << csvField(r.used)
        << "," << number(r.metrics.relativeRmse) << "," << number(r.metrics.psnr) << ","
        << number(r.metrics.maxAbsError) << "," << number(r.metrics.meanAbsError);
    for (const std::string& st : stages) {
      csv << ",";
      double ms = 0.0;
      bool found = false;
      for (const auto& row : r.timings.rows())
        if (row.stage == st) {
          ms += row.ms;
          found = true;
        }
      if (found) csv << fixed(ms, 3);
    }
    csv << "," << fixed(r.timings.total(), 3) << "\n";
  }
  return csv.str();
}

/// The contact sheet's columns: each method's composite, its error heat map against the reference (the
/// first), metrics and timings, every text line clipped to the tile.
std::vector<SheetColumn> sheetColumns(const CompareArgs& o, const std::vector<Result>& results) {
  const Image& reference = results.front().scattering;
  const double peak = results.front().metrics.peak;
  std::vector<SheetColumn> columns;
  const std::size_t maxChars = static_cast<std::size_t>(std::max(8, o.tileWidth / 6));
  auto clip = [&](std::string line) {
    if (line.size() > maxChars) line = line.substr(0, maxChars - 3) + "...";
    return line;
  };
  for (std::size_t i = 0; i < results.size(); ++i) {
    const Result& r = results[i];
    SheetColumn c;
    c.title = r.name + (r.used != r.name ? " (ran " + r.used + ")" : "");
    c.image = r.composite;
    if (i > 0) c.heat = heatMap(r.scattering, reference, peak, o.amplify);
    c.lines.push_back(clip(r.detail));
    if (i > 0) {
      c.lines.push_back(clip("rel RMSE " + fixed(100.0 * r.metrics.relativeRmse, 2) + "%   PSNR " +
                             fixed(r.metrics.psnr, 1) + " dB"));
      c.lines.push_back(
          clip("max |error| " + number(r.metrics.maxAbsError) + " (peak " + number(peak) + ")"));
    } else {
      c.lines.push_back(clip("the reference of the error maps"));
      c.lines.push_back(clip("in-scattering peak " + number(peak)));
    }
    for (const auto& row : r.timings.rows())
      c.lines.push_back(clip(row.stage + ": " + fixed(row.ms, 1) + " ms"));
    c.lines.push_back(clip("total: " + fixed(r.timings.total(), 1) + " ms"));
    columns.push_back(std::move(c));
  }
  return columns;
}

/// The contact sheet: the header line over the columns.
Image contactSheet(const CompareArgs& o, const std::vector<Result>& results) {
  const std::string header = "crep compare: scene " + o.sceneName + ", " + std::to_string(o.size.x) + "x" +
                             std::to_string(o.size.y) + ", map " + std::to_string(o.settings.mapSize) +
                             "^2, " +
                             (o.settings.prefilter.reconstruction == VisibilityReconstruction::Exact
                                  ? std::string("exact visibility")
                                  : "Fourier M = " + std::to_string(o.settings.prefilter.bases)) +
                             ", reference = world-space march, " + std::to_string(o.settings.steps) +
                             " steps; GL renderer: " + glRenderer();
  return composeSheet(header, sheetColumns(o, results), o.tileWidth, o.exposure, o.amplify);
}

/// The summary on stdout: one line per method.
void printSummary(const CompareArgs& o, const std::vector<Result>& results) {
  std::printf("crep compare: scene %s, %dx%d, map %d^2, reference %d march steps\n", o.sceneName.c_str(),
              o.size.x, o.size.y, o.settings.mapSize, o.settings.steps);
  std::printf("%-12s %-12s %10s %10s %12s %12s\n", "method", "ran", "rel RMSE", "PSNR dB", "max error",
              "total ms");
  for (const Result& r : results)
    std::printf("%-12s %-12s %9.3f%% %10s %12s %12.1f\n", r.name.c_str(), r.used.c_str(),
                100.0 * r.metrics.relativeRmse, number(r.metrics.psnr).c_str(),
                number(r.metrics.maxAbsError).c_str(), r.timings.total());
  std::printf("wrote %s (contact sheet) and %s\n", o.pngPath.c_str(), o.csvPath.c_str());
}

} // namespace

int compareCommand(const std::vector<std::string>& argv) {
  const CompareArgs o = parseCompareArgs(argv);
  // Both outputs checked now, written at the end, all or nothing (paths.h "The output rule").
  OutputFiles outputs;
  outputs.addFile({"--out", o.pngPath});
  outputs.addFile({"--out", o.csvPath});

  StageTimings timings;
  if (isatty(2)) timings.setProgress("crep compare");
  ensureGlContext("compare", o.debugGl, timings);
  SceneFrame s = makeSceneFrame(o.sceneName, o.size.x, o.size.y, o.settings.mapSize, timings);
  const std::vector<Result> results = runMethods(o, s);
  const std::string csv = compareCsv(o, results);
  outputs.write(o.csvPath, [&](const std::filesystem::path& file) { writeTextFile(file, csv); });
  const Image sheet = contactSheet(o, results);
  outputs.write(o.pngPath, [&](const std::filesystem::path& file) { writePng(file, sheet); });
  outputs.commit();
  printSummary(o, results);
  return 0;
}

} // namespace crep::tool
