// The shaders of examples/ (examples/glsl/passes/): the scene rasterizer's (scene*.vert/frag), the
// fullscreen-triangle helpers (fullscreen*.vert/frag) and the crep tool's world-space reference march
// and compositing (march_world.comp, composite.comp). They are embedded into crep_scenes, not into the
// runtime library, and registered with crep::ShaderLibrary on demand; they include the library's
// public files ("crep/common.glsl") like any engine shader would.
#pragma once

namespace crep::scenes {

/// Registers examples/glsl/ with the shader library (ShaderLibrary::addFiles), under the paths
/// "passes/<file>". Idempotent and thread-safe: SceneRenderer calls it, and programs that build these
/// shaders otherwise (the crep tool, crep_bench, the tests) call it at startup.
void registerShaders();

} // namespace crep::scenes
