#pragma once
// Serialises a ROS 2 message as CDR (XCDR1, little-endian), the form rosbag2 stores and CdrReader reads:
// the encapsulation header 00 01 00 00, then fields with each primitive aligned to its size counted from
// after the header; strings as u32 length (NUL included) + bytes + NUL, sequences as u32 count + items.
#include <cstdint>
#include <cstring>
#include <span>
#include <string_view>
#include <vector>

#include "rigcal/core/time.hpp"

namespace rigcal::bag {

class CdrWriter {
 public:
  CdrWriter() : bytes_(4, 0) { bytes_[1] = 0x01; }
  /// Reserves room for a message of about `bytes` (large point clouds, packet scans).
  void reserve(std::size_t bytes) { bytes_.reserve(bytes + 4); }

  template <class T>
  void put(T value) {
    align(sizeof(T));
    const std::size_t at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    std::memcpy(bytes_.data() + at, &value, sizeof(T));
  }
  void putString(std::string_view s);
  /// Raw bytes (a uint8[N] array, or a uint8[] after its count).
  void putBytes(std::span<const std::uint8_t> bytes) { bytes_.insert(bytes_.end(), bytes.begin(), bytes.end()); }
  /// `n` zero bytes (the unused tail of a fixed packet buffer).
  void putZeros(std::size_t n) { bytes_.resize(bytes_.size() + n, 0); }
  /// builtin_interfaces/Time: i32 sec, u32 nanosec (nanosec in [0, 1e9) also for times before 1970).
  void putTime(TimeNs t);
  /// std_msgs/Header: stamp, frame_id.
  void putHeader(TimeNs stamp, std::string_view frame_id) {
    putTime(stamp);
    putString(frame_id);
  }
  void align(std::size_t n) {
    while ((bytes_.size() - 4) % n) bytes_.push_back(0);
  }
  [[nodiscard]] const std::vector<std::uint8_t>& bytes() const { return bytes_; }
  std::vector<std::uint8_t> take() { return std::move(bytes_); }

 private:
  std::vector<std::uint8_t> bytes_;
};

}  // namespace rigcal::bag
