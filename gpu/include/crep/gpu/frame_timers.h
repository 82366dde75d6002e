// GPU times of a frame's spans without waiting for the GPU: each span ended with
// gpu::Backend::endTimerDeferred(), each frame's spans kept until every one has resolved
// (Backend::timerResult), the latest such frame handed over. What crep::Scattering and FroxelFog time their
// stages with when their timings do not block.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include <crep/gpu/backend.h>

namespace crep::gpu {

class FrameTimers {
public:
  /// Most ended frames waiting for their times: ending one more drops the oldest (never handed over).
  static constexpr std::size_t kMaxPendingFrames = 8;

  /// One frame's GPU times.
  struct Times {
    std::uint64_t frame = 0;          ///< as given to endFrame()
    std::vector<double> milliseconds; ///< per span in the order of add(): Backend::timerResult's
  };

  /// A span of the frame being recorded: an id of Backend::endTimerDeferred() (0: the backend times none;
  /// reads 0).
  void add(TimerId id) { recording_.push_back(id); }
  /// The spans added since the last endFrame() or discardFrame() become frame `frame`'s.
  void endFrame(std::uint64_t frame);
  /// Forgets the spans added since the last endFrame() (a frame that threw).
  void discardFrame() noexcept { recording_.clear(); }
  /// Never waits (Backend::timerResult only): the latest ended frame whose spans have all resolved, or
  /// std::nullopt when none has; that frame and every one ended before it are then forgotten.
  std::optional<Times> poll(Backend& backend);
  /// Ended frames waiting for their times, at most kMaxPendingFrames.
  std::size_t pendingFrames() const noexcept { return pending_.size(); }

private:
  struct Pending {
    std::uint64_t frame = 0;
    std::vector<TimerId> ids;
    std::vector<double> milliseconds; ///< the first `resolved` entries are known
    std::size_t resolved = 0;
  };
  std::vector<TimerId> recording_;
  std::deque<Pending> pending_;
};

} // namespace crep::gpu
