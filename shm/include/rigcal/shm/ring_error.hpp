#pragma once
// The one exception type of shm/: a one-line message naming the segment and what is wrong with it.
#include <stdexcept>
#include <string>

namespace rigcal::shm {

class RingError : public std::runtime_error {
 public:
  enum class Kind {
    kLiveWriter,      // a writer opened a ring another live process already writes
    kLayoutMismatch,  // the segment was written by a build with another layout version or hash
    kCorrupted,       // not a rigcal ring, or a header whose fields contradict each other
    kSystem,          // shm_open / mmap / ftruncate / flock failed
    kForeign,         // the segment belongs to another user or other users may open it
  };
  RingError(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  [[nodiscard]] Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

}  // namespace rigcal::shm
