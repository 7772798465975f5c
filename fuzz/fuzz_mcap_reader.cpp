// Fuzzes the MCAP reader (footer, summary, chunk index, linear scan, zstd/lz4 chunks, CRCs): any bytes as
// an .mcap file. It must refuse the file with BagError or stream messages in log-time order whose bytes
// are all readable, and never crash, hang or over-allocate.
#include <cstdint>
#include <cstdlib>

#include "fuzz_input_file.hpp"
#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/mcap_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static rigcal::fuzz::InputFile file("fuzz_mcap_reader");
  const std::string& path = file.write(data, size);
  try {
    rigcal::bag::McapFile mcap(path);
    std::uint64_t checksum = 0;
    rigcal::TimeNs previous = 0;
    bool first = true;
    while (const auto m = mcap.next()) {
      if (m->topic >= mcap.topics().size()) std::abort();
      // Unsigned log times: compare as the reader does (u64 order).
      if (!first && std::uint64_t(m->log_time_ns) < std::uint64_t(previous)) std::abort();
      previous = m->log_time_ns;
      first = false;
      for (const std::uint8_t b : m->data) checksum += b;  // every byte must be readable
    }
    (void)mcap.warning();
    if (checksum == 0xdeadbeefdeadbeefULL) std::abort();
  } catch (const rigcal::bag::BagError&) {
    // Refused with a one-line reason: the documented outcome for a corrupt file.
  }
  return 0;
}
