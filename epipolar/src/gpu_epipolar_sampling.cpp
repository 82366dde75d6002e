// The GPU stage passes of epipolar sampling (crep/epipolar/gpu_epipolar_sampling.h; Yusov 2012, Sec. 6):
// lines on the CPU (epipolarLines), then passes/epipolar/coordinates.comp (Sec. 6.1),
// passes/epipolar/refine.comp (Sec. 6.2, Yusov 2013's criterion), passes/epipolar/interpolate.comp
// (Sec. 6.5), passes/epipolar/unwarp.comp (Sec. 6.6) and passes/epipolar/upscale.comp (Sec. 6.8), with work
// lists in between.
#include <crep/core/error.h>
#include <crep/core/shader_library.h>
#include <crep/epipolar/gpu_epipolar_sampling.h>
#include <crep/scatter/gpu_world_march.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <string>
#include <vector>

namespace crep {

namespace gpu {

EpipolarSamplingParams makeEpipolarSamplingParams(const EpipolarLines& lines,
                                                  const EpipolarSamplingOptions& o) {
  EpipolarSamplingParams p;
  p.epipole = glm::vec4(static_cast<float>(lines.epipole.x), static_cast<float>(lines.epipole.y),
                        static_cast<float>(lines.arcBegin), static_cast<float>(lines.arcLength));
  p.border =
      glm::vec4(static_cast<float>(lines.width), static_cast<float>(lines.height),
                static_cast<float>(2 * (lines.width + lines.height)), lines.epipoleOnScreen ? 1.0f : 0.0f);
  p.counts = glm::ivec4(static_cast<int>(lines.lines.size()), lines.samples, o.initialStep, o.downscale);
  p.target = glm::ivec4(lines.width / o.downscale, lines.height / o.downscale, o.depthCriterion ? 1 : 0,
                        o.scatteringCriterion ? 1 : 0);
  p.thresholds = glm::vec4(static_cast<float>(o.depthThreshold), static_cast<float>(o.scatteringThreshold),
                           static_cast<float>(o.bilateralThreshold), 0.0f);
  return p;
}

} // namespace gpu

namespace {

constexpr const char* kCreate = "EpipolarSamplingPass::CreateInfo";

gl::Handle makeTexture(GLenum format, int width, int height) {
  return gl::createTexture2D(format, width, height, "EpipolarSamplingPass::CreateInfo.width/height");
}

GLuint groups(int n, int size) {
  return static_cast<GLuint>((n + size - 1) / size);
}

// The barriers after a stage: its images and lists are read by the next stage, the evaluator (indirect
// dispatch) or a read-back.
void stageBarrier() {
  gl::passOutputBarrier();
  glMemoryBarrier(GL_COMMAND_BARRIER_BIT);
}

// Before a stage that reads what the caller's evaluator wrote (images, through image loads).
void evaluatorBarrier() {
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
}

gpu::SampleList makeList(GLuint buffer, GLuint coordinates, GLuint output, int width, int height) {
  return gpu::SampleList{buffer, coordinates, output, width, height, width * height};
}

} // namespace

EpipolarSamplingPass::EpipolarSamplingPass(const CreateInfo& info) : info_(info) {
  if (info.width <= 0)
    throw InvalidArgument(std::string(kCreate) + ".width", std::to_string(info.width), "must be > 0");
  if (info.height <= 0)
    throw InvalidArgument(std::string(kCreate) + ".height", std::to_string(info.height), "must be > 0");
  crep::validate(info.options, std::string(kCreate) + ".options");
  const EpipolarSamplingOptions& o = info.options;
  gl::checkTextureSize("EpipolarSamplingPass::CreateInfo.width/height", info.width, info.height);
  if (info.width % o.downscale != 0)
    throw InvalidArgument(std::string(kCreate) + ".width", std::to_string(info.width),
                          "must be a multiple of options.downscale " + std::to_string(o.downscale));
  if (info.height % o.downscale != 0)
    throw InvalidArgument(std::string(kCreate) + ".height", std::to_string(info.height),
                          "must be a multiple of options.downscale " + std::to_string(o.downscale));
  // List entries pack x | y << 16.
  if (info.width > 65535 || info.height > 65535 || o.slices > 65535)
    throw GlError("crep: EpipolarSamplingPass: work lists hold at most 65535 texels per axis");
  gl::checkTextureSize("EpipolarSamplingPass::CreateInfo.options.samples/slices", o.samples, o.slices);
  GLint maxSize = 0, maxInvocations = 0;
  glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_SIZE, 0, &maxSize);
  glGetIntegerv(GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS, &maxInvocations);
  if (o.samples > maxSize || o.samples > maxInvocations)
    throw GlError("crep: EpipolarSamplingPass::CreateInfo.options.samples " + std::to_string(o.samples) +
                  " exceeds the compute work group limit " +
                  std::to_string(std::min(maxSize, maxInvocations)) +
                  " (one work group of samples threads per line)");
  targetWidth_ = info.width / o.downscale;
  targetHeight_ = info.height / o.downscale;

