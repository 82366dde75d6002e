// The GPU stage passes of epipolar sampling (crep/epipolar/gpu_epipolar_sampling.h; Yusov 2012, Sec. 6):
// lines on the CPU (epipolarLines), then passes/epipolar/coordinates.comp (Sec. 6.1),
// passes/epipolar/refine.comp (Sec. 6.2, Yusov 2013's criterion), passes/epipolar/interpolate.comp
// (Sec. 6.5), passes/epipolar/unwarp.comp (Sec. 6.6) and passes/epipolar/upscale.comp (Sec. 6.8), with work
// lists in between, each a gpu::Dispatch on the pass's backend.
#include <crep/core/error.h>
#include <crep/epipolar/gpu_epipolar_sampling.h>
#include <crep/gpu/checks.h>
#include <crep/gpu/gl_backend.h>
#include <crep/gpu/shader_library.h>
#include <crep/scatter/gpu_world_march.h>

#include "crep/bindings.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <new>
#include <span>
#include <string>
#include <string_view>
#include <utility>
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

unsigned groups(int n, int size) {
  return static_cast<unsigned>((n + size - 1) / size);
}

gpu::SampleList makeList(std::uint32_t buffer, std::uint32_t coordinates, std::uint32_t output, int width,
                         int height) {
  return gpu::SampleList{buffer, coordinates, output, width, height, width * height};
}

// The stage programs (Yusov 2012, Sec. 6.1, 6.2, 6.5, 6.6, 6.8).
ShaderStageSource stageSource(const char* path, int samples) {
  std::vector<ShaderDefine> defines;
  if (std::string_view(path) == "passes/epipolar/refine.comp")
    defines.push_back({"CREP_SAMPLES", std::to_string(samples)});
  return {ShaderStage::Compute, path, defines};
}

} // namespace

