#include "rigcal/sim/packet_encoder.hpp"

#include "encoders/encoders.hpp"

namespace rigcal::sim {

std::unique_ptr<PacketEncoder> makePacketEncoder(const LidarModel& model, const EncoderConfig& config) {
  switch (model.vendor) {
    case LidarVendor::kVelodyne: return encoders::makeVelodyneEncoder(model, config);
    case LidarVendor::kOuster: return encoders::makeOusterEncoder(model, config);
    case LidarVendor::kHesai: return encoders::makeHesaiEncoder(model, config);
    case LidarVendor::kRobosense: return encoders::makeRobosenseEncoder(model, config);
  }
  return nullptr;
}

}  // namespace rigcal::sim
