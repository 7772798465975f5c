#pragma once
// parallelFor (parallel.hpp) over threads kept between calls, for a loop run thousands of times: the
// lidar-pose objective evaluates in about a millisecond, so starting a thread per call would cost a
// measurable share of it. The helpers sleep on a condition variable between calls (no spinning on a
// 2-core target); the caller works too. Same contract as rigcal::parallelFor: each task once, outputs
// per task, the first exception rethrown after every thread has stopped. One caller at a time.
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

#include "rigcal/core/parallel.hpp"

namespace rigcal {

class WorkerPool {
 public:
  /// num_threads − 1 helpers (none for 1 or less).
  explicit WorkerPool(int num_threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  [[nodiscard]] int threads() const { return static_cast<int>(helpers_.size()) + 1; }

  template <class Body>
  void parallelFor(std::size_t num_tasks, Body&& body) {
    if (helpers_.empty() || num_tasks <= 1) {
      for (std::size_t t = 0; t < num_tasks; ++t) body(t);
      return;
    }
    detail::TaskQueue<std::remove_reference_t<Body>> queue(num_tasks, body);
    runOnAll([&queue] { queue.work(); });
    queue.rethrow();
  }

 private:
  /// `work` once on every helper and on the caller; returns when all have finished.
  void runOnAll(const std::function<void()>& work);
  void helperLoop();

  std::vector<std::thread> helpers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void()>* work_ = nullptr;
  std::size_t pending_ = 0;
  std::uint64_t generation_ = 0;
  bool stop_ = false;
};

}  // namespace rigcal
