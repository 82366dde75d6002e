// Deterministic row-parallel loops for the CPU references (prefilter, resampling, marches): each row is
// computed by exactly one worker and depends on nothing another worker writes, so results never depend
// on the thread count.
#pragma once

#include <algorithm>
#include <exception>
#include <thread>
#include <vector>

namespace crep {

/// Runs body(row) for row in [0, count) on min(threads, count) workers (threads <= 0: hardware
/// concurrency), rows interleaved. Rethrows the first exception (by worker index) after all joined.
template <class Body>
void parallelRows(int count, int threads, const Body& body) {
  int n = threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  n = std::min(n, count);
  if (n <= 1) {
    for (int row = 0; row < count; ++row)
      body(row);
    return;
  }
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(n));
  std::vector<std::thread> workers;
  workers.reserve(static_cast<std::size_t>(n));
  for (int t = 0; t < n; ++t)
    workers.emplace_back([&, t] {
      try {
        for (int row = t; row < count; row += n)
          body(row);
      } catch (...) {
        errors[static_cast<std::size_t>(t)] = std::current_exception();
      }
    });
  for (auto& w : workers)
    w.join();
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
}

} // namespace crep
