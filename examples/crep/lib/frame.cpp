#include "frame.h"

#include "gl_session.h"

#include <crep/core/error.h>
#include <crep/epipolar/resample.h>
#include <crep/gpu/gl_state.h>
#include <crep/scenes/engine_frame.h>
#include <crep/scenes/scene_renderer.h>

#include <epoxy/gl.h>

#include <vector>

namespace crep::tool {

LightTextureMap makeLightTextureMap(Image rgb, const glm::dmat4& textureClipFromWorld,
                                    const char* parameter) {
  if (rgb.channels() < 3) throw InvalidArgument(parameter, std::to_string(rgb.channels()), "must be RGB");
  LightTextureMap m;
  m.textureClipFromWorld = textureClipFromWorld;
  m.texture = gl::createTexture2D(GL_RGBA32F, rgb.width(), rgb.height(), parameter);
  const std::vector<float> rgba = scenes::rgbaTexels(rgb);
  const gl::PixelStoreScope pixelStore;
  glTextureSubImage2D(m.texture.get(), 0, 0, 0, rgb.width(), rgb.height(), GL_RGBA, GL_FLOAT, rgba.data());
  m.image = std::move(rgb);
  return m;
}

const RectifiedGpuMap* FrameInputs::rectified(const MethodSettings& settings, StageTimings& timings,
                                              Rectification* rectOut) {
  if (rect_ && rectifiedSize_ == settings.mapSize && rectifiedOptions_ == settings.rectify) {
    if (rectOut) *rectOut = *rect_;
    if (!rectified_) return nullptr;
    timings.append(rectified_->cost);
    return &*rectified_;
  }
  rectified_.reset();
  StageTimings cost;
  rect_ = cost.time("rectify", [&] { return rectify(camera, light, settings.rectify); });
  rectifiedSize_ = settings.mapSize;
  rectifiedOptions_ = settings.rectify;
  if (rectOut) *rectOut = *rect_;
  if (!rect_->projective()) {
    timings.append(cost.rows());
    return nullptr;
  }
  RectifiedGpuMap map;
  map.rect = *rect_;
  map.layout = std::make_shared<ProjectiveLayout>(*rect_);
  map.size = settings.mapSize;
  if (renderer) {
    map.source = "rasterized";
    map.texture = scenes::createDepthTexture(map.size, map.size, "--map-size");
    cost.time("shadow pass (rectified)", [&] {
      renderer->renderRectified(map.rect, map.texture.get(), map.size, map.size);
      glFinish();
    });
  } else {
    // Users' data: the library's point resampling of the standard map (Klehm et al. 2014, Sec. 4.1) into
    // the projective layout, on the CPU in double (crep/epipolar/resample.h).
    map.source = "resampled from the standard map (CPU)";
    const RectifiedMap resampled = cost.time("resample (CPU)", [&] {
      return resampleShadowMap(map.layout, map.size, map.size, shadowImage, lightClipFromWorld);
    });
    map.texture = cost.time("upload rectified map", [&] {
      gl::Handle t = uploadR32F(resampled.depth, "--map-size");
      glFinish();
      return t;
    });
  }
  map.cost = cost.rows();
  timings.append(map.cost);
  rectified_ = std::move(map);
  return &*rectified_;
}

} // namespace crep::tool
