// A consumer of the installed package: uses the public API without any GL loader header.
#include <crep/core/camera.h>
#include <crep/core/error.h>
#include <crep/core/shader_library.h>

#include <cstdio>
#include <filesystem>

int main() {
  const crep::Camera camera =
      crep::Camera::lookAt({0, 1, 5}, {0, 0, 0}, {0, 1, 0}, glm::radians(60.0), 16.0 / 9.0, 0.1, 100.0);
  const glm::dmat4 clipFromWorld = camera.clipFromWorld();
  if (!(clipFromWorld[3][3] == clipFromWorld[3][3])) return 1;
  try {
    crep::Camera::lookAt({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 1.0, 1.0, 1.0, 0.5);
    return 2; // near >= far must throw
  } catch (const crep::InvalidArgument& e) {
    std::printf("expected error: %s\n", e.what());
  }
  if (crep::ShaderLibrary::files().empty()) return 3;
  if (!std::filesystem::is_directory(CREP_GLSL_DIR)) return 4;
  std::printf("consumer ok, %zu embedded shader files, GLSL dir %s\n", crep::ShaderLibrary::files().size(),
              CREP_GLSL_DIR);
  return 0;
}
