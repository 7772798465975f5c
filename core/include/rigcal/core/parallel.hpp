#pragma once
// Deterministic 1..N-thread loops. Work is cut into tasks whose boundaries depend only on the input size
// (never on the thread count); each task writes its own outputs or returns a partial sum, and partial sums
// are added in task order. So a result is bit-identical whether 1 or 2 threads ran it.
// Helper threads are started per call and joined before it returns: nothing spins while idle. A loop run
// thousands of times a second keeps its threads in a WorkerPool (worker_pool.hpp) with the same contract.
// The one parallel loop of the project (registration, simulation, the lidar-pose objective).
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

namespace rigcal {

constexpr std::size_t chunkCount(std::size_t n, std::size_t chunk) { return (n + chunk - 1) / chunk; }

namespace detail {
// The task loop every thread of a parallel loop runs: claim the next task, run it; the first exception
// stops the handing out of tasks and is kept for the caller.
template <class Body>
class TaskQueue {
 public:
  TaskQueue(std::size_t num_tasks, Body& body) : num_tasks_(num_tasks), body_(body) {}
  void work() {
    for (;;) {
      const std::size_t t = next_.fetch_add(1, std::memory_order_relaxed);
      if (t >= num_tasks_) return;
      try {
        body_(t);
      } catch (...) {
        const std::lock_guard lock(error_mutex_);
        if (!error_) error_ = std::current_exception();
        next_.store(num_tasks_, std::memory_order_relaxed);
      }
    }
  }
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::size_t num_tasks_;
  Body& body_;
  std::atomic<std::size_t> next_{0};
  std::exception_ptr error_;
  std::mutex error_mutex_;
};
}  // namespace detail

/// Calls body(task) once for each task in [0, num_tasks), on the calling thread and num_threads − 1 helpers.
/// An exception thrown by a task is rethrown here (the first one) after all threads have stopped.
template <class Body>
void parallelFor(std::size_t num_tasks, int num_threads, Body&& body) {
  const std::size_t helpers =
      std::min<std::size_t>(num_threads > 1 ? static_cast<std::size_t>(num_threads - 1) : 0,
                            num_tasks > 0 ? num_tasks - 1 : 0);
  if (helpers == 0) {
    for (std::size_t t = 0; t < num_tasks; ++t) body(t);
    return;
  }
  detail::TaskQueue<std::remove_reference_t<Body>> queue(num_tasks, body);
  std::vector<std::thread> threads;
  threads.reserve(helpers);
  for (std::size_t i = 0; i < helpers; ++i) threads.emplace_back([&queue] { queue.work(); });
  queue.work();
  for (auto& th : threads) th.join();
  queue.rethrow();
}

/// init + body(0) + body(1) + ... + body(num_tasks − 1), summed in that order whatever the thread count.
/// T needs operator+=.
template <class T, class Body>
T parallelReduce(std::size_t num_tasks, int num_threads, T init, Body&& body) {
  if (num_threads <= 1) {
    for (std::size_t t = 0; t < num_tasks; ++t) init += body(t);
    return init;
  }
  std::vector<T> partial(num_tasks);
  parallelFor(num_tasks, num_threads, [&](std::size_t t) { partial[t] = body(t); });
  for (auto& p : partial) init += p;
  return init;
}

}  // namespace rigcal
