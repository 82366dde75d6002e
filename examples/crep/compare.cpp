// `crep compare`: one built-in scene and camera, every method of the registry plus the reference.
// Writes a contact sheet PNG (each method's composited image, an amplified error heat map against the
// reference, metrics and timings printed on the sheet) and a CSV (relative RMSE, PSNR, max and mean
// absolute error of the in-scattered radiance against the reference, milliseconds per stage).
#include "args.h"
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

} // namespace

int compareCommand(const std::vector<std::string>& argv) {
  std::set<std::string> valued = {"scene", "size", "out", "exposure", "amplify", "tile-width", "methods"};
  valued.insert(kMethodOptions.begin(), kMethodOptions.end());
  valued.erase("method");
  const Args args(argv, valued, {"debug-gl"});
  const std::string sceneName = args.string("scene", "colonnade");
  requireSceneName(sceneName); // before the default --out (crep-compare-<scene>) is derived from it
  const glm::ivec2 size = args.size("size", {640, 360}, Image::kMaxDimension, Image::kMaxPixels);
  MethodSettings settings = methodSettings(args);
  if (!args.has("steps")) settings.steps = 512;
  const double exposure = exposureOption(args);
  const double amplify = args.number("amplify", 20.0);
  // Bounded so that the legend prints a plain number; at 1e6 float rounding of the images (relative
  // 6e-8) already fills 6% of the heat map's scale.
  if (!(amplify > 0.0 && amplify <= 1e6)) throw UsageError("option --amplify: must be in (0, 1e6]");
  // Default: the image width within the accepted tile widths (a 1-pixel wide image is shown 16 wide).
  const int tileWidth =
      args.integer("tile-width", std::clamp(size.x, kMinTileWidth, 400), kMinTileWidth, kMaxTileWidth);
  const std::vector<std::string> names = selectedMethods(args);
  requireMethodImageSize(settings, names, size,
                         "--size " + std::to_string(size.x) + "x" + std::to_string(size.y), false);
  const glm::ivec2 sheetBound = sheetSizeBound(tileWidth, size, static_cast<int>(names.size()));
  if (sheetBound.y > Image::kMaxDimension ||
      static_cast<long long>(sheetBound.x) * sheetBound.y > Image::kMaxPixels)
    throw UsageError(
        "option --tile-width: tiles " + std::to_string(tileWidth) + " wide for --size " +
        std::to_string(size.x) + "x" + std::to_string(size.y) + " make a contact sheet of up to " +
        std::to_string(sheetBound.x) + "x" + std::to_string(sheetBound.y) +
        " pixels, beyond the image limits (" + std::to_string(Image::kMaxDimension) + " per side, " +
        std::to_string(Image::kMaxPixels) + " pixels): use a smaller --tile-width or a wider --size");
  const std::string out = args.string("out", "crep-compare-" + sceneName);
  requireOutputPrefix({"--out", out});
  const std::string csvPath = out + ".csv", pngPath = out + ".png";
  // Both outputs checked now, written at the end, all or nothing (paths.h "The output rule").
  OutputFiles outputs;
  outputs.addFile({"--out", pngPath});
  outputs.addFile({"--out", csvPath});

  StageTimings timings;
  if (isatty(2)) timings.setProgress("crep compare");
  ensureGlContext("compare", args.has("debug-gl"), timings);
  SceneFrame s = makeSceneFrame(sceneName, size.x, size.y, settings.mapSize, timings);
  FrameInputs& frame = *s.frame;

  std::vector<Result> results;
  for (const std::string& name : names) {
    if (isatty(2)) std::fprintf(stderr, "crep compare: method %s ...\n", name.c_str());
    MethodOutput o = runMethod(name, frame, settings);
    gl::Handle composite = compositeImage(frame, s.color.get(), o.scattering.get());
    Result r{name,
             o.used,
             o.detail,
             readRgba(o.scattering.get(), size.x, size.y),
             readRgba(composite.get(), size.x, size.y),
             {},
             o.timings};
    checkGlErrors(name.c_str());
    requireFinite(r.scattering, "the scattering image of " + name);
    results.push_back(std::move(r));
  }
  const Image& reference = results.front().scattering;
  CompareOptions compareOptions;
  compareOptions.channels = 3;
  for (Result& r : results)
    r.metrics = compareImages(r.scattering, reference, compareOptions);
  const double peak = results.front().metrics.peak;

  // CSV: one row per method; a column per stage any method has (empty where it has none).
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
    csv << sceneName << "," << size.x << "," << size.y << "," << r.name << "," << csvField(r.used) << ","
        << number(r.metrics.relativeRmse) << "," << number(r.metrics.psnr) << ","
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
  outputs.write(csvPath, [&](const std::filesystem::path& file) { writeTextFile(file, csv.str()); });

  // Contact sheet.
  std::vector<SheetColumn> columns;
  const std::size_t maxChars = static_cast<std::size_t>(std::max(8, tileWidth / 6));
  auto clip = [&](std::string line) {
    if (line.size() > maxChars) line = line.substr(0, maxChars - 3) + "...";
    return line;
  };
  for (std::size_t i = 0; i < results.size(); ++i) {
    const Result& r = results[i];
    SheetColumn c;
    c.title = r.name + (r.used != r.name ? " (ran " + r.used + ")" : "");
    c.image = r.composite;
    if (i > 0) c.heat = heatMap(r.scattering, reference, peak, amplify);
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
  const std::string header = "crep compare: scene " + sceneName + ", " + std::to_string(size.x) + "x" +
                             std::to_string(size.y) + ", map " + std::to_string(settings.mapSize) +
                             "^2, M = " + std::to_string(settings.prefilter.bases) +
                             ", reference = world-space march, " + std::to_string(settings.steps) +
                             " steps; GL renderer: " + glRenderer();
  const Image sheet = composeSheet(header, columns, tileWidth, exposure, amplify);
  outputs.write(pngPath, [&](const std::filesystem::path& file) { writePng(file, sheet); });
  outputs.commit();

  std::printf("crep compare: scene %s, %dx%d, map %d^2, reference %d march steps\n", sceneName.c_str(),
              size.x, size.y, settings.mapSize, settings.steps);
  std::printf("%-12s %-12s %10s %10s %12s %12s\n", "method", "ran", "rel RMSE", "PSNR dB", "max error",
              "total ms");
  for (const Result& r : results)
    std::printf("%-12s %-12s %9.3f%% %10s %12s %12.1f\n", r.name.c_str(), r.used.c_str(),
                100.0 * r.metrics.relativeRmse, number(r.metrics.psnr).c_str(),
                number(r.metrics.maxAbsError).c_str(), r.timings.total());
  std::printf("wrote %s (contact sheet) and %s\n", pngPath.c_str(), csvPath.c_str());
  return 0;
}

} // namespace crep::tool