EpipolarSamplingPass::EpipolarSamplingPass(const CreateInfo& info) : info_(info) {
  if (info.width <= 0)
    throw InvalidArgument(std::string(kCreate) + ".width", std::to_string(info.width), "must be > 0");
  if (info.height <= 0)
    throw InvalidArgument(std::string(kCreate) + ".height", std::to_string(info.height), "must be > 0");
  crep::validate(info.options, std::string(kCreate) + ".options");
  if (!(info.lineOffset >= 0.0 && info.lineOffset <= 0.5))
    throw InvalidArgument(std::string(kCreate) + ".lineOffset", detail::formatValue(info.lineOffset),
                          "must be in [0, 0.5]");
  const EpipolarSamplingOptions& o = info.options;
  backend_ = &gpu::givenOrGl(info.backend, ownBackend_);
  gpu::Backend& b = *backend_;
  gpu::checkTextureSize(b, "EpipolarSamplingPass::CreateInfo.width/height", info.width, info.height);
  if (info.width % o.downscale != 0)
    throw InvalidArgument(std::string(kCreate) + ".width", std::to_string(info.width),
                          "must be a multiple of options.downscale " + std::to_string(o.downscale));
  if (info.height % o.downscale != 0)
    throw InvalidArgument(std::string(kCreate) + ".height", std::to_string(info.height),
                          "must be a multiple of options.downscale " + std::to_string(o.downscale));
  // List entries pack x | y << 16.
  if (info.width > 65535 || info.height > 65535 || o.slices > 65535)
    throw InvalidArgument(std::string(kCreate) + ".width/height/options.slices",
                          std::to_string(info.width) + " x " + std::to_string(info.height) + ", " +
                              std::to_string(o.slices),
                          "must each be <= 65535 (work lists pack x | y << 16)");
  gpu::checkTextureSize(b, "EpipolarSamplingPass::CreateInfo.options.samples/slices", o.samples, o.slices);
  const gpu::ComputeLimits limits = b.computeLimits();
  const int maxGroup = std::min(limits.groupSize[0], limits.invocations);
  if (o.samples > maxGroup)
    gpu::throwBeyondLimit(b, "EpipolarSamplingPass::CreateInfo.options.samples (one work group per line)",
                          std::to_string(o.samples),
                          "min(GL_MAX_COMPUTE_WORK_GROUP_SIZE[0], GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS)",
                          "work-group size", maxGroup);
  targetWidth_ = info.width / o.downscale;
  targetHeight_ = info.height / o.downscale;

  for (const char* stage :
       {"passes/epipolar/coordinates.comp", "passes/epipolar/refine.comp", "passes/epipolar/interpolate.comp",
        "passes/epipolar/unwarp.comp", "passes/epipolar/upscale.comp"}) {
    if (std::string_view(stage) == "passes/epipolar/upscale.comp" && o.downscale == 1) continue;
    const ShaderStageSource source = stageSource(stage, o.samples);
    b.prepareProgram(source.path, source.defines);
  }

  params_ = gpu::Buffer(b, sizeof(gpu::MarchParams), "EpipolarSamplingPass: march block");
  samplingParams_ =
      gpu::Buffer(b, sizeof(gpu::EpipolarSamplingParams), "EpipolarSamplingPass: sampling block");
  lineBuffer_ = gpu::Buffer(b, sizeof(gpu::EpipolarSamplingLine) * static_cast<std::size_t>(o.slices),
                            "EpipolarSamplingPass: line table");
  const auto texture = [&](gpu::Format format, int width, int height, const char* label) {
    return gpu::Texture(b, {gpu::TextureType::Texture2D, format, width, height, 1, label});
  };
  coordinates_ = texture(gpu::Format::RGBA32F, o.samples, o.slices, "EpipolarSamplingPass: coordinates");
  unshadowed_ = texture(gpu::Format::R32F, o.samples, o.slices, "EpipolarSamplingPass: unshadowed");
  sources_ = texture(gpu::Format::RG32I, o.samples, o.slices, "EpipolarSamplingPass: sources");
  samples_ = texture(gpu::Format::RGBA32F, o.samples, o.slices, "EpipolarSamplingPass: samples");
  targetCoordinates_ =
      texture(gpu::Format::RGBA32F, targetWidth_, targetHeight_, "EpipolarSamplingPass: target coordinates");
  if (o.downscale > 1) {
    target_ = texture(gpu::Format::RGBA32F, targetWidth_, targetHeight_, "EpipolarSamplingPass: target");
    fullCoordinates_ =
        texture(gpu::Format::RGBA32F, info.width, info.height, "EpipolarSamplingPass: full coordinates");
  }
  sampleBuffer_ = gpu::createSampleListBuffer(b, o.samples * o.slices, "EpipolarSamplingPass: sample list");
  correctionBuffer_ =
      gpu::createSampleListBuffer(b, targetWidth_ * targetHeight_, "EpipolarSamplingPass: correction list");
  if (o.downscale > 1)
    upscaleBuffer_ =
        gpu::createSampleListBuffer(b, info.width * info.height, "EpipolarSamplingPass: upscale list");

  sampleList_ = makeList(sampleBuffer_.id(), coordinates_.id(), samples_.id(), o.samples, o.slices);
  correctionList_ =
      makeList(correctionBuffer_.id(), targetCoordinates_.id(), target_.id(), targetWidth_, targetHeight_);
  if (o.downscale > 1)
    upscaleList_ = makeList(upscaleBuffer_.id(), fullCoordinates_.id(), 0, info.width, info.height);
}

EpipolarSamplingPass::~EpipolarSamplingPass() = default;

EpipolarSamplingPass::EpipolarSamplingPass(EpipolarSamplingPass&& o) noexcept
    : info_(o.info_), targetWidth_(o.targetWidth_), targetHeight_(o.targetHeight_),
      lines_(std::move(o.lines_)), ownBackend_(std::move(o.ownBackend_)),
      backend_(std::exchange(o.backend_, nullptr)), params_(std::move(o.params_)),
      samplingParams_(std::move(o.samplingParams_)), lineBuffer_(std::move(o.lineBuffer_)),
      coordinates_(std::move(o.coordinates_)), unshadowed_(std::move(o.unshadowed_)),
      sources_(std::move(o.sources_)), samples_(std::move(o.samples_)), target_(std::move(o.target_)),
      targetCoordinates_(std::move(o.targetCoordinates_)), fullCoordinates_(std::move(o.fullCoordinates_)),
      sampleBuffer_(std::move(o.sampleBuffer_)), correctionBuffer_(std::move(o.correctionBuffer_)),
      upscaleBuffer_(std::move(o.upscaleBuffer_)), sampleList_(o.sampleList_),
      correctionList_(o.correctionList_), upscaleList_(o.upscaleList_) {}

EpipolarSamplingPass& EpipolarSamplingPass::operator=(EpipolarSamplingPass&& o) noexcept {
  if (this != &o) {
    this->~EpipolarSamplingPass(); // the textures and buffers go before the backend that made them
    new (this) EpipolarSamplingPass(std::move(o));
  }
  return *this;
}

