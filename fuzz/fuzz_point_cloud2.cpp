// Fuzzes the CDR sensor_msgs/PointCloud2 decoder. Half the inputs are raw bytes; the other half build a
// well-formed message around fuzzed dimensions, field table and data, so the point loop is reached.
// It must throw BagError or return a scan whose arrays agree, never read outside the message.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/point_cloud2_message.hpp"

namespace {

class Cdr {
 public:
  template <class T>
  void put(T v) {
    while ((bytes.size() - 4) % sizeof(T)) bytes.push_back(0);
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  void putString(const std::string& s) {
    put(std::uint32_t(s.size() + 1));
    bytes.insert(bytes.end(), s.begin(), s.end());
    bytes.push_back(0);
  }
  std::vector<std::uint8_t> bytes{0, 1, 0, 0};
};

std::vector<std::uint8_t> structured(FuzzedDataProvider& in) {
  static const char* const kNames[] = {"x", "y", "z", "intensity", "ring", "t", "time", "time_stamp",
                                       "timestamp", "offset_time", "channel", "reflectivity", "other"};
  Cdr c;
  c.put(in.ConsumeIntegral<std::int32_t>());
  c.put(in.ConsumeIntegral<std::uint32_t>());
  c.putString("frame");
  c.put(std::uint32_t(in.ConsumeIntegralInRange(0, 64)));    // height
  c.put(std::uint32_t(in.ConsumeIntegralInRange(0, 4096)));  // width
  const auto fields = in.ConsumeIntegralInRange(0, 8);
  c.put(std::uint32_t(fields));
  for (int i = 0; i < fields; ++i) {
    c.putString(kNames[in.ConsumeIntegralInRange<std::size_t>(0, std::size(kNames) - 1)]);
    c.put(std::uint32_t(in.ConsumeIntegralInRange(0, 64)));
    c.put(std::uint8_t(in.ConsumeIntegralInRange(0, 9)));
    c.put(std::uint32_t(1));
  }
  c.put(std::uint8_t(in.ConsumeBool() ? 0 : in.ConsumeIntegral<std::uint8_t>()));
  c.put(std::uint32_t(in.ConsumeIntegralInRange(0, 80)));    // point_step
  c.put(std::uint32_t(in.ConsumeIntegralInRange(0, 1 << 16)));  // row_step
  const auto data = in.ConsumeRemainingBytes<std::uint8_t>();
  c.put(std::uint32_t(data.size()));
  c.bytes.insert(c.bytes.end(), data.begin(), data.end());
  c.put(std::uint8_t(1));
  return c.bytes;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  const bool build = in.ConsumeBool();
  const std::vector<std::uint8_t> message = build ? structured(in) : in.ConsumeRemainingBytes<std::uint8_t>();
  try {
    const auto cloud = rigcal::bag::decodePointCloud2(message, "fuzz");
    const auto& s = cloud.scan;
    const std::size_t n = s.size();
    if (s.y.size() != n || s.z.size() != n || s.intensity.size() != n || s.ring.size() != n ||
        s.offset_ns.size() != n)
      std::abort();
  } catch (const rigcal::bag::BagError&) {
    // Refused with a one-line reason.
  }
  return 0;
}
