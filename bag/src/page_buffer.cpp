#include "rigcal/bag/page_buffer.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <new>
#include <utility>

namespace rigcal::bag {

namespace {

std::size_t roundToPages(std::size_t bytes) {
  static const std::size_t page = std::size_t(::sysconf(_SC_PAGESIZE));
  return (bytes + page - 1) / page * page;
}

}  // namespace

PageBuffer::~PageBuffer() { release(); }

PageBuffer::PageBuffer(PageBuffer&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)),
      size_(std::exchange(other.size_, 0)),
      capacity_(std::exchange(other.capacity_, 0)) {}

PageBuffer& PageBuffer::operator=(PageBuffer&& other) noexcept {
  if (this != &other) {
    release();
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
    capacity_ = std::exchange(other.capacity_, 0);
  }
  return *this;
}

std::span<std::uint8_t> PageBuffer::resize(std::size_t size) {
  if (size > capacity_) {
    const std::size_t capacity = roundToPages(std::max(size, 2 * capacity_));
    void* mapped = ::mmap(nullptr, capacity, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mapped == MAP_FAILED) throw std::bad_alloc();
    release();  // the old contents are not carried over: every caller overwrites them
    data_ = static_cast<std::uint8_t*>(mapped);
    capacity_ = capacity;
  }
  size_ = size;
  return {data_, size_};
}

void PageBuffer::release() noexcept {
  if (data_) ::munmap(data_, capacity_);
  data_ = nullptr;
  size_ = capacity_ = 0;
}

}  // namespace rigcal::bag
