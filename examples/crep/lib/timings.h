// Per-stage wall-clock timings for the crep tool. GPU stages end with glFinish, so each row is the
// time the stage really took, including the GPU work it issued.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace crep::tool {

class StageTimings {
public:
  struct Row {
    std::string stage;
    double ms;
  };

  /// Progress: when set, each timed stage is announced on stderr as "<prefix>: <stage> ..." before it
  /// runs (the commands enable it when stderr is a terminal).
  void setProgress(std::string prefix) { progress_ = std::move(prefix); }

  void add(std::string stage, double milliseconds) { rows_.push_back({std::move(stage), milliseconds}); }
  void append(const std::vector<Row>& rows) { rows_.insert(rows_.end(), rows.begin(), rows.end()); }

  /// Runs `f`, records its wall time under `stage` and returns its result.
  template <class F>
  auto time(std::string stage, F&& f) {
    if (!progress_.empty()) std::fprintf(stderr, "%s: %s ...\n", progress_.c_str(), stage.c_str());
    const auto start = std::chrono::steady_clock::now();
    if constexpr (std::is_void_v<decltype(f())>) {
      f();
      add(std::move(stage), elapsed(start));
    } else {
      auto result = f();
      add(std::move(stage), elapsed(start));
      return result;
    }
  }

  double total() const {
    double sum = 0;
    for (const auto& r : rows_)
      sum += r.ms;
    return sum;
  }

  void print(std::FILE* out) const {
    std::fprintf(out, "%-32s %12s\n", "stage", "ms");
    for (const auto& r : rows_)
      std::fprintf(out, "%-32s %12.3f\n", r.stage.c_str(), r.ms);
    std::fprintf(out, "%-32s %12.3f\n", "total", total());
  }
  const std::vector<Row>& rows() const { return rows_; }

private:
  static double elapsed(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  std::vector<Row> rows_;
  std::string progress_;
};

} // namespace crep::tool
