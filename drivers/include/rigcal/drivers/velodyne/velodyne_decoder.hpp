#pragma once
// Velodyne decoder: VLP-16, VLP-32C, HDL-32E and VLS-128 data packets (single and dual return) into
// points with absolute per-firing times. Position packets (512 bytes, port 8308) are ignored.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rigcal/core/time.hpp"
#include "rigcal/drivers/packet_decoder.hpp"

namespace rigcal::drivers {

/// Velodyne-specific choices beyond DecoderConfig. The defaults are what rigcal uses; the others
/// exist to reproduce other decoders' output (tests compare against nebula reference decodes).
struct VelodyneOptions {
  /// What DecodedPacket::azimuth_deg reports, i.e. where ScanAssembler can cut a sweep.
  enum class Cut : std::uint8_t {
    kBlock,   // each point's block azimuth: sweeps split between blocks (VeloView's frames)
    kPacket,  // the packet's first block azimuth: sweeps split between packets, the packet that
              // crosses the cut angle staying with the sweep it started (nebula's scans)
  };
  Cut cut = Cut::kBlock;
  /// Per-point azimuth as nebula computes it (its block/step pairing, rounding in float, azimuth
  /// correction folded into the rounded angle, no interpolation in a packet's last block) instead of
  /// by firing time. Only for bit-level comparison with nebula decodes.
  bool nebula_azimuth = false;
};

/// Builds a Velodyne decoder. `config.calibration` is a ROS YAML or VeloView XML file; when empty the
/// manual's nominal table is used (VLP-16, VLP-32C, HDL-32E; the VLS-128 requires a file). Throws
/// std::runtime_error naming the model, or the file and its bad field.
std::unique_ptr<PacketDecoder> makeVelodyneDecoder(const DecoderConfig& config);
std::unique_ptr<PacketDecoder> makeVelodyneDecoder(const DecoderConfig& config, const VelodyneOptions& options);

/// The model names makeVelodyneDecoder accepts.
std::vector<std::string> velodyneModels();

namespace velodyne {

struct Calibration;
enum class Model : std::uint8_t;

/// The same from an already loaded calibration (its laser count must be the model's).
std::unique_ptr<PacketDecoder> makeDecoder(Model model, const Calibration& calibration, const DecoderConfig& config,
                                           const VelodyneOptions& options = {});

/// Resolves a Velodyne timestamp (µs past the top of the hour) to absolute time, taking the hour from
/// a reference clock (the receive time). The first packet takes the hour that puts the sensor time
/// nearest the reference; later packets keep the running hour and step it when the microsecond count
/// wraps (forward at the top of the hour, backward for a packet reordered across it). A jump of the
/// reference by more than ten minutes re-anchors.
class HourResolver {
 public:
  TimeNs resolve(std::uint32_t micros_past_hour, TimeNs reference_ns);
  void reset() { anchored_ = false; }

 private:
  bool anchored_ = false;
  TimeNs hour_start_ns_ = 0;   // top of the hour of the last resolved time
  TimeNs last_ns_ = 0;         // last resolved time
  TimeNs last_reference_ns_ = 0;
};

}  // namespace velodyne
}  // namespace rigcal::drivers
