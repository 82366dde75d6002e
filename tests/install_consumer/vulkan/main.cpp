// The installed Vulkan backend from an engine's side, with the validation layer on: a depth map uploaded to
// gpu::VulkanBackend and the library's MinMaxTreePass run on it (its trees read back and compared with the
// CPU reference, bit for bit), then a whole crep::Scattering frame on the same device from the engine's
// own maps (a flat ground under an open sky: every pixel lit, so in-scattering > 0 and transmittance in
// (0, 1]). Exit 0 when both hold and the layer said nothing.
#include <crep/core/image.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/pipeline/scattering.h>
#include <crep/vulkan/vulkan_backend.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>

int main() {
  try {
    crep::gpu::VulkanBackend::CreateInfo info;
    info.validation = true;
    crep::gpu::VulkanBackend vk(info);
    const int W = 300, H = 4;
    crep::Image depth(W, H, 1);
    for (int j = 0; j < H; ++j)
      for (int i = 0; i < W; ++i)
        depth.at(i, j) = static_cast<float>(((i * 37 + j * 11) % 101) / 100.0);
    crep::gpu::Texture map(vk,
                           {crep::gpu::TextureType::Texture2D, crep::gpu::Format::R32F, W, H, 1, "depth"});
    vk.writeTexture(map.id(), depth.data());
    crep::MinMaxTreePass trees({.mapWidth = W, .mapHeight = H, .backend = &vk});
    trees.run(map.id());
    const std::vector<float> nodes = trees.readNodes();
    const crep::MinMaxTrees cpu(depth);
    const bool same =
        nodes.size() == cpu.data().size() && std::equal(nodes.begin(), nodes.end(), cpu.data().begin());
    // The frame: camera 2 units above the ground looking ahead and down; the ground's depth per pixel from
    // its ray; an empty sun map (cleared to 1: nothing casts).
    const int w = 64, h = 36;
    const crep::Camera camera = crep::Camera::lookAt({0.0, 2.0, 0.0}, {0.0, 0.0, -10.0}, {0.0, 1.0, 0.0}, 1.0,
                                                     double(w) / h, 0.1, 100.0);
    crep::Image cameraDepth(w, h, 1);
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i) {
        const glm::dvec3 d = camera.rayDirection(2.0 * (i + 0.5) / w - 1.0, 2.0 * (j + 0.5) / h - 1.0);
        const double t = d.y < -1e-6 ? -2.0 / d.y : 1e9; // the ground y = 0, else the sky
        const glm::dvec4 clip = camera.clipFromWorld() * glm::dvec4(camera.position() + t * d, 1.0);
        cameraDepth.at(i, j) =
            t < 1e8 ? static_cast<float>(std::clamp(0.5 * clip.z / clip.w + 0.5, 0.0, 1.0)) : 1.0f;
      }
    const crep::DirectionalLight sun(glm::normalize(glm::dvec3(0.3, -1.0, -0.2)), glm::dvec3(3.0));
    const crep::Medium medium(crep::MediumCoefficients{.mieScattering = glm::dvec3(0.02), .hgG = 0.5});
    const auto corners = camera.frustumCorners();
    const glm::dmat4 sunMatrix = crep::orthographicLightClipFromWorld(sun, corners);
    crep::gpu::Texture depthTexture(
        vk, {crep::gpu::TextureType::Texture2D, crep::gpu::Format::Depth32F, w, h, 1, "camera depth"}),
        sunMap(vk, {crep::gpu::TextureType::Texture2D, crep::gpu::Format::Depth32F, 256, 256, 1, "sun map"}),
        output(vk, {crep::gpu::TextureType::Texture2D, crep::gpu::Format::RGBA32F, w, h, 1, "output"});
    vk.writeTexture(depthTexture.id(), cameraDepth.data());
    vk.writeTexture(sunMap.id(), std::vector<float>(256 * 256, 1.0f));
    crep::Scattering::CreateInfo frameInfo{.width = w, .height = h, .mapSize = 256};
    frameInfo.backend = &vk;
    crep::Scattering scattering(frameInfo);
    const crep::Scattering::ShadowMap sunShadow{sunMap.id(), sunMatrix, 0.0};
    crep::Scattering::FrameAttribs f;
    f.camera = &camera;
    f.light = &sun;
    f.medium = &medium;
    f.cameraDepth = depthTexture.id();
    f.output = output.id();
    f.shadowMap = &sunShadow;
    const crep::Scattering::FrameResult r = scattering.run(f);
    const std::vector<float> rgba = vk.readTexture(output.id());
    int lit = 0, bad = 0;
    for (std::size_t p = 0; p < rgba.size(); p += 4) {
      const bool finite = std::isfinite(rgba[p]) && std::isfinite(rgba[p + 1]) &&
                          std::isfinite(rgba[p + 2]) && std::isfinite(rgba[p + 3]);
      bad += !finite || rgba[p + 3] <= 0.0f || rgba[p + 3] > 1.0f || rgba[p] < 0.0f;
      lit += finite && rgba[p] > 0.0f;
    }
    std::printf("vulkan consumer: crep::Scattering %dx%d on %s (%s layout, %zu stages): %d of %d pixels lit, "
                "%d out of range\n",
                w, h, vk.deviceName().c_str(), crep::layoutToken(r.layout), r.stages.size(), lit, w * h, bad);
    const bool frameOk = bad == 0 && lit == w * h;
    const std::size_t messages = vk.validationMessages().size();
    std::printf("vulkan consumer on %s: %zu tree nodes %s the CPU's, %zu validation messages\n",
                vk.deviceName().c_str(), nodes.size() / 2, same ? "equal to" : "DIFFERENT from", messages);
    return same && frameOk && messages == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::printf("vulkan consumer failed: %s\n", e.what());
    return 1;
  }
}
