#pragma once
// Reads a ROS 2 message serialised as CDR (XCDR1, little-endian): a 4-byte encapsulation header, then
// fields with each primitive aligned to its size counted from after the header. Strings are a u32
// length including the NUL, sequences a u32 count. Running past the end throws BagError naming the
// message (`what`) and the field: "a CDR message shorter than its layout".
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>

#include "rigcal/bag/bag_error.hpp"
#include "rigcal/core/time.hpp"

namespace rigcal::bag {

struct RosHeader {
  TimeNs stamp_ns = 0;
  std::string frame_id;
};

class CdrReader {
 public:
  /// Throws BagError unless `message` starts with a little-endian CDR encapsulation header.
  CdrReader(std::span<const std::uint8_t> message, std::string what);

  template <class T>
  T read(const char* field) {
    align(sizeof(T), field);
    T value;
    std::memcpy(&value, take(sizeof(T), field).data(), sizeof(T));
    return value;
  }
  std::string_view readString(const char* field);
  /// A sequence's element count, refused when even `min_element_bytes` each would not fit.
  std::uint32_t readCount(const char* field, std::size_t min_element_bytes);
  std::span<const std::uint8_t> take(std::size_t n, const char* field);
  void align(std::size_t n, const char* field);
  /// builtin_interfaces/Time: i32 sec, u32 nanosec.
  TimeNs readTime(const char* field);
  /// std_msgs/Header: stamp, frame_id.
  RosHeader readHeader();
  [[nodiscard]] std::size_t remaining() const { return body_.size() - pos_; }
  [[nodiscard]] const std::string& what() const { return what_; }

 private:
  std::span<const std::uint8_t> body_;  // after the encapsulation header
  std::string what_;
  std::size_t pos_ = 0;
};

}  // namespace rigcal::bag
