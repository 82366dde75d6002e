// GPU times of a frame's spans without waiting (crep/gpu/frame_timers.h).
#include <crep/gpu/frame_timers.h>

#include <utility>

namespace crep::gpu {

void FrameTimers::endFrame(std::uint64_t frame) {
  Pending p;
  p.frame = frame;
  p.ids = std::move(recording_);
  p.milliseconds.assign(p.ids.size(), 0.0);
  recording_.clear();
  pending_.push_back(std::move(p));
  if (pending_.size() > kMaxPendingFrames) pending_.pop_front();
}

std::optional<FrameTimers::Times> FrameTimers::poll(Backend& backend) {
  std::optional<std::size_t> latest;
  for (std::size_t i = 0; i < pending_.size(); ++i) {
    Pending& p = pending_[i];
    // In the order the GPU ran them: a span still pending leaves the later ones of its frame unasked.
    while (p.resolved < p.ids.size()) {
      const std::optional<double> ms = backend.timerResult(p.ids[p.resolved]);
      if (!ms) break;
      p.milliseconds[p.resolved++] = *ms;
    }
    if (p.resolved == p.ids.size()) latest = i;
  }
  if (!latest) return std::nullopt;
  Times t{pending_[*latest].frame, std::move(pending_[*latest].milliseconds)};
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(*latest) + 1);
  return t;
}

} // namespace crep::gpu