  coordinatesProgram_ = buildProgram({{ShaderStage::Compute, "passes/epipolar/coordinates.comp", {}}});
  refineProgram_ = buildProgram(
      {{ShaderStage::Compute, "passes/epipolar/refine.comp", {{"CREP_SAMPLES", std::to_string(o.samples)}}}});
  interpolateProgram_ = buildProgram({{ShaderStage::Compute, "passes/epipolar/interpolate.comp", {}}});
  unwarpProgram_ = buildProgram({{ShaderStage::Compute, "passes/epipolar/unwarp.comp", {}}});
  if (o.downscale > 1)
    upscaleProgram_ = buildProgram({{ShaderStage::Compute, "passes/epipolar/upscale.comp", {}}});

  params_ = gl::createDynamicBuffer(sizeof(gpu::MarchParams));
  samplingParams_ = gl::createDynamicBuffer(sizeof(gpu::EpipolarSamplingParams));
  lineBuffer_ =
      gl::createDynamicBuffer(sizeof(gpu::EpipolarSamplingLine) * static_cast<std::size_t>(o.slices));
  sampler_ = gl::createClampSampler(GL_NEAREST);

  coordinates_ = makeTexture(GL_RGBA32F, o.samples, o.slices);
  unshadowed_ = makeTexture(GL_R32F, o.samples, o.slices);
  sources_ = makeTexture(GL_RG32I, o.samples, o.slices);
  samples_ = makeTexture(GL_RGBA32F, o.samples, o.slices);
  targetCoordinates_ = makeTexture(GL_RGBA32F, targetWidth_, targetHeight_);
  if (o.downscale > 1) {
    target_ = makeTexture(GL_RGBA32F, targetWidth_, targetHeight_);
    fullCoordinates_ = makeTexture(GL_RGBA32F, info.width, info.height);
  }
  sampleBuffer_ = gpu::createSampleListBuffer(o.samples * o.slices);
  correctionBuffer_ = gpu::createSampleListBuffer(targetWidth_ * targetHeight_);
  if (o.downscale > 1) upscaleBuffer_ = gpu::createSampleListBuffer(info.width * info.height);

  sampleList_ = makeList(sampleBuffer_.get(), coordinates_.get(), samples_.get(), o.samples, o.slices);
  correctionList_ =
      makeList(correctionBuffer_.get(), targetCoordinates_.get(), target_.get(), targetWidth_, targetHeight_);
  if (o.downscale > 1)
    upscaleList_ = makeList(upscaleBuffer_.get(), fullCoordinates_.get(), 0, info.width, info.height);
  gl::checkError("EpipolarSamplingPass");
}

void EpipolarSamplingPass::validate(const FrameAttribs& f, std::string_view owner) const {
  const std::string p = std::string(owner) + ".";
  if (!f.camera) invalid(p + "camera", "null", "must be set");
  if (!f.light) invalid(p + "light", "null", "must be set");
  if (!f.medium) invalid(p + "medium", "null", "must be set");
  gl::requireTexture2D((p + "cameraDepth").c_str(), f.cameraDepth, info_.width, info_.height);
  gl::requireDepthFormat((p + "cameraDepth").c_str(), f.cameraDepth);
  gl::requireTexture2D((p + "output").c_str(), f.output, info_.width, info_.height, GL_RGBA32F);
}

void EpipolarSamplingPass::bindCommon(std::uint32_t program) const {
  glUseProgram(program);
  glBindBufferBase(GL_UNIFORM_BUFFER, CREP_EPIPOLAR_SAMPLING_MARCH_BINDING, params_.get());
  glBindBufferBase(GL_UNIFORM_BUFFER, CREP_EPIPOLAR_SAMPLING_PARAMS_BINDING, samplingParams_.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, CREP_EPIPOLAR_SAMPLING_LINES_BINDING, lineBuffer_.get());
}

