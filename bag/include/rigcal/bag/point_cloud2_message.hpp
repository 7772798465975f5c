#pragma once
// sensor_msgs/PointCloud2 decoded from CDR without ROS: Header, u32 height, u32 width,
// PointField[]{string name, u32 offset, u8 datatype, u32 count}, bool is_bigendian, u32 point_step,
// u32 row_step, uint8[] data, bool is_dense. x y z (float32 or float64), intensity when present (any
// numeric type), ring/channel when present, and the per-point time under the names common drivers use:
//   t (u32 ns, ouster), time_stamp (u32 ns, nebula), offset_time (u32 ns, livox): relative to the stamp;
//   time (f32 s, velodyne/hesai ROS drivers): relative;
//   timestamp (f64 s, rslidar_sdk/hesai_ros_driver): absolute (a value under 1e6 s is taken as relative).
// Organised (height > 1, rows row_step apart) and unorganised clouds; points with a NaN/inf coordinate
// are dropped.
#include <cstdint>
#include <span>
#include <string>

#include "rigcal/core/scan.hpp"

namespace rigcal::bag {

inline constexpr const char* kPointCloud2Type = "sensor_msgs/msg/PointCloud2";

struct DecodedCloud {
  TimeNs header_stamp_ns = 0;
  std::string frame_id;
  std::string time_field;      // the per-point time field used, empty when none (all points at the stamp)
  std::size_t dropped_nan = 0;  // points skipped for a non-finite coordinate
  Scan scan;                    // stamp_ns = earliest point time
};

/// Throws BagError naming `what` and the field when the message is shorter than its layout, big-endian,
/// lacks x/y/z, or a field lies outside point_step.
DecodedCloud decodePointCloud2(std::span<const std::uint8_t> message, const std::string& what);

}  // namespace rigcal::bag
