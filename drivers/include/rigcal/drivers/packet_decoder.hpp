#pragma once
// A vendor decoder turns one UDP payload into points with absolute per-point times. Decoders are
// stateful (dual-return pairing, loss detection, time resolution) and never throw on packet content:
// a malformed packet comes back as kMalformed with a one-line reason, and is counted by the caller.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/core/scan.hpp"
#include "rigcal/core/time.hpp"
#include "rigcal/drivers/udp_packet.hpp"

namespace rigcal::drivers {

struct DecoderConfig {
  std::string model;                   // "VLP-16", "VLP-32C", "HDL-32E", "VLS-128", "OS1-64", "PandarXT32", ...
  std::filesystem::path calibration;   // Velodyne YAML / VeloView XML, Hesai angle CSV (empty: built-in)
  std::filesystem::path metadata;      // Ouster sensor_info JSON
  TimeSource time_source = TimeSource::kSensorClock;
  float min_range_m = 0.3f;
  float max_range_m = 300.0f;
};

struct DecodedPacket {
  enum class Kind : std::uint8_t {
    kData,       // points decoded (possibly zero after range filtering)
    kIgnored,    // a valid packet carrying no points (position/telemetry/IMU)
    kMalformed,  // wrong size, unknown magic, inconsistent field: dropped and counted
  };
  Kind kind = Kind::kData;
  std::string error;                    // kMalformed: names the packet field that is wrong
  TimeNs packet_time_ns = 0;            // time of the packet's first firing
  TimeNs receive_ns = 0;                // when its datagram arrived (pcap record time); 0 = unknown
  std::uint64_t order_key = 0;          // increases in sensor order (sequence / measurement id / time)
  std::uint32_t lost_before = 0;        // packets the decoder knows were lost just before this one
  std::optional<std::uint64_t> frame_id;  // sensor-defined frame number (Ouster), cut on its change
  std::vector<Point> points;            // in firing order, sensor frame (x fwd, y left, z up)
  std::vector<float> azimuth_deg;       // per point: rotor angle in [0, 360), for the scan cut

  void reset() {
    kind = Kind::kData;
    error.clear();
    packet_time_ns = 0;
    receive_ns = 0;
    order_key = 0;
    lost_before = 0;
    frame_id.reset();
    points.clear();
    azimuth_deg.clear();
  }
};

class PacketDecoder {
 public:
  virtual ~PacketDecoder() = default;
  /// Decodes `packet` into `out` (reset first). Never throws on packet content.
  virtual void decode(const UdpPacket& packet, DecodedPacket& out) = 0;
  /// End of input: hands over points the decoder still holds back (Hesai orders points by azimuth
  /// across packets). `out` is reset first; feed it to the assembler when it has points.
  virtual void flush(DecodedPacket& out) { out.reset(); }
  [[nodiscard]] virtual std::string model() const = 0;
  /// Nominal sweep rate (Hz), from metadata or the packet stream once known; 10 until then.
  [[nodiscard]] virtual double scanRateHz() const { return 10.0; }
  /// Upper bound of points in one sweep (sizes shared-memory slots).
  [[nodiscard]] virtual std::size_t maxPointsPerScan() const = 0;
};

/// Builds the decoder for config.model. Throws std::runtime_error with a one-line message naming the
/// model or the calibration/metadata file (and its bad field) when it cannot.
std::unique_ptr<PacketDecoder> makeDecoder(const DecoderConfig& config);

/// The model names makeDecoder accepts.
std::vector<std::string> supportedModels();

}  // namespace rigcal::drivers
