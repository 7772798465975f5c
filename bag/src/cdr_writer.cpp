#include "rigcal/bag/cdr_writer.hpp"

namespace rigcal::bag {

void CdrWriter::putString(std::string_view s) {
  put(std::uint32_t(s.size() + 1));
  bytes_.insert(bytes_.end(), s.begin(), s.end());
  bytes_.push_back(0);
}

void CdrWriter::putTime(TimeNs t) {
  TimeNs sec = t / kNsPerSec, nanosec = t % kNsPerSec;
  if (nanosec < 0) {
    --sec;
    nanosec += kNsPerSec;
  }
  put(std::int32_t(sec));
  put(std::uint32_t(nanosec));
}

}  // namespace rigcal::bag
