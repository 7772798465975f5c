#include "rigcal/bag/byte_cursor.hpp"

namespace rigcal::bag {

std::span<const std::uint8_t> ByteCursor::take(std::size_t n) {
  if (n > remaining())
    throw BagError(std::string(what_) + ": field at byte " + std::to_string(pos_) + " needs " + std::to_string(n) +
                   " bytes, " + std::to_string(remaining()) + " left");
  const auto out = bytes_.subspan(pos_, n);
  pos_ += n;
  return out;
}

std::string_view ByteCursor::readString() {
  const auto length = read<std::uint32_t>();
  const auto bytes = take(length);
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

}  // namespace rigcal::bag
