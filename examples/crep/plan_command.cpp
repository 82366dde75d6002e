// `crep plan`: the shadow passes crep::Scattering plans for a built-in scene's frame (Scattering::plan,
// crep/pipeline/shadow_pass_plan.h) in an engine's clip convention: printed as a table, or written as JSON
// for debugging an engine's shadow passes against it. CPU only once the front door is built.
#include "args.h"
#include "command_registry.h"
#include "gl_session.h"
#include "paths.h"
#include "scene_frame.h"

#include <crep/core/error.h>
#include <crep/pipeline/scattering.h>
#include <crep/pipeline/shadow_pass_plan.h>
#include <crep/scenes/scene.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace crep::tool {

namespace {

ClipConvention conventionOption(const std::string& token) {
  for (ClipConvention c : {ClipConvention::OpenGL, ClipConvention::OpenGLZeroToOne, ClipConvention::Vulkan,
                           ClipConvention::Direct3D12, ClipConvention::Metal})
    if (token == conventionToken(c)) return c;
  throw UsageError("option --convention: unknown convention '" + token +
                   "' (one of: opengl, opengl-zero-to-one, vulkan, d3d12, metal)");
}

std::string lightName(const ShadowPass& p) {
  switch (p.light) {
  case ShadowPass::Light::Sun:
    return "sun";
  case ShadowPass::Light::Spot:
    return "spot " + std::to_string(p.index);
  case ShadowPass::Light::PointFace:
    return "point " + std::to_string(p.index) + " face " + std::to_string(p.face);
  }
  return "?";
}

std::string kindName(const ShadowPass& p) {
  if (p.kind == ShadowPass::Kind::Rectified) return "rectified";
  if (p.kind == ShadowPass::Kind::Standard) return p.served ? "standard (served)" : "standard";
  return "none";
}

int planCommand(const std::vector<std::string>& argv) {
  const Args args(argv, {"scene", "size", "map-size", "splits", "convention", "json"}, {"reversed-z"});
  const std::string sceneName = args.string("scene", "colonnade");
  requireSceneName(sceneName);
  const glm::ivec2 size = args.size("size", {1280, 720}, Image::kMaxDimension, Image::kMaxPixels);
  const ShadowPassPlanOptions options{conventionOption(args.string("convention", "opengl")),
                                      args.has("reversed-z")};
  Scattering::CreateInfo info;
  info.width = size.x;
  info.height = size.y;
  info.mapSize = args.integer("map-size", 1024, 16, 16384);
  info.rectify.splits = args.integer("splits", 8, 1, RectifyOptions::kMaxSplits);
  info.stageTimings = false;
  if (info.mapSize % info.mapSizeMultiple() != 0)
    throw UsageError("option --map-size: " + std::to_string(info.mapSize) + " must be a multiple of " +
                     std::to_string(info.mapSizeMultiple()) +
                     " (2 x --splits and the fallback's 16 regions)");
  const std::string json = args.string("json", "");
  OutputFiles files;
  if (args.has("json") && json != "-") files.addFile({"--json", json});

  StageTimings timings;
  ensureGlContext("plan", false, timings); // the front door is built on the GL backend; plan() is CPU only
  const scenes::Scene scene = scenes::makeScene(sceneName, double(size.x) / size.y);
  const Scattering scattering(info);
  Scattering::FrameAttribs frame;
  frame.camera = &scene.camera;
  frame.light = scene.hasSun ? &scene.sun : nullptr;
  frame.medium = &scene.medium;
  frame.spotLights = scene.spotLights;
  frame.pointLights = scene.pointLights;
  const ShadowPassPlan plan = scattering.plan(frame, options);

  if (json == "-") {
    std::printf("%s\n", toJson(plan).c_str());
    return 0;
  }
  std::printf("crep plan: scene %s, %dx%d, convention %s%s, map %d^2, %d splits, standard maps %d^2\n",
              sceneName.c_str(), size.x, size.y, conventionToken(options.convention),
              options.reversedZ ? " (reversed-Z)" : "", info.mapSize, info.rectify.splits,
              info.ownShadowMapSize);
  std::printf("%-4s %-18s %-18s %-11s %-11s %-5s %s\n", "pass", "light", "kind", "status", "target", "draws",
              "reason");
  for (std::size_t i = 0; i < plan.passes.size(); ++i) {
    const ShadowPass& p = plan.passes[i];
    const std::string target = p.needsMap() ? std::to_string(p.width) + "x" + std::to_string(p.height) : "-";
    std::printf("%-4zu %-18s %-18s %-11s %-11s %-5zu %s\n", i, lightName(p).c_str(), kindName(p).c_str(),
                statusToken(p.status), target.c_str(), p.splits.size(), reasonToken(p.reason));
  }
  std::printf("%d maps to rasterize; depth clamp on, culling off, compare %s, clear %g\n", plan.mapCount(),
              options.reversedZ ? "GREATER" : "LESS", options.reversedZ ? 0.0 : 1.0);
  if (!json.empty()) {
    files.write(json, [&](const std::filesystem::path& path) {
      std::ofstream out(path);
      out << toJson(plan) << "\n";
      if (!out) throw IoError("--json: cannot write " + path.string());
    });
    files.commit();
    std::printf("wrote %s\n", json.c_str());
  }
  return 0;
}

const CommandRegistrar
    registrar({"plan",
               R"(the shadow passes crep::Scattering plans for a scene's frame, in an engine's
            clip convention (Scattering::plan): per light rectified / standard / none and why,
            the target, the draws; --json FILE writes every matrix, viewport and state
            --scene NAME (colonnade) --size WxH (1280x720) --map-size N (1024) --splits K (8)
            --convention opengl | opengl-zero-to-one | vulkan | d3d12 | metal (opengl)
            --reversed-z        matrices for depth 1 at the near side, clear 0, GREATER
            --json FILE         the plan as JSON (crep/pipeline/shadow_pass_plan.h); - for stdout
)",
               planCommand});

} // namespace

} // namespace crep::tool
