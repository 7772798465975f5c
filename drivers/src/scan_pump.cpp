#include "rigcal/drivers/scan_pump.hpp"

namespace rigcal::drivers {

void pumpScans(PacketSource& source, PacketDecoder& decoder, ScanAssembler& assembler,
               const std::function<bool(bool idle)>& keep_going) {
  DecodedPacket decoded;
  while (true) {
    auto packet = source.next();
    if (packet) {
      decoder.decode(*packet, decoded);
      decoded.receive_ns = packet->receive_ns;
      assembler.add(std::move(decoded));
    }
    if (keep_going ? !keep_going(!packet) : !packet) break;
  }
  decoder.flush(decoded);
  if (!decoded.points.empty()) assembler.add(std::move(decoded));
  assembler.flush();
}

}  // namespace rigcal::drivers
