// The projective layout's GPU block (crep/rectify/gpu_layout.h; Klehm et al. 2014, Sec. 4.2: the frame,
// slopes and split zetas that map a world point into the rectified map).
#include <crep/core/error.h>
#include <crep/rectify/gpu_layout.h>
#include <crep/rectify/rectified_map.h>

#include <cstring>
#include <string>

namespace crep {

namespace gpu {

ProjectiveLayoutParams makeProjectiveLayoutParams(const ProjectiveLayout& layout) {
  const Rectification& r = layout.rectification();
  const int K = r.splitCount();
  if (K > kMaxLayoutRegions)
    throw InvalidArgument("ProjectiveLayout.regionCount", detail::formatValue(K),
                          "must be <= " + std::to_string(kMaxLayoutRegions) + " on the GPU");
  const RectifiedFrame& f = r.frame;
  ProjectiveLayoutParams p;
  p.origin = glm::vec4(glm::vec3(f.origin), static_cast<float>(f.inverseLightDistance));
  p.axisX = glm::vec4(glm::vec3(f.axisX), 0.0f);
  p.axisY = glm::vec4(glm::vec3(f.axisY), 0.0f);
  p.axisZ = glm::vec4(glm::vec3(f.axisZ), 0.0f);
  p.slopes = glm::vec4(static_cast<float>(f.rowSlopeMin), static_cast<float>(f.rowSlopeMax),
                       static_cast<float>(f.depthSlopeMin), static_cast<float>(f.depthSlopeMax));
  p.counts = glm::ivec4(K, 0, 0, 0);
  for (int k = 0; k < K; ++k) {
    const Split& s = r.splits[static_cast<std::size_t>(k)];
    p.splitZeta[k] = glm::vec4(static_cast<float>(s.zetaBegin), static_cast<float>(s.zetaEnd), 0.0f, 0.0f);
  }
  return p;
}

} // namespace gpu

std::optional<GpuLayoutData> ProjectiveLayout::gpuLayoutData() const {
  const gpu::ProjectiveLayoutParams p = gpu::makeProjectiveLayoutParams(*this);
  GpuLayoutData d;
  d.kind = gpu::LayoutKind::Projective;
  d.block.resize(sizeof(p));
  std::memcpy(d.block.data(), &p, sizeof(p));
  d.regionCount = regionCount();
  return d;
}

} // namespace crep
