#pragma once
// The queue between two stage threads: moodycamel's lock-free ConcurrentQueue with a capacity.
//  - Offline (lossless): push() waits for room; nothing is ever dropped.
//  - Real time: pushDropOldest() never blocks the producer; when full it discards the oldest item
//    and counts it.
// Consumers block on a semaphore (futex) when the queue is empty; nobody spins (2-core targets).
// FIFO holds per producer; every queue in the pipeline has exactly one producer.
#include <concurrentqueue/concurrentqueue.h>
#include <concurrentqueue/lightweightsemaphore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>

namespace rigcal::pipeline {

template <class T>
class BoundedQueue {
 public:
  explicit BoundedQueue(std::size_t capacity)
      : queue_(std::min(capacity, kMaxPreallocated)), items_(0, kSpins), slots_(std::ptrdiff_t(capacity), kSpins), capacity_(capacity) {}

  /// Lossless: waits while the queue is full. Returns false if the queue was closed.
  bool push(T item) {
    while (!slots_.wait(kWakeCheckUs))
      if (closed_.load(std::memory_order_acquire)) return false;
    enqueue(std::move(item));
    return true;
  }

  /// Never blocks: when full, the oldest item is discarded (and counted) to make room.
  void pushDropOldest(T item) {
    while (!slots_.tryWait()) {
      if (items_.tryWait()) {  // claim the oldest item and discard it; its slot becomes ours
        T discarded;
        while (!queue_.try_dequeue(discarded)) {
        }
        dropped_.fetch_add(1, std::memory_order_relaxed);
        depth_.fetch_sub(1, std::memory_order_relaxed);
        break;
      }
    }
    enqueue(std::move(item));
  }

  /// Waits up to `timeout` for an item; nullopt on timeout or once closed and drained.
  std::optional<T> pop(std::chrono::microseconds timeout = std::chrono::seconds(1)) {
    if (!items_.wait(timeout.count())) return std::nullopt;
    T item;
    // The semaphore counted a completed enqueue; the item is visible, possibly after a retry.
    while (!queue_.try_dequeue(item)) {
    }
    depth_.fetch_sub(1, std::memory_order_relaxed);
    slots_.signal();
    return item;
  }

  /// Never waits: the next item, or nullopt when the queue is empty.
  std::optional<T> tryPop() {
    if (!items_.tryWait()) return std::nullopt;
    T item;
    while (!queue_.try_dequeue(item)) {
    }
    depth_.fetch_sub(1, std::memory_order_relaxed);
    slots_.signal();
    return item;
  }

  /// Wakes blocked producers; consumers drain what is left, then see empty pops.
  void close() { closed_.store(true, std::memory_order_release); }
  [[nodiscard]] bool closed() const { return closed_.load(std::memory_order_acquire); }

  [[nodiscard]] std::size_t capacity() const { return capacity_; }
  [[nodiscard]] std::size_t depth() const { return depth_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::size_t maxDepth() const { return max_depth_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

 private:
  // moodycamel preallocates its initial size: a 65536-item lossless queue of frames would hold tens of MB
  // that it rarely uses. Beyond this many items it allocates blocks as they are needed.
  static constexpr std::size_t kMaxPreallocated = 256;
  static constexpr int kSpins = 1;                  // block at once: spinning steals a core
  static constexpr std::int64_t kWakeCheckUs = 100'000;  // producers re-check close() this often

  void enqueue(T&& item) {
    queue_.enqueue(std::move(item));
    const std::size_t d = depth_.fetch_add(1, std::memory_order_relaxed) + 1;
    std::size_t m = max_depth_.load(std::memory_order_relaxed);
    while (d > m && !max_depth_.compare_exchange_weak(m, d, std::memory_order_relaxed)) {
    }
    items_.signal();
  }

  moodycamel::ConcurrentQueue<T> queue_;
  moodycamel::LightweightSemaphore items_;
  moodycamel::LightweightSemaphore slots_;
  std::size_t capacity_;
  std::atomic<bool> closed_{false};
  std::atomic<std::size_t> depth_{0};
  std::atomic<std::size_t> max_depth_{0};
  std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace rigcal::pipeline
