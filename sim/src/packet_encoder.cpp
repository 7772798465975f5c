#include "rigcal/sim/packet_encoder.hpp"

namespace rigcal::sim {

std::unique_ptr<PacketEncoder> makePacketEncoder(const LidarModel& /*model*/, const EncoderConfig& /*config*/) {
  // Phase 2 adds one encoder per vendor format here (Velodyne VLP-16/VLP-32C/VLS-128, Ouster RNG19,
  // Hesai XT32). Until then no model has one: no capture is written rather than a fake one.
  return nullptr;
}

}  // namespace rigcal::sim