void EpipolarSamplingPass::placeSamples(const FrameAttribs& f) {
  validate(f);
  const EpipolarSamplingOptions& o = info_.options;
  lines_ = epipolarLines(*f.camera, *f.light, info_.width, info_.height, o);
  const gpu::MarchParams march =
      gpu::makeMarchParams(*f.camera, *f.light, *f.medium, info_.width, info_.height, o.samples, o.slices);
  glNamedBufferSubData(params_.get(), 0, sizeof(march), &march);
  const gpu::EpipolarSamplingParams params = gpu::makeEpipolarSamplingParams(lines_, o);
  glNamedBufferSubData(samplingParams_.get(), 0, sizeof(params), &params);
  std::vector<gpu::EpipolarSamplingLine> table(lines_.lines.size());
  for (std::size_t i = 0; i < table.size(); ++i) {
    const EpipolarLines::Line& l = lines_.lines[i];
    table[i].ends = glm::vec4(glm::vec2(l.entry), glm::vec2(l.exit));
    table[i].info = glm::ivec4(l.lastValid, lines_.denseEnd, lines_.denseStep, 0);
  }
  glNamedBufferSubData(lineBuffer_.get(), 0, static_cast<GLsizeiptr>(table.size() * sizeof(table[0])),
                       table.data());

  bindCommon(coordinatesProgram_.get());
  glBindTextureUnit(CREP_EPIPOLAR_SAMPLING_CAMERA_DEPTH_UNIT, f.cameraDepth);
  glBindSampler(CREP_EPIPOLAR_SAMPLING_CAMERA_DEPTH_UNIT, sampler_.get());
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_COORDINATES_OUT_IMAGE, coordinates_.get(), 0, GL_FALSE, 0,
                     GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_UNSHADOWED_OUT_IMAGE, unshadowed_.get(), 0, GL_FALSE, 0,
                     GL_WRITE_ONLY, GL_R32F);
  glDispatchCompute(groups(o.samples, 64), static_cast<GLuint>(o.slices), 1);
  stageBarrier();
  gl::unbindPassState(4);
  gl::checkError("EpipolarSamplingPass::placeSamples");
}

void EpipolarSamplingPass::refine() {
  const EpipolarSamplingOptions& o = info_.options;
  gpu::clearSampleList(sampleBuffer_.get());
  bindCommon(refineProgram_.get());
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_COORDINATES_IN_IMAGE, coordinates_.get(), 0, GL_FALSE, 0,
                     GL_READ_ONLY, GL_RGBA32F);
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_UNSHADOWED_IN_IMAGE, unshadowed_.get(), 0, GL_FALSE, 0,
                     GL_READ_ONLY, GL_R32F);
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_SOURCES_OUT_IMAGE, sources_.get(), 0, GL_FALSE, 0, GL_WRITE_ONLY,
                     GL_RG32I);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, CREP_SAMPLE_LIST_DEFAULT_BINDING, sampleBuffer_.get());
  glDispatchCompute(static_cast<GLuint>(o.slices), 1, 1);
  stageBarrier();
  gl::unbindPassState(4);
  gl::checkError("EpipolarSamplingPass::refine");
}

void EpipolarSamplingPass::interpolate() {
  const EpipolarSamplingOptions& o = info_.options;
  evaluatorBarrier();
  glUseProgram(interpolateProgram_.get());
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_SOURCES_IN_IMAGE, sources_.get(), 0, GL_FALSE, 0, GL_READ_ONLY,
                     GL_RG32I);
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_SAMPLES_IMAGE, samples_.get(), 0, GL_FALSE, 0, GL_READ_WRITE,
                     GL_RGBA32F);
  glDispatchCompute(groups(o.samples, 64), static_cast<GLuint>(o.slices), 1);
  stageBarrier();
  gl::unbindPassState(4);
  gl::checkError("EpipolarSamplingPass::interpolate");
}

void EpipolarSamplingPass::unwarp(const FrameAttribs& f) {
  validate(f);
  const GLuint out = info_.options.downscale > 1 ? target_.get() : f.output;
  correctionList_.output = out;
  evaluatorBarrier();
  gpu::clearSampleList(correctionBuffer_.get());
  bindCommon(unwarpProgram_.get());
  glBindTextureUnit(CREP_EPIPOLAR_SAMPLING_CAMERA_DEPTH_UNIT, f.cameraDepth);
  glBindSampler(CREP_EPIPOLAR_SAMPLING_CAMERA_DEPTH_UNIT, sampler_.get());
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_COORDINATES_IN_IMAGE, coordinates_.get(), 0, GL_FALSE, 0,
                     GL_READ_ONLY, GL_RGBA32F);
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_SAMPLES_IN_IMAGE, samples_.get(), 0, GL_FALSE, 0, GL_READ_ONLY,
                     GL_RGBA32F);
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_OUTPUT_IMAGE, out, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_TARGET_COORDINATES_OUT_IMAGE, targetCoordinates_.get(), 0,
                     GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, CREP_SAMPLE_LIST_DEFAULT_BINDING, correctionBuffer_.get());
  glDispatchCompute(groups(targetWidth_, 8), groups(targetHeight_, 8), 1);
  stageBarrier();
  gl::unbindPassState(4);
  gl::checkError("EpipolarSamplingPass::unwarp");
}

