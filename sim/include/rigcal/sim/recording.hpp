#pragma once
// A whole capture: runs the simulation, feeds each sensor's firings to its packet encoder and writes
// every packet into one pcap, each sensor from its own address and port, stamped as a NIC would.
#include <filesystem>
#include <memory>
#include <vector>

#include "rigcal/sim/packet_encoder.hpp"
#include "rigcal/sim/recording_writer.hpp"
#include "rigcal/sim/simulation.hpp"

namespace rigcal::sim {

struct RecordingResult {
  SimulationStats stats;
  std::uint64_t datagrams = 0;
  std::uint64_t frames = 0;  // Ethernet frames (fragments count separately)
};

/// Where each sensor's packets come from and go to: its address and port; Ouster sends unicast to
/// the .100 host of its /24, Velodyne and Hesai broadcast (their defaults).
RecordingSensor recordingEndpoints(const SensorSpec& sensor, const LidarModel& model);

/// The port a sensor's second stream goes to (RoboSense DIFOP), 0 when it has none: the data port
/// + 1089, so the vendor's default 6699 pairs with its 7788 and sensors on distinct ports stay distinct.
std::uint16_t infoPort(const SensorSpec& sensor, const LidarModel& model);

/// Encoders for every sensor (nullptr entries where a model has none yet).
std::vector<std::unique_ptr<PacketEncoder>> makeEncoders(const Simulation& sim);

/// Runs `sim` and writes `pcap` (none when empty). `encoders` has one non-null encoder per sensor; `also`
/// (optional) receives the same firings and sweeps (e.g. to dump them), `datagrams` (optional) every
/// datagram with its capture stamp (e.g. to write a bag). Throws std::invalid_argument when an
/// encoder is missing, std::runtime_error on I/O errors.
RecordingResult writeRecording(const Simulation& sim, std::vector<std::unique_ptr<PacketEncoder>> encoders,
                               const std::filesystem::path& pcap, const SimulationOptions& options,
                               SimulationSink* also = nullptr, DatagramObserver* datagrams = nullptr);

}  // namespace rigcal::sim
