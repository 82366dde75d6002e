// The installed Vulkan backend from an engine's side: a depth map uploaded to gpu::VulkanBackend, the
// library's MinMaxTreePass run on it, its trees read back and compared with the CPU reference, with the
// validation layer on. Exit 0 when they agree bit for bit and the layer said nothing.
#include <crep/core/image.h>
#include <crep/epipolar/gpu_march.h>
#include <crep/epipolar/march.h>
#include <crep/vulkan/vulkan_backend.h>

#include <algorithm>
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
    const std::size_t messages = vk.validationMessages().size();
    std::printf("vulkan consumer on %s: %zu tree nodes %s the CPU's, %zu validation messages\n",
                vk.deviceName().c_str(), nodes.size() / 2, same ? "equal to" : "DIFFERENT from", messages);
    return same && messages == 0 ? 0 : 1;
  } catch (const std::exception& e) {
    std::printf("vulkan consumer failed: %s\n", e.what());
    return 1;
  }
}
