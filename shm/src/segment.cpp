#include "segment.hpp"

#include <sys/file.h>
#include <sys/mman.h>
#include <sys/stat.h>

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "rigcal/shm/ring_error.hpp"
#include "rigcal/shm/ring_segment.hpp"

namespace bip = boost::interprocess;

namespace rigcal::shm::detail {

namespace {

[[noreturn]] void fail(const std::string& what, const std::string& name, const std::string& why) {
  throw RingError(RingError::Kind::kSystem, "shared-memory ring '" + name + "': " + what + ": " + why);
}

}  // namespace

std::optional<Segment> Segment::create(const std::string& name) {
  Segment s;
  s.name_ = name;
  s.writable_ = true;
  try {
    s.shm_ = bip::shared_memory_object(bip::create_only, name.c_str(), bip::read_write,
                                       bip::permissions(0600));
  } catch (const bip::interprocess_exception& e) {
    if (e.get_error_code() == bip::already_exists_error) return std::nullopt;
    fail("cannot create", name, e.what());
  }
  return s;
}

std::optional<Segment> Segment::open(const std::string& name, bool writable) {
  Segment s;
  s.name_ = name;
  s.writable_ = writable;
  try {
    s.shm_ = bip::shared_memory_object(bip::open_only, name.c_str(),
                                       writable ? bip::read_write : bip::read_only);
  } catch (const bip::interprocess_exception& e) {
    if (e.get_error_code() == bip::not_found_error) return std::nullopt;
    fail("cannot open", name, e.what());
  }
  return s;
}

int Segment::fd() const { return shm_.get_mapping_handle().handle; }

std::uint64_t Segment::size() const {
  bip::offset_t size = 0;
  if (!shm_.get_size(size)) fail("cannot read the size", name_, std::strerror(errno));
  return static_cast<std::uint64_t>(size);
}

void Segment::truncate(std::uint64_t bytes) {
  try {
    shm_.truncate(static_cast<bip::offset_t>(bytes));
  } catch (const bip::interprocess_exception& e) {
    fail("cannot size to " + std::to_string(bytes) + " bytes", name_, e.what());
  }
}

void Segment::map(bool populate) {
  try {
    region_ = bip::mapped_region(shm_, writable_ ? bip::read_write : bip::read_only, 0, 0, nullptr,
                                 populate ? MAP_POPULATE : bip::default_map_options);
  } catch (const bip::interprocess_exception& e) {
    fail("cannot map", name_, e.what());
  }
}

bool Segment::tryLockExclusive() {
  if (::flock(fd(), LOCK_EX | LOCK_NB) == 0) return true;
  if (errno == EWOULDBLOCK) return false;
  fail("flock", name_, std::strerror(errno));
}

void Segment::requireOwnedPrivately() const {
  struct stat st {};
  if (::fstat(fd(), &st) != 0) fail("fstat", name_, std::strerror(errno));
  const std::string where = "shared-memory ring '" + name_ + "' (" + segmentPath(name_).string() + ") ";
  if (st.st_uid != ::geteuid())
    throw RingError(RingError::Kind::kForeign, where + "belongs to uid " + std::to_string(st.st_uid) + ", not uid " +
                                                   std::to_string(::geteuid()) +
                                                   ": refusing a ring another user created (remove it if it is stale)");
  if ((st.st_mode & 0022) != 0) {  // others may write or truncate it (reading leaks only scans)
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", unsigned(st.st_mode & 07777));
    throw RingError(RingError::Kind::kForeign, where + "has mode " + mode +
                                                   ": other users could change or truncate it; refusing it (remove it)");
  }
}

bool Segment::isStillNamed() const {
  struct stat mine {};
  struct stat named {};
  if (::fstat(fd(), &mine) != 0) return false;
  if (::stat(segmentPath(name_).c_str(), &named) != 0) return false;
  return mine.st_dev == named.st_dev && mine.st_ino == named.st_ino;
}

}  // namespace rigcal::shm::detail