void EpipolarSamplingPass::validate(const FrameAttribs& f, std::string_view owner) const {
  gpu::requireNotMovedFrom(backend_, "EpipolarSamplingPass");
  const std::string p = std::string(owner) + ".";
  if (!f.camera) invalid(p + "camera", "null", "must be set");
  if (!f.light) invalid(p + "light", "null", "must be set");
  if (!f.medium) invalid(p + "medium", "null", "must be set");
  const gpu::Backend& b = *backend_;
  gpu::requireTexture2DOf(b, (p + "cameraDepth").c_str(), f.cameraDepth, info_.width, info_.height);
  gpu::requireDepthFormatOf(b, (p + "cameraDepth").c_str(), f.cameraDepth);
  gpu::requireTexture2DOf(b, (p + "output").c_str(), f.output, info_.width, info_.height,
                          gpu::Format::RGBA32F);
}

void EpipolarSamplingPass::dispatch(const char* stage, std::vector<gpu::Resource> resources, unsigned groupsX,
                                    unsigned groupsY) {
  const ShaderStageSource source = stageSource(stage, info_.options.samples);
  gpu::Dispatch d;
  d.label = std::string("EpipolarSamplingPass (") + stage + ")";
  d.program = source.path;
  d.defines = source.defines;
  // Every stage but the interpolation reads the two blocks and the line table.
  if (std::string_view(stage) != "passes/epipolar/interpolate.comp")
    d.resources = {gpu::Resource::uniform(CREP_EPIPOLAR_SAMPLING_MARCH_BINDING, params_.id()),
                   gpu::Resource::uniform(CREP_EPIPOLAR_SAMPLING_PARAMS_BINDING, samplingParams_.id()),
                   gpu::Resource::storage(CREP_EPIPOLAR_SAMPLING_LINES_BINDING, lineBuffer_.id())};
  d.resources.insert(d.resources.end(), resources.begin(), resources.end());
  d.groups = glm::uvec3(groupsX, groupsY, 1u);
  backend_->dispatch(d);
}

void EpipolarSamplingPass::placeSamples(const FrameAttribs& f) {
  validate(f);
  const EpipolarSamplingOptions& o = info_.options;
  gpu::Backend& b = *backend_;
  lines_ = epipolarLines(*f.camera, *f.light, info_.width, info_.height, o, info_.lineOffset);
  const gpu::MarchParams march =
      gpu::makeMarchParams(*f.camera, *f.light, *f.medium, info_.width, info_.height, o.samples, o.slices);
  b.writeBuffer(params_.id(), 0, std::as_bytes(std::span(&march, 1)));
  const gpu::EpipolarSamplingParams params = gpu::makeEpipolarSamplingParams(lines_, o);
  b.writeBuffer(samplingParams_.id(), 0, std::as_bytes(std::span(&params, 1)));
  std::vector<gpu::EpipolarSamplingLine> table(lines_.lines.size());
  for (std::size_t i = 0; i < table.size(); ++i) {
    const EpipolarLines::Line& l = lines_.lines[i];
    table[i].ends = glm::vec4(glm::vec2(l.entry), glm::vec2(l.exit));
    table[i].info = glm::ivec4(l.lastValid, lines_.denseEnd, lines_.denseStep, 0);
  }
  if (!table.empty()) b.writeBuffer(lineBuffer_.id(), 0, std::as_bytes(std::span(table)));
  dispatch("passes/epipolar/coordinates.comp",
           {gpu::Resource::sampled(CREP_EPIPOLAR_SAMPLING_CAMERA_DEPTH_UNIT, f.cameraDepth),
            gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_COORDINATES_OUT_IMAGE, coordinates_.id(),
                                 gpu::Access::WriteOnly),
            gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_UNSHADOWED_OUT_IMAGE, unshadowed_.id(),
                                 gpu::Access::WriteOnly)},
           groups(o.samples, 64), static_cast<unsigned>(o.slices));
}

