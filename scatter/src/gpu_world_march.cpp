// The GL pass of the world-space reference march (crep/scatter/gpu_world_march.h; Klehm et al. 2014,
// Eq. 1 and 3) and the shared march block. Shader: passes/scatter/march_reference.comp, crep/march.glsl,
// crep/local_light.glsl.
#include <crep/core/error.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/shader_library.h>
#include <crep/scatter/gpu_world_march.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace crep {

namespace gpu {

GpuCamera gpuCamera(const Camera& camera) {
  const glm::dvec4& t = camera.tangents();
  const double hx = 0.5 * (t.y - t.x), hy = 0.5 * (t.w - t.z), cx = 0.5 * (t.x + t.y), cy = 0.5 * (t.z + t.w);
  GpuCamera c;
  c.position = glm::vec4(glm::vec3(camera.position()), static_cast<float>(camera.near()));
  c.forward = glm::vec4(glm::vec3(camera.forward()), static_cast<float>(camera.far()));
  c.right = glm::vec4(glm::vec3(camera.right() * hx), 0.0f);
  c.up = glm::vec4(glm::vec3(camera.up() * hy), 0.0f);
  c.center = glm::vec4(glm::vec3(camera.right() * cx + camera.up() * cy), 0.0f);
  const double projectionFar = std::isinf(camera.projectionFar()) ? 0.0 : camera.projectionFar();
  c.depth = glm::vec4(static_cast<float>(camera.near()), static_cast<float>(projectionFar),
                      static_cast<float>(camera.far()), camera.reversedZ() ? 1.0f : 0.0f);
  return c;
}

namespace {

/// The camera and medium part of MarchParams (no light: the light members stay zero).
MarchParams cameraMediumParams(const Camera& camera, const Medium& medium, int width, int height,
                               int mapWidth, int mapHeight) {
  MarchParams p;
  assignCamera(p, camera);
  p.lightDirection = glm::vec4(0.0f);
  p.mieScattering = glm::vec4(glm::vec3(medium.mieScattering()), static_cast<float>(medium.hgG()));
  p.rayleighScattering = glm::vec4(glm::vec3(medium.rayleighScattering()), 0.0f);
  const glm::dvec3 sigma = medium.extinction();
  p.extinction = glm::vec4(glm::vec3(sigma), static_cast<float>(weightExtinction(medium)));
  p.sizes = glm::ivec4(width, height, mapWidth, mapHeight);
  p.region = glm::ivec4(0, 0, width, height); // the whole image (setMarchRegion narrows it to a block)
  return p;
}

} // namespace

MarchParams makeMarchParams(const Camera& camera, const DirectionalLight& light, const Medium& medium,
                            int width, int height, int mapWidth, int mapHeight) {
  MarchParams p = cameraMediumParams(camera, medium, width, height, mapWidth, mapHeight);
  p.lightDirection = glm::vec4(glm::vec3(light.direction()), 0.0f);
  p.lightIrradiance = glm::vec4(glm::vec3(light.irradiance()), 0.0f);
  return p;
}

MarchParams makeMarchParams(const Camera& camera, const LocalLight& light, const Medium& medium, int width,
                            int height, int mapWidth, int mapHeight) {
  MarchParams p = cameraMediumParams(camera, medium, width, height, mapWidth, mapHeight);
  p.lightPosition = glm::vec4(glm::vec3(light.position), 1.0f);
  p.lightAxis = glm::vec4(glm::vec3(light.axis), static_cast<float>(light.face));
  p.lightCone = glm::vec4(static_cast<float>(light.cosInner), static_cast<float>(light.cosOuter),
                          static_cast<float>(light.nearPlane), light.cone ? 1.0f : 0.0f);
  p.lightIntensity = glm::vec4(glm::vec3(light.intensity), 0.0f);
  return p;
}

void bindMarchResources(std::uint32_t program, std::uint32_t params, std::uint32_t cameraDepth,
                        std::uint32_t map, std::uint32_t sampler, std::uint32_t scattering,
                        std::uint32_t steps) {
  glUseProgram(program);
  glBindBufferBase(GL_UNIFORM_BUFFER, CREP_MARCH_PARAMS_BINDING, params);
  glBindTextureUnit(CREP_MARCH_CAMERA_DEPTH_UNIT, cameraDepth);
  glBindTextureUnit(CREP_MARCH_MAP_UNIT, map);
  glBindSampler(CREP_MARCH_CAMERA_DEPTH_UNIT, sampler);
  glBindSampler(CREP_MARCH_MAP_UNIT, sampler);
  glBindImageTexture(CREP_MARCH_SCATTERING_OUT_IMAGE, scattering, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(CREP_MARCH_STEPS_OUT_IMAGE, steps, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
}

bool setMarchRegion(MarchParams& params, int width, int height, const glm::dvec2& blockCenter,
                    double blockRadius, const std::string& owner) {
  if (!std::isfinite(blockRadius) || !std::isfinite(blockCenter.x) || !std::isfinite(blockCenter.y))
    throw InvalidArgument(owner + ".blockCenter/blockRadius", detail::formatValue(blockRadius),
                          "must be finite");
  // The dispatch: the whole image, or the block's bounding box clipped to it.
  glm::ivec4 region(0, 0, width, height);
  params.block = glm::vec4(0.0f, 0.0f, -1.0f, 0.0f);
  if (blockRadius >= 0.0) {
    const auto lo = glm::max(glm::floor(blockCenter - blockRadius - 1.0), glm::dvec2(0.0));
    const auto hi = glm::min(glm::ceil(blockCenter + blockRadius + 1.0), glm::dvec2(width, height));
    region =
        glm::ivec4(static_cast<int>(lo.x), static_cast<int>(lo.y), std::max(0, static_cast<int>(hi.x - lo.x)),
                   std::max(0, static_cast<int>(hi.y - lo.y)));
    params.block = glm::vec4(static_cast<float>(blockCenter.x), static_cast<float>(blockCenter.y),
                             static_cast<float>(blockRadius), 0.0f);
  }
  params.region = region;
  return region.z > 0 && region.w > 0;
}

void dispatchMarch(int width, int height, const char* what) {
  // 8 x 8 pixels per workgroup: 64 invocations, a multiple of every GPU's SIMD width (32 / 64); the
  // rectified marches of neighbouring pixels read neighbouring rows of the map.
  glDispatchCompute(static_cast<GLuint>((width + 7) / 8), static_cast<GLuint>((height + 7) / 8), 1);
  gl::passOutputBarrier();
  gl::unbindPassState(2);
  gl::checkError(what);
}

} // namespace gpu

WorldMarchPass::WorldMarchPass(const CreateInfo& info) : info_(info) {
  crep::validate(info.options);
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  backend_->prepareProgram("passes/scatter/march_reference.comp", {});
  params_ = gpu::Buffer(*backend_, sizeof(gpu::MarchParams), "WorldMarchPass: parameters");
}

/// A validated frame of the pass (WorldMarchPass::validate) and what run() derives from it.
struct WorldMarchPass::Plan {
  gpu::TextureLevel depth, shadow, lightTexture; ///< level 0 of the camera depth, the map, the light texture
};

void WorldMarchPass::validate(const FrameAttribs& frame, std::string_view owner) const {
  plan(frame, owner);
}

WorldMarchPass::Plan WorldMarchPass::plan(const FrameAttribs& f, std::string_view owner) const {
  const std::string p = std::string(owner) + ".";
  if (!f.camera || !f.medium) invalid(p + "camera/medium", "null", "must be set");
  if ((f.light != nullptr) == (f.localLight != nullptr))
    invalid(p + "light/localLight", f.light ? "both set" : "both null", "exactly one must be set");
  // The image and map sizes are the textures' own.
  const gpu::Backend& b = *backend_;
  Plan plan;
  plan.depth = gpu::requireTexture2DOf(b, (p + "cameraDepth").c_str(), f.cameraDepth);
  plan.shadow = gpu::requireTexture2DOf(b, (p + "shadowMap").c_str(), f.shadowMap);
  gpu::requireDepthFormatOf(b, (p + "cameraDepth").c_str(), f.cameraDepth);
  gpu::requireDepthFormatOf(b, (p + "shadowMap").c_str(), f.shadowMap);
  const int width = plan.depth.width, height = plan.depth.height;
  gpu::requireTexture2DOf(b, (p + "output").c_str(), f.output, width, height, gpu::Format::RGBA32F);
  if (f.stepsOutput != 0)
    gpu::requireTexture2DOf(b, (p + "stepsOutput").c_str(), f.stepsOutput, width, height, gpu::Format::R32F);
  requireFinite(p + "lightClipFromWorld", f.lightClipFromWorld);
  if (const LocalLight* l = f.localLight) {
    const auto finite3 = [](const glm::dvec3& v) {
      return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
    };
    const bool finite = finite3(l->position) && finite3(l->intensity) && finite3(l->axis) &&
                        std::isfinite(l->nearPlane) && std::isfinite(l->cosInner) &&
                        std::isfinite(l->cosOuter);
    if (!finite) invalid(p + "localLight", "a non-finite member", "must be finite");
    if (l->face < -1 || l->face > 5)
      invalid(p + "localLight->face", detail::formatValue(l->face),
              "must be -1 or a point light face in [0, 5]");
  }
  requireFinite(p + "bias", f.bias);
  if (f.lightTexture.texture != 0)
    plan.lightTexture =
        gpu::validateGpuLightTexture(b, f.lightTexture, f.light, f.localLight, p + "lightTexture");
  if (!std::isfinite(f.blockRadius) || !std::isfinite(f.blockCenter.x) || !std::isfinite(f.blockCenter.y))
    invalid(p + "blockCenter/blockRadius", detail::formatValue(f.blockRadius), "must be finite");
  return plan;
}

void WorldMarchPass::run(const FrameAttribs& f) {
  const Plan p = plan(f, "WorldMarchPass::FrameAttribs");
  const int width = p.depth.width, height = p.depth.height;
  const gpu::TextureLevel& shadow = p.shadow;
  const bool textured = f.lightTexture.texture != 0;
  gpu::MarchParams params = f.light ? gpu::makeMarchParams(*f.camera, *f.light, *f.medium, width, height,
                                                           shadow.width, shadow.height)
                                    : gpu::makeMarchParams(*f.camera, *f.localLight, *f.medium, width, height,
                                                           shadow.width, shadow.height);
  params.info = glm::ivec4(info_.options.steps, info_.options.refinements, 0, 0);
  params.bias = glm::vec4(static_cast<float>(f.bias), 0.0f, 0.0f, 0.0f);
  params.lightClipFromWorld = glm::mat4(f.lightClipFromWorld);
  if (!gpu::setMarchRegion(params, width, height, f.blockCenter, f.blockRadius,
                           "WorldMarchPass::FrameAttribs"))
    return; // the block misses the image
  gpu::Backend& b = *backend_;
  b.writeBuffer(params_.id(), 0, std::as_bytes(std::span(&params, 1)));
  std::uint32_t steps = f.stepsOutput;
  if (steps == 0) { // the program always writes its step counts: a scratch target of the image's size
    if (!dummySteps_ || dummyWidth_ != width || dummyHeight_ != height) {
      dummySteps_ = gpu::Texture(b, {gpu::TextureType::Texture2D, gpu::Format::R32F, width, height, 1,
                                     "WorldMarchPass: step counts (unused)"});
      dummyWidth_ = width;
      dummyHeight_ = height;
    }
    steps = dummySteps_.id();
  }
  gpu::Dispatch d;
  d.label = "WorldMarchPass::run";
  d.program = "passes/scatter/march_reference.comp";
  d.resources = {gpu::Resource::uniform(CREP_MARCH_PARAMS_BINDING, params_.id()),
                 gpu::Resource::sampled(CREP_MARCH_CAMERA_DEPTH_UNIT, f.cameraDepth),
                 gpu::Resource::sampled(CREP_MARCH_MAP_UNIT, f.shadowMap),
                 gpu::Resource::image(CREP_MARCH_SCATTERING_OUT_IMAGE, f.output, gpu::Access::WriteOnly),
                 gpu::Resource::image(CREP_MARCH_STEPS_OUT_IMAGE, steps, gpu::Access::WriteOnly)};
  if (textured) {
    // Light textures (Klehm et al. 2014, Sec. 3.2): the CREP_LIGHT_TEXTURE variant and its block.
    if (!textureParams_)
      textureParams_ = gpu::Buffer(b, sizeof(gpu::LightTextureParams), "WorldMarchPass: light texture");
    const gpu::LightTextureParams tp =
        gpu::makeLightTextureParams(f.lightTexture, p.lightTexture, 0, 0, f.localLight);
    b.writeBuffer(textureParams_.id(), 0, std::as_bytes(std::span(&tp, 1)));
    d.defines = {{"CREP_LIGHT_TEXTURE", "1"}};
    d.resources.push_back(gpu::Resource::uniform(CREP_MARCH_LIGHT_TEXTURE_BINDING, textureParams_.id()));
    d.resources.push_back(gpu::Resource::sampled(CREP_MARCH_LIGHT_TEXTURE_UNIT, f.lightTexture.texture));
  }
  // 8 x 8 pixels per workgroup (gpu::dispatchMarch's choice): the block's bounding box or the image.
  d.groups = glm::uvec3(static_cast<unsigned>((params.region.z + 7) / 8),
                        static_cast<unsigned>((params.region.w + 7) / 8), 1u);
  b.dispatch(d);
}

} // namespace crep
