#pragma once
// Bounds-checked little-endian reads over a byte span, for MCAP record bodies. Every read past the end
// throws BagError naming `what` (the record or field being read) and the offset within it.
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>

#include "rigcal/bag/bag_error.hpp"

namespace rigcal::bag {

class ByteCursor {
 public:
  ByteCursor(std::span<const std::uint8_t> bytes, std::string_view what) : bytes_(bytes), what_(what) {}

  template <class T>
  T read() {
    T value;
    std::memcpy(&value, take(sizeof(T)).data(), sizeof(T));  // the formats are little-endian, as our hosts
    return value;
  }
  /// u32 length + bytes (MCAP string and byte-array fields).
  std::string_view readString();
  std::span<const std::uint8_t> take(std::size_t n);
  [[nodiscard]] std::span<const std::uint8_t> rest() const { return bytes_.subspan(pos_); }
  [[nodiscard]] std::size_t position() const { return pos_; }
  [[nodiscard]] std::size_t remaining() const { return bytes_.size() - pos_; }

 private:
  std::span<const std::uint8_t> bytes_;
  std::string_view what_;
  std::size_t pos_ = 0;
};

}  // namespace rigcal::bag
