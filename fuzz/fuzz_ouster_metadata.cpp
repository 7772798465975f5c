// libFuzzer harness: arbitrary text as Ouster sensor_info JSON. Parsing either succeeds or throws
// std::runtime_error with a one-line message; a parsed file must give a decoder that builds.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

#include "rigcal/drivers/ouster/ouster_decoder.hpp"
#include "rigcal/drivers/ouster/ouster_raw_scan.hpp"

using namespace rigcal::drivers;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  ouster::Metadata md;
  try {
    md = ouster::parseMetadata(text, "fuzz.json");
  } catch (const std::runtime_error& e) {
    if (std::string_view(e.what()).find('\n') != std::string_view::npos) __builtin_trap();
    return 0;
  }
  if (md.beam_altitude_deg.size() != std::size_t(md.pixels_per_column)) __builtin_trap();
  if (std::size_t(md.columns_per_frame) * std::size_t(md.pixels_per_column) > (1u << 18)) return 0;  // keep it fast
  DecoderConfig config;
  config.model = "Ouster";
  try {
    ouster::OusterDecoder decoder(config, md);
    ouster::RawScan raw(md);
    std::vector<std::uint8_t> zeros(decoder.format().packet_size, 0);
    DecodedPacket out;
    UdpPacket packet;
    packet.payload = zeros;
    decoder.decode(packet, out);
    raw.add(zeros);
  } catch (const std::runtime_error&) {
    // a model/metadata mismatch is a clean refusal
  }
  return 0;
}
