// The epipolar layout's GPU block and slice table (crep/epipolar/gpu_layout.h, glsl/crep/layout.glsl).
#include <crep/core/error.h>
#include <crep/epipolar/epipolar.h>
#include <crep/epipolar/gpu_layout.h>

#include <cmath>
#include <cstring>
#include <string>

namespace crep {

namespace gpu {

EpipolarLayoutParams makeEpipolarLayoutParams(const EpipolarLayout& layout) {
  const Camera& c = layout.camera();
  const double tanY = std::tan(0.5 * c.fovY()), tanX = tanY * c.aspect();
  EpipolarLayoutParams p;
  p.origin = glm::vec4(glm::vec3(c.position()), static_cast<float>(layout.lightDistance()));
  p.towardLight = glm::vec4(glm::vec3(-layout.lightDirection()), 0.0f);
  p.imageX = glm::vec4(glm::vec3(c.right() / tanX), 0.0f);
  p.imageY = glm::vec4(glm::vec3(c.up() / tanY), 0.0f);
  p.forward = glm::vec4(glm::vec3(c.forward()), 0.0f);
  p.cameraTan = glm::vec4(static_cast<float>(tanX), static_cast<float>(tanY), 0.0f, 0.0f);
  p.border = glm::vec4(static_cast<float>(layout.screenWidth()), static_cast<float>(layout.screenHeight()),
                       static_cast<float>(layout.perimeter()), 0.0f);
  p.arc = glm::vec4(static_cast<float>(layout.arcBegin()), static_cast<float>(layout.arcLength()),
                    layout.epipoleKind() == EpipoleKind::AntiEpipole ? 0.0f : 1.0f,
                    static_cast<float>(layout.options().depthWarp));
  p.counts = glm::ivec4(layout.sliceCount(), layout.regionCount(), 0, 0);
  const std::vector<double>& f = layout.regionFractions();
  for (std::size_t k = 0; k < f.size(); ++k)
    p.regionFractions[k / 4][static_cast<int>(k % 4)] = static_cast<float>(f[k]);
  return p;
}

std::vector<EpipolarSlice> makeEpipolarSlices(const EpipolarLayout& layout) {
  std::vector<EpipolarSlice> out;
  out.reserve(layout.slices().size());
  for (const auto& s : layout.slices())
    out.push_back({glm::vec4(static_cast<float>(layout.localLight() ? s.thetaMax : s.bMax),
                             static_cast<float>(layout.warp(s.psiMin)),
                             static_cast<float>(layout.warp(s.psiMax)), 0.0f)});
  return out;
}

// The map-size rule of the passes that read a layout's map (gpu_march.h, resample.h, the atmosphere's).
void requireMapSize(const RectifiedLayout& layout, int width, int height, const std::string& parameter) {
  if (width % layout.regionCount() != 0)
    throw InvalidArgument(parameter, std::to_string(width),
                          "must be a multiple of the layout's region count " +
                              std::to_string(layout.regionCount()));
  if (const auto* e = dynamic_cast<const EpipolarLayout*>(&layout); e && e->sliceCount() != height)
    throw InvalidArgument(parameter, "height " + std::to_string(height),
                          "must be the EpipolarLayout's slice count " + std::to_string(e->sliceCount()));
}

} // namespace gpu

std::optional<GpuLayoutData> EpipolarLayout::gpuLayoutData() const {
  const gpu::EpipolarLayoutParams p = gpu::makeEpipolarLayoutParams(*this);
  const std::vector<gpu::EpipolarSlice> table = gpu::makeEpipolarSlices(*this);
  GpuLayoutData d;
  d.kind = gpu::LayoutKind::Epipolar;
  d.block.resize(sizeof(p));
  std::memcpy(d.block.data(), &p, sizeof(p));
  d.rows.resize(table.size() * sizeof(gpu::EpipolarSlice));
  std::memcpy(d.rows.data(), table.data(), d.rows.size());
  d.rowCount = sliceCount();
  d.regionCount = regionCount();
  return d;
}

} // namespace crep
