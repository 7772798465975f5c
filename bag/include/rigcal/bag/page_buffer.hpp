#pragma once
// A byte buffer in its own anonymous memory mapping, reused across MCAP chunks. Chunk buffers are
// large (~1 MB) and short-lived; allocated through malloc they changed glibc's heap state (its dynamic
// mmap threshold and trims) for the decoders running alongside: bag -> scans took 1.4-1.5x the pcap
// time in the benchmark although it executes only ~3 % more instructions. Kept out of the heap and
// grown geometrically, a bag stream maps its few chunk buffers once.
#include <cstddef>
#include <cstdint>
#include <span>

namespace rigcal::bag {

class PageBuffer {
 public:
  PageBuffer() = default;
  ~PageBuffer();
  PageBuffer(PageBuffer&& other) noexcept;
  PageBuffer& operator=(PageBuffer&& other) noexcept;
  PageBuffer(const PageBuffer&) = delete;
  PageBuffer& operator=(const PageBuffer&) = delete;

  /// `size` writable bytes. Contents are kept only while the mapping does not grow (callers overwrite
  /// them); growing at least doubles the capacity. Throws std::bad_alloc when the mapping fails.
  std::span<std::uint8_t> resize(std::size_t size);

  [[nodiscard]] std::span<const std::uint8_t> bytes() const { return {data_, size_}; }
  [[nodiscard]] std::size_t size() const { return size_; }
  /// Bytes mapped (a whole number of pages).
  [[nodiscard]] std::size_t capacity() const { return capacity_; }

 private:
  void release() noexcept;

  std::uint8_t* data_ = nullptr;
  std::size_t size_ = 0, capacity_ = 0;
};

}  // namespace rigcal::bag
