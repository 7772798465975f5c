#pragma once
// One POSIX shared-memory segment through Boost.Interprocess (shared_memory_object + mapped_region), plus
// what Boost does not offer: the writer's flock and the inode check that tells whether the name still
// refers to the segment we hold.
#include <boost/interprocess/mapped_region.hpp>
#include <boost/interprocess/shared_memory_object.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace rigcal::shm::detail {

class Segment {
 public:
  Segment() = default;
  Segment(Segment&&) noexcept = default;
  Segment& operator=(Segment&&) noexcept = default;

  /// Creates `name` exclusively, empty, mode 0600 (only this user); nullopt if one of that name exists.
  static std::optional<Segment> create(const std::string& name);
  /// Opens an existing segment; nullopt if there is none.
  static std::optional<Segment> open(const std::string& name, bool writable);

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] int fd() const;
  [[nodiscard]] std::uint64_t size() const;
  void truncate(std::uint64_t bytes);
  /// Maps all of it, read-write or read-only as opened. `populate` pre-faults every page (MAP_POPULATE) so
  /// the first lap of the ring does not pay a page fault per 4 KiB.
  void map(bool populate = false);
  [[nodiscard]] void* base() const { return region_.get_address(); }
  [[nodiscard]] std::size_t mappedBytes() const { return region_.get_size(); }
  /// flock(LOCK_EX | LOCK_NB): true if this process now holds the writer lock. The kernel drops it when
  /// the descriptor closes — including when the process is killed — which is what makes takeover safe.
  bool tryLockExclusive();
  /// Refuses (RingError kForeign) a segment this user does not own or that other users may write:
  /// another local user could otherwise pre-create the ring, then read, overwrite or truncate it.
  void requireOwnedPrivately() const;
  /// True while /dev/shm/<name> is this very segment (same device and inode).
  [[nodiscard]] bool isStillNamed() const;

 private:
  std::string name_;
  bool writable_ = false;
  boost::interprocess::shared_memory_object shm_;
  boost::interprocess::mapped_region region_;
};

}  // namespace rigcal::shm::detail
