#pragma once
// Serialises test messages as little-endian CDR (encapsulation 00 01 00 00, primitives aligned to their
// size from after the header), the form rosbag2 stores: for layouts no shared bag holds.
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace rigcal::bag::test {

class CdrWriter {
 public:
  CdrWriter() : bytes_{0x00, 0x01, 0x00, 0x00} {}

  template <class T>
  CdrWriter& put(T v) {
    while ((bytes_.size() - 4) % sizeof(T)) bytes_.push_back(0);
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
    return *this;
  }
  CdrWriter& putString(const std::string& s) {
    put(std::uint32_t(s.size() + 1));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back(0);
    return *this;
  }
  CdrWriter& putBytes(const std::vector<std::uint8_t>& b) {
    bytes_.insert(bytes_.end(), b.begin(), b.end());
    return *this;
  }
  CdrWriter& putHeader(std::int64_t stamp_ns, const std::string& frame) {
    put(std::int32_t(stamp_ns / 1'000'000'000));
    put(std::uint32_t(stamp_ns % 1'000'000'000));
    return putString(frame);
  }
  [[nodiscard]] const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
};

}  // namespace rigcal::bag::test