void EpipolarSamplingPass::refine() {
  gpu::requireNotMovedFrom(backend_, "EpipolarSamplingPass");
  gpu::clearSampleList(*backend_, sampleBuffer_.id());
  dispatch(
      "passes/epipolar/refine.comp",
      {gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_COORDINATES_IN_IMAGE, coordinates_.id(),
                            gpu::Access::ReadOnly),
       gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_UNSHADOWED_IN_IMAGE, unshadowed_.id(),
                            gpu::Access::ReadOnly),
       gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_SOURCES_OUT_IMAGE, sources_.id(), gpu::Access::WriteOnly),
       gpu::Resource::storage(CREP_SAMPLE_LIST_DEFAULT_BINDING, sampleBuffer_.id())},
      static_cast<unsigned>(info_.options.slices), 1u);
}

void EpipolarSamplingPass::interpolate() {
  gpu::requireNotMovedFrom(backend_, "EpipolarSamplingPass");
  evaluatorBarrier();
  const EpipolarSamplingOptions& o = info_.options;
  dispatch(
      "passes/epipolar/interpolate.comp",
      {gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_SOURCES_IN_IMAGE, sources_.id(), gpu::Access::ReadOnly),
       gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_SAMPLES_IMAGE, samples_.id(), gpu::Access::ReadWrite)},
      groups(o.samples, 64), static_cast<unsigned>(o.slices));
}

void EpipolarSamplingPass::unwarp(const FrameAttribs& f) {
  validate(f);
  const std::uint32_t out = info_.options.downscale > 1 ? target_.id() : f.output;
  correctionList_.output = out;
  evaluatorBarrier();
  gpu::clearSampleList(*backend_, correctionBuffer_.id());
  dispatch(
      "passes/epipolar/unwarp.comp",
      {gpu::Resource::sampled(CREP_EPIPOLAR_SAMPLING_CAMERA_DEPTH_UNIT, f.cameraDepth),
       gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_COORDINATES_IN_IMAGE, coordinates_.id(),
                            gpu::Access::ReadOnly),
       gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_SAMPLES_IN_IMAGE, samples_.id(), gpu::Access::ReadOnly),
       gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_OUTPUT_IMAGE, out, gpu::Access::WriteOnly),
       gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_TARGET_COORDINATES_OUT_IMAGE, targetCoordinates_.id(),
                            gpu::Access::WriteOnly),
       gpu::Resource::storage(CREP_SAMPLE_LIST_DEFAULT_BINDING, correctionBuffer_.id())},
      groups(targetWidth_, 8), groups(targetHeight_, 8));
}

void EpipolarSamplingPass::upscale(const FrameAttribs& f) {
  if (info_.options.downscale == 1) return;
  validate(f);
  upscaleList_.output = f.output;
  evaluatorBarrier();
  gpu::clearSampleList(*backend_, upscaleBuffer_.id());
  dispatch("passes/epipolar/upscale.comp",
           {gpu::Resource::sampled(CREP_EPIPOLAR_SAMPLING_CAMERA_DEPTH_UNIT, f.cameraDepth),
            gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_TARGET_IN_IMAGE, target_.id(), gpu::Access::ReadOnly),
            gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_TARGET_COORDINATES_IN_IMAGE, targetCoordinates_.id(),
                                 gpu::Access::ReadOnly),
            gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_OUTPUT_IMAGE, f.output, gpu::Access::WriteOnly),
            gpu::Resource::image(CREP_EPIPOLAR_SAMPLING_FULL_COORDINATES_OUT_IMAGE, fullCoordinates_.id(),
                                 gpu::Access::WriteOnly),
            gpu::Resource::storage(CREP_SAMPLE_LIST_DEFAULT_BINDING, upscaleBuffer_.id())},
           groups(info_.width, 8), groups(info_.height, 8));
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
}

// On OpenGL a caller's evaluator may have written the samples or the output with its own GL dispatches: the
// barrier for them, as the GL pass always issued (other backends order an evaluator that runs on them).
void EpipolarSamplingPass::evaluatorBarrier() const {
  if (backend_->kind() == gpu::BackendKind::OpenGL)
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
}

EpipolarSamplingPass::Statistics EpipolarSamplingPass::statistics() const {
  Statistics s;
  for (const EpipolarLines::Line& l : lines_.lines)
    s.validSamples += l.lastValid + 1;
  if (backend_ == nullptr) return s; // moved from
  s.marchedSamples = gpu::sampleListCount(*backend_, sampleBuffer_.id());
  s.correctedPixels = gpu::sampleListCount(*backend_, correctionBuffer_.id());
  if (upscaleBuffer_.id() != 0) s.correctedFullPixels = gpu::sampleListCount(*backend_, upscaleBuffer_.id());
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
