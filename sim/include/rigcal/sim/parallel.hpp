#pragma once
// A minimal deterministic parallel-for: items are claimed through an atomic counter, each item's
// output goes to its own slot, so results never depend on the thread count or scheduling.
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace rigcal::sim {

template <class Fn>
void parallelFor(std::size_t items, int threads, Fn&& fn) {
  if (threads <= 1 || items <= 1) {
    for (std::size_t i = 0; i < items; ++i) fn(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto work = [&] {
    try {
      for (std::size_t i = next++; i < items; i = next++) fn(i);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      next = items;
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace rigcal::sim
