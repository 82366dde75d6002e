// The shaders of examples/glsl/passes/ (scene rasterizer, fullscreen helpers, the tool's compositing),
// embedded into crep_scenes, not the runtime library. The list: examples/README.md.
#pragma once

namespace crep::scenes {

/// Registers examples/glsl/ with the shader library under "passes/<file>". Idempotent and thread-safe;
/// call it at startup unless SceneRenderer does.
void registerShaders();

} // namespace crep::scenes
