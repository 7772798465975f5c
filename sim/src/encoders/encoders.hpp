#pragma once
// The vendor encoders behind makePacketEncoder, one file per vendor family. Each returns nullptr for
// a model outside its family.
#include <memory>

#include "rigcal/sim/packet_encoder.hpp"

namespace rigcal::sim::encoders {

std::unique_ptr<PacketEncoder> makeVelodyneEncoder(const LidarModel& model, const EncoderConfig& config);
std::unique_ptr<PacketEncoder> makeOusterEncoder(const LidarModel& model, const EncoderConfig& config);
std::unique_ptr<PacketEncoder> makeHesaiEncoder(const LidarModel& model, const EncoderConfig& config);
/// Pandar64 (pandar64_encoder.cpp); makeHesaiEncoder hands that model on to it.
std::unique_ptr<PacketEncoder> makePandar64Encoder(const LidarModel& model, const EncoderConfig& config);
std::unique_ptr<PacketEncoder> makeRobosenseEncoder(const LidarModel& model, const EncoderConfig& config);

}  // namespace rigcal::sim::encoders
