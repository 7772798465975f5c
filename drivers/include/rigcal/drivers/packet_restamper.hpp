#pragma once
// Shifts the sensor timestamps a lidar writes into its own data packets, in place, so that a capture
// replayed over UDP can look recorded at another time while every packet stays valid for our decoders:
//  - Velodyne: the u32 µs past the top of the hour (modulo the hour: the receiver takes the hour from
//    its clock, so only the minutes, seconds and µs travel);
//  - Ouster: every column's u64 ns timestamp, and the CRC-64 footer when the firmware writes one;
//  - Hesai: the tail's UTC date-time and µs, and the tail CRC (protocol 3.2);
//  - RoboSense: the MSOP header's UTC seconds and µs (DIFOP device-info packets are left as they are).
// The shift is in whole microseconds: the finest unit every vendor carries, so that sensors of
// different vendors shifted by the same amount stay exactly as consistent as they were.
// Packets that are not the sensor's data packets (position, IMU, GPS, foreign) are left untouched.
#include <cstdint>
#include <memory>
#include <span>

#include "rigcal/drivers/packet_decoder.hpp"

namespace rigcal::drivers {

class PacketRestamper {
 public:
  /// For one sensor's model (and its Ouster metadata). Throws std::runtime_error with a one-line reason
  /// naming the model or the metadata file when it cannot.
  explicit PacketRestamper(const DecoderConfig& sensor);
  ~PacketRestamper();
  PacketRestamper(PacketRestamper&&) noexcept;
  PacketRestamper& operator=(PacketRestamper&&) noexcept;

  /// Adds `shift_us` to every timestamp in `payload`. Returns false, and leaves the payload as it was,
  /// when it is not one of this sensor's data packets (or a shifted Hesai date would leave 1900-2155).
  bool restamp(std::span<std::uint8_t> payload, std::int64_t shift_us) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rigcal::drivers
