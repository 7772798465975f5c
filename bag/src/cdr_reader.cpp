#include "rigcal/bag/cdr_reader.hpp"

namespace rigcal::bag {

CdrReader::CdrReader(std::span<const std::uint8_t> message, std::string what) : what_(std::move(what)) {
  if (message.size() < 4)
    throw BagError(what_ + ": CDR message of " + std::to_string(message.size()) + " bytes has no encapsulation header");
  // Representation id: 0x0001 CDR_LE, 0x0003 PL_CDR_LE; the big-endian ones (0x0000, 0x0002) are refused.
  if (message[0] != 0x00 || (message[1] != 0x01 && message[1] != 0x03))
    throw BagError(what_ + ": CDR encapsulation " + std::to_string(message[0]) + "," + std::to_string(message[1]) +
                   " is not little-endian CDR");
  body_ = message.subspan(4);
}

std::span<const std::uint8_t> CdrReader::take(std::size_t n, const char* field) {
  if (n > remaining())
    throw BagError(what_ + ": message shorter than its layout: field " + field + " at byte " +
                   std::to_string(pos_ + 4) + " needs " + std::to_string(n) + " bytes, " +
                   std::to_string(remaining()) + " left");
  const auto out = body_.subspan(pos_, n);
  pos_ += n;
  return out;
}

void CdrReader::align(std::size_t n, const char* field) {
  const std::size_t pad = (n - pos_ % n) % n;
  if (pad) take(pad, field);
}

std::string_view CdrReader::readString(const char* field) {
  const auto length = read<std::uint32_t>(field);
  const auto bytes = take(length, field);
  std::size_t n = bytes.size();
  if (n > 0 && bytes[n - 1] == 0) --n;  // the NUL counted in the length
  return {reinterpret_cast<const char*>(bytes.data()), n};
}

std::uint32_t CdrReader::readCount(const char* field, std::size_t min_element_bytes) {
  const auto count = read<std::uint32_t>(field);
  if (min_element_bytes && count > remaining() / min_element_bytes)
    throw BagError(what_ + ": message shorter than its layout: sequence " + field + " claims " +
                   std::to_string(count) + " elements of at least " + std::to_string(min_element_bytes) +
                   " bytes, " + std::to_string(remaining()) + " bytes left");
  return count;
}

TimeNs CdrReader::readTime(const char* field) {
  const auto sec = read<std::int32_t>(field);
  const auto nanosec = read<std::uint32_t>(field);
  return TimeNs(sec) * kNsPerSec + TimeNs(nanosec);
}

RosHeader CdrReader::readHeader() {
  RosHeader h;
  h.stamp_ns = readTime("header.stamp");
  h.frame_id = readString("header.frame_id");
  return h;
}

}  // namespace rigcal::bag
