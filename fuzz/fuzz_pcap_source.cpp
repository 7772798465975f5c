// Fuzzes PcapSource: any bytes as a capture file. It must either refuse the file with
// std::runtime_error or yield datagrams whose payloads are readable and within UDP's limits.
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include "fuzz_input_file.hpp"
#include "rigcal/drivers/pcap_source.hpp"

using rigcal::drivers::PacketFilter;
using rigcal::drivers::PcapSource;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static rigcal::fuzz::InputFile file("fuzz_pcap_source");
  const std::string& path = file.write(data, size);
  try {
    PcapSource source(path, PacketFilter{});
    std::uint64_t checksum = 0, count = 0;
    while (auto packet = source.next()) {
      if (packet->payload.size() > 65535 - 8) std::abort();
      for (const std::uint8_t b : packet->payload) checksum += b;  // every byte must be readable
      ++count;
    }
    const auto& stats = source.stats();
    if (stats.packets != count) std::abort();
    (void)source.warning();
    if (checksum == 0xdeadbeefdeadbeefULL) std::abort();  // keep the reads from being optimised away
  } catch (const std::runtime_error&) {
    // Refused as a capture: the documented outcome for a file that is not one.
  }
  return 0;
}
