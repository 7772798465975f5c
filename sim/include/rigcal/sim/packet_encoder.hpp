#pragma once
// The boundary between the physics and the wire formats. A PacketEncoder receives one sensor's
// simulated firing sequences, in order, and emits finished UDP payloads, byte-exact in the vendor's
// format, each with the time the sensor sends it. The recording writer wraps them in Ethernet/IPv4/UDP
// (fragmenting what exceeds the MTU) and stamps them as the capturing NIC would.
//
// What an encoder gets (see firing.hpp and lidar_model.hpp):
//  - SimFiring per firing sequence: sensor-clock start time (what timestamps in packets carry), rotor
//    azimuth at the start (clockwise from +x, degrees; Velodyne/Hesai block azimuth in 0.01° is
//    round(azimuth·100)), sequence number (gaps = the sensor was silent), frame (rotation count), and
//    for Ouster the measurement id (column).
//  - LaserReturn per beam in the model's data order (laser id / channel / pixel row): range in metres
//    from the lidar origin, already quantised to the model's distance unit (divide and round to get the
//    packet's integer), intensity 0..255, valid flag (an invalid return is encoded as "no return").
//  - The LidarModel: beam tables, firing period, distance unit, rotation rate.
// Encoders must be deterministic (same input → same bytes) and may keep state (partial packets,
// packet counters, frame ids).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rigcal/core/time.hpp"
#include "rigcal/sim/firing.hpp"
#include "rigcal/sim/lidar_model.hpp"

namespace rigcal::sim {

struct EncodedPacket {
  std::vector<std::uint8_t> payload;  // the UDP payload
  // When the sensor sends it, on the sensor's clock; never before the sensor time of the last firing
  // it carries (the capture is merged on that promise).
  TimeNs send_time_ns = 0;
  // Where it goes: 0 for the sensor's data port; RoboSense sends its DIFOP to EncoderConfig::info_port.
  std::uint16_t destination_port = 0;
};

/// What an encoder may need beyond the model (its packets must agree with the files rig.yaml names).
struct EncoderConfig {
  std::string sensor_name;
  std::uint16_t lidar_port = 0;       // Ouster metadata names it
  bool dual_return = false;           // single (strongest) return unless asked
  std::uint64_t seed = 0;             // for anything a real sensor randomises (e.g. initial counters)
  bool ouster_legacy = false;         // Ouster: LEGACY profile (the metadata must say so too)
  std::uint16_t info_port = 0;        // RoboSense: the DIFOP port (rig.yaml's source info_port)
};

class PacketEncoder {
 public:
  virtual ~PacketEncoder() = default;
  /// Encodes the firings of `batch` (consecutive calls continue the stream); appends every packet
  /// completed by them to `out`, in send order.
  virtual void add(const FiringBatch& batch, std::vector<EncodedPacket>& out) = 0;
  /// End of the recording: emits what the format allows of a partly filled packet.
  virtual void finish(std::vector<EncodedPacket>& out) = 0;
  [[nodiscard]] virtual std::string model() const = 0;
};

/// The encoder for `model`, or nullptr when none is built in yet (the vendor encoders are phase 2 of
/// the simulator; callers must then say so and write no capture). writeRecording (recording.hpp)
/// drives the encoders and writes the capture.
std::unique_ptr<PacketEncoder> makePacketEncoder(const LidarModel& model, const EncoderConfig& config);

}  // namespace rigcal::sim
