// Per-stage wall-clock timings for the crep tool. GPU stages end with glFinish, so each row is the
// time the stage really took, including the GPU work it issued.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

namespace crep::tool {

class StageTimings {
public:
  void add(std::string stage, double milliseconds) { rows_.push_back({std::move(stage), milliseconds}); }

  /// Runs `f`, records its wall time under `stage` and returns its result.
  template <class F>
  auto time(std::string stage, F&& f) {
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

  void print(std::FILE* out) const {
    double total = 0;
    std::fprintf(out, "%-28s %12s\n", "stage", "ms");
    for (const auto& r : rows_) {
      std::fprintf(out, "%-28s %12.3f\n", r.stage.c_str(), r.ms);
      total += r.ms;
    }
    std::fprintf(out, "%-28s %12.3f\n", "total", total);
  }
  struct Row {
    std::string stage;
    double ms;
  };
  const std::vector<Row>& rows() const { return rows_; }

private:
  static double elapsed(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  std::vector<Row> rows_;
};

} // namespace crep::tool
