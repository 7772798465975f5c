#pragma once
// The driver loop: pulls datagrams from a source, decodes them and assembles sweeps, until the source
// ends (pcap) or `keep_going` says stop (live: a source's next() returns nullopt on each idle timeout).
#include <functional>

#include "rigcal/drivers/packet_decoder.hpp"
#include "rigcal/drivers/packet_source.hpp"
#include "rigcal/drivers/scan_assembler.hpp"

namespace rigcal::drivers {

/// Without `keep_going`, returns when the source ends (its first empty next()). With it, asks
/// keep_going(idle) after every next() — idle: no datagram came — and returns once it says false.
/// At the end the decoder's held-back points and the partial sweep are flushed.
void pumpScans(PacketSource& source, PacketDecoder& decoder, ScanAssembler& assembler,
               const std::function<bool(bool idle)>& keep_going = {});

}  // namespace rigcal::drivers