void EpipolarSamplingPass::upscale(const FrameAttribs& f) {
  if (info_.options.downscale == 1) return;
  validate(f);
  upscaleList_.output = f.output;
  evaluatorBarrier();
  gpu::clearSampleList(upscaleBuffer_.get());
  bindCommon(upscaleProgram_.get());
  glBindTextureUnit(CREP_EPIPOLAR_SAMPLING_CAMERA_DEPTH_UNIT, f.cameraDepth);
  glBindSampler(CREP_EPIPOLAR_SAMPLING_CAMERA_DEPTH_UNIT, sampler_.get());
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_TARGET_IN_IMAGE, target_.get(), 0, GL_FALSE, 0, GL_READ_ONLY,
                     GL_RGBA32F);
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_TARGET_COORDINATES_IN_IMAGE, targetCoordinates_.get(), 0,
                     GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_OUTPUT_IMAGE, f.output, 0, GL_FALSE, 0, GL_WRITE_ONLY,
                     GL_RGBA32F);
  glBindImageTexture(CREP_EPIPOLAR_SAMPLING_FULL_COORDINATES_OUT_IMAGE, fullCoordinates_.get(), 0, GL_FALSE,
                     0, GL_WRITE_ONLY, GL_RGBA32F);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, CREP_SAMPLE_LIST_DEFAULT_BINDING, upscaleBuffer_.get());
  glDispatchCompute(groups(info_.width, 8), groups(info_.height, 8), 1);
  stageBarrier();
  gl::unbindPassState(4);
  gl::checkError("EpipolarSamplingPass::upscale");
}

void EpipolarSamplingPass::run(const FrameAttribs& f,
                               const std::function<void(const gpu::SampleList&)>& evaluate) {
  if (!evaluate) throw InvalidArgument("EpipolarSamplingPass::run.evaluate", "empty", "must be callable");
  placeSamples(f);
  refine();
  evaluate(sampleList_);
  interpolate();
  unwarp(f);
  evaluate(correctionList_);
  if (info_.options.downscale > 1) {
    upscale(f);
    evaluate(upscaleList_);
  }
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                  GL_TEXTURE_UPDATE_BARRIER_BIT);
}

EpipolarSamplingPass::Statistics EpipolarSamplingPass::statistics() const {
  Statistics s;
  for (const EpipolarLines::Line& l : lines_.lines)
    s.validSamples += l.lastValid + 1;
  s.marchedSamples = gpu::sampleListCount(sampleBuffer_.get());
  s.correctedPixels = gpu::sampleListCount(correctionBuffer_.get());
  if (upscaleBuffer_) s.correctedFullPixels = gpu::sampleListCount(upscaleBuffer_.get());
  return s;
}

std::size_t EpipolarSamplingPass::memoryBytes() const noexcept {
  const auto texels = [](int w, int h) { return static_cast<std::size_t>(w) * static_cast<std::size_t>(h); };
  const EpipolarSamplingOptions& o = info_.options;
  const std::size_t lineTexels = texels(o.samples, o.slices);
  const std::size_t target = texels(targetWidth_, targetHeight_);
  const std::size_t full = o.downscale > 1 ? texels(info_.width, info_.height) : 0;
  std::size_t bytes = lineTexels * (16 + 4 + 8 + 16);         // coordinates, U, sources, samples
  bytes += target * 16 + (o.downscale > 1 ? target * 16 : 0); // target coordinates, target
  bytes += full * 16;                                         // full-resolution coordinates
  bytes += gpu::kSampleListHeaderBytes * 3 + 4 * (lineTexels + target + full); // lists
  bytes += sizeof(gpu::MarchParams) + sizeof(gpu::EpipolarSamplingParams) +
           sizeof(gpu::EpipolarSamplingLine) * static_cast<std::size_t>(o.slices);
  return bytes;
}

} // namespace crep
